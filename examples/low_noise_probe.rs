//! How clean is the denoiser's x̂0 at small timesteps? Noises one dataset clip to a few
//! timesteps and prints, for x_t/√ᾱ (read as a motion) and for x̂0: bone-length variation
//! (std/mean over time, averaged over bones; the data's is 0), jitter (mean |second
//! difference| of the joint positions, cm), the x̂0 MSE (normalised features; the identity
//! x̂0 = x_t/√ᾱ scores (1−ᾱ)/ᾱ) and the input skip's gain on the joint positions. A model
//! whose x̂0 is no cleaner than x_t at small t leaves the chain's last noise in its samples.
//!
//! ```text
//! cargo run --release --example low_noise_probe -- <bundle> <dataset> <clip name>
//! ```

mod probe_clip;

use burn::prelude::*;
use mprog::dataset::FEATURE_DIM;
use mprog::features::{denormalize_slice, recover_from_ric};
use mprog::model::denoiser::{Denoiser, DenoiserInput};
use mprog::model::noise::NoiseSource;
use mprog::model::schedule::{DIFFUSION_STEPS, NoiseSchedule};
use mprog::skeleton::{NUM_JOINTS, PARENTS};
use probe_clip::ProbeClip;

/// (bone variation, jitter in cm) of a raw feature clip.
fn roughness(raw: &[f32]) -> (f32, f32) {
    let m = recover_from_ric(raw).expect("feature rows");
    let n = m.frames.len() as f32;
    let mut var = 0.0;
    for j in 1..NUM_JOINTS {
        let l: Vec<f32> = m
            .frames
            .iter()
            .map(|f| (f[j] - f[PARENTS[j]]).length())
            .collect();
        let mean = l.iter().sum::<f32>() / n;
        let sd = (l.iter().map(|x| (x - mean).powi(2)).sum::<f32>() / n).sqrt();
        var += sd / mean;
    }
    let mut jit = 0.0;
    let mut count = 0.0;
    for w in m.frames.windows(3) {
        for ((a, b), c) in w[0].iter().zip(&w[1]).zip(&w[2]) {
            jit += (*b - (*a + *c) * 0.5).length();
            count += 1.0;
        }
    }
    (var / (NUM_JOINTS - 1) as f32, 100.0 * jit / count)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let ProbeClip {
        device,
        bundle,
        clip,
        frames: n,
        raw,
        clean,
    } = probe_clip::load(&args, "low_noise_probe <bundle> <dataset> <clip name>");
    let (v, j) = roughness(&raw);
    println!(
        "{} ({} steps); clip {} ({n} frames): bones {v:.4}, jitter {j:.3} cm",
        bundle.manifest.weights_id, bundle.manifest.steps, clip.name
    );
    println!(
        "| t | x_t bones | x_t jitter | x̂0 bones | x̂0 jitter | x̂0 MSE | skip gain, centre | all taps | 1/√ᾱ |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    let schedule = NoiseSchedule::cosine(DIFFUSION_STEPS);
    let as_raw = |t: Tensor<3>| {
        let mut v = t.into_data().try_to_vec::<f32>().unwrap();
        denormalize_slice(&mut v, &bundle.mean, &bundle.std).expect("feature rows");
        v
    };
    for t in [0usize, 20, 40, 100, 200, 400] {
        let ab = schedule.alphas_cumprod[t];
        let eps = NoiseSource::new(1).tensor([1, n, FEATURE_DIM], &device);
        let x_t = clean.clone() * (ab.sqrt() as f32) + eps * ((1.0 - ab).sqrt() as f32);
        let input = DenoiserInput {
            x_t: x_t.clone(),
            timesteps: vec![t],
            text: bundle.text.batch(&[clip.captions[0].as_str()], &device),
            keep_text: Tensor::from_data(TensorData::new(vec![1.0f32], [1]), &device),
            padding: None,
        };
        let pred = bundle.model.predict_x0(&input);
        let mse = (pred.clone() - clean.clone())
            .powi_scalar(2)
            .mean()
            .into_scalar::<f32>();
        let (xv, xj) = roughness(&as_raw(x_t * (1.0 / ab.sqrt() as f32)));
        let (pv, pj) = roughness(&as_raw(pred));
        // The skip's gain on the joint positions (columns 4..67): the centre tap (the frame
        // itself) and the sum over taps (what a constant signal gets).
        let gain = bundle.model.input_skip_gain(t).unwrap_or_default();
        let taps = (gain.len() / FEATURE_DIM).max(1);
        let mean_of = |tap: usize| {
            let at = tap * FEATURE_DIM;
            gain.get(at + 4..at + 67)
                .map_or(f32::NAN, |v| v.iter().sum::<f32>() / 63.0)
        };
        let total: f32 = (0..taps).map(mean_of).sum();
        println!(
            "| {t} | {xv:.4} | {xj:.3} | {pv:.4} | {pj:.3} | {mse:.4} | {:.3} | {total:.3} | {:.3} |",
            mean_of(taps / 2),
            1.0 / ab.sqrt()
        );
    }
}
