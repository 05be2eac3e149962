//! Contrastive training of the evaluator on the train split (`mprog eval train-encoder`).
//!
//! Each step draws `batch_size` training clips (seeded), a random crop of at most
//! `crop_frames` frames from each and one of its captions. With unit embeddings m (motion)
//! and t (text), logits = m·tᵀ / τ. Captions come from labels, so a batch often holds
//! several clips of the same content and style: those pairs are positives too. The loss is
//! the symmetric cross-entropy against the row-normalised "same content and style" matrix
//! (InfoNCE with label-aware positives).

use super::encoder::{EncoderConfig, EvaluatorNet, motion_batch};
use super::error::MetricsError;
use super::evaluator::{EVALUATOR_VERSION, Evaluator, EvaluatorManifest};
use super::scores::{Distractor, r_precision};
use crate::dataset::{ClipInfo, Dataset, FEATURE_DIM, Split};
use crate::model::text::{TokenBatch, Vocabulary};
use burn::optim::{AdamWConfig, GradientsParams, ModuleOptimizer};
use burn::prelude::*;
use burn::tensor::activation::log_softmax;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Settings of an evaluator training run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EncoderTrainConfig {
    /// Network shape.
    pub encoder: EncoderConfig,
    /// Optimisation steps.
    pub steps: usize,
    /// Clips per batch.
    pub batch_size: usize,
    /// Longest training crop (frames).
    pub crop_frames: usize,
    /// Peak AdamW learning rate (linear warm-up, cosine decay to a tenth).
    pub learning_rate: f64,
    /// Warm-up steps.
    pub warmup_steps: usize,
    /// AdamW weight decay.
    pub weight_decay: f64,
    /// Seed of the weights, the batches and the crops.
    pub seed: u64,
}

impl Default for EncoderTrainConfig {
    fn default() -> Self {
        EncoderTrainConfig {
            encoder: EncoderConfig::default(),
            steps: 500,
            batch_size: 64,
            crop_frames: 120,
            learning_rate: 1e-3,
            warmup_steps: 50,
            weight_decay: 1e-4,
            seed: 1,
        }
    }
}

fn learning_rate(cfg: &EncoderTrainConfig, step: usize) -> f64 {
    let warm = ((step + 1) as f64 / cfg.warmup_steps.max(1) as f64).min(1.0);
    let progress = step as f64 / cfg.steps.max(1) as f64;
    let cosine = 0.1 + 0.9 * 0.5 * (1.0 + (std::f64::consts::PI * progress).cos());
    cfg.learning_rate * warm * cosine
}

/// One training batch on the host.
struct Batch<'a> {
    crops: Vec<&'a [f32]>,
    captions: Vec<&'a str>,
    /// `[B, B]` row-normalised positives.
    targets: Vec<f32>,
}

fn draw_batch<'a>(
    data: &'a Dataset,
    clips: &[&'a ClipInfo],
    cfg: &EncoderTrainConfig,
    rng: &mut ChaCha8Rng,
) -> Batch<'a> {
    let b = cfg.batch_size;
    let chosen: Vec<&ClipInfo> = (0..b)
        .map(|_| clips[rng.random_range(0..clips.len())])
        .collect();
    let mut crops = Vec::with_capacity(b);
    let mut captions = Vec::with_capacity(b);
    for clip in &chosen {
        let rows = data.clip_features(clip);
        let len = clip.frames.min(cfg.crop_frames);
        let start = rng.random_range(0..=clip.frames - len);
        crops.push(&rows[start * FEATURE_DIM..(start + len) * FEATURE_DIM]);
        captions.push(clip.captions[rng.random_range(0..clip.captions.len())].as_str());
    }
    let mut targets = vec![0.0f32; b * b];
    for i in 0..b {
        let same: Vec<usize> = (0..b)
            .filter(|&j| {
                chosen[j].content == chosen[i].content && chosen[j].style == chosen[i].style
            })
            .collect();
        for &j in &same {
            targets[i * b + j] = 1.0 / same.len() as f32;
        }
    }
    Batch {
        crops,
        captions,
        targets,
    }
}

/// Symmetric soft-target cross-entropy of a batch.
fn batch_loss(
    net: &EvaluatorNet,
    data: &Dataset,
    vocab: &Vocabulary,
    batch: &Batch,
    cfg: &EncoderTrainConfig,
    device: &Device,
) -> Tensor<1> {
    let (x, valid) = motion_batch(
        &batch.crops,
        &data.mean,
        &data.std,
        cfg.encoder.max_frames,
        device,
    );
    let m = net.motion.forward(x, valid); // [B, D]
    let t = net
        .text
        .forward(&TokenBatch::new(vocab, &batch.captions, device)); // [B, D]
    let logits = m.matmul(t.transpose()).div_scalar(cfg.encoder.temperature); // [B, B]
    let b = cfg.batch_size;
    let p: Tensor<2> = Tensor::from_data(TensorData::new(batch.targets.clone(), [b, b]), device);
    let m2t = -(log_softmax(logits.clone(), 1) * p.clone()).sum() / b as f32;
    let t2m = -(log_softmax(logits.transpose(), 1) * p.transpose()).sum() / b as f32;
    (m2t + t2m) / 2.0
}

/// Top-1/2/3 R-precision of real clips of `split` with one of their own captions each;
/// None when the split has too few clips of other labels to draw 31 distractors from.
pub fn split_r_precision(
    evaluator: &Evaluator,
    data: &Dataset,
    split: Split,
    seed: u64,
    device: &Device,
) -> Result<Option<[f64; 3]>, MetricsError> {
    let clips: Vec<&ClipInfo> = data
        .clips(split)
        .filter(|c| c.frames >= 2 && !c.captions.is_empty())
        .collect();
    let groups: Vec<String> = clips.iter().map(|c| c.content.clone()).collect();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let captions: Vec<&str> = clips
        .iter()
        .map(|c| c.captions[rng.random_range(0..c.captions.len())].as_str())
        .collect();
    let enough = groups
        .iter()
        .all(|g| groups.iter().filter(|o| *o != g).count() >= 31);
    if clips.is_empty() || !enough {
        return Ok(None);
    }
    let rows: Vec<&[f32]> = clips.iter().map(|c| data.clip_features(c)).collect();
    let motions = evaluator.embed_motions(&rows, device)?;
    let texts = evaluator.embed_captions(&captions, device)?;
    let distractors: Vec<Distractor> = texts
        .iter()
        .zip(&groups)
        .map(|(e, g)| Distractor {
            embedding: e.clone(),
            group: g.clone(),
        })
        .collect();
    Ok(Some(r_precision(
        &motions,
        &texts,
        &groups,
        &distractors,
        seed,
    )?))
}

/// Trains an evaluator on the train split; `progress(step, loss)` after every step.
/// Returns the evaluator (with validation R-precision in its manifest) and the losses.
pub fn train_evaluator(
    data: &Dataset,
    cfg: &EncoderTrainConfig,
    progress: &mut dyn FnMut(usize, f32),
) -> Result<(Evaluator, Vec<f32>), MetricsError> {
    cfg.encoder.validate().map_err(MetricsError::Invalid)?;
    if cfg.encoder.features != FEATURE_DIM || data.mean.len() != FEATURE_DIM {
        return Err(MetricsError::Invalid(format!(
            "the evaluator reads {FEATURE_DIM} features, configured for {}",
            cfg.encoder.features
        )));
    }
    if cfg.batch_size < 2 || cfg.steps == 0 || cfg.crop_frames < 2 {
        return Err(MetricsError::Invalid(
            "evaluator training needs batch_size ≥ 2, steps ≥ 1 and crop_frames ≥ 2".into(),
        ));
    }
    let clips: Vec<&ClipInfo> = data
        .clips(Split::Train)
        .filter(|c| c.frames >= 2 && !c.captions.is_empty())
        .collect();
    if clips.len() < 2 {
        return Err(MetricsError::Invalid(
            "the dataset has fewer than two captioned training clips".into(),
        ));
    }
    let vocab = Vocabulary::from_captions(
        clips
            .iter()
            .flat_map(|c| c.captions.iter().map(String::as_str)),
        16,
    );
    let plain = Device::flex();
    let device = plain.clone().autodiff();
    device.seed(cfg.seed);
    let mut net = EvaluatorNet::new(&cfg.encoder, vocab.len(), &device);
    let mut optim: ModuleOptimizer = AdamWConfig::new()
        .with_weight_decay(cfg.weight_decay as f32)
        .init();
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed ^ 0xE7A1_0A7E);
    let mut losses = Vec::with_capacity(cfg.steps);
    let clock = Instant::now();
    for step in 0..cfg.steps {
        let batch = draw_batch(data, &clips, cfg, &mut rng);
        let loss = batch_loss(&net, data, &vocab, &batch, cfg, &device);
        let value = loss.clone().into_scalar::<f32>();
        if !value.is_finite() {
            return Err(MetricsError::Diverged { step, loss: value });
        }
        let grads = GradientsParams::from_grads(loss.backward(), &net);
        net = optim.step(learning_rate(cfg, step), net, grads);
        losses.push(value);
        progress(step + 1, value);
    }
    let tail = &losses[losses.len().saturating_sub(50)..];
    let mut evaluator = Evaluator {
        manifest: EvaluatorManifest {
            version: EVALUATOR_VERSION,
            config: cfg.encoder.clone(),
            vocab_size: vocab.len(),
            steps: cfg.steps,
            train_seconds: clock.elapsed().as_secs_f64(),
            final_loss: tail.iter().map(|&l| l as f64).sum::<f64>() / tail.len() as f64,
            val_r_precision: None,
            train_clips: clips.len(),
            half_precision: true,
        },
        vocab,
        mean: data.mean.clone(),
        std: data.std.clone(),
        net: net.valid(),
    };
    evaluator.manifest.val_r_precision =
        split_r_precision(&evaluator, data, Split::Val, cfg.seed, &plain)?;
    Ok((evaluator, losses))
}
