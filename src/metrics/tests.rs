//! Evaluation tests on a synthetic dataset of four easily told-apart motions (walk, run,
//! wave, squat): evaluator training, its files, and `run_eval` end to end with a tiny
//! random model.

use super::encoder::{EncoderConfig, EvaluatorNet, motion_batch, rows_of};
use super::evaluator::{EVALUATOR_VERSION, Evaluator};
use super::report::{EvalSettings, PER_LABELS, run_eval};
use super::table::report_markdown;
use super::train_encoder::{EncoderTrainConfig, train_evaluator};
use crate::dataset::stats::feature_stats;
use crate::dataset::{ClipInfo, Dataset, DatasetIndex, FEATURE_DIM, Split, SplitStats};
use crate::features::{ExtractOptions, extract};
use crate::model::config::ModelConfig;
use crate::model::prompt::PromptEncoder;
use crate::model::sampler::SamplerKind;
use crate::model::text::Vocabulary;
use crate::model::weights::{BUNDLE_VERSION, Manifest};
use crate::model::{Mdm, ModelBundle};
use crate::motion::Motion;
use crate::skeleton::{NUM_JOINTS, rest_pose};
use burn::prelude::*;
use glam::Vec3;

const LABELS: [(&str, &str); 4] = [
    ("walk", "a person walks forward"),
    ("run", "a person runs forward"),
    ("wave-right-hand", "a person waves the right hand"),
    ("squat", "a person squats down"),
];

/// One synthetic clip of `label` with `frames + 1` poses; `v` varies speed and phase.
fn synthetic_motion(label: usize, frames: usize, v: f32) -> Motion {
    let rest = rest_pose();
    let poses = (0..=frames)
        .map(|t| {
            let s = t as f32 / 20.0;
            let mut p = rest;
            let (shift, lift) = match label {
                0 => (Vec3::Z * (1.0 + 0.1 * v) * s, 0.0),
                1 => (Vec3::Z * (3.0 + 0.2 * v) * s, 0.0),
                _ => (Vec3::ZERO, 0.0),
            };
            for q in p.iter_mut() {
                *q += shift + Vec3::Y * lift;
            }
            let phase = (6.0 + v) * s;
            match label {
                0 | 1 => {
                    // Feet swing back and forth.
                    let a = 0.2 * phase.sin();
                    for j in [4, 7, 10] {
                        p[j].z += a;
                    }
                    for j in [5, 8, 11] {
                        p[j].z -= a;
                    }
                }
                2 => {
                    // Right arm up, the wrist swinging sideways above the head.
                    let top = p[15].y + 0.2;
                    p[19] = p[17] + Vec3::new(-0.05, 0.25, 0.0);
                    p[21] = Vec3::new(p[19].x - 0.15 * phase.sin(), top, p[19].z);
                }
                _ => {
                    // Upper body moves down and up.
                    let d = 0.25 * (0.5 - 0.5 * phase.cos());
                    for (j, q) in p.iter_mut().enumerate() {
                        if ![7, 8, 10, 11].contains(&j) {
                            q.y -= d;
                        }
                    }
                }
            }
            p
        })
        .collect();
    Motion::new(poses)
}

/// `per_split[k]` clips per label in train, val, test.
fn synthetic_dataset(per_split: [usize; 3]) -> Dataset {
    let mut clips = Vec::new();
    let mut features = Vec::new();
    let mut joints = Vec::new();
    let mut offset = 0;
    for (s, split) in [Split::Train, Split::Val, Split::Test]
        .into_iter()
        .enumerate()
    {
        for (l, (label, caption)) in LABELS.iter().enumerate() {
            for i in 0..per_split[s] {
                let frames = 40 + 7 * (i % 4);
                let m = synthetic_motion(l, frames, (i * 7 % 5) as f32 * 0.3);
                let f = extract(&m, &ExtractOptions::default()).unwrap().into_vec();
                features.extend_from_slice(&f);
                joints.extend(m.to_flat()[..frames * NUM_JOINTS * 3].iter());
                clips.push(ClipInfo {
                    name: format!("{label}_{s}_{i}"),
                    source: format!("{label}_{s}_{i}.bvh"),
                    content: label.to_string(),
                    style: "normal".into(),
                    mirrored: false,
                    split,
                    offset,
                    frames,
                    captions: vec![caption.to_string(), format!("someone {label}s")],
                });
                offset += frames;
            }
        }
    }
    let train: Vec<&[f32]> = clips
        .iter()
        .filter(|c| c.split == Split::Train)
        .map(|c| &features[c.offset * FEATURE_DIM..(c.offset + c.frames) * FEATURE_DIM])
        .collect();
    let (mean, std) = feature_stats(&train);
    Dataset {
        index: DatasetIndex {
            version: 1,
            fps: 20.0,
            clips,
            stats: [
                SplitStats::default(),
                SplitStats::default(),
                SplitStats::default(),
            ],
            skipped: vec![],
            build_seconds: 0.0,
        },
        features,
        joints,
        mean,
        std,
    }
}

fn tiny_encoder() -> EncoderConfig {
    EncoderConfig {
        hidden: 16,
        embed_dim: 16,
        word_dim: 8,
        max_frames: 60,
        ..EncoderConfig::default()
    }
}

fn tiny_training(steps: usize) -> EncoderTrainConfig {
    EncoderTrainConfig {
        encoder: tiny_encoder(),
        steps,
        batch_size: 12,
        crop_frames: 40,
        learning_rate: 3e-3,
        warmup_steps: 2,
        ..EncoderTrainConfig::default()
    }
}

#[test]
fn encoder_training_lowers_the_contrastive_loss() {
    let data = synthetic_dataset([4, 1, 0]);
    let (evaluator, losses) = train_evaluator(&data, &tiny_training(40), &mut |_, _| {}).unwrap();
    assert_eq!(losses.len(), 40);
    let early: f32 = losses[..5].iter().sum::<f32>() / 5.0;
    let late: f32 = losses[35..].iter().sum::<f32>() / 5.0;
    assert!(late < 0.7 * early, "loss did not fall: {early} -> {late}");
    // Four labels, 12 clips a batch: the trained encoder puts a walk nearer its caption
    // than the wave caption.
    let dev = Device::flex();
    let walk = data
        .clips(Split::Train)
        .find(|c| c.content == "walk")
        .unwrap();
    let m = evaluator
        .embed_motions(&[data.clip_features(walk)], &dev)
        .unwrap();
    let t = evaluator
        .embed_captions(&[LABELS[0].1, LABELS[2].1], &dev)
        .unwrap();
    let dot = |a: &[f32], b: &[f32]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f32>();
    assert!(dot(&m[0], &t[0]) > dot(&m[0], &t[1]));
}

#[test]
fn motion_embedding_does_not_depend_on_batch_padding() {
    let data = synthetic_dataset([2, 0, 0]);
    let dev = Device::flex();
    let cfg = tiny_encoder();
    let net = EvaluatorNet::new(&cfg, 10, &dev);
    let clips: Vec<&ClipInfo> = data.clips(Split::Train).collect();
    let short = data.clip_features(clips[0]); // 40 frames
    let long = data.clip_features(clips[3]); // 47 frames
    assert!(long.len() > short.len());
    let embed = |rows: &[&[f32]]| {
        let (x, valid) = motion_batch(rows, &data.mean, &data.std, cfg.max_frames, &dev);
        rows_of(net.motion.forward(x, valid)).unwrap()
    };
    let alone = embed(&[short]);
    let padded = embed(&[short, long]);
    for (a, b) in alone[0].iter().zip(&padded[0]) {
        assert!((a - b).abs() < 1e-5, "{a} vs {b}");
    }
    let norm: f32 = padded[1].iter().map(|v| v * v).sum();
    assert!((norm - 1.0).abs() < 1e-4);
}

#[test]
fn evaluator_files_round_trip_and_mismatches_are_refused() {
    let data = synthetic_dataset([2, 0, 0]);
    let (evaluator, _) = train_evaluator(&data, &tiny_training(2), &mut |_, _| {}).unwrap();
    let dir = tempfile::tempdir().unwrap();
    evaluator.save(dir.path()).unwrap();
    assert!(dir.path().join("README.md").exists());
    let dev = Device::flex();
    let loaded = Evaluator::load(dir.path(), &dev).unwrap();
    let rows = [data.clip_features(&data.index.clips[0])];
    let a = evaluator.embed_motions(&rows, &dev).unwrap();
    let b = loaded.embed_motions(&rows, &dev).unwrap();
    let diff = a[0]
        .iter()
        .zip(&b[0])
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max);
    assert!(diff < 1e-2, "f16 round trip changed an embedding by {diff}");
    // A manifest claiming another shape: the weights no longer fit.
    let manifest_path = dir.path().join("manifest.json");
    let text = std::fs::read_to_string(&manifest_path).unwrap();
    let mut manifest = evaluator.manifest.clone();
    manifest.config.hidden = 24;
    std::fs::write(&manifest_path, serde_json::to_string(&manifest).unwrap()).unwrap();
    let err = Evaluator::load(dir.path(), &dev).unwrap_err().to_string();
    assert!(err.contains("do not fit"), "{err}");
    // Another version.
    manifest = evaluator.manifest.clone();
    manifest.version = EVALUATOR_VERSION + 1;
    std::fs::write(&manifest_path, serde_json::to_string(&manifest).unwrap()).unwrap();
    let err = Evaluator::load(dir.path(), &dev).unwrap_err().to_string();
    assert!(err.contains("version"), "{err}");
    std::fs::write(&manifest_path, text).unwrap();
    // Wrong statistics width.
    crate::dataset::store::write_f32_npy(&dir.path().join("std.npy"), &[3], &[1.0; 3]).unwrap();
    let err = Evaluator::load(dir.path(), &dev).unwrap_err().to_string();
    assert!(err.contains("std.npy"), "{err}");
}

/// An untrained tiny denoiser over the synthetic data's vocabulary and statistics.
fn tiny_bundle(data: &Dataset, dev: &Device) -> ModelBundle {
    let config = ModelConfig {
        d_model: 32,
        layers: 1,
        heads: 2,
        d_ff: 64,
        d_text: 8,
        text_encoder: Default::default(),
        max_frames: 50,
        input_skip: false,
        skip_taps: 1,
        skip_taps_below: None,
        side_input: false,
        ..ModelConfig::default()
    };
    let vocab = Vocabulary::from_captions(
        data.index
            .clips
            .iter()
            .flat_map(|c| c.captions.iter().map(String::as_str)),
        16,
    );
    ModelBundle {
        model: Mdm::new(&config, vocab.len(), dev),
        config,
        text: PromptEncoder::Words(vocab),
        mean: data.mean.clone(),
        std: data.std.clone(),
        manifest: Manifest {
            version: BUNDLE_VERSION,
            weights_id: "tiny-random".into(),
            steps: 0,
            train_seconds: 0.0,
            half_precision: false,
            text_encoder_id: None,
            control_id: None,
            consistency: None,
        },
    }
}

#[test]
fn eval_runs_end_to_end_on_a_tiny_dataset_and_model() {
    let data = synthetic_dataset([4, 0, 12]);
    let dev = Device::flex();
    let (evaluator, _) = train_evaluator(&data, &tiny_training(30), &mut |_, _| {}).unwrap();
    let bundle = tiny_bundle(&data, &dev);
    let settings = EvalSettings {
        count: 8,
        seed: 3,
        sampler: SamplerKind::Ddim(3),
        batch_size: 3,
        per_label: Some(2),
        ..EvalSettings::default()
    };
    let mut lines = Vec::new();
    let (report, samples) = run_eval(&data, &bundle, &evaluator, &settings, &dev, &mut |l| {
        lines.push(l.to_string())
    })
    .unwrap();
    assert!(lines.iter().any(|l| l.contains("8 prompts")), "{lines:?}");
    assert_eq!(report.rows.len(), 3);
    let [real, model, frozen] = [&report.rows[0], &report.rows[1], &report.rows[2]];
    assert!(
        report
            .rows
            .iter()
            .all(|r| r.count == 8 && r.fid.is_finite())
    );
    // Real clips: no sliding, rigid bones, at rest on the floor; the frozen baseline
    // does not move at all and has no diversity of motion beyond its first poses.
    assert_eq!(frozen.metrics.max_accel, 0.0);
    assert_eq!(frozen.metrics.speed, 0.0);
    assert!(real.metrics.speed > 0.0);
    // A random untrained model is worse than the real clips on FID and R-precision.
    assert!(model.fid > real.fid, "{} vs {}", model.fid, real.fid);
    assert!(real.r_precision[2] > 0.5, "{:?}", real.r_precision);
    assert!(real.r_precision[2] >= model.r_precision[2]);
    // Per-label rows: the synthetic set has walk, run and wave-right-hand of the six.
    assert_eq!(report.labels.len(), PER_LABELS.len());
    let walk = &report.labels[0];
    assert!((walk.real.speed - 1.05).abs() < 0.1, "{:?}", walk.real);
    assert_eq!(walk.generated.as_ref().unwrap().count, 2);
    assert!(
        report.labels[2].generated.is_none(),
        "no raise-up-both-hands clips"
    );
    assert!(
        report.labels[5].real.wrists > 0.1,
        "{:?}",
        report.labels[5].real
    );
    assert!(
        report.labels[5].real.wrist_side > 0.3,
        "the right hand waves"
    );
    assert_eq!(samples.len(), 8 + 3 * 2);
    assert!(
        samples
            .iter()
            .all(|s| s.motion.len() >= 40 && s.motion.len() <= 50)
    );
    let text = report_markdown(&report);
    assert!(
        text.contains("| real test data | 8 |") && text.contains("tiny-random"),
        "{text}"
    );
    assert!(text.contains("| raise-up-both-hands | 0 / 0 |"), "{text}");
    // Same seed, same report.
    let (again, _) = run_eval(&data, &bundle, &evaluator, &settings, &dev, &mut |_| {}).unwrap();
    assert_eq!(again.rows, report.rows);
}

/// The foot cleanup (solve) lowers the skating ratio measured here: the rest pose gliding
/// forward 36 cm with its feet on the floor.
#[test]
fn foot_cleanup_lowers_the_skating_ratio() {
    use crate::features::recover_from_ric;
    use crate::motion::Motion;
    use crate::solve::cleanup::{FootCleanup, clean_feet};
    let frames = 12;
    let pose = crate::skeleton::rest_pose();
    let glide = Motion::new(
        (0..=frames)
            .map(|t| pose.map(|p| p + glam::Vec3::Z * 0.6 * t as f32 / 20.0))
            .collect(),
    );
    let mut rows = extract(&glide, &ExtractOptions::default())
        .unwrap()
        .into_vec();
    let before = super::per_motion::foot_skating_ratio(&recover_from_ric(&rows).unwrap());
    clean_feet(&mut rows, frames, FEATURE_DIM, &FootCleanup::default());
    let after = super::per_motion::foot_skating_ratio(&recover_from_ric(&rows).unwrap());
    assert!(after < before, "skating {before} -> {after}");
}

#[test]
fn text_match_scores_each_span_of_a_long_motion_against_its_prompt() {
    use super::text_match::{PromptSpan, text_match};
    let data = synthetic_dataset([4, 1, 0]);
    let (evaluator, _) = train_evaluator(&data, &tiny_training(60), &mut |_, _| {}).unwrap();
    let window = evaluator.manifest.config.max_frames;
    // A walk of 150 frames, then a squat of 100 where the walk ended: longer than the
    // evaluator's 60 frames, so both spans are scored in windows.
    let walk = synthetic_motion(0, 150, 0.3);
    let end = walk.frames[149][0] - rest_pose()[0];
    let squat = synthetic_motion(3, 100, 0.3);
    let mut frames = walk.frames[..150].to_vec();
    frames.extend(
        squat
            .frames
            .iter()
            .map(|p| p.map(|q| q + Vec3::new(end.x, 0.0, end.z))),
    );
    let motion = Motion::new(frames);
    assert!(motion.len() > 3 * window);
    let span = |from, to, prompt: &str| PromptSpan {
        person: 0,
        from,
        to,
        prompt: prompt.into(),
    };
    let spans = [span(0, 150, LABELS[0].1), span(150, 300, LABELS[3].1)];
    let dev = Device::flex();
    let got = text_match(&evaluator, std::slice::from_ref(&motion), &spans, &dev).unwrap();
    assert_eq!(got.len(), 2);
    assert_eq!(
        got[0].windows,
        super::text_match::windows(149, window).len()
    );
    assert!(got[0].windows >= 3 && got[1].windows >= 2);
    assert_eq!(got[1].span.to, motion.len(), "cut to the motion");
    for (m, s) in got.iter().zip(&spans) {
        let sim = m.similarity.unwrap();
        assert!((-1.0..=1.0).contains(&sim));
        // Each span looks most like its own prompt.
        assert_eq!(m.closest.as_ref().unwrap().0, s.prompt, "{m:?}");
    }
    // One span over the whole motion: its own prompt only, no "closest".
    let whole = text_match(
        &evaluator,
        std::slice::from_ref(&motion),
        &[span(0, 300, "a person walks forward")],
        &dev,
    )
    .unwrap();
    assert!(whole[0].closest.is_none() && whole[0].windows > 1);
    // A prompt without a known word has no similarity; a missing person is an error.
    let odd = text_match(
        &evaluator,
        std::slice::from_ref(&motion),
        &[span(0, 100, "zyx qwv")],
        &dev,
    )
    .unwrap();
    assert_eq!(odd[0].similarity, None);
    assert_eq!(odd[0].unknown_words, ["zyx", "qwv"]);
    let bad = PromptSpan {
        person: 1,
        ..span(0, 100, "a person walks forward")
    };
    assert!(text_match(&evaluator, &[motion], &[bad], &dev).is_err());
}
