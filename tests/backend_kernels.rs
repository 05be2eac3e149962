//! The patched burn-flex kernels (`patches/burn-flex`, see `patches/README.md`) against
//! f64 references: GELU and its gradient, `exp`, softmax, and element-wise arithmetic,
//! each on a small tensor (the single-thread path) and a large one (split across the
//! rayon pool), on a uniquely owned tensor (computed in place) and a shared one.

use burn::tensor::activation::{gelu, softmax};
use burn::tensor::{Device, Int, Tensor, TensorData};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// flex's seeded RNG is one per process: the tests that draw from it take turns.
static RNG: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Small enough for one thread, and large enough for the parallel path (≥ 32K elements).
const SIZES: [usize; 2] = [1_000, 100_003];

fn random(n: usize, lo: f32, hi: f32, seed: u64) -> Vec<f32> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| rng.random_range(lo..hi)).collect()
}

fn tensor(v: &[f32], device: &Device) -> Tensor<1> {
    Tensor::from_data(TensorData::new(v.to_vec(), [v.len()]), device)
}

fn values(t: Tensor<1>) -> Vec<f32> {
    t.into_data().try_into_vec::<f32>().unwrap()
}

/// erf in f64 by its Maclaurin series (|x| ≤ 3.5: 1e-12 or better after cancellation),
/// and 1 - erfc by Lentz's continued fraction beyond.
fn erf_f64(x: f64) -> f64 {
    let a = x.abs();
    let v = if a <= 3.5 {
        let (mut term, mut sum, mut n) = (a, a, 0.0);
        loop {
            n += 1.0;
            term *= -a * a / n;
            let add = term / (2.0 * n + 1.0);
            sum += add;
            if add.abs() <= 1e-17 * sum.abs() {
                break;
            }
        }
        sum * 2.0 / std::f64::consts::PI.sqrt()
    } else {
        // erfc(a) = exp(-a²)/√π · 1/(a + (1/2)/(a + 1/(a + (3/2)/(a + …))))
        let mut f = a;
        for k in (1..60).rev() {
            f = a + (k as f64 / 2.0) / f;
        }
        1.0 - (-a * a).exp() / std::f64::consts::PI.sqrt() / f
    };
    v.copysign(x)
}

fn gelu_f64(x: f64) -> f64 {
    0.5 * x * (1.0 + erf_f64(x / std::f64::consts::SQRT_2))
}

fn gelu_grad_f64(x: f64) -> f64 {
    let pdf = (-0.5 * x * x).exp() / (2.0 * std::f64::consts::PI).sqrt();
    0.5 * (1.0 + erf_f64(x / std::f64::consts::SQRT_2)) + x * pdf
}

#[test]
fn the_f64_reference_erf_is_right() {
    // Values from Abramowitz & Stegun, table 7.1 and beyond.
    for (x, want) in [
        (0.5, 0.520_499_877_813_046_5),
        (1.0, 0.842_700_792_949_714_9),
        (2.0, 0.995_322_265_018_952_7),
        (3.0, 0.999_977_909_503_001_4),
        (4.0, 0.999_999_984_582_742_1),
    ] {
        assert!((erf_f64(x) - want).abs() < 1e-13, "erf({x})");
        assert!((erf_f64(-x) + want).abs() < 1e-13, "erf(-{x})");
    }
}

#[test]
fn gelu_matches_the_erf_definition() {
    let device = Device::flex();
    for (seed, &n) in SIZES.iter().enumerate() {
        let mut x = random(n, -8.0, 8.0, seed as u64);
        x[..6].copy_from_slice(&[0.0, -0.0, 4.0 * std::f32::consts::SQRT_2, -6.0, 30.0, -30.0]);
        let input = tensor(&x, &device);
        // A shared input takes the allocating path, a unique one is computed in place.
        let shared = values(gelu(input.clone()));
        let unique = values(gelu(input));
        assert_eq!(
            shared, unique,
            "n={n}: in-place and allocating paths differ"
        );
        for (&xi, &yi) in x.iter().zip(&unique) {
            let want = gelu_f64(xi as f64);
            let err = (yi as f64 - want).abs();
            assert!(
                err <= 2e-6 * (1.0 + want.abs()),
                "gelu({xi}) = {yi}, want {want}"
            );
        }
    }
}

#[test]
fn gelu_gradient_matches_its_formula() {
    let device = Device::flex().autodiff();
    for (seed, &n) in SIZES.iter().enumerate() {
        let x = random(n, -6.0, 6.0, 10 + seed as u64);
        let upstream = random(n, -2.0, 2.0, 20 + seed as u64);
        let input = tensor(&x, &device).require_grad();
        let loss = (gelu(input.clone()) * tensor(&upstream, &device)).sum();
        let grads = loss.backward();
        let grad = values(input.grad(&grads).unwrap());
        for ((&xi, &gi), &ui) in x.iter().zip(&grad).zip(&upstream) {
            let want = ui as f64 * gelu_grad_f64(xi as f64);
            assert!(
                (gi as f64 - want).abs() <= 2e-6 * (1.0 + want.abs()),
                "d gelu({xi}) · {ui} = {gi}, want {want}"
            );
        }
    }
}

#[test]
fn exp_is_accurate_and_keeps_its_edges() {
    let device = Device::flex();
    for (seed, &n) in SIZES.iter().enumerate() {
        let x = random(n, -80.0, 80.0, 30 + seed as u64);
        let shared_in = tensor(&x, &device);
        let shared = values(shared_in.clone().exp());
        let unique = values(shared_in.exp());
        assert_eq!(
            shared, unique,
            "n={n}: in-place and allocating paths differ"
        );
        for (&xi, &yi) in x.iter().zip(&unique) {
            let want = (xi as f64).exp();
            assert!(
                ((yi as f64 - want) / want).abs() < 1e-6,
                "exp({xi}) = {yi}, want {want}"
            );
        }
    }
    let edges = values(tensor(&[0.0, 88.0, 89.0, 1e4, -90.0, -1e4, f32::NAN], &device).exp());
    assert_eq!(edges[0], 1.0);
    assert!(edges[1].is_finite() && (edges[1] / 88f32.exp() - 1.0).abs() < 1e-6);
    assert_eq!(edges[2], f32::INFINITY);
    assert_eq!(edges[3], f32::INFINITY);
    assert!(edges[4] >= 0.0 && edges[4] < 1e-38);
    assert_eq!(edges[5], 0.0);
    assert!(edges[6].is_nan());
}

#[test]
fn softmax_rows_sum_to_one_and_match_f64() {
    let device = Device::flex();
    let (rows, cols) = (400, 121);
    let x = random(rows * cols, -20.0, 20.0, 40);
    let t: Tensor<2> = Tensor::from_data(TensorData::new(x.clone(), [rows, cols]), &device);
    let y = softmax(t, 1).into_data().try_into_vec::<f32>().unwrap();
    for r in 0..rows {
        let row = &x[r * cols..(r + 1) * cols];
        let max = row.iter().fold(f64::MIN, |m, &v| m.max(v as f64));
        let sum: f64 = row.iter().map(|&v| (v as f64 - max).exp()).sum();
        for c in 0..cols {
            let want = (row[c] as f64 - max).exp() / sum;
            let got = y[r * cols + c] as f64;
            assert!(
                (got - want).abs() < 1e-6,
                "softmax[{r},{c}] = {got}, want {want}"
            );
        }
    }
}

/// An op's name, what burn computed, and the f32 arithmetic it must equal.
type Case = (&'static str, Vec<f32>, fn(f32, f32) -> f32);

#[test]
fn elementwise_arithmetic_is_exact_on_both_paths() {
    let device = Device::flex();
    for (seed, &n) in SIZES.iter().enumerate() {
        let a = random(n, -3.0, 3.0, 50 + seed as u64);
        let b = random(n, 0.5, 3.0, 60 + seed as u64);
        let (ta, tb) = (tensor(&a, &device), tensor(&b, &device));
        let cases: [Case; 5] = [
            ("add", values(ta.clone() + tb.clone()), |x, y| x + y),
            ("sub", values(ta.clone() - tb.clone()), |x, y| x - y),
            ("mul", values(ta.clone() * tb.clone()), |x, y| x * y),
            ("div", values(ta.clone() / tb.clone()), |x, y| x / y),
            ("mul_scalar", values(ta.clone() * 1.5), |x, _| x * 1.5),
        ];
        for (name, got, op) in cases {
            for i in 0..n {
                assert_eq!(got[i], op(a[i], b[i]), "{name}[{i}] (n={n})");
            }
        }
        // In place (unique operands): the same numbers.
        let inplace = values(tensor(&a, &device) * tensor(&b, &device) + 2.0);
        for i in 0..n {
            assert_eq!(
                inplace[i],
                a[i] * b[i] + 2.0,
                "in-place mul+add [{i}] (n={n})"
            );
        }
    }
}

#[test]
fn dropout_masks_keep_the_asked_fraction() {
    use burn::tensor::Distribution;
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let device = Device::flex();
    let n = 200_000;
    let mask: Tensor<1> = Tensor::random([n], Distribution::Bernoulli(0.9), &device);
    let kept = values(mask);
    assert!(kept.iter().all(|&v| v == 0.0 || v == 1.0));
    let frac = kept.iter().sum::<f32>() / n as f32;
    // 5 standard deviations of a Binomial(200000, 0.9) fraction: 0.0034.
    assert!((frac - 0.9).abs() < 0.0034, "kept {frac}");
}

#[test]
fn select_gradient_scatters_back_to_every_index() {
    // The backward of `select` on a 3-D tensor is the patched N-D select-add: repeated
    // indices must accumulate, unselected rows get zero.
    let device = Device::flex().autodiff();
    let (b, rows, c) = (4, 50, 3);
    let x = random(b * rows * c, -1.0, 1.0, 70);
    let picks: Vec<i64> = vec![7, 0, 49, 7, 13, 7];
    let upstream = random(b * picks.len() * c, -1.0, 1.0, 71);
    let input: Tensor<3> =
        Tensor::from_data(TensorData::new(x, [b, rows, c]), &device).require_grad();
    let index = Tensor::<1, burn::tensor::Int>::from_data(
        TensorData::new(picks.clone(), [picks.len()]),
        &device,
    );
    let up: Tensor<3> = Tensor::from_data(
        TensorData::new(upstream.clone(), [b, picks.len(), c]),
        &device,
    );
    let loss = (input.clone().select(1, index) * up).sum();
    let grads = loss.backward();
    let grad = input
        .grad(&grads)
        .unwrap()
        .into_data()
        .try_into_vec::<f32>()
        .unwrap();
    let mut want = vec![0.0f32; b * rows * c];
    for bi in 0..b {
        for (k, &r) in picks.iter().enumerate() {
            for ci in 0..c {
                want[(bi * rows + r as usize) * c + ci] +=
                    upstream[(bi * picks.len() + k) * c + ci];
            }
        }
    }
    for (i, (g, w)) in grad.iter().zip(&want).enumerate() {
        assert!((g - w).abs() < 1e-6, "grad[{i}] = {g}, want {w}");
    }
}

#[test]
fn slice_gradients_add_into_their_parent_in_place() {
    // The patched burn-autodiff adds a slice's gradient into the parent's gradient
    // accumulated so far: overlapping slices, disjoint columns and a whole-tensor use of
    // the same parent must sum exactly as separate zero-filled gradients would.
    let device = Device::flex().autodiff();
    for (rows, seed) in [(10, 80), (20_000, 81)] {
        let c = 3;
        let x = random(rows * c, -1.0, 1.0, seed);
        let input: Tensor<2> =
            Tensor::from_data(TensorData::new(x.clone(), [rows, c]), &device).require_grad();
        let col = |k: usize| input.clone().narrow(1, k, 1);
        let head = input.clone().narrow(0, 0, rows / 2); // overlaps the columns
        let loss = col(0).mul_scalar(2.0).sum()
            + col(2).powf_scalar(2.0).sum()
            + col(0).mul_scalar(3.0).sum()
            + head.mul_scalar(5.0).sum()
            + input.clone().mul_scalar(0.5).sum();
        let grad = input
            .grad(&loss.backward())
            .unwrap()
            .into_data()
            .try_into_vec::<f32>()
            .unwrap();
        for r in 0..rows {
            for k in 0..c {
                let mut want = 0.5 + if r < rows / 2 { 5.0 } else { 0.0 };
                match k {
                    0 => want += 5.0,
                    2 => want += 2.0 * x[r * c + k],
                    _ => {}
                }
                let g = grad[r * c + k];
                assert!((g - want).abs() < 1e-5, "grad[{r}, {k}] = {g}, want {want}");
            }
        }
    }
}

#[test]
fn a_seeded_dropout_mask_repeats() {
    use burn::tensor::Distribution;
    let _turn = RNG.lock().unwrap_or_else(|e| e.into_inner());
    let device = Device::flex();
    let draw = || {
        device.seed(7);
        values(Tensor::random(
            [150_000],
            Distribution::Bernoulli(0.5),
            &device,
        ))
    };
    let (a, b) = (draw(), draw());
    assert_eq!(a, b, "the same seed gave two masks");
    // Blocks are seeded apart: the second 64K block is not a copy of the first.
    assert_ne!(a[..1000], a[65_536..66_536]);
}

#[test]
fn strided_and_broadcast_operands_and_slice_writes_are_exact() {
    // One coordinate of `[B, N, J, 3]` joints (a stride-3 view) against a broadcast
    // scalar, a broadcast row, another strided view and itself broadcast; then the
    // backward of that slice (a write of the last dim's column into zeros).
    let dev = Device::flex().autodiff();
    let (b, n, j) = (4, 50, 22);
    let v = random(b * n * j * 3, -2.0, 2.0, 11);
    let joints =
        Tensor::<4>::from_data(TensorData::new(v.clone(), [b, n, j, 3]), &dev).require_grad();
    let x = joints.clone().slice([0..b, 0..n, 0..j, 0..1]);
    let z = joints.clone().slice([0..b, 0..n, 0..j, 2..3]);
    let half = Tensor::<4>::from_data(TensorData::new(vec![0.5f32], [1, 1, 1, 1]), &dev);
    let row = Tensor::<4>::from_data(
        TensorData::new(random(j, -1.0, 1.0, 12), [1, 1, j, 1]),
        &dev,
    );
    let flat = |t: Tensor<4>| t.into_data().try_into_vec::<f32>().unwrap();
    let at = |k: usize, c: usize| v[k * 3 + c];
    let rows = b * n * j;
    let got = flat(x.clone() - half.clone());
    assert!((0..rows).all(|k| got[k] == at(k, 0) - 0.5));
    let got = flat(half.clone() - x.clone());
    assert!((0..rows).all(|k| got[k] == 0.5 - at(k, 0)));
    let got = flat(x.clone() * z.clone());
    assert!((0..rows).all(|k| got[k] == at(k, 0) * at(k, 2)));
    let r = flat(row.clone());
    let got = flat(z.clone() - row.clone());
    assert!((0..rows).all(|k| got[k] == at(k, 2) - r[k % j]));
    // Both operands broadcast along the innermost dim: a stride-0 pair.
    let col =
        |seed| Tensor::<2>::from_data(TensorData::new(random(5, -1.0, 1.0, seed), [5, 1]), &dev);
    let (p, q) = (col(13), col(14));
    let (pv, qv) = (
        p.clone().into_data().try_into_vec::<f32>().unwrap(),
        q.clone().into_data().try_into_vec::<f32>().unwrap(),
    );
    let got = (p.expand([5, 7]) - q.expand([5, 7]))
        .into_data()
        .try_into_vec::<f32>()
        .unwrap();
    assert!((0..35).all(|k| got[k] == pv[k / 7] - qv[k / 7]));
    // ∂/∂joints of Σ 2·x + 3·z: 2 on the x column, 3 on the z column, 0 on y.
    let loss = (x * 2.0).sum() + (z * 3.0).sum();
    let g = joints.grad(&loss.backward()).unwrap();
    let g = g.into_data().try_into_vec::<f32>().unwrap();
    assert!(
        g.chunks_exact(3).all(|c| c == [2.0, 0.0, 3.0]),
        "{:?}",
        &g[..6]
    );
}

#[test]
fn first_dim_sums_split_by_columns_are_exact() {
    let device = Device::flex();
    // [rows, cols]: small (one thread), large with a ragged last column chunk, and the
    // shape of a bias gradient ([B·N, D] = [3872, 256]) seen as [32, 121·256].
    for (rows, cols) in [(7, 100), (33, 4_099), (32, 121 * 256)] {
        let v = random(rows * cols, -1.0, 1.0, 11);
        let t: Tensor<2> = Tensor::from_data(TensorData::new(v.clone(), [rows, cols]), &device);
        let got = t.sum_dim(0).into_data().try_into_vec::<f32>().unwrap();
        // The same order as the kernel: each column summed row by row from 0.
        let want: Vec<f32> = (0..cols)
            .map(|c| (0..rows).fold(0.0f32, |acc, r| acc + v[r * cols + c]))
            .collect();
        assert_eq!(got, want, "[{rows}, {cols}]");
    }
    // A fresh tensor's storage is zero, whatever its element width.
    let z: Tensor<3> = Tensor::zeros([3, 5, 7], &device);
    assert!(values(z.reshape([105])).iter().all(|&x| x == 0.0));
}

#[test]
fn large_broadcast_and_strided_binary_ops_are_exact() {
    let device = Device::flex();
    let (rows, cols) = (300, 257); // 77K elements: the parallel path, a ragged last task
    let a = random(rows * cols, -2.0, 2.0, 21);
    let bias = random(cols, -1.0, 1.0, 22);
    let a_t = || Tensor::<2>::from_data(TensorData::new(a.clone(), [rows, cols]), &device);
    let bias_t = Tensor::<2>::from_data(TensorData::new(bias.clone(), [1, cols]), &device);
    let flat = |t: Tensor<2>| t.into_data().try_into_vec::<f32>().unwrap();
    let want: Vec<f32> = (0..rows * cols).map(|i| a[i] * bias[i % cols]).collect();
    // Uniquely owned lhs: written in place.
    assert_eq!(flat(a_t() * bias_t.clone()), want);
    // Shared lhs: a new output.
    let shared = a_t();
    let keep = shared.clone();
    assert_eq!(flat(shared * bias_t.clone()), want);
    drop(keep);
    // A transposed (strided) operand against a contiguous one.
    let b = random(rows * cols, -1.0, 1.0, 23);
    let bt = Tensor::<2>::from_data(TensorData::new(b.clone(), [cols, rows]), &device).transpose();
    let want: Vec<f32> = (0..rows * cols)
        .map(|i| a[i] - b[(i % cols) * rows + i / cols])
        .collect();
    let keep = a_t();
    assert_eq!(flat(keep.clone() - bt), want);
}

#[test]
fn one_long_strided_run_splits_exactly() {
    // The x column of `[32, 196, 22, 3]` joints collapses to one run of 137,984 elements
    // at stride 3: against a broadcast scalar (a new output) and as the source of an
    // in-place op on a uniquely owned contiguous tensor. Both split across the pool.
    let device = Device::flex();
    let (b, n, j) = (32, 196, 22);
    let rows = b * n * j;
    let v = random(rows * 3, -2.0, 2.0, 31);
    let joints = Tensor::<4>::from_data(TensorData::new(v.clone(), [b, n, j, 3]), &device);
    let x = joints.clone().slice([0..b, 0..n, 0..j, 0..1]);
    let half = Tensor::<4>::from_data(TensorData::new(vec![0.5f32], [1, 1, 1, 1]), &device);
    let flat = |t: Tensor<4>| t.into_data().try_into_vec::<f32>().unwrap();
    let got = flat(x.clone() - half);
    assert!((0..rows).all(|k| got[k] == v[k * 3] - 0.5));
    let w = random(rows, -1.0, 1.0, 32);
    let unique = Tensor::<4>::from_data(TensorData::new(w.clone(), [b, n, j, 1]), &device);
    let got = flat(unique * x);
    assert!((0..rows).all(|k| got[k] == w[k] * v[k * 3]));
}

#[test]
fn row_selects_and_column_cats_are_exact() {
    // A select of joint rows from `[B, rows, 3]` (3-element slices, the short-slice path)
    // and of 12-element rows (the bulk path), and a cat of three `[B, F, 1]` columns
    // along the last dim (one-element chunks).
    let device = Device::flex();
    // The last case is a batch of 32 motions (the parallel path, one task per motion).
    for (b, rows, width, count) in [(5, 40, 3usize, 5usize), (5, 40, 12, 5), (32, 2112, 3, 700)] {
        let v = random(b * rows * width, -1.0, 1.0, 41);
        let t = Tensor::<3>::from_data(TensorData::new(v.clone(), [b, rows, width]), &device);
        let picks: Vec<i64> = (0..count).map(|k| ((k * 7 + 3) % rows) as i64).collect();
        let idx = Tensor::<1, Int>::from_data(TensorData::new(picks.clone(), [count]), &device);
        let got = t.select(1, idx).into_data().try_into_vec::<f32>().unwrap();
        let want: Vec<f32> = (0..b)
            .flat_map(|s| {
                let v = &v;
                picks.iter().flat_map(move |&r| {
                    let at = (s * rows + r as usize) * width;
                    v[at..at + width].iter().copied()
                })
            })
            .collect();
        assert_eq!(got, want, "width {width}");
    }
    let (b, f) = (5, 9);
    let cols: Vec<Vec<f32>> = (0..3).map(|c| random(b * f, -1.0, 1.0, 50 + c)).collect();
    let parts: Vec<Tensor<3>> = cols
        .iter()
        .map(|c| Tensor::from_data(TensorData::new(c.clone(), [b, f, 1]), &device))
        .collect();
    let got = Tensor::cat(parts, 2)
        .into_data()
        .try_into_vec::<f32>()
        .unwrap();
    let want: Vec<f32> = (0..b * f)
        .flat_map(|k| (0..3).map(move |c| (k, c)))
        .map(|(k, c)| cols[c][k])
        .collect();
    assert_eq!(got, want);
}
