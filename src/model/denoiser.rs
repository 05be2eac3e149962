//! The MDM-style denoiser: a transformer encoder over frames that predicts the clean
//! motion x̂0 from a noisy motion x_t, the timestep t and the text.
//!
//! Sequence layout: one condition token (timestep MLP + projected text) followed by the
//! N frame tokens, sinusoidal positions added to all N+1, post-norm encoder layers, the
//! condition token dropped at the output.

use super::config::{ModelConfig, TextEncoderKind};
use super::prompt::TextBatch;
use super::text::{BagOfWords, TextEncoder};
use burn::nn::transformer::{
    TransformerEncoder, TransformerEncoderConfig, TransformerEncoderInput,
};
use burn::nn::{Dropout, DropoutConfig, Linear, LinearConfig};
use burn::prelude::*;
use burn::tensor::activation::silu;

/// What a denoiser is asked: the noisy motions, their timesteps and their condition.
#[derive(Clone, Debug)]
pub struct DenoiserInput {
    /// `[B, N, F]` noisy motion in normalised feature space.
    pub x_t: Tensor<3>,
    /// Original-schedule timestep of each sample.
    pub timesteps: Vec<usize>,
    /// The prompts, one per sample, as the model's text encoder reads them.
    pub text: TextBatch,
    /// `[B]` 1.0 keeps the text condition, 0.0 drops it (unconditional pass).
    pub keep_text: Tensor<1>,
    /// `[B, N]` true on padded frames.
    pub padding: Option<Tensor<2, Bool>>,
}

/// Anything that predicts x̂0; samplers and solvers only see this.
pub trait Denoiser {
    /// `[B, N, F]` prediction of the clean motion.
    fn predict_x0(&self, input: &DenoiserInput) -> Tensor<3>;
}

/// The MDM denoiser.
#[derive(Module, Debug)]
pub struct Mdm {
    input_proj: Linear,
    time_1: Linear,
    time_2: Linear,
    /// The bag-of-words encoder; None when the model reads sentence vectors.
    text: Option<BagOfWords>,
    text_proj: Linear,
    encoder: TransformerEncoder,
    output_proj: Linear,
    /// Timestep sinusoid → per-feature gain on x_t added to the output (`input_skip`).
    skip: Option<Linear>,
    dropout: Dropout,
    d_model: usize,
}

/// A `d → features` linear layer that starts at zero (weights and bias).
fn zero_skip(d: usize, features: usize, device: &Device) -> Linear {
    LinearConfig::new(d, features)
        .with_initializer(burn::nn::Initializer::Zeros)
        .init(device)
}

/// Sinusoidal table rows for the given positions: `[len(positions), d]`.
fn sinusoids(positions: impl Iterator<Item = usize>, d: usize, device: &Device) -> Tensor<2> {
    let mut data = Vec::new();
    let mut rows = 0;
    for p in positions {
        rows += 1;
        for i in 0..d {
            let freq = (-((2 * (i / 2)) as f64) * (10000f64).ln() / d as f64).exp();
            let a = p as f64 * freq;
            data.push(if i % 2 == 0 { a.sin() } else { a.cos() } as f32);
        }
    }
    Tensor::from_data(TensorData::new(data, [rows, d]), device)
}

impl Mdm {
    /// A freshly initialised denoiser; `vocab_size` ids for a bag-of-words text encoder
    /// (unused with sentence vectors).
    pub fn new(config: &ModelConfig, vocab_size: usize, device: &Device) -> Self {
        let d = config.d_model;
        Mdm {
            input_proj: LinearConfig::new(config.features, d).init(device),
            time_1: LinearConfig::new(d, d).init(device),
            time_2: LinearConfig::new(d, d).init(device),
            text: (config.text_encoder == TextEncoderKind::BagOfWords)
                .then(|| BagOfWords::new(vocab_size, config.d_text, device)),
            text_proj: LinearConfig::new(config.d_text, d).init(device),
            encoder: TransformerEncoderConfig::new(d, config.d_ff, config.heads, config.layers)
                .with_dropout(config.dropout)
                .init(device),
            output_proj: LinearConfig::new(d, config.features).init(device),
            skip: config
                .input_skip
                .then(|| zero_skip(d, config.features, device)),
            dropout: DropoutConfig::new(config.dropout).init(),
            d_model: d,
        }
    }

    /// This denoiser with a zero input skip added (no change to what it predicts), so a
    /// model trained without `input_skip` can continue training with it.
    pub fn with_input_skip(mut self, device: &Device) -> Self {
        if self.skip.is_none() {
            let features = self.output_proj.weight.dims()[1];
            self.skip = Some(zero_skip(self.d_model, features, device));
        }
        self
    }

    /// The input skip's per-feature gain at timestep `t` (None without `input_skip`).
    pub fn input_skip_gain(&self, t: usize) -> Option<Vec<f32>> {
        let skip = self.skip.as_ref()?;
        let device = skip.weight.device();
        let gain = skip.forward(sinusoids(std::iter::once(t), self.d_model, &device));
        Some(gain.into_data().try_into_vec::<f32>().expect("f32 tensor"))
    }

    /// `[B, d]` condition token: timestep embedding plus (possibly dropped) text.
    fn condition(&self, input: &DenoiserInput, device: &Device) -> Tensor<2> {
        let t = sinusoids(input.timesteps.iter().copied(), self.d_model, device);
        let t = self.time_2.forward(silu(self.time_1.forward(t)));
        let text = match (&self.text, &input.text) {
            (Some(bag), TextBatch::Words(tokens)) => bag.encode(tokens),
            (None, TextBatch::Sentences(s)) => s.vectors.clone(),
            _ => unreachable!("the bundle's prompt encoder matches its denoiser"),
        }; // [B, d_text]
        let text = text * input.keep_text.clone().unsqueeze_dim::<2>(1);
        t + self.text_proj.forward(text)
    }
}

impl Mdm {
    /// The encoder's input: the condition token then the projected frames, positions
    /// added, dropout applied (`[B, N+1, d]`), with the padding mask of that sequence.
    pub(crate) fn embed(&self, input: &DenoiserInput) -> (Tensor<3>, Option<Tensor<2, Bool>>) {
        let device = input.x_t.device();
        let [b, n, _] = input.x_t.dims();
        let frames = self.input_proj.forward(input.x_t.clone()); // [B, N, d]
        let cond = self.condition(input, &device).unsqueeze_dim::<3>(1); // [B, 1, d]
        let seq = Tensor::cat(vec![cond, frames], 1); // [B, N+1, d]
        let pos = sinusoids(0..n + 1, self.d_model, &device).unsqueeze_dim::<3>(0);
        let seq = self.dropout.forward(seq + pos);
        let mask = input.padding.as_ref().map(|pad| {
            let cond_col =
                Tensor::<2, Bool>::from_data(TensorData::new(vec![false; b], [b, 1]), &device);
            Tensor::cat(vec![cond_col, pad.clone()], 1)
        });
        (seq, mask)
    }

    /// The encoder's layers (a ControlNet adds into the stream after each one).
    pub(crate) fn encoder(&self) -> &TransformerEncoder {
        &self.encoder
    }

    /// x̂0 `[B, N, F]` from the encoder's output `[B, N+1, d]`.
    pub(crate) fn output(&self, out: Tensor<3>, input: &DenoiserInput) -> Tensor<3> {
        let device = input.x_t.device();
        let n = input.x_t.dims()[1];
        let out = self.output_proj.forward(out.narrow(1, 1, n)); // [B, N, F]
        match &self.skip {
            Some(skip) => {
                let t = sinusoids(input.timesteps.iter().copied(), self.d_model, &device);
                let gain = skip.forward(t).unsqueeze_dim::<3>(1); // [B, 1, F]
                out + gain * input.x_t.clone()
            }
            None => out,
        }
    }
}

impl Denoiser for Mdm {
    fn predict_x0(&self, input: &DenoiserInput) -> Tensor<3> {
        let (seq, mask) = self.embed(input);
        let mut enc_in = TransformerEncoderInput::new(seq);
        if let Some(mask) = mask {
            enc_in = enc_in.mask_pad(mask);
        }
        let out = self.encoder.forward(enc_in); // [B, N+1, d]
        self.output(out, input)
    }
}
