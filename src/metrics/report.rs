//! `mprog eval`: real test clips, a model's motions for the same captions and a trivial
//! baseline, each scored with the motion metrics and the learned evaluator.
//!
//! * Prompts: `count` test clips (≥ `min_frames` frames) drawn by seed, one caption each;
//!   motion lengths are the clips' lengths capped at the model's `max_frames`.
//! * Reference of FID: every other eligible test clip whose source file is not among the
//!   prompts' (so a clip's mirrored copy is not its own reference).
//! * Model: generated in batches of clips of similar length (sorted), each batch at its
//!   longest length, each motion cut to its own length.
//! * Trivial baseline: the first pose of each prompt clip held still for its length.
//! * Per label (optional): the baseline table's descriptors for real test clips of a label
//!   and for `per_label` motions generated from captions of that label.

use super::error::MetricsError;
use super::evaluator::Evaluator;
use super::per_motion::MotionMetrics;
use super::scores::{DIVERSITY_PAIRS, Distractor, diversity, fid, r_precision};
use crate::dataset::{ClipInfo, Dataset, FEATURE_DIM, Split};
use crate::features::{ExtractOptions, extract};
use crate::model::ModelBundle;
use crate::model::generate::{GenerateRequest, generate};
use crate::model::sampler::SamplerKind;
use crate::motion::Motion;
use crate::solve::cleanup::{FootCleanup, clean_generated};
use burn::prelude::*;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::HashSet;

/// Labels of the per-label table (those of `notes/training-baseline.md`, plus a wave).
pub const PER_LABELS: [&str; 6] = [
    "walk",
    "run",
    "raise-up-both-hands",
    "walk-turn-left",
    "walk-turn-right",
    "wave-right-hand",
];

/// Settings of an evaluation.
#[derive(Clone, Debug, PartialEq)]
pub struct EvalSettings {
    /// Test captions to generate from.
    pub count: usize,
    /// Seed of the clip choice, captions, noise and pairs.
    pub seed: u64,
    /// Sampler.
    pub sampler: SamplerKind,
    /// Classifier-free guidance scale.
    pub guidance_scale: f32,
    /// Motions generated per call.
    pub batch_size: usize,
    /// Test clips shorter than this are not used (T2M drops clips under 40 frames).
    pub min_frames: usize,
    /// Motions generated per label for the per-label table; None skips the table.
    pub per_label: Option<usize>,
    /// Foot cleanup of the generated motions, as `mprog gen` does; None scores them raw.
    pub foot_cleanup: Option<FootCleanup>,
    /// Average the denoiser with its left/right mirror (`GenerateRequest::mirror_average`).
    pub mirror_average: bool,
}

impl Default for EvalSettings {
    fn default() -> Self {
        EvalSettings {
            count: 32,
            seed: 1,
            sampler: SamplerKind::Ddim(50),
            guidance_scale: 2.5,
            batch_size: 16,
            min_frames: 40,
            per_label: None,
            foot_cleanup: None,
            mirror_average: false,
        }
    }
}

/// Motions scored together: joints for the metrics, de-normalised features for the
/// evaluator, and the caption each one stands for.
#[derive(Clone, Debug, Default)]
pub struct MotionSet {
    /// Joint positions.
    pub motions: Vec<Motion>,
    /// `[frames, 263]` de-normalised feature rows of each motion.
    pub features: Vec<Vec<f32>>,
    /// Caption of each motion.
    pub captions: Vec<String>,
    /// Content label of each motion's caption.
    pub labels: Vec<String>,
}

/// Scores of one set (means over its motions for the per-motion metrics).
#[derive(Clone, Debug, PartialEq)]
pub struct SetScores {
    /// Row name.
    pub name: String,
    /// Motions in the set.
    pub count: usize,
    /// Mean per-motion metrics (penetration fields are means too).
    pub metrics: MotionMetrics,
    /// FID against the reference clips.
    pub fid: f64,
    /// Mean distance of random pairs.
    pub diversity: f64,
    /// Top-1/2/3 R-precision with the set's captions.
    pub r_precision: [f64; 3],
}

/// Descriptor means of one side of a per-label row.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LabelStats {
    /// Motions measured.
    pub count: usize,
    /// Mean horizontal root speed (m/s).
    pub speed: f32,
    /// Mean total turn (degrees).
    pub turn: f32,
    /// Smallest and largest total turn.
    pub turn_range: (f32, f32),
    /// Mean highest wrist above head (m).
    pub wrists: f32,
    /// Mean right-minus-left wrist peak height (m).
    pub wrist_side: f32,
    /// Mean foot skating ratio.
    pub skating: f32,
}

/// One per-label row: real test clips vs generated motions.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelRow {
    /// Content label.
    pub label: String,
    /// Real test clips of the label.
    pub real: LabelStats,
    /// Generated motions (None when the test split has no clip of the label).
    pub generated: Option<LabelStats>,
}

/// Everything `mprog eval` prints.
#[derive(Clone, Debug)]
pub struct EvalReport {
    /// Real, model, baseline.
    pub rows: Vec<SetScores>,
    /// Per-label comparison (empty unless asked for).
    pub labels: Vec<LabelRow>,
    /// The model's weights id and training steps.
    pub model: (String, usize),
    /// The evaluator's training steps and validation R-precision.
    pub evaluator: (usize, Option<[f64; 3]>),
    /// Clips in the FID reference.
    pub reference_clips: usize,
    /// The settings used.
    pub settings: EvalSettings,
    /// Seconds spent generating.
    pub generate_seconds: f64,
}

/// A generated motion with what it was asked for (for pictures).
#[derive(Clone, Debug)]
pub struct Sample {
    /// Caption.
    pub caption: String,
    /// Content label of the caption's clip.
    pub label: String,
    /// The motion.
    pub motion: Motion,
}

/// A prompt: a test clip, its caption and the length to generate.
#[derive(Clone, Debug)]
struct Prompt<'a> {
    clip: &'a ClipInfo,
    caption: String,
    frames: usize,
}

fn pick_caption(clip: &ClipInfo, rng: &mut ChaCha8Rng) -> String {
    clip.captions[rng.random_range(0..clip.captions.len())].clone()
}

/// Real clip `clip` cut to its first `frames` frames.
fn real_motion(data: &Dataset, clip: &ClipInfo, frames: usize) -> (Motion, Vec<f32>) {
    let joints = &data.clip_joints(clip)[..frames * 66];
    let features = data.clip_features(clip)[..frames * FEATURE_DIM].to_vec();
    (Motion::from_flat(joints), features)
}

/// The first pose of `clip` held for `frames` frames, with its features.
fn frozen_motion(
    data: &Dataset,
    clip: &ClipInfo,
    frames: usize,
) -> Result<(Motion, Vec<f32>), MetricsError> {
    let first = Motion::from_flat(&data.clip_joints(clip)[..66]).frames[0];
    let motion = Motion::new(vec![first; frames]);
    // F + 1 frames give F feature rows.
    let longer = Motion::new(vec![first; frames + 1]);
    let features = extract(&longer, &ExtractOptions::default())?.into_vec();
    Ok((motion, features))
}

/// Generates one motion per prompt, batching prompts of similar length.
fn generate_for(
    bundle: &ModelBundle,
    prompts: &[Prompt],
    settings: &EvalSettings,
    seed: u64,
    device: &Device,
    log: &mut dyn FnMut(&str),
) -> Result<MotionSet, MetricsError> {
    let mut order: Vec<usize> = (0..prompts.len()).collect();
    order.sort_by_key(|&i| prompts[i].frames);
    let mut out: Vec<Option<(Motion, Vec<f32>)>> = vec![None; prompts.len()];
    for (b, chunk) in order.chunks(settings.batch_size.max(1)).enumerate() {
        let frames = chunk.iter().map(|&i| prompts[i].frames).max().unwrap_or(2);
        let req = GenerateRequest {
            prompts: chunk.iter().map(|&i| prompts[i].caption.clone()).collect(),
            frames,
            seed: seed.wrapping_add(b as u64),
            sampler: settings.sampler,
            guidance_scale: settings.guidance_scale,
            mirror_average: settings.mirror_average,
        };
        log(&format!(
            "generating {} motions of {frames} frames ({}/{} done)",
            chunk.len(),
            out.iter().filter(|o| o.is_some()).count(),
            prompts.len()
        ));
        let mut generated = generate(bundle, &req, device, |_, _| {})?;
        if let Some(cfg) = &settings.foot_cleanup {
            clean_generated(&mut generated, frames, cfg)?;
        }
        let per = frames * FEATURE_DIM;
        for (k, &i) in chunk.iter().enumerate() {
            let len = prompts[i].frames;
            let mut motion = generated.motions[k].clone();
            motion.frames.truncate(len);
            let features = generated.features[k * per..k * per + len * FEATURE_DIM].to_vec();
            out[i] = Some((motion, features));
        }
    }
    let mut set = MotionSet::default();
    for (p, o) in prompts.iter().zip(out) {
        let (motion, features) =
            o.ok_or_else(|| MetricsError::Invalid("a prompt was not generated".into()))?;
        set.motions.push(motion);
        set.features.push(features);
        set.captions.push(p.caption.clone());
        set.labels.push(p.clip.content.clone());
    }
    Ok(set)
}

/// Mean of the per-motion metrics of a set.
pub fn mean_metrics(motions: &[Motion]) -> MotionMetrics {
    let n = motions.len().max(1) as f32;
    let mut m = MotionMetrics::default();
    for x in motions.iter().map(MotionMetrics::of) {
        m.skating += x.skating / n;
        m.max_accel += x.max_accel / n;
        m.bone_variation += x.bone_variation / n;
        m.penetration.mean_depth += x.penetration.mean_depth / n;
        m.penetration.frame_fraction += x.penetration.frame_fraction / n;
        m.speed += x.speed / n;
        m.turn_deg += x.turn_deg / n;
        m.wrists_above_head += x.wrists_above_head / n;
        m.wrist_side += x.wrist_side / n;
    }
    m
}

/// What every set is scored against.
struct Reference {
    embeddings: Vec<Vec<f32>>,
    distractors: Vec<Distractor>,
}

fn score_set(
    name: &str,
    set: &MotionSet,
    reference: &Reference,
    evaluator: &Evaluator,
    seed: u64,
    device: &Device,
) -> Result<SetScores, MetricsError> {
    let rows: Vec<&[f32]> = set.features.iter().map(Vec::as_slice).collect();
    let motions = evaluator.embed_motions(&rows, device)?;
    let captions: Vec<&str> = set.captions.iter().map(String::as_str).collect();
    let texts = evaluator.embed_captions(&captions, device)?;
    Ok(SetScores {
        name: name.to_string(),
        count: set.motions.len(),
        metrics: mean_metrics(&set.motions),
        fid: fid(&motions, &reference.embeddings)?,
        diversity: diversity(&motions, DIVERSITY_PAIRS, seed)?,
        r_precision: r_precision(&motions, &texts, &set.labels, &reference.distractors, seed)?,
    })
}

fn label_stats(motions: &[Motion]) -> LabelStats {
    let all: Vec<MotionMetrics> = motions.iter().map(MotionMetrics::of).collect();
    let m = mean_metrics(motions);
    let turns = all.iter().map(|x| x.turn_deg);
    LabelStats {
        count: motions.len(),
        speed: m.speed,
        turn: m.turn_deg,
        turn_range: (
            turns.clone().fold(f32::INFINITY, f32::min),
            turns.fold(f32::NEG_INFINITY, f32::max),
        ),
        wrists: m.wrists_above_head,
        wrist_side: m.wrist_side,
        skating: m.skating,
    }
}

/// Runs the whole evaluation; `log` receives progress lines. Also returns the generated
/// motions (main set first, then per label) for pictures.
pub fn run_eval(
    data: &Dataset,
    bundle: &ModelBundle,
    evaluator: &Evaluator,
    settings: &EvalSettings,
    device: &Device,
    log: &mut dyn FnMut(&str),
) -> Result<(EvalReport, Vec<Sample>), MetricsError> {
    if bundle.config.features != FEATURE_DIM || evaluator.manifest.config.features != FEATURE_DIM {
        return Err(MetricsError::Invalid(format!(
            "model and evaluator must both read {FEATURE_DIM} features"
        )));
    }
    let eval = Evaluation {
        data,
        bundle,
        evaluator,
        settings,
        device,
        cap: bundle
            .config
            .max_frames
            .min(evaluator.manifest.config.max_frames),
    };
    // One generator, drawn from in this order: clips, captions, distractors, per label.
    let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
    let chosen = eval.choose_clips(&mut rng)?;
    log(&format!(
        "{} prompts, FID reference of {} held-out test clips",
        chosen.prompts.len(),
        chosen.reference.len()
    ));
    let reference = eval.reference(&chosen, &mut rng)?;
    let (real, frozen) = real_and_frozen(data, &chosen.prompts)?;
    let clock = std::time::Instant::now();
    let generated = generate_for(
        bundle,
        &chosen.prompts,
        settings,
        settings.seed,
        device,
        log,
    )?;
    let mut generate_seconds = clock.elapsed().as_secs_f64();
    let mut samples = samples_of(&generated);
    let rows = eval.score_rows([&real, &generated, &frozen], &reference)?;
    let mut labels = Vec::new();
    if let Some(k) = settings.per_label.filter(|&k| k > 0) {
        for (li, label) in PER_LABELS.iter().enumerate() {
            let (row, seconds) = eval.label_row(li, label, k, &mut rng, log, &mut samples)?;
            generate_seconds += seconds;
            labels.push(row);
        }
    }
    let report = EvalReport {
        rows,
        labels,
        model: (bundle.manifest.weights_id.clone(), bundle.manifest.steps),
        evaluator: (evaluator.manifest.steps, evaluator.manifest.val_r_precision),
        reference_clips: chosen.reference.len(),
        settings: settings.clone(),
        generate_seconds,
    };
    Ok((report, samples))
}

/// What every step of an evaluation reads.
struct Evaluation<'a> {
    data: &'a Dataset,
    bundle: &'a ModelBundle,
    evaluator: &'a Evaluator,
    settings: &'a EvalSettings,
    device: &'a Device,
    /// The longest motion both the model and the evaluator take.
    cap: usize,
}

/// The test clips an evaluation uses.
struct ChosenClips<'a> {
    /// Clips long enough and captioned.
    eligible: Vec<&'a ClipInfo>,
    /// The prompts, drawn from `eligible`.
    prompts: Vec<Prompt<'a>>,
    /// The FID reference: eligible clips from other source files than the prompts'.
    reference: Vec<&'a ClipInfo>,
}

impl<'a> Evaluation<'a> {
    /// Draws the prompts and sets the FID reference apart.
    fn choose_clips(&self, rng: &mut ChaCha8Rng) -> Result<ChosenClips<'a>, MetricsError> {
        let settings = self.settings;
        let eligible: Vec<&ClipInfo> = self
            .data
            .clips(Split::Test)
            .filter(|c| c.frames >= settings.min_frames.max(2) && !c.captions.is_empty())
            .collect();
        let count = settings.count.min(eligible.len());
        if count < 2 {
            return Err(MetricsError::Invalid(format!(
                "the test split has {} clips of at least {} frames; at least 2 are needed",
                eligible.len(),
                settings.min_frames
            )));
        }
        let mut shuffled = eligible.clone();
        shuffled.shuffle(rng);
        let prompts: Vec<Prompt> = shuffled[..count]
            .iter()
            .map(|&clip| Prompt {
                clip,
                caption: pick_caption(clip, rng),
                frames: clip.frames.min(self.cap),
            })
            .collect();
        let sources: HashSet<&str> = prompts.iter().map(|p| p.clip.source.as_str()).collect();
        let reference: Vec<&ClipInfo> = eligible
            .iter()
            .copied()
            .filter(|c| !sources.contains(c.source.as_str()))
            .collect();
        if reference.len() < 2 {
            return Err(MetricsError::Invalid(format!(
                "only {} test clips are left for the FID reference; lower --count",
                reference.len()
            )));
        }
        Ok(ChosenClips {
            eligible,
            prompts,
            reference,
        })
    }

    /// The reference clips' embeddings, and a caption of every eligible clip as an
    /// R-precision distractor.
    fn reference(
        &self,
        chosen: &ChosenClips,
        rng: &mut ChaCha8Rng,
    ) -> Result<Reference, MetricsError> {
        let (evaluator, device) = (self.evaluator, self.device);
        let ref_rows: Vec<&[f32]> = chosen
            .reference
            .iter()
            .map(|c| &self.data.clip_features(c)[..c.frames.min(self.cap) * FEATURE_DIM])
            .collect();
        let distractor_captions: Vec<String> = chosen
            .eligible
            .iter()
            .map(|c| pick_caption(c, rng))
            .collect();
        let captions: Vec<&str> = distractor_captions.iter().map(String::as_str).collect();
        Ok(Reference {
            embeddings: evaluator.embed_motions(&ref_rows, device)?,
            distractors: evaluator
                .embed_captions(&captions, device)?
                .into_iter()
                .zip(&chosen.eligible)
                .map(|(embedding, c)| Distractor {
                    embedding,
                    group: c.content.clone(),
                })
                .collect(),
        })
    }

    /// The table's rows: real test data, the model, the trivial baseline.
    fn score_rows(
        &self,
        [real, generated, frozen]: [&MotionSet; 3],
        reference: &Reference,
    ) -> Result<Vec<SetScores>, MetricsError> {
        let (evaluator, seed, device) = (self.evaluator, self.settings.seed, self.device);
        let model_name = format!(
            "model ({}, {} steps)",
            self.bundle.manifest.weights_id, self.bundle.manifest.steps
        );
        Ok(vec![
            score_set("real test data", real, reference, evaluator, seed, device)?,
            score_set(&model_name, generated, reference, evaluator, seed, device)?,
            score_set(
                "trivial baseline (first pose held)",
                frozen,
                reference,
                evaluator,
                seed,
                device,
            )?,
        ])
    }

    /// The per-label row of `label` (the `li`-th): its real test clips against `k`
    /// motions generated from their captions, which join `samples`; also returns the
    /// seconds spent generating.
    fn label_row(
        &self,
        li: usize,
        label: &str,
        k: usize,
        rng: &mut ChaCha8Rng,
        log: &mut dyn FnMut(&str),
        samples: &mut Vec<Sample>,
    ) -> Result<(LabelRow, f64), MetricsError> {
        let (data, cap) = (self.data, self.cap);
        let clips: Vec<&ClipInfo> = data
            .clips(Split::Test)
            .filter(|c| c.content == *label && c.frames >= 2 && !c.captions.is_empty())
            .collect();
        let real_motions: Vec<Motion> = clips
            .iter()
            .map(|c| real_motion(data, c, c.frames.min(cap)).0)
            .collect();
        let mut seconds = 0.0;
        let generated = if clips.is_empty() {
            None
        } else {
            let chosen: Vec<Prompt> = (0..k)
                .map(|_| {
                    let clip = clips[rng.random_range(0..clips.len())];
                    Prompt {
                        clip,
                        caption: pick_caption(clip, rng),
                        frames: clip.frames.min(cap).max(2),
                    }
                })
                .collect();
            log(&format!("per-label: {label}"));
            let label_seed = self.settings.seed.wrapping_add(1000 * (li as u64 + 1));
            let clock = std::time::Instant::now();
            let set = generate_for(
                self.bundle,
                &chosen,
                self.settings,
                label_seed,
                self.device,
                log,
            )?;
            seconds = clock.elapsed().as_secs_f64();
            samples.extend(set.motions.iter().zip(&set.captions).map(|(m, c)| Sample {
                caption: c.clone(),
                label: label.to_string(),
                motion: m.clone(),
            }));
            Some(label_stats(&set.motions))
        };
        let row = LabelRow {
            label: label.to_string(),
            real: label_stats(&real_motions),
            generated,
        };
        Ok((row, seconds))
    }
}

/// The prompts' real clips and the trivial baseline's frozen first poses.
fn real_and_frozen(
    data: &Dataset,
    prompts: &[Prompt],
) -> Result<(MotionSet, MotionSet), MetricsError> {
    let mut real = MotionSet::default();
    let mut frozen = MotionSet::default();
    for p in prompts {
        for (set, (motion, features)) in [
            (&mut real, real_motion(data, p.clip, p.frames)),
            (&mut frozen, frozen_motion(data, p.clip, p.frames)?),
        ] {
            set.motions.push(motion);
            set.features.push(features);
            set.captions.push(p.caption.clone());
            set.labels.push(p.clip.content.clone());
        }
    }
    Ok((real, frozen))
}

/// The motions of a generated set, with their captions and labels, for pictures.
fn samples_of(set: &MotionSet) -> Vec<Sample> {
    set.motions
        .iter()
        .zip(&set.captions)
        .zip(&set.labels)
        .map(|((m, c), l)| Sample {
            caption: c.clone(),
            label: l.clone(),
            motion: m.clone(),
        })
        .collect()
}
