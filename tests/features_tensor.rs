//! The burn `recover_from_ric_tensor`: golden clip, agreement with the f32 version on random
//! features, gradients against finite differences, (de)normalisation, and (ignored) timings.

mod common;

use burn::tensor::{Device, Tensor, TensorData};
use common::{golden, mean_std};
use mprog::features::layout::RIC;
use mprog::features::{
    FEATURE_DIM, denormalize, normalize, recover_from_ric, recover_from_ric_tensor,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::Normal;

/// Random de-normalised features with realistic scales, flat `[b, n, 263]`.
fn random_features(b: usize, n: usize, seed: u64) -> Vec<f32> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let normal = Normal::new(0.0f32, 1.0).unwrap();
    (0..b * n * FEATURE_DIM)
        .map(|i| {
            let scale = match i % FEATURE_DIM {
                0 => 0.05,
                1 | 2 => 0.05,
                3 => 0.1,
                _ => 0.4,
            };
            let offset = if i % FEATURE_DIM == 3 { 0.9 } else { 0.0 };
            offset + scale * rng.sample(normal)
        })
        .collect()
}

fn to_tensor(data: Vec<f32>, b: usize, n: usize, device: &Device) -> Tensor<3> {
    Tensor::from_data(TensorData::new(data, [b, n, FEATURE_DIM]), device)
}

fn to_vec<const D: usize>(t: Tensor<D>) -> Vec<f32> {
    t.into_data().try_into_vec::<f32>().unwrap()
}

#[test]
fn golden_clip_through_the_tensor_version() {
    let (feats, joints) = golden();
    let out = recover_from_ric_tensor(to_tensor(feats, 1, 170, &Device::flex()));
    assert_eq!(out.dims(), [1, 170, 22, 3]);
    let err = to_vec(out)
        .iter()
        .zip(joints.to_flat())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    println!("golden recover_from_ric_tensor: max coordinate error {err:.2e} m");
    assert!(err < 1e-4, "max error {err}");
}

#[test]
fn tensor_version_equals_the_f32_version_on_random_features() {
    let (b, n) = (3, 60);
    let data = random_features(b, n, 7);
    let out = to_vec(recover_from_ric_tensor(to_tensor(
        data.clone(),
        b,
        n,
        &Device::flex(),
    )));
    let mut max = 0.0f32;
    for (i, clip) in data.chunks_exact(n * FEATURE_DIM).enumerate() {
        let want = recover_from_ric(clip).unwrap().to_flat();
        let got = &out[i * n * 66..(i + 1) * n * 66];
        max = got
            .iter()
            .zip(&want)
            .map(|(a, b)| (a - b).abs())
            .fold(max, f32::max);
    }
    println!("tensor vs f32 on random features: max difference {max:.2e}");
    assert!(max < 1e-4, "max difference {max}");
}

/// Loss Σ (J − T)² of the f32 version, in f64.
fn loss_f32(data: &[f32], targets: &[f32]) -> f64 {
    let j = recover_from_ric(data).unwrap().to_flat();
    j.iter()
        .zip(targets)
        .map(|(a, t)| ((a - t) as f64).powi(2))
        .sum()
}

#[test]
fn gradient_matches_finite_differences() {
    let (b, n) = (1, 12);
    let data = random_features(b, n, 11);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let targets: Vec<f32> = (0..b * n * 66)
        .map(|_| rng.random_range(-1.0..1.0))
        .collect();
    let device = Device::flex().autodiff();
    let x = to_tensor(data.clone(), b, n, &device).require_grad();
    let t = Tensor::<4>::from_data(TensorData::new(targets.clone(), [b, n, 22, 3]), &device);
    let loss = (recover_from_ric_tensor(x.clone()) - t).square().sum();
    let grads = loss.backward();
    let g = to_vec(x.grad(&grads).expect("gradient of the features"));
    let eps = 1e-3f32;
    let mut worst = 0.0f64;
    for (i, &gi) in g.iter().enumerate() {
        let col = i % FEATURE_DIM;
        if col >= RIC.end {
            // Rotation, velocity and contact blocks do not enter the joints.
            assert_eq!(gi, 0.0, "feature {i}");
            continue;
        }
        let (mut plus, mut minus) = (data.clone(), data.clone());
        plus[i] += eps;
        minus[i] -= eps;
        let fd = (loss_f32(&plus, &targets) - loss_f32(&minus, &targets)) / (2.0 * eps as f64);
        let err = (gi as f64 - fd).abs() / (1.0 + fd.abs());
        worst = worst.max(err);
        assert!(
            err < 2e-3,
            "feature {i} (column {col}): autodiff {gi} vs finite difference {fd}"
        );
    }
    println!("gradient vs finite differences: worst relative error {worst:.2e}");
}

#[test]
fn normalize_round_trips_and_matches_the_formula() {
    let (mean, std) = mean_std();
    let device = Device::flex();
    let m = Tensor::<1>::from_data(TensorData::new(mean.clone(), [FEATURE_DIM]), &device);
    let s = Tensor::<1>::from_data(TensorData::new(std.clone(), [FEATURE_DIM]), &device);
    let data = random_features(2, 5, 1);
    let x = to_tensor(data.clone(), 2, 5, &device);
    let z = normalize(x, m.clone(), s.clone());
    let zv = to_vec(z.clone());
    let i = FEATURE_DIM + 100;
    assert!((zv[i] - (data[i] - mean[100]) / std[100]).abs() < 1e-4);
    let back = to_vec(denormalize(z, m, s));
    let max = back
        .iter()
        .zip(&data)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    assert!(max < 1e-5, "round trip {max}");
}

/// Median wall time (ms) of `f` over `runs` runs after one warm-up.
fn time_ms(runs: usize, mut f: impl FnMut()) -> f64 {
    f();
    let mut t: Vec<f64> = (0..runs)
        .map(|_| {
            let start = std::time::Instant::now();
            f();
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[runs / 2]
}

/// Timings of `recover_from_ric_tensor` on `Device::flex()`, N = 196:
/// `cargo test --test features_tensor -- --ignored --nocapture recover_timings`.
#[test]
#[ignore = "timing table, run by hand"]
fn recover_timings() {
    mprog::backend::tune_allocator();
    let n = 196;
    println!("| B | fwd (flex) | fwd (flex+autodiff) | fwd+bwd of Σ(J−T)² |");
    println!("| --- | --- | --- | --- |");
    for b in [1usize, 32] {
        let runs = if b == 1 { 51 } else { 11 };
        let data = random_features(b, n, 5);
        let plain = Device::flex();
        let ad = Device::flex().autodiff();
        let x = to_tensor(data.clone(), b, n, &plain);
        let fwd = time_ms(runs, || {
            let _ = to_vec(recover_from_ric_tensor(x.clone()));
        });
        let xa = to_tensor(data.clone(), b, n, &ad);
        let fwd_ad = time_ms(runs, || {
            let _ = to_vec(recover_from_ric_tensor(xa.clone().require_grad()));
        });
        let t = Tensor::<4>::zeros([b, n, 22, 3], &ad);
        let both = time_ms(runs, || {
            let x = xa.clone().require_grad();
            let loss = (recover_from_ric_tensor(x.clone()) - t.clone())
                .square()
                .sum();
            let g = loss.backward();
            let _ = to_vec(x.grad(&g).unwrap());
        });
        println!("| {b} | {fwd:.2} ms | {fwd_ad:.2} ms | {both:.2} ms |");
    }
}
