//! Where does a turn lose its angle? Takes held-out turning clips and prints the mean
//! absolute turn (2·Σ yaw velocity, degrees) of the denoiser's x̂0 (guidance 2.5, the
//! clips' own captions):
//! 1. from the clips noised to a few timesteps (t = 1 is nearly a copy: whatever is lost
//!    there the model loses at every step);
//! 2. at t = 1 with the yaw column of x_t zeroed (how much of the turn it reads from the
//!    other columns), with another caption, and unconditioned;
//! 3. the mean yaw velocity per frame at t = 1 against the clips' (where the turn is lost);
//! 4. along a DDIM-50 chain from pure noise with the same captions;
//!
//! and, for a model with `input_skip`, the skip's gain on the yaw column.
//!
//! ```text
//! cargo run --release --example turn_probe -- <bundle dir> <dataset dir>
//! RAW=<run>/ckpt/model.bpk cargo run --release --example turn_probe -- <run>/bundle <dataset dir>
//! ```
//! `RAW` replaces the bundle's EMA weights with a run's training weights.

use burn::module::Module;
use burn::prelude::*;
use burn::store::ModuleRecord;
use mprog::dataset::{Dataset, FEATURE_DIM, Split};
use mprog::features::normalize_slice;
use mprog::model::ModelBundle;
use mprog::model::denoiser::Mdm;
use mprog::model::noise::NoiseSource;
use mprog::model::sampler::{Condition, ddim_step, guided_x0};
use mprog::model::schedule::{DIFFUSION_STEPS, NoiseSchedule};
use std::path::PathBuf;

const FRAMES: usize = 88;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: turn_probe <bundle dir> <dataset dir>");
        std::process::exit(2);
    }
    let device = Device::flex();
    let mut bundle = ModelBundle::load(&PathBuf::from(&args[1]), &device).expect("bundle");
    if let Ok(raw) = std::env::var("RAW") {
        let record = ModuleRecord::load(PathBuf::from(raw)).expect("training weights");
        bundle.model =
            Mdm::new(&bundle.config, bundle.text.vocab_size(), &device).load_record(record);
    }
    let data = Dataset::load(&PathBuf::from(&args[2])).expect("dataset");
    let clips: Vec<_> = data
        .clips(Split::Test)
        .filter(|c| c.content.starts_with("walk-turn") && c.frames >= FRAMES)
        .step_by(6)
        .take(16)
        .collect();
    let b = clips.len();
    let (mean, std) = (bundle.mean.clone(), bundle.std.clone());
    // +1 for a left-turn clip: yaw velocities of left turns are negative.
    let sign: Vec<f32> = clips
        .iter()
        .map(|c| {
            if c.content.ends_with("left") {
                -1.0
            } else {
                1.0
            }
        })
        .collect();
    // Full-angle yaw velocity (degrees/frame) of clip k at frame t of normalised samples.
    let yaw = |flat: &[f32], k: usize, t: usize| {
        (2.0 * (flat[(k * FRAMES + t) * FEATURE_DIM] * std[0] + mean[0])).to_degrees()
    };
    let turn = |x: Tensor<3>| -> f32 {
        let flat = x.into_data().try_to_vec::<f32>().unwrap();
        (0..b)
            .map(|k| (0..FRAMES - 1).map(|t| yaw(&flat, k, t)).sum::<f32>().abs())
            .sum::<f32>()
            / b as f32
    };
    let mut x0 = Vec::with_capacity(b * FRAMES * FEATURE_DIM);
    for c in &clips {
        let mut v = data.clip_features(c)[..FRAMES * FEATURE_DIM].to_vec();
        normalize_slice(&mut v, &mean, &std).expect("rows");
        x0.extend(v);
    }
    let clean: Tensor<3> =
        Tensor::from_data(TensorData::new(x0, [b, FRAMES, FEATURE_DIM]), &device);
    let captions: Vec<&str> = clips.iter().map(|c| c.captions[0].as_str()).collect();
    let cond = Condition::new(&bundle.text, &captions, 2.5, &device);
    println!(
        "{}: {b} turning test clips, {FRAMES} frames; clean mean |turn| {:.1}°",
        bundle.manifest.weights_id,
        turn(clean.clone())
    );
    for t in [1usize, 50, 200, 500, 900] {
        if let Some(g) = bundle.model.input_skip_gain(t) {
            let avg = g.iter().sum::<f32>() / g.len() as f32;
            println!(
                "input skip gain at t {t}: yaw column {:.3}, mean {avg:.3}",
                g[0]
            );
        }
    }

    let schedule = NoiseSchedule::cosine(DIFFUSION_STEPS);
    let noised = |t: usize| {
        let ab = schedule.alphas_cumprod[t];
        let eps = NoiseSource::new(7).tensor([b, FRAMES, FEATURE_DIM], &device);
        clean.clone() * (ab.sqrt() as f32) + eps * ((1.0 - ab).sqrt() as f32)
    };
    println!("\n| t | mean |turn| of x̂0 (°) |\n| --- | --- |");
    for t in [1usize, 10, 50, 100, 200, 400, 600, 800, 950] {
        println!(
            "| {t} | {:.1} |",
            turn(guided_x0(&bundle.model, noised(t), t, &cond))
        );
    }

    let x1 = noised(1);
    let zero_yaw = x1.clone().slice_assign(
        [0..b, 0..FRAMES, 0..1],
        Tensor::zeros([b, FRAMES, 1], &device) - (mean[0] / std[0]),
    );
    let walk = Condition::new(
        &bundle.text,
        &vec!["a person walks forward"; b],
        2.5,
        &device,
    );
    let uncond = Condition::new(&bundle.text, &captions, 0.0, &device);
    println!(
        "\nt 1: yaw column of x_t zeroed {:.1}; caption \"a person walks forward\" {:.1}; unconditional {:.1}",
        turn(guided_x0(&bundle.model, zero_yaw, 1, &cond)),
        turn(guided_x0(&bundle.model, x1.clone(), 1, &walk)),
        turn(guided_x0(&bundle.model, x1.clone(), 1, &uncond)),
    );

    println!("\nyaw velocity towards the turn at t 1 (°/frame, mean over clips): frame, clean, x̂0");
    let pred = guided_x0(&bundle.model, x1, 1, &cond).into_data();
    let pred = pred.try_to_vec::<f32>().unwrap();
    let real = clean.into_data().try_to_vec::<f32>().unwrap();
    for t in (0..FRAMES).step_by(8) {
        let avg = |flat: &[f32]| (0..b).map(|k| sign[k] * yaw(flat, k, t)).sum::<f32>() / b as f32;
        println!("  {t:3}  {:6.3}  {:6.3}", avg(&real), avg(&pred));
    }

    println!("\nDDIM 50 from noise, same captions: t, mean |turn| of x̂0");
    let ddim = schedule.respaced(50);
    let mut x = NoiseSource::new(1).tensor([b, FRAMES, FEATURE_DIM], &device);
    for i in (0..ddim.len()).rev() {
        let pred = guided_x0(&bundle.model, x.clone(), ddim.timesteps[i], &cond);
        if i % 10 == 0 {
            println!("  t {:4}: {:.1}", ddim.timesteps[i], turn(pred.clone()));
        }
        x = if i > 0 {
            ddim_step(&ddim, i, x, pred)
        } else {
            pred
        };
    }
    println!("final sample: {:.1}", turn(x));
}
