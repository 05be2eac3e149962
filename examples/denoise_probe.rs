//! Where does a sample's jitter come from? Noises held-out test clips to a few timesteps,
//! asks the denoiser for x̂0 once (conditional, no guidance) and prints the median
//! frame-to-frame acceleration of the feet in the recovered joints, next to the clean clip's.
//! A model that cannot reproduce a nearly clean input smoothly at small t makes jittery
//! samples whatever the sampler.
//!
//! ```text
//! cargo run --example denoise_probe -- <bundle dir> <dataset dir> [clips]
//! ```

use burn::prelude::*;
use mprog::dataset::{Dataset, FEATURE_DIM, Split};
use mprog::features::{denormalize_slice, normalize_slice, recover_from_ric};
use mprog::model::ModelBundle;
use mprog::model::denoiser::{Denoiser, DenoiserInput};
use mprog::model::noise::NoiseSource;
use mprog::model::sampler::{Condition, ddim_step, guided_x0};
use mprog::model::schedule::{DIFFUSION_STEPS, NoiseSchedule};
use mprog::motion::Motion;
use std::path::PathBuf;

const FRAMES: usize = 120;
const FEET: [usize; 2] = [10, 11];

/// Median over frames of the larger foot acceleration (m/frame²).
fn foot_jitter(m: &Motion) -> f32 {
    let mut acc: Vec<f32> = (1..m.len() - 1)
        .map(|t| {
            FEET.iter()
                .map(|&j| (m.frames[t + 1][j] - 2.0 * m.frames[t][j] + m.frames[t - 1][j]).length())
                .fold(0.0, f32::max)
        })
        .collect();
    acc.sort_by(f32::total_cmp);
    acc[acc.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: denoise_probe <bundle dir> <dataset dir> [clips]");
        std::process::exit(2);
    }
    let device = Device::flex();
    let bundle = ModelBundle::load(&PathBuf::from(&args[1]), &device).expect("bundle");
    let data = Dataset::load(&PathBuf::from(&args[2])).expect("dataset");
    let count: usize = args.get(3).and_then(|a| a.parse().ok()).unwrap_or(8);
    let clips: Vec<_> = data
        .clips(Split::Test)
        .filter(|c| c.frames >= FRAMES)
        .step_by(37)
        .take(count)
        .collect();
    let schedule = NoiseSchedule::cosine(DIFFUSION_STEPS);
    let (mean, std) = (&bundle.mean, &bundle.std);
    let normalise = |raw: &[f32]| -> Vec<f32> {
        let mut v = raw.to_vec();
        normalize_slice(&mut v, mean, std).expect("feature rows");
        v
    };
    let denormalise = |n: &[f32]| -> Vec<f32> {
        let mut v = n.to_vec();
        denormalize_slice(&mut v, mean, std).expect("feature rows");
        v
    };
    let b = clips.len();
    let mut x0 = Vec::with_capacity(b * FRAMES * FEATURE_DIM);
    for c in &clips {
        x0.extend(normalise(&data.clip_features(c)[..FRAMES * FEATURE_DIM]));
    }
    let captions: Vec<&str> = clips.iter().map(|c| c.captions[0].as_str()).collect();
    let real: f32 = clips
        .iter()
        .map(|c| {
            let raw = &data.clip_features(c)[..FRAMES * FEATURE_DIM];
            foot_jitter(&recover_from_ric(raw).unwrap())
        })
        .sum::<f32>()
        / b as f32;
    println!(
        "{} ({} steps), {b} test clips: clean clips' foot jitter {real:.4} m/frame²",
        bundle.manifest.weights_id, bundle.manifest.steps
    );
    println!("| t | √(1−ᾱ) | foot jitter of x̂0 | x̂0 MSE (normalised) |");
    println!("| --- | --- | --- | --- |");
    let clean: Tensor<3> = Tensor::from_data(
        TensorData::new(x0.clone(), [b, FRAMES, FEATURE_DIM]),
        &device,
    );
    for t in [0usize, 5, 20, 50, 100, 200, 400, 700] {
        let ab = schedule.alphas_cumprod[t];
        let eps = NoiseSource::new(7).tensor([b, FRAMES, FEATURE_DIM], &device);
        let x_t = clean.clone() * (ab.sqrt() as f32) + eps * ((1.0 - ab).sqrt() as f32);
        let input = DenoiserInput {
            x_t,
            timesteps: vec![t; b],
            text: bundle.text.batch(&captions, &device),
            keep_text: Tensor::ones([b], &device),
            padding: None,
        };
        let pred = bundle.model.predict_x0(&input);
        let mse = (pred.clone() - clean.clone())
            .powi_scalar(2)
            .mean()
            .into_scalar::<f32>();
        let flat = pred.into_data().try_to_vec::<f32>().unwrap();
        let jitter: f32 = flat
            .chunks(FRAMES * FEATURE_DIM)
            .map(|one| foot_jitter(&recover_from_ric(&denormalise(one)).unwrap()))
            .sum::<f32>()
            / b as f32;
        println!(
            "| {t} | {:.3} | {jitter:.4} | {mse:.4} |",
            (1.0 - ab).sqrt()
        );
    }

    // The same measure along a DDIM-50 chain from pure noise, with the same captions.
    let jitter_of = |x: Tensor<3>| -> f32 {
        let flat = x.into_data().try_to_vec::<f32>().unwrap();
        flat.chunks(FRAMES * FEATURE_DIM)
            .map(|one| foot_jitter(&recover_from_ric(&denormalise(one)).unwrap()))
            .sum::<f32>()
            / b as f32
    };
    for scale in [1.0f32, 2.5] {
        println!(
            "\nDDIM 50 from noise, guidance {scale}: step t, jitter of x̂0, jitter of x_t read as a motion"
        );
        let ddim = schedule.respaced(50);
        let cond = Condition::new(&bundle.text, &captions, scale, &device);
        let mut x = NoiseSource::new(1).tensor([b, FRAMES, FEATURE_DIM], &device);
        for i in (0..ddim.len()).rev() {
            let t = ddim.timesteps[i];
            let pred = guided_x0(&bundle.model, x.clone(), t, &cond);
            if i % 7 == 0 || i < 4 {
                let ab = ddim.alphas_cumprod[i] as f32;
                println!(
                    "  t {t:4}: x̂0 {:.4}   x_t/√ᾱ {:.4}",
                    jitter_of(pred.clone()),
                    jitter_of(x.clone() / ab.sqrt())
                );
            }
            x = if i > 0 {
                ddim_step(&ddim, i, x, pred)
            } else {
                pred
            };
        }
    }
}
