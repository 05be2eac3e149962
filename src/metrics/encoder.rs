//! The evaluator networks: a motion encoder (per-frame linear layer, two temporal
//! convolutions, masked mean + max pooling) and a caption encoder (bag of words and an
//! MLP), both ending in unit-length `embed_dim` vectors in one shared space.
//!
//! Motions go in as **normalised** features `[B, T, 263]` with a `[B, T]` 0/1 validity
//! mask; hidden activations are zeroed on padded frames after every layer, so a motion's
//! embedding does not depend on how long the other motions of its batch are.

use crate::model::text::{PAD, TokenBatch};
use burn::nn::conv::{Conv1d, Conv1dConfig};
use burn::nn::{Embedding, EmbeddingConfig, Linear, LinearConfig, PaddingConfig1d};
use burn::prelude::*;
use burn::tensor::activation::gelu;
use serde::{Deserialize, Serialize};

/// Shape of the evaluator networks.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EncoderConfig {
    /// Feature width of a frame (263).
    pub features: usize,
    /// Width of the per-frame and first convolution layers; the second has twice this.
    pub hidden: usize,
    /// Temporal kernel size (odd).
    pub kernel: usize,
    /// Width of the shared embedding space.
    pub embed_dim: usize,
    /// Width of the word embeddings.
    pub word_dim: usize,
    /// Motions are cut to their first `max_frames` frames before encoding.
    pub max_frames: usize,
    /// Softmax temperature of the contrastive loss.
    pub temperature: f64,
}

impl Default for EncoderConfig {
    fn default() -> Self {
        EncoderConfig {
            features: 263,
            hidden: 128,
            kernel: 5,
            embed_dim: 256,
            word_dim: 128,
            max_frames: 196,
            temperature: 0.1,
        }
    }
}

impl EncoderConfig {
    /// Checks the shape is buildable.
    pub fn validate(&self) -> Result<(), String> {
        if self.features == 0 || self.hidden == 0 || self.embed_dim == 0 || self.word_dim == 0 {
            return Err("encoder widths must be positive".into());
        }
        if self.kernel == 0 || self.kernel.is_multiple_of(2) {
            return Err(format!("encoder kernel must be odd, got {}", self.kernel));
        }
        if self.max_frames < 2 {
            return Err("encoder max_frames must be at least 2".into());
        }
        if !(self.temperature > 0.0 && self.temperature.is_finite()) {
            return Err("encoder temperature must be positive".into());
        }
        Ok(())
    }
}

/// Scales each row to unit length.
pub fn l2_normalize(z: Tensor<2>) -> Tensor<2> {
    let norm = z.clone().powi_scalar(2).sum_dim(1).add_scalar(1e-12).sqrt();
    z / norm
}

/// Motion encoder.
#[derive(Module, Debug)]
pub struct MotionEncoder {
    input: Linear,
    conv1: Conv1d,
    conv2: Conv1d,
    output: Linear,
}

impl MotionEncoder {
    /// A fresh encoder.
    pub fn new(cfg: &EncoderConfig, device: &Device) -> Self {
        let pad = PaddingConfig1d::Explicit(cfg.kernel / 2, cfg.kernel / 2);
        let conv = |i, o| {
            Conv1dConfig::new(i, o, cfg.kernel)
                .with_padding(pad.clone())
                .init(device)
        };
        MotionEncoder {
            input: LinearConfig::new(cfg.features, cfg.hidden).init(device),
            conv1: conv(cfg.hidden, cfg.hidden),
            conv2: conv(cfg.hidden, 2 * cfg.hidden),
            output: LinearConfig::new(4 * cfg.hidden, cfg.embed_dim).init(device),
        }
    }

    /// `[B, T, F]` normalised features and `[B, T]` validity → `[B, embed_dim]` unit vectors.
    pub fn forward(&self, x: Tensor<3>, valid: Tensor<2>) -> Tensor<2> {
        let m = valid.clone().unsqueeze_dim::<3>(2); // [B, T, 1]
        let h = gelu(self.input.forward(x)) * m.clone(); // [B, T, H]
        let conv = |c: &Conv1d, h: Tensor<3>| gelu(c.forward(h.swap_dims(1, 2))).swap_dims(1, 2);
        let h = conv(&self.conv1, h) * m.clone(); // [B, T, H]
        let h = conv(&self.conv2, h) * m.clone(); // [B, T, 2H]
        let count = valid.sum_dim(1).clamp_min(1.0); // [B, 1]
        let mean = h.clone().sum_dim(1).squeeze_dim::<2>(1) / count; // [B, 2H]
        let mask_offset = m.sub_scalar(1.0).mul_scalar(1e4); // 0 valid, −1e4 padded
        let max = (h + mask_offset).max_dim(1).squeeze_dim::<2>(1); // [B, 2H]
        l2_normalize(self.output.forward(Tensor::cat(vec![mean, max], 1)))
    }
}

/// Caption encoder: mean of word embeddings, then a two-layer MLP.
#[derive(Module, Debug)]
pub struct CaptionEncoder {
    words: Embedding,
    hidden: Linear,
    output: Linear,
}

impl CaptionEncoder {
    /// A fresh encoder for `vocab_size` token ids (including [`PAD`]).
    pub fn new(cfg: &EncoderConfig, vocab_size: usize, device: &Device) -> Self {
        CaptionEncoder {
            words: EmbeddingConfig::new(vocab_size.max(PAD + 1), cfg.word_dim).init(device),
            hidden: LinearConfig::new(cfg.word_dim, cfg.embed_dim).init(device),
            output: LinearConfig::new(cfg.embed_dim, cfg.embed_dim).init(device),
        }
    }

    /// Tokenised captions → `[B, embed_dim]` unit vectors.
    pub fn forward(&self, tokens: &TokenBatch) -> Tensor<2> {
        let emb = self.words.forward(tokens.ids.clone()); // [B, L, W]
        let mask = tokens.mask.clone().unsqueeze_dim::<3>(2); // [B, L, 1]
        let count = tokens.mask.clone().sum_dim(1).clamp_min(1.0); // [B, 1]
        let bag = (emb * mask).sum_dim(1).squeeze_dim::<2>(1) / count; // [B, W]
        l2_normalize(self.output.forward(gelu(self.hidden.forward(bag))))
    }
}

/// Both encoders, saved as one module.
#[derive(Module, Debug)]
pub struct EvaluatorNet {
    /// Motion side.
    pub motion: MotionEncoder,
    /// Text side.
    pub text: CaptionEncoder,
}

impl EvaluatorNet {
    /// Fresh networks.
    pub fn new(cfg: &EncoderConfig, vocab_size: usize, device: &Device) -> Self {
        EvaluatorNet {
            motion: MotionEncoder::new(cfg, device),
            text: CaptionEncoder::new(cfg, vocab_size, device),
        }
    }
}

/// Motions (de-normalised feature rows `[frames, F]` each) as a padded, normalised batch:
/// `[B, T, F]` features and a `[B, T]` validity mask; each motion is cut to `max_frames`.
pub fn motion_batch(
    motions: &[&[f32]],
    mean: &[f32],
    std: &[f32],
    max_frames: usize,
    device: &Device,
) -> (Tensor<3>, Tensor<2>) {
    let f = mean.len();
    let lens: Vec<usize> = motions
        .iter()
        .map(|m| (m.len() / f).min(max_frames))
        .collect();
    let t = lens.iter().copied().max().unwrap_or(1).max(1);
    let b = motions.len();
    let mut x = vec![0.0f32; b * t * f];
    let mut valid = vec![0.0f32; b * t];
    for (i, (m, &len)) in motions.iter().zip(&lens).enumerate() {
        for (k, row) in m.chunks_exact(f).take(len).enumerate() {
            let dst = &mut x[(i * t + k) * f..(i * t + k + 1) * f];
            for (((d, &v), &mu), &s) in dst.iter_mut().zip(row).zip(mean).zip(std) {
                *d = (v - mu) / s;
            }
            valid[i * t + k] = 1.0;
        }
    }
    (
        Tensor::from_data(TensorData::new(x, [b, t, f]), device),
        Tensor::from_data(TensorData::new(valid, [b, t]), device),
    )
}

/// Rows of a `[B, D]` tensor as host vectors.
pub fn rows_of(z: Tensor<2>) -> Result<Vec<Vec<f32>>, String> {
    let [_, d] = z.dims();
    let data = z
        .into_data()
        .convert::<f32>()
        .try_into_vec::<f32>()
        .map_err(|e| format!("reading embeddings back: {e:?}"))?;
    Ok(data.chunks_exact(d.max(1)).map(<[f32]>::to_vec).collect())
}
