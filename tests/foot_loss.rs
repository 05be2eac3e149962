//! The training loss's extra terms (foot contact, velocity, root columns) against hand computations
//! on the golden clip.

mod common;

use burn::prelude::*;
use common::{golden, mean_std};
use mprog::features::layout::{CONTACT, RIC};
use mprog::features::{FEATURE_DIM, recover_from_ric};
use mprog::model::train::{FootLoss, VelocityLoss, root_mse};
use mprog::skeleton::{FOOT_LEFT, FOOT_RIGHT};

fn normalised(feats: &[f32], mean: &[f32], std: &[f32]) -> Vec<f32> {
    feats
        .iter()
        .enumerate()
        .map(|(i, v)| (v - mean[i % FEATURE_DIM]) / std[i % FEATURE_DIM])
        .collect()
}

#[test]
fn foot_term_is_the_mean_squared_slide_of_planted_feet_in_cm2() {
    let (feats, _) = golden();
    let (mean, std) = mean_std();
    let n = feats.len() / FEATURE_DIM;
    // Hand computation: FK on the host, contact labels straight from the features.
    let joints = recover_from_ric(&feats).unwrap();
    let feet = [FOOT_LEFT[0], FOOT_LEFT[1], FOOT_RIGHT[0], FOOT_RIGHT[1]];
    let (mut sum, mut count) = (0.0f64, 0.0f64);
    for t in 0..n - 1 {
        for (k, &j) in feet.iter().enumerate() {
            if feats[t * FEATURE_DIM + CONTACT.start + k] > 0.5 {
                let d = (joints.frames[t + 1][j] - joints.frames[t][j]) * 100.0;
                sum += d.length_squared() as f64;
                count += 1.0;
            }
        }
    }
    let expected = sum / (count + 1.0);
    assert!(count > 50.0 && expected > 0.0, "{count} planted pairs");

    let dev = Device::flex();
    let foot = FootLoss::new(1.0, &mean, &std, &dev).expect("weight > 0");
    let x0: Tensor<3> = Tensor::from_data(
        TensorData::new(normalised(&feats, &mean, &std), [1, n, FEATURE_DIM]),
        &dev,
    );
    let valid: Tensor<3> = Tensor::ones([1, n, 1], &dev);
    let got = foot
        .term(x0.clone(), x0.clone(), valid.clone())
        .into_scalar::<f32>() as f64;
    println!("foot term {got:.5} cm², hand {expected:.5} cm² over {count} pairs");
    assert!(
        (got - expected).abs() < 1e-3 * expected.max(1.0),
        "{got} vs {expected}"
    );

    // Padding drops the pairs that touch it.
    let half: Vec<f32> = (0..n).map(|t| if t < n / 2 { 1.0 } else { 0.0 }).collect();
    let half: Tensor<3> = Tensor::from_data(TensorData::new(half, [1, n, 1]), &dev);
    let padded = foot.term(x0.clone(), x0.clone(), half).into_scalar::<f32>() as f64;
    assert!((padded - got).abs() > 1e-4, "padding must change the term");

    // Weight 0 disables the term.
    assert!(FootLoss::new(0.0, &mean, &std, &dev).is_none());

    // It has a gradient with respect to the prediction.
    let ad = dev.clone().autodiff();
    let pred: Tensor<3> = Tensor::from_data(x0.to_data(), &ad).require_grad();
    let foot = FootLoss::new(1.0, &mean, &std, &ad).unwrap();
    let loss = foot.term(
        pred.clone(),
        Tensor::from_data(x0.to_data(), &ad),
        Tensor::from_data(valid.to_data(), &ad),
    );
    let grads = loss.backward();
    let g = pred.grad(&grads).expect("gradient");
    let norm = g.abs().sum().into_scalar::<f32>();
    assert!(norm.is_finite() && norm > 0.0, "gradient norm {norm}");
}

#[test]
fn velocity_term_counts_jitter_and_ignores_a_constant_offset() {
    let (feats, _) = golden();
    let (mean, std) = mean_std();
    let n = feats.len() / FEATURE_DIM;
    let dev = Device::flex();
    let x0n = normalised(&feats, &mean, &std);
    let tensor = |v: Vec<f32>| -> Tensor<3> {
        Tensor::from_data(TensorData::new(v, [1, n, FEATURE_DIM]), &dev)
    };
    let valid: Tensor<3> = Tensor::ones([1, n, 1], &dev);
    let vel = VelocityLoss::new(1.0, &std, &dev).expect("weight > 0");
    let term = |pred: Vec<f32>| -> f64 {
        vel.term(tensor(pred), tensor(x0n.clone()), valid.clone())
            .into_scalar::<f32>() as f64
    };
    assert!(
        term(x0n.clone()).abs() < 1e-9,
        "a perfect prediction costs nothing"
    );

    // One joint coordinate 2 cm off on every frame: no velocity error.
    let col = RIC.start;
    let delta = 0.02f32;
    let mut offset = x0n.clone();
    for t in 0..n {
        offset[t * FEATURE_DIM + col] += delta / std[col];
    }
    assert!(
        term(offset).abs() < 1e-6,
        "a constant offset has the data's velocity"
    );

    // The same error on one frame only: two frame pairs see a 2 cm step each.
    let k = n / 2;
    let mut spike = x0n.clone();
    spike[k * FEATURE_DIM + col] += delta / std[col];
    let per_joint = 2.0 * (100.0 * delta as f64).powi(2) / (64.0 / 3.0);
    let expected = per_joint / n as f64; // n - 1 valid pairs, + 1 in the denominator
    let got = term(spike);
    assert!(
        (got - expected).abs() < 1e-3 * expected,
        "{got} vs {expected}"
    );
    assert!(VelocityLoss::new(0.0, &std, &dev).is_none());
}

#[test]
fn root_term_is_the_mse_of_the_four_root_columns_and_ignores_the_rest() {
    let dev = Device::flex();
    let (b, n) = (2, 5);
    let x0: Tensor<3> = Tensor::zeros([b, n, FEATURE_DIM], &dev);
    // An error of 1 in every non-root column: the root term must not see it.
    let mut pred = vec![1.0f32; b * n * FEATURE_DIM];
    // Errors of 0, 1, 2, 3 in the root columns of every frame.
    for row in pred.chunks_exact_mut(FEATURE_DIM) {
        row[..4].copy_from_slice(&[0.0, 1.0, 2.0, 3.0]);
    }
    let pred: Tensor<3> = Tensor::from_data(TensorData::new(pred, [b, n, FEATURE_DIM]), &dev);
    // The last two frames of the second clip are padding with a huge error.
    let mut mask = vec![1.0f32; b * n];
    mask[2 * n - 2..].fill(0.0);
    let valid: Tensor<3> = Tensor::from_data(TensorData::new(mask, [b, n, 1]), &dev);
    let pred = pred.clone() + (Tensor::ones_like(&valid) - valid.clone()) * 100.0;
    let got = root_mse(pred, x0, valid).into_scalar::<f32>();
    let expected = (0.0 + 1.0 + 4.0 + 9.0) / 4.0;
    assert!((got - expected).abs() < 1e-5, "{got} vs {expected}");
}
