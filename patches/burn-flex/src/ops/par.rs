//! mprog patch: element-wise work split across the rayon pool, and vectorisable f32
//! `exp` / `erf` kernels.
//!
//! Upstream burn-flex 0.22.1 runs element-wise ops (unary, scalar, same-shape binary,
//! GELU and its backward) on the calling thread, and its GELU calls libm's scalar `erff`
//! per element. On a 2-core machine that left half the CPU idle in a transformer's
//! training step (see mprog's `patches/README.md` for the profile). These helpers are the
//! whole change: chunks of at least `PAR_MIN_ELEMS` go to rayon, and the math kernels are
//! written branch-free so that LLVM vectorises them inside `macerator::with_simd`
//! (which compiles them once per instruction set and dispatches at run time).

/// Below this many elements an element-wise op stays on the calling thread: rayon's
/// fork/join (a few µs) would cost more than the second core saves.
pub(crate) const PAR_MIN_ELEMS: usize = 32 * 1024;

/// Elements per rayon task (a multiple of 64 keeps chunk starts cache-line aligned).
#[cfg(feature = "rayon")]
pub(crate) fn chunk_len(len: usize) -> usize {
    let tasks = 4 * rayon::current_num_threads().max(1);
    (len.div_ceil(tasks)).div_ceil(64).max(1) * 64
}

/// Runs `f` over `data`, split across the rayon pool when `data` is large.
pub(crate) fn for_chunks_mut<T, F>(data: &mut [T], f: F)
where
    T: Send,
    F: Fn(&mut [T]) + Send + Sync,
{
    #[cfg(feature = "rayon")]
    if data.len() >= PAR_MIN_ELEMS {
        use rayon::prelude::*;
        let chunk = chunk_len(data.len());
        data.par_chunks_mut(chunk).for_each(f);
        return;
    }
    f(data)
}

/// Runs `f` over matching chunks of `dst` and `src` (same length), split across the
/// rayon pool when large.
pub(crate) fn zip_chunks_mut<T, U, F>(dst: &mut [T], src: &[U], f: F)
where
    T: Send,
    U: Sync,
    F: Fn(&mut [T], &[U]) + Send + Sync,
{
    debug_assert_eq!(dst.len(), src.len());
    #[cfg(feature = "rayon")]
    if dst.len() >= PAR_MIN_ELEMS {
        use rayon::prelude::*;
        let chunk = chunk_len(dst.len());
        dst.par_chunks_mut(chunk)
            .zip(src.par_chunks(chunk))
            .for_each(|(d, s)| f(d, s));
        return;
    }
    f(dst, src)
}

/// `src.map(op)` into a new vector, split across the rayon pool when large.
pub(crate) fn map_collect<E, R, F>(src: &[E], op: F) -> alloc::vec::Vec<R>
where
    E: Sync + Copy,
    R: Send,
    F: Fn(E) -> R + Send + Sync,
{
    #[cfg(feature = "rayon")]
    if src.len() >= PAR_MIN_ELEMS {
        use rayon::prelude::*;
        let mut out = alloc::vec::Vec::with_capacity(src.len());
        src.par_iter()
            .with_min_len(chunk_len(src.len()))
            .map(|&x| op(x))
            .collect_into_vec(&mut out);
        return out;
    }
    src.iter().map(|&x| op(x)).collect()
}

/// `n` zeros, written across the rayon pool when `n` is large. New tensors (every matmul
/// output) are zeroed on the calling thread otherwise, while the workers wait.
pub(crate) fn zeroed<T: bytemuck::Zeroable + Copy + Send + Sync>(n: usize) -> alloc::vec::Vec<T> {
    #[cfg(feature = "rayon")]
    if n >= PAR_MIN_ELEMS {
        use rayon::prelude::*;
        let mut out = alloc::vec::Vec::with_capacity(n);
        out.spare_capacity_mut()[..n]
            .par_chunks_mut(chunk_len(n))
            .for_each(|c| c.fill(core::mem::MaybeUninit::new(T::zeroed())));
        // Safety: every one of the n elements was written just above.
        unsafe { out.set_len(n) };
        return out;
    }
    alloc::vec![T::zeroed(); n]
}

// ---------------------------------------------------------------------------------------
// Branch-free f32 math (vectorised by LLVM inside the `with_simd` kernels below)
// ---------------------------------------------------------------------------------------

/// `exp(x)` for f32: Cephes' range reduction `x = n ln2 + r` and degree-6 polynomial,
/// with `2^n` built from the exponent bits. Max relative error about 2e-7; results below
/// f32's normal range flush to 0 (x < -87.33), x > 88.72 gives +inf, NaN stays NaN.
#[inline(always)]
pub fn exp_f32(x: f32) -> f32 {
    const LOG2E: f32 = core::f32::consts::LOG2_E;
    const LN2_HI: f32 = 0.693_359_4;
    const LN2_LO: f32 = -2.121_944_4e-4;
    // ln(f32::MAX) and ln(f32::MIN_POSITIVE)
    const X_MAX: f32 = 88.722_83;
    const X_MIN: f32 = -87.336_55;
    // 1.5 * 2^23: adding it rounds to the nearest integer in the low mantissa bits.
    const ROUND: f32 = 12_582_912.0;
    let xc = x.clamp(X_MIN, X_MAX);
    let t = xc * LOG2E + ROUND;
    let n = t - ROUND;
    let r = xc - n * LN2_HI - n * LN2_LO;
    let p = 1.987_569_1e-4_f32;
    let p = p * r + 1.398_199_9e-3;
    let p = p * r + 8.333_452e-3;
    let p = p * r + 4.166_579_6e-2;
    let p = p * r + 1.666_666_5e-1;
    let p = p * r + 5.000_000_1e-1;
    let p = p * (r * r) + r + 1.0;
    // The rounded n (in -126..=128) sits in t's low mantissa bits, offset by 0x40_0000.
    // 2^n is applied as 2^(n-1) * 2 so that n = 128 stays finite in the bits; n = -126
    // gives the bit pattern 0, which is the flush to zero.
    let n_int = (t.to_bits() as i32).wrapping_sub(0x4B40_0000);
    let half_scale = f32::from_bits(((n_int + 126).max(0) << 23) as u32);
    let y = p * half_scale * 2.0;
    if x > X_MAX { f32::INFINITY } else { y }
}

/// `erf(x)` for f32: the rational approximation Eigen and XLA use (odd degree-13 over
/// even degree-8 polynomial on x clamped to [-4, 4], where f32 erf is already ±1).
/// Max absolute error about 1e-7.
#[inline(always)]
pub fn erf_f32(x: f32) -> f32 {
    let x = x.clamp(-4.0, 4.0);
    let x2 = x * x;
    let p = -2.726_142_3e-10_f32;
    let p = p * x2 + 2.770_681_4e-8;
    let p = p * x2 + -2.101_024e-6;
    let p = p * x2 + -5.692_506_4e-5;
    let p = p * x2 + -7.349_906_3e-4;
    let p = p * x2 + -2.954_600_1e-3;
    let p = p * x2 + -1.609_603_3e-2;
    let p = p * x;
    let q = -1.456_607_2e-5_f32;
    let q = q * x2 + -2.133_740_6e-4;
    let q = q * x2 + -1.682_827e-3;
    let q = q * x2 + -7.373_329e-3;
    let q = q * x2 + -1.426_474e-2;
    p / q
}

const FRAC_1_SQRT_2: f32 = core::f32::consts::FRAC_1_SQRT_2;
/// 1 / sqrt(2π)
const INV_SQRT_2PI: f32 = 0.398_942_3;

/// GELU (erf form): `0.5 x (1 + erf(x / √2))`.
#[inline(always)]
pub fn gelu_f32(x: f32) -> f32 {
    0.5 * x * (1.0 + erf_f32(x * FRAC_1_SQRT_2))
}

/// GELU's derivative times the incoming gradient.
#[inline(always)]
pub fn gelu_grad_f32(x: f32, g: f32) -> f32 {
    let cdf = 0.5 * (1.0 + erf_f32(x * FRAC_1_SQRT_2));
    let pdf = INV_SQRT_2PI * exp_f32(-0.5 * x * x);
    g * (cdf + x * pdf)
}

#[cfg(feature = "simd")]
mod kernels {
    use super::*;

    #[macerator::with_simd]
    pub fn exp_inplace<S: macerator::Simd>(a: &mut [f32]) {
        for v in a.iter_mut() {
            *v = exp_f32(*v);
        }
    }

    #[macerator::with_simd]
    pub fn gelu_inplace<S: macerator::Simd>(a: &mut [f32]) {
        for v in a.iter_mut() {
            *v = gelu_f32(*v);
        }
    }

    #[macerator::with_simd]
    pub fn exp_into<S: macerator::Simd>(out: &mut [f32], x: &[f32]) {
        for (o, &x) in out.iter_mut().zip(x) {
            *o = exp_f32(x);
        }
    }

    #[macerator::with_simd]
    pub fn gelu_into<S: macerator::Simd>(out: &mut [f32], x: &[f32]) {
        for (o, &x) in out.iter_mut().zip(x) {
            *o = gelu_f32(x);
        }
    }

    #[macerator::with_simd]
    pub fn gelu_grad_inplace<S: macerator::Simd>(g: &mut [f32], x: &[f32]) {
        for (g, &x) in g.iter_mut().zip(x) {
            *g = gelu_grad_f32(x, *g);
        }
    }
}

#[cfg(not(feature = "simd"))]
mod kernels {
    use super::*;

    pub fn exp_inplace(a: &mut [f32]) {
        a.iter_mut().for_each(|v| *v = exp_f32(*v));
    }

    pub fn gelu_inplace(a: &mut [f32]) {
        a.iter_mut().for_each(|v| *v = gelu_f32(*v));
    }

    pub fn gelu_grad_inplace(g: &mut [f32], x: &[f32]) {
        g.iter_mut().zip(x).for_each(|(g, &x)| *g = gelu_grad_f32(x, *g));
    }

    pub fn exp_into(out: &mut [f32], x: &[f32]) {
        out.iter_mut().zip(x).for_each(|(o, &x)| *o = exp_f32(x));
    }

    pub fn gelu_into(out: &mut [f32], x: &[f32]) {
        out.iter_mut().zip(x).for_each(|(o, &x)| *o = gelu_f32(x));
    }
}

/// `a = exp(a)`, vectorised and split across threads.
pub fn exp_inplace_f32(a: &mut [f32]) {
    for_chunks_mut(a, kernels::exp_inplace);
}

/// `a = gelu(a)`, vectorised and split across threads.
pub fn gelu_inplace_f32(a: &mut [f32]) {
    for_chunks_mut(a, kernels::gelu_inplace);
}

/// `g = g * gelu'(x)`, vectorised and split across threads.
pub fn gelu_grad_inplace_f32(g: &mut [f32], x: &[f32]) {
    zip_chunks_mut(g, x, kernels::gelu_grad_inplace);
}

/// `exp` of a shared input into a new vector, vectorised and split across threads.
pub fn exp_f32_to_vec(x: &[f32]) -> alloc::vec::Vec<f32> {
    let mut out = alloc::vec![0.0f32; x.len()];
    zip_chunks_mut(&mut out, x, kernels::exp_into);
    out
}

/// `gelu` of a shared input (autodiff keeps GELU's input for the backward, so in
/// training it is never uniquely owned) into a new vector.
pub fn gelu_f32_to_vec(x: &[f32]) -> alloc::vec::Vec<f32> {
    let mut out = alloc::vec![0.0f32; x.len()];
    zip_chunks_mut(&mut out, x, kernels::gelu_into);
    out
}

/// Elements per independently seeded block of a Bernoulli mask: fixed, so the mask a
/// seed gives does not depend on the number of threads.
const BERNOULLI_BLOCK: usize = 64 * 1024;

/// A Bernoulli(p) mask of 1.0 / 0.0 (dropout's `random_like`), drawn 16 bits per element
/// from one ChaCha stream per block of `BERNOULLI_BLOCK` elements, each seeded from one
/// draw of `rng`, and filled in parallel. The sequential sampler drew a whole u64 per
/// element from one stream: 10 % of a training step. `p` is resolved to 1/65536.
pub fn bernoulli_f32(
    n: usize,
    p: f64,
    rng: &mut burn_std::rand::StdRng,
) -> alloc::vec::Vec<f32> {
    use burn_std::rand::{RngExt, SeedableRng, StdRng};
    let base: u64 = rng.random();
    let threshold = (p.clamp(0.0, 1.0) * 65536.0).round() as u32; // keep when draw < threshold
    let mut out = alloc::vec![0.0f32; n];
    let fill = |block: usize, chunk: &mut [f32]| {
        let seed = base ^ (block as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        let mut r = StdRng::seed_from_u64(seed);
        for quad in chunk.chunks_mut(4) {
            let bits: u64 = r.random();
            for (k, v) in quad.iter_mut().enumerate() {
                let draw = ((bits >> (16 * k)) & 0xFFFF) as u32;
                *v = if draw < threshold { 1.0 } else { 0.0 };
            }
        }
    };
    #[cfg(feature = "rayon")]
    {
        use rayon::prelude::*;
        out.par_chunks_mut(BERNOULLI_BLOCK)
            .enumerate()
            .for_each(|(b, c)| fill(b, c));
    }
    #[cfg(not(feature = "rayon"))]
    for (b, c) in out.chunks_mut(BERNOULLI_BLOCK).enumerate() {
        fill(b, c);
    }
    out
}
