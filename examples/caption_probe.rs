//! Does the denoiser read a clip's caption? Noises one training clip to a few timesteps and
//! asks for x̂0 three ways: with the clip's caption, with another caption, and
//! unconditioned. Prints the highest ankle and the lowest foot pair of each x̂0 and its MSE
//! to the clean clip. When the caption's x̂0 is no closer than the unconditioned one at
//! large t, the model has not tied the caption to the motion.
//!
//! ```text
//! cargo run --release --example caption_probe -- <bundle> <dataset> <clip name> [other caption]
//! ```

mod probe_clip;

use burn::prelude::*;
use mprog::dataset::FEATURE_DIM;
use mprog::features::{denormalize_slice, recover_from_ric};
use mprog::model::denoiser::{Denoiser, DenoiserInput};
use mprog::model::noise::NoiseSource;
use mprog::model::schedule::{DIFFUSION_STEPS, NoiseSchedule};
use probe_clip::ProbeClip;

/// Highest ankle (m) and highest lowest-foot-joint (both feet up, m) of a feature clip,
/// both above the clip's lowest foot joint.
fn heights(raw: &[f32]) -> (f32, f32) {
    let m = recover_from_ric(raw).expect("feature rows");
    // Per frame: the lowest of the four foot joints.
    let lowest_foot: Vec<f32> = m
        .frames
        .iter()
        .map(|f| {
            [7, 8, 10, 11]
                .iter()
                .map(|&j| f[j].y)
                .fold(f32::MAX, f32::min)
        })
        .collect();
    let floor = lowest_foot.iter().copied().fold(f32::MAX, f32::min);
    let both = lowest_foot.iter().copied().fold(f32::MIN, f32::max);
    let ankle = m
        .frames
        .iter()
        .map(|f| f[7].y.max(f[8].y))
        .fold(f32::MIN, f32::max);
    (ankle - floor, both - floor)
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
    } = probe_clip::load(
        &args,
        "caption_probe <bundle> <dataset> <clip name> [other caption]",
    );
    let other = args.get(4).map_or("a person walks forward", String::as_str);
    let (ankle, both) = heights(&raw);
    println!(
        "{} ({} steps); clip {} ({n} frames, \"{}\"): ankle {ankle:.2} m, both feet {both:.2} m",
        bundle.manifest.weights_id, bundle.manifest.steps, clip.name, clip.captions[0]
    );
    println!("| t | condition | ankle (m) | both feet (m) | x̂0 MSE |");
    println!("| --- | --- | --- | --- | --- |");
    let schedule = NoiseSchedule::cosine(DIFFUSION_STEPS);
    for t in [500usize, 900, 950, 975, 990, 999] {
        let ab = schedule.alphas_cumprod[t];
        let mut rows = Vec::new();
        for seed in 0..4u64 {
            let eps = NoiseSource::new(seed).tensor([1, n, FEATURE_DIM], &device);
            let x_t = clean.clone() * (ab.sqrt() as f32) + eps * ((1.0 - ab).sqrt() as f32);
            for (name, caption, keep) in [
                ("caption", clip.captions[0].as_str(), 1.0f32),
                ("other", other, 1.0),
                ("none", "", 0.0),
            ] {
                let input = DenoiserInput {
                    x_t: x_t.clone(),
                    timesteps: vec![t],
                    text: bundle.text.batch(&[caption], &device),
                    keep_text: Tensor::from_data(TensorData::new(vec![keep], [1]), &device),
                    padding: None,
                };
                let pred = bundle.model.predict_x0(&input);
                let mse = (pred.clone() - clean.clone())
                    .powi_scalar(2)
                    .mean()
                    .into_scalar::<f32>();
                let mut v = pred.into_data().try_to_vec::<f32>().unwrap();
                denormalize_slice(&mut v, &bundle.mean, &bundle.std).expect("feature rows");
                let (a, b) = heights(&v);
                rows.push((name, a, b, mse));
            }
        }
        for name in ["caption", "other", "none"] {
            let r: Vec<_> = rows.iter().filter(|r| r.0 == name).collect();
            let k = r.len() as f32;
            println!(
                "| {t} | {name} | {:.2} | {:.2} | {:.3} |",
                r.iter().map(|r| r.1).sum::<f32>() / k,
                r.iter().map(|r| r.2).sum::<f32>() / k,
                r.iter().map(|r| r.3).sum::<f32>() / k
            );
        }
    }
}
