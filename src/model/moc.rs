//! OMG's text ControlNet (Liang et al., "OMG", §3.2): text enters a frozen unconditional
//! denoiser only through a trainable copy of each of its layers and a Mixture-of-Controllers
//! block that adds a residual after that layer.
//!
//! Per layer `l`, with `h_l` the frozen stream entering it:
//! - the copy reads `h_l`; its frame tokens are projected down to `d_control`;
//! - cross-attention from those frames to the prompt's token states fuses the text into
//!   them (`f' = f + softmax(QKᵀ/√d)·V`) and gives the attention map `A` `[frames, tokens]`;
//! - adaptive instance normalisation over the frames, its scale and shift read from the
//!   prompt's sentence vector (OMG conditions it on CLIP's `<eos>` token, which sums the
//!   text up as MiniLM's pooled vector does);
//! - each token gets its own two-layer expert, its weights a blend of an expert pool by a
//!   gate that reads the token (`e(i) = Σ_j ω_ij e_j`, `ω_i = softmax(G(E(c_i)))`);
//! - token `i`'s expert acts on the frames its column of `A` points at:
//!   `r_i = sigmoid(γ(A_{*,i} − β·max A_{*,i})) ∘ F(f'|e(i))`; the residuals are summed and
//!   projected back up by a zero-initialised layer, so a fresh ControlNet changes nothing.
//!
//! A sample whose text is dropped (`keep_text` 0: the unconditional half of classifier-free
//! guidance) gets no residual, so the guided prediction is OMG's
//! `(1 − s)·D_u + s·D_c`.

use crate::model::sentence::TokenStates;
use burn::module::Param;
use burn::nn::transformer::TransformerEncoderLayer;
use burn::nn::{Initializer, Linear, LinearConfig};
use burn::prelude::*;
use burn::tensor::activation::{gelu, relu, sigmoid, softmax};
use serde::{Deserialize, Serialize};

/// Shape of a text ControlNet ([`super::config::ModelConfig::text_control`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MocConfig {
    /// Width of the MoC blocks (OMG: 256 beside a 1,024–2,048-wide model; a quarter of
    /// `d_model` here).
    pub d_control: usize,
    /// Experts in each block's pool (OMG: 12).
    pub experts: usize,
    /// Sharpness γ of the attention mask (OMG: 24).
    pub sharpness: f64,
    /// Threshold β of the attention mask, a fraction of the column's maximum (OMG: 0.25).
    pub threshold: f64,
}

impl Default for MocConfig {
    fn default() -> Self {
        MocConfig {
            d_control: 64,
            experts: 8,
            sharpness: 24.0,
            threshold: 0.25,
        }
    }
}

impl MocConfig {
    /// Checks the numbers; the message names the field.
    pub fn check(&self) -> Result<(), String> {
        if !(1..=4096).contains(&self.d_control) {
            return Err(format!(
                "`text_control.d_control` is {}; it must be in [1, 4096]",
                self.d_control
            ));
        }
        if !(1..=64).contains(&self.experts) {
            return Err(format!(
                "`text_control.experts` is {}; it must be in [1, 64]",
                self.experts
            ));
        }
        if !(self.sharpness.is_finite() && self.sharpness > 0.0 && self.sharpness <= 1000.0) {
            return Err(format!(
                "`text_control.sharpness` is {}; it must be in (0, 1000]",
                self.sharpness
            ));
        }
        if !(self.threshold.is_finite() && (0.0..=1.0).contains(&self.threshold)) {
            return Err(format!(
                "`text_control.threshold` is {}; it must be in [0, 1]",
                self.threshold
            ));
        }
        Ok(())
    }
}

/// One layer's Mixture-of-Controllers block.
#[derive(Module, Debug)]
pub struct MocBlock {
    down: Linear,
    query: Linear,
    key: Linear,
    value: Linear,
    /// Sentence vector → AdaIN scale and shift, zero at first (scale 1, shift 0).
    ada: Linear,
    gate_1: Linear,
    gate_2: Linear,
    gate_3: Linear,
    /// The expert pool: `[K, d, 2d]`, `[K, 2d]`, `[K, 2d, d]`, `[K, d]`.
    w0: Param<Tensor<3>>,
    b0: Param<Tensor<2>>,
    w1: Param<Tensor<3>>,
    b1: Param<Tensor<2>>,
    up: Linear,
    sharpness: f64,
    threshold: f64,
}

/// The trainable copies of the denoiser's layers and their MoC blocks.
#[derive(Module, Debug)]
pub struct TextControl {
    copies: Vec<TransformerEncoderLayer>,
    blocks: Vec<MocBlock>,
}

/// What a layer's residual reads besides the stream: the prompts' tokens, their sentence
/// vectors and which samples keep their text.
pub struct TextControlInput<'a> {
    /// The prompts' token states (`[B, L, D_text]`).
    pub tokens: &'a TokenStates,
    /// `[B, D_text]` sentence vectors.
    pub sentences: &'a Tensor<2>,
    /// `[B]` 1 where the sample keeps its text.
    pub keep: &'a Tensor<1>,
    /// `[B, N+1]` true on padded positions of the stream (condition token first).
    pub padding: Option<&'a Tensor<2, Bool>>,
}

/// Gives every parameter a new id (a clone keeps its source's ids, and an optimiser steps
/// parameters by id: a copy sharing its frozen original's ids would move the original).
struct FreshParams;

impl burn::module::ModuleMapper for FreshParams {
    fn map_float<const D: usize>(&mut self, param: Param<Tensor<D>>) -> Param<Tensor<D>> {
        Param::from_tensor(param.val().detach())
    }
}

fn zero_linear(d_in: usize, d_out: usize, device: &Device) -> Linear {
    LinearConfig::new(d_in, d_out)
        .with_initializer(Initializer::Zeros)
        .init(device)
}

/// Kaiming-uniform-like values for an expert pool tensor whose rows fan in `fan_in`.
fn pool_param<const D: usize>(
    shape: [usize; D],
    fan_in: usize,
    device: &Device,
) -> Param<Tensor<D>> {
    let bound = 1.0 / (fan_in as f64).sqrt();
    Param::from_tensor(Tensor::random(
        shape,
        burn::tensor::Distribution::Uniform(-bound, bound),
        device,
    ))
}

impl MocBlock {
    fn new(d_model: usize, d_text: usize, c: &MocConfig, device: &Device) -> MocBlock {
        let (d, k) = (c.d_control, c.experts);
        MocBlock {
            down: LinearConfig::new(d_model, d).init(device),
            query: LinearConfig::new(d, d).init(device),
            key: LinearConfig::new(d_text, d).init(device),
            value: LinearConfig::new(d_text, d).init(device),
            ada: zero_linear(d_text, 2 * d, device),
            gate_1: LinearConfig::new(d_text, d).init(device),
            gate_2: LinearConfig::new(d, d).init(device),
            gate_3: LinearConfig::new(d, k).init(device),
            w0: pool_param([k, d, 2 * d], d, device),
            b0: pool_param([k, 2 * d], d, device),
            w1: pool_param([k, 2 * d, d], 2 * d, device),
            b1: pool_param([k, d], 2 * d, device),
            up: zero_linear(d, d_model, device),
            sharpness: c.sharpness,
            threshold: c.threshold,
        }
    }

    /// The residual `[B, N, d_model]` for the frames `[B, N, d_model]` of the copy's output.
    fn residual(
        &self,
        frames: Tensor<3>,
        tokens: &TokenStates,
        sentences: Tensor<2>,
        valid: Tensor<3>,
    ) -> Tensor<3> {
        let [b, n, _] = frames.dims();
        let l = tokens.mask.dims()[1];
        let f = self.down.forward(frames); // [B, N, d]
        let d = f.dims()[2];
        let k = self.w0.dims()[0];
        // Cross-attention from frames to tokens; padded tokens get no weight.
        let q = self.query.forward(f.clone());
        let key = self.key.forward(tokens.states.clone()); // [B, L, d]
        let value = self.value.forward(tokens.states.clone());
        let token_mask = tokens.mask.clone().unsqueeze_dim::<3>(1); // [B, 1, L]
        let logits =
            q.matmul(key.swap_dims(1, 2)) / (d as f64).sqrt() + (token_mask.clone() - 1.0) * 1e9;
        let attention = softmax(logits, 2); // [B, N, L]
        let fused = f + attention.clone().matmul(value);
        // AdaIN over the valid frames, per sample and channel.
        let count = valid.clone().sum_dim(1).clamp_min(1.0); // [B, 1, 1]
        let mean = (fused.clone() * valid.clone()).sum_dim(1) / count.clone();
        let centred = fused - mean;
        let var = (centred.clone().powi_scalar(2) * valid.clone()).sum_dim(1) / count;
        let normed = centred / (var + 1e-5).sqrt();
        let style = self.ada.forward(sentences).unsqueeze_dim::<3>(1); // [B, 1, 2d]
        let scale = style.clone().narrow(2, 0, d) + 1.0;
        let shift = style.narrow(2, d, d);
        let styled = normed * scale + shift; // [B, N, d]
        // Each token's blend of the expert pool.
        let g = relu(self.gate_1.forward(tokens.states.clone()));
        let g = relu(self.gate_2.forward(g));
        let weights = softmax(self.gate_3.forward(g), 2); // [B, L, K]
        // First layer, linear in the expert weights: every expert on every frame, then
        // blended per token.
        let w0 = self.w0.val().swap_dims(0, 1).reshape([d, k * 2 * d]);
        let hidden = styled
            .reshape([b * n, d])
            .matmul(w0)
            .reshape([b, n, k, 2 * d])
            + self.b0.val().reshape([1, 1, k, 2 * d]);
        let hidden = hidden.swap_dims(1, 2).reshape([b, k, n * 2 * d]);
        let hidden = weights.clone().matmul(hidden).reshape([b * l, n, 2 * d]);
        let hidden = gelu(hidden);
        // Second layer with each token's blended weights.
        let w1 = weights
            .clone()
            .matmul(self.w1.val().reshape([1, k, 2 * d * d]))
            .reshape([b * l, 2 * d, d]);
        let b1 = weights.matmul(self.b1.val().unsqueeze_dim::<3>(0)); // [B, L, d]
        let out = hidden.matmul(w1).reshape([b, l, n, d]) + b1.unsqueeze_dim::<4>(2);
        // Each token acts where its column of the attention map is near its maximum.
        let frame_valid = valid.clone(); // [B, N, 1]
        let column_max = (attention.clone() * frame_valid).max_dim(1); // [B, 1, L]
        let mask = sigmoid((attention - column_max * self.threshold) * self.sharpness) * token_mask; // [B, N, L]
        let mask = mask.swap_dims(1, 2).unsqueeze_dim::<4>(3); // [B, L, N, 1]
        let summed = (out * mask).sum_dim(1).reshape([b, n, d]);
        self.up.forward(summed) * valid
    }
}

impl TextControl {
    /// A fresh text ControlNet for a denoiser whose layers are `layers`: the copies start
    /// as those layers (ControlNet's trainable copy), the blocks' outputs at zero.
    pub fn new(
        layers: &[TransformerEncoderLayer],
        d_model: usize,
        d_text: usize,
        config: &MocConfig,
        device: &Device,
    ) -> TextControl {
        TextControl {
            copies: layers
                .iter()
                .map(|l| l.clone().to_device(device).map(&mut FreshParams))
                .collect(),
            blocks: (0..layers.len())
                .map(|_| MocBlock::new(d_model, d_text, config, device))
                .collect(),
        }
    }

    /// This ControlNet with random (non-zero) outputs, so that it steers: for tests.
    #[cfg(test)]
    pub(crate) fn randomised(mut self, device: &Device) -> TextControl {
        for block in &mut self.blocks {
            let [d, d_model] = block.up.weight.dims();
            block.up = LinearConfig::new(d, d_model).init(device);
            let [d_text, d2] = block.ada.weight.dims();
            block.ada = LinearConfig::new(d_text, d2).init(device);
        }
        self
    }

    /// The residual to add after layer `layer` of the frozen stream, for the stream `h`
    /// `[B, N+1, d]` that entered it (zero on the condition token and on samples without
    /// text).
    pub fn residual(&self, layer: usize, h: Tensor<3>, input: &TextControlInput) -> Tensor<3> {
        let [b, n1, d] = h.dims();
        let n = n1 - 1;
        let device = h.device();
        let copied = self.copies[layer].forward(h, input.padding.cloned(), None);
        let valid = match input.padding {
            Some(pad) => pad.clone().narrow(1, 1, n).bool_not().float(),
            None => Tensor::ones([b, n], &device),
        }
        .unsqueeze_dim::<3>(2); // [B, N, 1]
        let keep = input.keep.clone().reshape([b, 1, 1]);
        let sentences = input.sentences.clone() * keep.clone().reshape([b, 1]);
        let frames =
            self.blocks[layer].residual(copied.narrow(1, 1, n), input.tokens, sentences, valid)
                * keep;
        Tensor::cat(vec![Tensor::zeros([b, 1, d], &device), frames], 1)
    }

    /// Layers this ControlNet follows.
    pub fn layers(&self) -> usize {
        self.blocks.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::config::{ModelConfig, TextEncoderKind};
    use crate::model::denoiser::{Denoiser, DenoiserInput, Mdm};
    use crate::model::noise::NoiseSource;
    use crate::model::prompt::{PromptTokens, SentenceBatch, TextBatch};

    fn config(control: bool) -> ModelConfig {
        ModelConfig {
            d_model: 16,
            layers: 2,
            heads: 2,
            d_ff: 32,
            d_text: 8,
            text_encoder: TextEncoderKind::Sentence,
            max_frames: 40,
            text_control: control.then(|| MocConfig {
                d_control: 8,
                experts: 3,
                ..MocConfig::default()
            }),
            ..ModelConfig::default()
        }
    }

    fn tokens(b: usize, len: usize, valid: usize, seed: u64, dev: &Device) -> TokenStates {
        let mask: Vec<f32> = (0..b)
            .flat_map(|_| (0..len).map(move |k| f32::from(u8::from(k < valid))))
            .collect();
        TokenStates {
            states: NoiseSource::new(seed).tensor([b, len, 8], dev),
            mask: Tensor::from_data(TensorData::new(mask, [b, len]), dev),
        }
    }

    fn input(b: usize, keep: f32, toks: TokenStates, dev: &Device) -> DenoiserInput {
        let vectors = NoiseSource::new(9).tensor([b, 8], dev);
        DenoiserInput {
            x_t: NoiseSource::new(4).tensor([b, 6, 263], dev),
            timesteps: vec![300; b],
            text: TextBatch::Sentences(SentenceBatch {
                vectors: vectors.clone(),
                mirrored: vectors,
                tokens: Some(Box::new(PromptTokens {
                    own: toks.clone(),
                    mirrored: toks,
                })),
            }),
            keep_text: Tensor::full([b], keep, dev),
            padding: None,
        }
    }

    fn max_diff(a: Tensor<3>, b: Tensor<3>) -> f32 {
        (a - b).abs().max().into_scalar::<f32>()
    }

    #[test]
    fn a_fresh_text_control_predicts_what_the_unconditional_prior_does() {
        let dev = Device::flex();
        let prior = Mdm::new(&config(false), 0, &dev).valid();
        let with = prior
            .clone()
            .with_text_control(config(true).text_control.as_ref(), &dev);
        assert!(with.has_text_control());
        let asked = input(2, 1.0, tokens(2, 5, 4, 1, &dev), &dev);
        let dropped = input(2, 0.0, tokens(2, 5, 4, 1, &dev), &dev);
        // The prior reads the dropped text (it was trained without any).
        let want = prior.predict_x0(&dropped);
        assert!(max_diff(with.predict_x0(&asked), want.clone()) < 1e-5);
        // Once it steers, the text changes the prediction, and only where it is kept.
        let steering = with.with_random_text_control(&dev);
        assert!(max_diff(steering.predict_x0(&asked), want.clone()) > 1e-3);
        assert!(max_diff(steering.predict_x0(&dropped), want) < 1e-5);
    }

    #[test]
    fn padded_tokens_are_never_read() {
        let dev = Device::flex();
        let model = Mdm::new(&config(true), 0, &dev)
            .with_random_text_control(&dev)
            .valid();
        let short = tokens(2, 4, 4, 1, &dev);
        // The same four tokens, then three padded ones holding other numbers.
        let padding = tokens(2, 3, 0, 3, &dev);
        let padded = TokenStates {
            states: Tensor::cat(vec![short.states.clone(), padding.states], 1),
            mask: Tensor::cat(vec![short.mask.clone(), padding.mask], 1),
        };
        let a = model.predict_x0(&input(2, 1.0, short, &dev));
        let b = model.predict_x0(&input(2, 1.0, padded, &dev));
        assert!(max_diff(a, b) < 1e-5);
    }

    #[test]
    fn only_the_text_control_takes_gradients_when_the_prior_is_frozen() {
        let dev = Device::flex().autodiff();
        let model = Mdm::new(&config(true), 0, &dev)
            .with_random_text_control(&dev)
            .freeze_all_but_text_control();
        let pred = model.predict_x0(&input(2, 1.0, tokens(2, 5, 4, 1, &dev), &dev));
        let grads =
            burn::optim::GradientsParams::from_grads(pred.powi_scalar(2).sum().backward(), &model);
        let trainable = model.text_control().unwrap().num_params();
        let mut counted = 0;
        struct Count<'a>(&'a burn::optim::GradientsParams, &'a mut usize);
        impl burn::module::ModuleVisitor for Count<'_> {
            fn visit_float<const D: usize>(&mut self, p: &Param<Tensor<D>>) {
                if self.0.get::<D>(p.id).is_some() {
                    *self.1 += p.shape().num_elements();
                }
            }
        }
        model.visit(&mut Count(&grads, &mut counted));
        assert_eq!(counted, trainable);
    }

    #[test]
    fn bad_shapes_are_refused_by_name() {
        let mut c = config(true);
        c.text_control.as_mut().unwrap().experts = 0;
        assert!(c.check().unwrap_err().contains("text_control.experts"));
        let words = ModelConfig {
            text_encoder: TextEncoderKind::BagOfWords,
            ..config(true)
        };
        assert!(words.check().unwrap_err().contains("minilm"));
    }
}
