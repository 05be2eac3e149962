//! Model tests on tiny configurations: shapes, weights round trips and mismatches,
//! determinism of the samplers, and a short training run that learns and resumes.

use super::config::{ModelConfig, TrainConfig};
use super::denoiser::{Denoiser, DenoiserInput, Mdm};
use super::noise::NoiseSource;
use super::prompt::{PromptEncoder, TextBatch};
use super::sampler::{Condition, SamplerKind, sample_chain, schedule_for};
use super::schedule::{DIFFUSION_STEPS, NoiseSchedule};
use super::text::{TokenBatch, Vocabulary};
use super::train::TrainRun;
use super::weights::{model_from_safetensors, model_to_safetensors};
use crate::dataset::{ClipInfo, Dataset, DatasetIndex, FEATURE_DIM, Split, SplitStats};
use burn::prelude::*;

pub(super) fn tiny() -> ModelConfig {
    ModelConfig {
        features: FEATURE_DIM,
        d_model: 32,
        layers: 2,
        heads: 2,
        d_ff: 64,
        dropout: 0.1,
        d_text: 8,
        text_encoder: Default::default(),
        max_frames: 40,
        input_skip: false,
        skip_taps: 1,
        skip_taps_below: None,
        side_input: false,
        text_control: None,
    }
}

fn vocab() -> Vocabulary {
    Vocabulary::from_captions(["a person walks forward", "a person waves"], 8)
}

fn input(b: usize, n: usize, dev: &Device) -> DenoiserInput {
    let prompts = vec!["a person walks"; b];
    DenoiserInput {
        x_t: NoiseSource::new(3).tensor([b, n, FEATURE_DIM], dev),
        timesteps: vec![500; b],
        text: TextBatch::Words(TokenBatch::new(&vocab(), &prompts, dev)),
        keep_text: Tensor::ones([b], dev),
        padding: None,
    }
}

#[test]
fn denoiser_keeps_shape_and_ignores_padded_frames() {
    let dev = Device::flex();
    let model = Mdm::new(&tiny(), vocab().len(), &dev).valid();
    let mut inp = input(2, 10, &dev);
    assert_eq!(model.predict_x0(&inp).dims(), [2, 10, FEATURE_DIM]);
    // Changing padded frames must not change the prediction of valid frames.
    let mut pad = vec![false; 20];
    pad[8..10].fill(true);
    pad[18..20].fill(true);
    inp.padding = Some(Tensor::from_data(TensorData::new(pad, [2, 10]), &dev));
    let a = model.predict_x0(&inp).narrow(1, 0, 8);
    let noise = NoiseSource::new(9).tensor([2, 2, FEATURE_DIM], &dev);
    inp.x_t = Tensor::cat(vec![inp.x_t.clone().narrow(1, 0, 8), noise], 1);
    let b = model.predict_x0(&inp).narrow(1, 0, 8);
    let diff = (a - b).abs().max().into_scalar::<f32>();
    assert!(diff < 1e-5, "padded frames leaked into valid ones: {diff}");
}

#[test]
fn half_precision_round_trip_is_close_and_wrong_shapes_are_refused() {
    let dev = Device::flex();
    let model = Mdm::new(&tiny(), vocab().len(), &dev).valid();
    let bytes = model_to_safetensors(&model, true).unwrap();
    let loaded =
        model_from_safetensors(Mdm::new(&tiny(), vocab().len(), &dev), bytes.clone(), true)
            .unwrap()
            .valid();
    let inp = input(1, 6, &dev);
    let diff = (model.predict_x0(&inp) - loaded.predict_x0(&inp))
        .abs()
        .max()
        .into_scalar::<f32>();
    assert!(diff < 2e-2, "f16 round trip error {diff}");
    let mut other = tiny();
    other.d_model = 48;
    let err =
        model_from_safetensors(Mdm::new(&other, vocab().len(), &dev), bytes, true).unwrap_err();
    assert!(err.contains("do not fit"), "{err}");
}

#[test]
fn ddim_is_deterministic_from_the_seed() {
    let dev = Device::flex();
    let model = Mdm::new(&tiny(), vocab().len(), &dev).valid();
    let base = NoiseSchedule::cosine(DIFFUSION_STEPS);
    let kind = SamplerKind::Ddim(5);
    let s = schedule_for(&base, kind);
    let cond = Condition::new(
        &PromptEncoder::Words(vocab()),
        &["a person walks"],
        2.5,
        &dev,
    );
    let run = |seed| {
        let x = NoiseSource::new(seed).tensor([1, 8, FEATURE_DIM], &dev);
        sample_chain(
            &model,
            &s,
            kind,
            x,
            &cond,
            &mut NoiseSource::new(seed + 1),
            |_, _| {},
        )
        .into_data()
        .try_into_vec::<f32>()
        .unwrap()
    };
    assert_eq!(run(1), run(1));
    assert_ne!(run(1), run(2));
}

/// A dataset of two synthetic "clips": smooth sinusoids with a caption each.
pub(super) fn synthetic_dataset() -> Dataset {
    let frames = 24;
    let mut features = Vec::new();
    for c in 0..2 {
        for t in 0..frames {
            for f in 0..FEATURE_DIM {
                features.push(((t as f32 * 0.3 + f as f32 * 0.1) * (c + 1) as f32).sin());
            }
        }
    }
    let clip = |i: usize, caption: &str| ClipInfo {
        name: format!("c{i}"),
        source: format!("c{i}.bvh"),
        content: "walk".into(),
        style: "normal".into(),
        mirrored: false,
        split: if i == 0 { Split::Train } else { Split::Val },
        offset: i * frames,
        frames,
        captions: vec![caption.into()],
    };
    Dataset {
        index: DatasetIndex {
            version: 1,
            fps: 20.0,
            clips: vec![clip(0, "a person walks forward"), clip(1, "a person waves")],
            stats: [
                SplitStats::default(),
                SplitStats::default(),
                SplitStats::default(),
            ],
            skipped: vec![],
            build_seconds: 0.0,
        },
        joints: vec![0.0; 2 * frames * 66],
        features,
        mean: vec![0.0; FEATURE_DIM],
        std: vec![1.0; FEATURE_DIM],
    }
}

#[test]
fn training_learns_and_resumes_from_checkpoints() {
    let data = synthetic_dataset();
    let dir = tempfile::tempdir().unwrap();
    let config = TrainConfig {
        model: tiny(),
        batch_size: 4,
        crop_frames: 16,
        learning_rate: 3e-3,
        warmup_steps: 1,
        checkpoint_every: 10,
        steps: 60,
        ..TrainConfig::default()
    };
    let run = |steps| TrainRun {
        data: &data,
        config: config.clone(),
        out: dir.path().to_path_buf(),
        max_steps_now: Some(steps),
        interrupt: Default::default(),
        init_from: None,
        device: Device::flex(),
        after_checkpoint: Some(mark_checkpoint),
        text_encoder: None,
    };
    let first = run(30).run(&|_, _, _| {}).unwrap();
    assert_eq!(first.step, 30);
    assert!(dir.path().join("ckpt/state.json").exists());
    assert!(dir.path().join("bundle/model.safetensors").exists());
    assert!(
        dir.path().join("hook.txt").exists(),
        "the after-checkpoint hook ran"
    );
    let second = run(30).run(&|_, _, _| {}).unwrap();
    assert_eq!(second.step, 60, "resumed from step 30");
    let csv = std::fs::read_to_string(dir.path().join("loss.csv")).unwrap();
    let losses: Vec<f64> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(losses.len(), 60);
    let early: f64 = losses[..10].iter().sum::<f64>() / 10.0;
    let late: f64 = losses[50..].iter().sum::<f64>() / 10.0;
    assert!(late < 0.7 * early, "loss did not fall: {early} -> {late}");
    // The exported bundle loads.
    let bundle =
        super::weights::ModelBundle::load(&dir.path().join("bundle"), &Device::flex()).unwrap();
    assert_eq!(bundle.manifest.steps, 60);
}

#[test]
fn interrupted_training_saves_a_checkpoint_and_resumes() {
    let data = synthetic_dataset();
    let dir = tempfile::tempdir().unwrap();
    let config = TrainConfig {
        model: tiny(),
        batch_size: 2,
        crop_frames: 8,
        warmup_steps: 1,
        checkpoint_every: 10,
        steps: 12,
        ..TrainConfig::default()
    };
    let interrupt = crate::interrupt::Interrupt::new();
    let run = TrainRun {
        data: &data,
        config: config.clone(),
        out: dir.path().to_path_buf(),
        max_steps_now: None,
        interrupt: interrupt.clone(),
        init_from: None,
        device: Device::flex(),
        after_checkpoint: None,
        text_encoder: None,
    };
    // Ctrl-C arrives during step 4, between checkpoints (every 10 steps).
    let stopped = run
        .run(&|state, _, _| {
            if state.step == 4 {
                interrupt.request();
            }
        })
        .unwrap();
    assert_eq!(stopped.step, 4, "the run stops after the step in progress");
    let state = std::fs::read_to_string(dir.path().join("ckpt/state.json")).unwrap();
    assert!(
        state.contains("\"step\": 4"),
        "checkpoint of step 4: {state}"
    );
    let csv = std::fs::read_to_string(dir.path().join("loss.csv")).unwrap();
    assert_eq!(
        csv.lines().count(),
        1 + 4,
        "every finished step is logged once"
    );
    let resumed = TrainRun {
        interrupt: Default::default(),
        ..run
    }
    .run(&|_, _, _| {})
    .unwrap();
    assert_eq!(resumed.step, 12);
    let csv = std::fs::read_to_string(dir.path().join("loss.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 12);
}

/// Short runs of the tiny model that checkpoint every 5 steps.
fn tiny_run_config() -> TrainConfig {
    TrainConfig {
        model: tiny(),
        batch_size: 4,
        crop_frames: 16,
        warmup_steps: 1,
        checkpoint_every: 5,
        steps: 100,
        ..TrainConfig::default()
    }
}

#[test]
fn a_new_run_can_start_from_a_bundle() {
    let data = synthetic_dataset();
    let first = tempfile::tempdir().unwrap();
    let config = tiny_run_config();
    let run = |out: &std::path::Path, init: Option<std::path::PathBuf>, steps| TrainRun {
        data: &data,
        config: config.clone(),
        out: out.to_path_buf(),
        max_steps_now: Some(steps),
        interrupt: Default::default(),
        init_from: init,
        device: Device::flex(),
        after_checkpoint: None,
        text_encoder: None,
    };
    run(first.path(), None, 5).run(&|_, _, _| {}).unwrap();
    let second = tempfile::tempdir().unwrap();
    let state = run(second.path(), Some(first.path().join("bundle")), 5)
        .run(&|_, _, _| {})
        .unwrap();
    assert_eq!(state.step, 10, "the bundle's 5 steps carry on");
    // A bundle of another shape is refused.
    let mut other = config.clone();
    other.model.d_model = 48;
    let third = tempfile::tempdir().unwrap();
    let err = TrainRun {
        config: other,
        ..run(third.path(), Some(first.path().join("bundle")), 1)
    }
    .run(&|_, _, _| {})
    .unwrap_err();
    assert!(err.to_string().contains("does not match"), "{err}");
}

#[test]
fn a_run_with_input_skip_can_start_from_a_bundle_without_it() {
    let data = synthetic_dataset();
    let first = tempfile::tempdir().unwrap();
    let config = TrainConfig {
        learning_rate: 1e-2,
        ..tiny_run_config()
    };
    let run = |out: &std::path::Path, config: &TrainConfig, init, steps| TrainRun {
        data: &data,
        config: config.clone(),
        out: out.to_path_buf(),
        max_steps_now: Some(steps),
        interrupt: Default::default(),
        init_from: init,
        device: Device::flex(),
        after_checkpoint: None,
        text_encoder: None,
    };
    run(first.path(), &config, None, 5)
        .run(&|_, _, _| {})
        .unwrap();
    let dev = Device::flex();
    let plain = super::weights::ModelBundle::load(&first.path().join("bundle"), &dev).unwrap();
    assert_eq!(plain.model.input_skip_gain(10), None);
    // Adding the skip changes nothing until it is trained.
    let inp = input(2, 8, &dev);
    let with = plain.model.clone().with_input_skip(&dev);
    let diff = (plain.model.predict_x0(&inp) - with.predict_x0(&inp))
        .abs()
        .max()
        .into_scalar::<f32>();
    assert_eq!(diff, 0.0);
    let mut skip = config.clone();
    skip.model.input_skip = true;
    let second = tempfile::tempdir().unwrap();
    let state = run(second.path(), &skip, Some(first.path().join("bundle")), 5)
        .run(&|_, _, _| {})
        .unwrap();
    assert_eq!(state.step, 10);
    let trained = super::weights::ModelBundle::load(&second.path().join("bundle"), &dev).unwrap();
    assert!(trained.config.input_skip);
    let gain = trained.model.input_skip_gain(10).unwrap();
    assert_eq!(gain.len(), FEATURE_DIM);
    assert!(gain.iter().any(|g| *g != 0.0), "the skip learned nothing");
    // ... and it resumes.
    let state = run(second.path(), &skip, None, 5)
        .run(&|_, _, _| {})
        .unwrap();
    assert_eq!(state.step, 15);
    // A learned skip is not dropped by starting a run without it.
    let third = tempfile::tempdir().unwrap();
    let err = run(third.path(), &config, Some(second.path().join("bundle")), 1)
        .run(&|_, _, _| {})
        .unwrap_err();
    assert!(err.to_string().contains("does not match"), "{err}");
    // The one-frame skip widens to a temporal filter, trains with the low-noise weights,
    // and resumes.
    let mut taps = skip.clone();
    taps.model.skip_taps = 5;
    taps.low_noise_below = 200;
    taps.low_noise_loss_cap = 50.0;
    let fourth = tempfile::tempdir().unwrap();
    let state = run(fourth.path(), &taps, Some(second.path().join("bundle")), 3)
        .run(&|_, _, _| {})
        .unwrap();
    assert_eq!(state.step, 18, "the bundle's 15 steps carry on");
    let wide = super::weights::ModelBundle::load(&fourth.path().join("bundle"), &dev).unwrap();
    assert_eq!(wide.config.skip_taps, 5);
    let gain = wide.model.input_skip_gain(10).unwrap();
    assert_eq!(gain.len(), 5 * FEATURE_DIM);
    assert!(
        gain[..FEATURE_DIM].iter().any(|g| *g != 0.0),
        "the outer tap learned nothing"
    );
    let state = run(fourth.path(), &taps, None, 2)
        .run(&|_, _, _| {})
        .unwrap();
    assert_eq!(state.step, 20);
}

/// A hook that leaves `hook.txt` in the run folder.
fn mark_checkpoint(out: &std::path::Path) -> Result<(), String> {
    std::fs::write(out.join("hook.txt"), "ran").map_err(|e| e.to_string())
}

#[test]
fn a_high_noise_share_draws_late_timesteps_and_none_keeps_the_old_draw() {
    use super::batch::{HIGH_NOISE_FROM, draw_batch, step_rng};
    use rand::Rng;
    let data = synthetic_dataset();
    let clips: Vec<&ClipInfo> = data.clips(Split::Train).collect();
    let draws = |fraction: f64| -> Vec<usize> {
        let cfg = TrainConfig {
            batch_size: 64,
            crop_frames: 16,
            high_noise_fraction: fraction,
            ..TrainConfig::default()
        };
        (0..8)
            .flat_map(|step| draw_batch(&data, &clips, &cfg, step).timesteps)
            .collect()
    };
    let all_late = draws(1.0);
    assert!(
        all_late
            .iter()
            .all(|&t| (HIGH_NOISE_FROM..DIFFUSION_STEPS).contains(&t))
    );
    let uniform = draws(0.0);
    let late = |ts: &[usize]| ts.iter().filter(|&&t| t >= HIGH_NOISE_FROM).count() as f64;
    // A third drawn late plus the uniform tenth: ~40 % at t ≥ 900, against ~10 %.
    let mixed = draws(1.0 / 3.0);
    let n = mixed.len() as f64;
    assert!(
        (late(&mixed) / n - 0.4).abs() < 0.08,
        "{}",
        late(&mixed) / n
    );
    assert!(late(&uniform) / n < 0.2, "{}", late(&uniform) / n);
    // Share 0 is the draw runs made before the option: the same generator calls.
    let cfg = TrainConfig {
        batch_size: 64,
        crop_frames: 16,
        ..TrainConfig::default()
    };
    let batch = draw_batch(&data, &clips, &cfg, 3);
    let mut rng = step_rng(cfg.seed, 3);
    for _ in 0..cfg.batch_size {
        let _ = rng.random_range(0..1usize); // the clip (one clip: a plain range draw)
        let _ = rng.random_range(0..=data.index.clips[0].frames - 16); // its crop
        let _ = rng.random_range(0..1usize); // its caption
    }
    let want: Vec<usize> = (0..cfg.batch_size)
        .map(|_| rng.random_range(0..DIFFUSION_STEPS))
        .collect();
    assert_eq!(batch.timesteps, want);
}

#[test]
fn hold_padding_places_a_short_clip_inside_a_still_window() {
    use crate::features::layout::{LOCAL_VEL, RIC, ROOT_VEL, ROOT_YAW_VEL};
    use crate::model::batch::draw_batch;
    let ds = synthetic_dataset();
    let train: Vec<&ClipInfo> = ds.clips(Split::Train).collect();
    let cfg = TrainConfig {
        batch_size: 8,
        crop_frames: 40,
        hold_pad: 1.0,
        ..TrainConfig::default()
    };
    let clip = &ds.features[..24 * FEATURE_DIM];
    let mut padded = 0;
    for step in 0..6 {
        let b = draw_batch(&ds, &train, &cfg, step);
        assert!(b.frames <= 40 && b.frames >= 24);
        for i in 0..8 {
            let rows: Vec<&[f32]> = (0..b.frames)
                .filter(|&k| !b.padding[i * b.frames + k])
                .map(|k| &b.x0[(i * b.frames + k) * FEATURE_DIM..][..FEATURE_DIM])
                .collect();
            assert!((24..=40).contains(&rows.len()), "{}", rows.len());
            // The clip appears whole and in order; every other row holds its first or
            // last pose, still.
            let at = (0..=rows.len() - 24)
                .find(|&a| rows[a] == &clip[..FEATURE_DIM])
                .expect("the clip's first frame");
            for k in 0..24 {
                assert_eq!(rows[at + k], &clip[k * FEATURE_DIM..][..FEATURE_DIM]);
            }
            for (k, row) in rows.iter().enumerate() {
                if (at..at + 24).contains(&k) {
                    continue;
                }
                padded += 1;
                let src = if k < at { 0 } else { 23 };
                let pose = &clip[src * FEATURE_DIM..][..FEATURE_DIM];
                assert_eq!(row[RIC], pose[RIC]);
                for r in [ROOT_YAW_VEL, ROOT_VEL, LOCAL_VEL] {
                    assert!(row[r].iter().all(|&v| v == 0.0));
                }
            }
        }
    }
    assert!(padded > 0, "no sample was padded");
    // Without hold_pad the clip is its own length.
    let plain = draw_batch(
        &ds,
        &train,
        &TrainConfig {
            hold_pad: 0.0,
            ..cfg
        },
        0,
    );
    assert_eq!(plain.frames, 24);
}

#[test]
fn distillation_fits_a_student_to_its_teacher_and_marks_the_bundle() {
    use super::config::DistilConfig;
    use super::generate::{GenerateRequest, generate};
    use super::sampler::SamplerKind;
    let data = synthetic_dataset();
    let teacher = tempfile::tempdir().unwrap();
    let config = TrainConfig {
        learning_rate: 3e-3,
        ..tiny_run_config()
    };
    let run = |out: &std::path::Path, config: TrainConfig, init, steps| TrainRun {
        data: &data,
        config,
        out: out.to_path_buf(),
        max_steps_now: Some(steps),
        interrupt: Default::default(),
        init_from: init,
        device: Device::flex(),
        after_checkpoint: None,
        text_encoder: None,
    };
    run(teacher.path(), config.clone(), None, 20)
        .run(&|_, _, _| {})
        .unwrap();
    let bundle_dir = teacher.path().join("bundle");
    let distil = TrainConfig {
        learning_rate: 1e-3,
        ema_decay: 0.95,
        // The student's bone term runs too.
        bone_loss: 1e-4,
        distil: Some(DistilConfig {
            teacher: bundle_dir.display().to_string(),
            guidance: 2.5,
            grid: 10,
            huber_c: 0.03,
        }),
        ..config.clone()
    };
    let student = tempfile::tempdir().unwrap();
    run(student.path(), distil.clone(), Some(bundle_dir.clone()), 40)
        .run(&|_, _, _| {})
        .unwrap();
    let csv = std::fs::read_to_string(student.path().join("loss.csv")).unwrap();
    let losses: Vec<f64> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(losses.len(), 40);
    assert!(losses.iter().all(|l| l.is_finite() && *l >= 0.0));
    let early: f64 = losses[..10].iter().sum::<f64>() / 10.0;
    let late: f64 = losses[30..].iter().sum::<f64>() / 10.0;
    assert!(
        late < early,
        "the consistency loss did not fall: {early} -> {late}"
    );
    let bundle =
        super::weights::ModelBundle::load(&student.path().join("bundle"), &Device::flex()).unwrap();
    let c = bundle
        .manifest
        .consistency
        .clone()
        .expect("marked as a consistency model");
    assert_eq!((c.grid, c.guidance), (10, 2.5));
    assert!(bundle.manifest.weights_id.starts_with("lcm-"));
    // It samples in two steps, deterministically.
    let req = GenerateRequest {
        prompts: vec!["walk".into()],
        frames: 12,
        seed: 3,
        sampler: SamplerKind::Consistency { steps: 2, grid: 10 },
        guidance_scale: 1.0,
        mirror_average: false,
    };
    let mut steps = 0;
    let a = generate(&bundle, &req, &Device::flex(), |_, _| steps += 1).unwrap();
    let b = generate(&bundle, &req, &Device::flex(), |_, _| {}).unwrap();
    assert_eq!(steps, 2);
    assert_eq!(a.features, b.features);
    // A consistency bundle cannot teach another.
    let again = tempfile::tempdir().unwrap();
    let mut from_student = distil;
    from_student.distil.as_mut().unwrap().teacher =
        student.path().join("bundle").display().to_string();
    let err = run(again.path(), from_student, Some(bundle_dir), 1)
        .run(&|_, _, _| {})
        .unwrap_err();
    assert!(err.to_string().contains("few-step"), "{err}");
}
