//! The MDM-style denoiser: a transformer encoder over frames that predicts the clean
//! motion x̂0 from a noisy motion x_t, the timestep t and the text.
//!
//! Sequence layout: one condition token (timestep MLP + projected text) followed by the
//! N frame tokens, sinusoidal positions added to all N+1, post-norm encoder layers, the
//! condition token dropped at the output.

use super::config::{ModelConfig, TextEncoderKind};
use super::moc::{MocConfig, TextControl, TextControlInput};
use super::prompt::TextBatch;
use super::text::{BagOfWords, TextEncoder};
use burn::nn::transformer::{TransformerEncoder, TransformerEncoderConfig};
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
    /// Side vector → condition token ([`ModelConfig::side_input`]), zero at first.
    side_proj: Option<Linear>,
    encoder: TransformerEncoder,
    output_proj: Linear,
    /// Timestep sinusoid → per-feature gain on x_t added to the output (`input_skip`).
    skip: Option<Linear>,
    /// OMG's text ControlNet ([`ModelConfig::text_control`]): when present, the text
    /// enters only through it and the condition token reads the timestep alone.
    text_control: Option<TextControl>,
    dropout: Dropout,
    d_model: usize,
    /// Frames the input skip reads around each frame ([`ModelConfig::skip_taps`]).
    skip_taps: usize,
    /// Timestep from which only the centre tap reads ([`ModelConfig::skip_taps_below`];
    /// `usize::MAX`: every tap at every t).
    skip_taps_below: usize,
}

/// Makes every parameter a constant: its value detached and excluded from the gradients.
/// With `no_grad` alone, a model loaded from a bundle failed in its second training step
/// ("graph tape has already been consumed"; a fresh model did not), so the frozen values
/// are cut from whatever built them.
struct Frozen;

impl burn::module::ModuleMapper for Frozen {
    fn map_float<const D: usize>(
        &mut self,
        param: burn::module::Param<Tensor<D>>,
    ) -> burn::module::Param<Tensor<D>> {
        let id = param.id;
        burn::module::Param::initialized(id, param.val().detach().set_require_grad(false))
    }
}

/// `module` with every parameter a constant ([`Frozen`]).
fn frozen<M: Module>(module: M) -> M {
    module.map(&mut Frozen)
}

/// A `d → features` linear layer that starts at zero (weights and bias).
fn zero_skip(d: usize, features: usize, device: &Device) -> Linear {
    LinearConfig::new(d, features)
        .with_initializer(burn::nn::Initializer::Zeros)
        .init(device)
}

/// The side input's layer: zero, and without a bias, so that a prompt naming no side (and
/// the unconditioned pass) gets exactly nothing from it.
fn zero_side(d_text: usize, d: usize, device: &Device) -> Linear {
    LinearConfig::new(d_text, d)
        .with_bias(false)
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
            side_proj: config
                .side_input
                .then(|| zero_side(config.d_text, d, device)),
            encoder: TransformerEncoderConfig::new(d, config.d_ff, config.heads, config.layers)
                .with_dropout(config.dropout)
                .init(device),
            output_proj: LinearConfig::new(d, config.features).init(device),
            skip: config
                .input_skip
                .then(|| zero_skip(d, config.features * config.skip_taps, device)),
            text_control: None,
            dropout: DropoutConfig::new(config.dropout).init(),
            d_model: d,
            skip_taps: config.skip_taps,
            skip_taps_below: config.skip_taps_below.unwrap_or(usize::MAX),
        }
        .with_text_control(config.text_control.as_ref(), device)
    }

    /// This denoiser with a fresh text ControlNet (its layer copies start as this model's
    /// layers, its outputs at zero: it predicts the same), so an unconditional prior can
    /// start OMG's second stage. Already there, or None asked: unchanged.
    pub fn with_text_control(mut self, config: Option<&MocConfig>, device: &Device) -> Self {
        if let (Some(c), None) = (config, &self.text_control) {
            let d_text = self.text_proj.weight.dims()[0];
            self.text_control = Some(TextControl::new(
                &self.encoder.layers,
                self.d_model,
                d_text,
                c,
                device,
            ));
        }
        self
    }

    /// Whether the text enters through a text ControlNet (the prompts' token states must
    /// travel with them).
    pub fn has_text_control(&self) -> bool {
        self.text_control.is_some()
    }

    /// This denoiser with everything but its text ControlNet excluded from the gradients:
    /// OMG's second stage trains the ControlNet on the frozen prior. Without one, the
    /// whole model is frozen.
    pub fn freeze_all_but_text_control(self) -> Self {
        Mdm {
            input_proj: frozen(self.input_proj),
            time_1: frozen(self.time_1),
            time_2: frozen(self.time_2),
            text: self.text.map(frozen),
            text_proj: frozen(self.text_proj),
            side_proj: self.side_proj.map(frozen),
            encoder: frozen(self.encoder),
            output_proj: frozen(self.output_proj),
            skip: self.skip.map(frozen),
            ..self
        }
    }

    /// The text ControlNet, if the model has one.
    #[cfg(test)]
    pub(crate) fn text_control(&self) -> Option<&TextControl> {
        self.text_control.as_ref()
    }

    /// This model's text ControlNet randomised so that it steers (tests).
    #[cfg(test)]
    pub(crate) fn with_random_text_control(mut self, device: &Device) -> Self {
        self.text_control = self.text_control.map(|c| c.randomised(device));
        self
    }

    /// This denoiser with its input skip reading `taps` frames instead of one: the one-frame
    /// gain becomes the centre tap and the others start at zero, so it predicts the same.
    /// Already wider, or without a skip: unchanged.
    pub fn with_skip_taps(mut self, taps: usize) -> Self {
        let Some(skip) = self.skip.take() else {
            return self;
        };
        if self.skip_taps != 1 || taps <= 1 {
            self.skip = Some(skip);
            return self;
        }
        let device = skip.weight.device();
        let [d, f] = skip.weight.dims();
        let centre = taps / 2;
        let widen = |t: Tensor<2>| {
            let rows = t.dims()[0];
            let mut blocks = vec![Tensor::<2>::zeros([rows, f], &device); taps];
            blocks[centre] = t;
            Tensor::cat(blocks, 1)
        };
        let weight = widen(skip.weight.val());
        let bias = skip
            .bias
            .as_ref()
            .map(|b| widen(b.val().reshape([1, f])).reshape([f * taps]));
        // Fresh leaf parameters (the widened values are built from the old ones).
        let mut wide = zero_skip(d, f * taps, &device);
        wide.weight = burn::module::Param::from_tensor(weight.detach());
        if let Some(bias) = bias {
            wide.bias = Some(burn::module::Param::from_tensor(bias.detach()));
        }
        self.skip = Some(wide);
        self.skip_taps = taps;
        self
    }

    /// This denoiser with a zero side input added (no change to what it predicts), so a
    /// sentence-encoder model trained without [`ModelConfig::side_input`] can continue with
    /// it. Already there: unchanged.
    pub fn with_side_input(mut self, device: &Device) -> Self {
        if self.side_proj.is_none() {
            let [d_text, d] = self.text_proj.weight.dims();
            self.side_proj = Some(zero_side(d_text, d, device));
        }
        self
    }

    /// This denoiser with a zero input skip added (no change to what it predicts), so a
    /// model trained without `input_skip` can continue training with it.
    pub fn with_input_skip(mut self, device: &Device) -> Self {
        if self.skip.is_none() {
            let features = self.output_proj.weight.dims()[1];
            self.skip = Some(zero_skip(self.d_model, features * self.skip_taps, device));
        }
        self
    }

    /// The input skip's per-feature gain at timestep `t` (None without `input_skip`); with
    /// several taps, K·F values, tap by tap (the centre tap reads the frame itself).
    pub fn input_skip_gain(&self, t: usize) -> Option<Vec<f32>> {
        let skip = self.skip.as_ref()?;
        let device = skip.weight.device();
        let gain = skip.forward(sinusoids(std::iter::once(t), self.d_model, &device));
        let mut gain = gain.into_data().try_into_vec::<f32>().expect("f32 tensor");
        let f = gain.len() / self.skip_taps;
        for (tap, g) in gain.chunks_mut(f).enumerate() {
            if !self.tap_reads(tap, t) {
                g.fill(0.0);
            }
        }
        Some(gain)
    }

    /// Whether skip tap `tap` reads its frame at timestep `t`: the centre tap always, the
    /// others below [`ModelConfig::skip_taps_below`].
    fn tap_reads(&self, tap: usize, t: usize) -> bool {
        tap == self.skip_taps / 2 || t < self.skip_taps_below
    }

    /// This denoiser with its outer skip taps read only below timestep `below` (None: at
    /// every t), as [`ModelConfig::skip_taps_below`] says.
    pub fn with_skip_taps_below(mut self, below: Option<usize>) -> Self {
        self.skip_taps_below = below.unwrap_or(usize::MAX);
        self
    }

    /// `[B, d]` condition token: timestep embedding plus (possibly dropped) text.
    fn condition(&self, input: &DenoiserInput, device: &Device) -> Tensor<2> {
        let t = sinusoids(input.timesteps.iter().copied(), self.d_model, device);
        let t = self.time_2.forward(silu(self.time_1.forward(t)));
        let keep = input.keep_text.clone().unsqueeze_dim::<2>(1);
        // OMG: the prior was trained without text, so its condition token always reads the
        // dropped text (the projection's bias); the text ControlNet carries the prompt.
        let keep = if self.text_control.is_some() {
            keep.zeros_like()
        } else {
            keep
        };
        let (text, side) = match (&self.text, &input.text) {
            (Some(bag), TextBatch::Words(tokens)) => (bag.encode(tokens), None),
            (None, TextBatch::Sentences(s)) => (
                s.vectors.clone(),
                self.side_proj
                    .as_ref()
                    .map(|p| p.forward((s.vectors.clone() - s.mirrored.clone()) * keep.clone())),
            ),
            _ => unreachable!("the bundle's prompt encoder matches its denoiser"),
        }; // [B, d_text]
        let cond = t + self.text_proj.forward(text * keep);
        match side {
            Some(side) => cond + side,
            None => cond,
        }
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

    /// The encoder over the embedded `seq`, the text ControlNet's residual (if any) and
    /// `controls` (a realism ControlNet's, one per layer, if any) added after each layer.
    pub(crate) fn layers(
        &self,
        seq: Tensor<3>,
        mask: Option<Tensor<2, Bool>>,
        input: &DenoiserInput,
        controls: Option<&[Tensor<3>]>,
    ) -> Tensor<3> {
        let text = self.text_control.as_ref().map(|c| {
            let TextBatch::Sentences(s) = &input.text else {
                unreachable!("a text ControlNet reads sentence batches")
            };
            let tokens = s
                .tokens
                .as_ref()
                .expect("a model with a text ControlNet is given its prompts' token states");
            (c, tokens, s.vectors.clone())
        });
        let mut x = seq;
        for (l, layer) in self.encoder.layers.iter().enumerate() {
            let out = layer.forward(x.clone(), mask.clone(), None);
            let out = match &text {
                Some((c, tokens, sentences)) => {
                    let residual = c.residual(
                        l,
                        x,
                        &TextControlInput {
                            tokens: &tokens.own,
                            sentences,
                            keep: &input.keep_text,
                            padding: mask.as_ref(),
                        },
                    );
                    out + residual
                }
                None => out,
            };
            x = match controls {
                Some(c) => out + c[l].clone(),
                None => out,
            };
        }
        x
    }

    /// x̂0 `[B, N, F]` from the encoder's output `[B, N+1, d]`.
    pub(crate) fn output(&self, out: Tensor<3>, input: &DenoiserInput) -> Tensor<3> {
        let device = input.x_t.device();
        let n = input.x_t.dims()[1];
        let out = self.output_proj.forward(out.narrow(1, 1, n)); // [B, N, F]
        match &self.skip {
            Some(skip) if self.skip_taps == 1 => {
                let t = sinusoids(input.timesteps.iter().copied(), self.d_model, &device);
                let gain = skip.forward(t).unsqueeze_dim::<3>(1); // [B, 1, F]
                out + gain * input.x_t.clone()
            }
            Some(skip) => out + self.filtered_skip(skip, input),
            None => out,
        }
    }

    /// The input skip with [`ModelConfig::skip_taps`] K > 1: `Σ_k g_k(t) ⊙ x_t[n + k − K/2]`,
    /// each sample's frames clamped to its valid ones (padding is never read), `[B, N, F]`.
    fn filtered_skip(&self, skip: &Linear, input: &DenoiserInput) -> Tensor<3> {
        let device = input.x_t.device();
        let [b, n, f] = input.x_t.dims();
        let k = self.skip_taps;
        let valid: Vec<usize> = match &input.padding {
            Some(pad) => pad
                .clone()
                .into_data()
                .iter::<bool>()
                .collect::<Vec<_>>()
                .chunks(n)
                .map(|row| row.iter().filter(|&&p| !p).count().max(1))
                .collect(),
            None => vec![n; b],
        };
        // Row of x_t (flattened to [B·N, F]) each tap reads, tap-major: [K·B·N].
        let mut rows = Vec::with_capacity(k * b * n);
        for tap in 0..k {
            for (s, &len) in valid.iter().enumerate() {
                for frame in 0..n {
                    let at = (frame + tap).saturating_sub(k / 2).min(len - 1);
                    rows.push((s * n + at) as i64);
                }
            }
        }
        let rows = Tensor::<1, Int>::from_data(TensorData::new(rows, [k * b * n]), &device);
        let taps = input
            .x_t
            .clone()
            .reshape([b * n, f])
            .select(0, rows)
            .reshape([k, b, n, f]);
        let t = sinusoids(input.timesteps.iter().copied(), self.d_model, &device);
        // [B, K·F] tap-major → [K, B, 1, F].
        let gains = skip
            .forward(t)
            .reshape([b, k, f])
            .swap_dims(0, 1)
            .unsqueeze_dim::<4>(2);
        let gains = if self.skip_taps_below == usize::MAX {
            gains
        } else {
            // [K, B, 1, 1]: 0 where a tap is shut at its sample's t.
            let open: Vec<f32> = (0..k)
                .flat_map(|tap| {
                    input
                        .timesteps
                        .iter()
                        .map(move |&t| f32::from(u8::from(self.tap_reads(tap, t))))
                })
                .collect();
            gains * Tensor::<4>::from_data(TensorData::new(open, [k, b, 1, 1]), &device)
        };
        (taps * gains).sum_dim(0).reshape([b, n, f])
    }
}

impl Denoiser for Mdm {
    fn predict_x0(&self, input: &DenoiserInput) -> Tensor<3> {
        let (seq, mask) = self.embed(input);
        let out = self.layers(seq, mask, input, None); // [B, N+1, d]
        self.output(out, input)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::noise::NoiseSource;
    use crate::model::text::{TokenBatch, Vocabulary};

    fn input(frames: usize, valid: &[usize], dev: &Device) -> DenoiserInput {
        let vocab = Vocabulary::from_captions(["a person walks"], 8);
        let b = valid.len();
        let pad: Vec<bool> = valid
            .iter()
            .flat_map(|&len| (0..frames).map(move |f| f >= len))
            .collect();
        DenoiserInput {
            x_t: NoiseSource::new(4).tensor([b, frames, 263], dev),
            timesteps: vec![30; b],
            text: TextBatch::Words(TokenBatch::new(&vocab, &vec!["a person walks"; b], dev)),
            keep_text: Tensor::ones([b], dev),
            padding: Some(Tensor::from_data(TensorData::new(pad, [b, frames]), dev)),
        }
    }

    fn tiny(taps: usize) -> ModelConfig {
        ModelConfig {
            d_model: 16,
            layers: 1,
            heads: 2,
            d_ff: 32,
            d_text: 8,
            max_frames: 40,
            input_skip: true,
            skip_taps: taps,
            ..ModelConfig::default()
        }
    }

    #[test]
    fn widening_the_skip_keeps_the_prediction() {
        let dev = Device::flex();
        let mut one = Mdm::new(&tiny(1), 8, &dev);
        // A trained one-frame skip (random, not zero).
        one.skip = Some(LinearConfig::new(16, 263).init(&dev));
        let wide = one.clone().with_skip_taps(5);
        assert_eq!(wide.skip_taps, 5);
        let (g1, g5) = (
            one.input_skip_gain(30).unwrap(),
            wide.input_skip_gain(30).unwrap(),
        );
        assert_eq!(
            &g5[2 * 263..3 * 263],
            &g1[..],
            "the centre tap is the old gain"
        );
        assert!(
            g5[..2 * 263]
                .iter()
                .chain(&g5[3 * 263..])
                .all(|&g| g == 0.0)
        );
        let inp = input(6, &[6, 4], &dev);
        let (a, b) = (one.valid().predict_x0(&inp), wide.valid().predict_x0(&inp));
        // Valid frames only: on padding the wide skip reads the last valid frame.
        let diff = (a - b).narrow(1, 0, 4).abs().max().into_scalar::<f32>();
        assert!(diff < 1e-5, "{diff}");
    }

    #[test]
    fn a_tap_reads_its_neighbouring_frame_and_never_padding() {
        let dev = Device::flex();
        let model = Mdm::new(&tiny(5), 8, &dev);
        // Only the first tap (two frames back) passes its frame through, gain 1.
        let mut bias = vec![0.0f32; 5 * 263];
        bias[..263].fill(1.0);
        let mut skip = zero_skip(16, 5 * 263, &dev);
        skip.bias = Some(burn::module::Param::from_tensor(Tensor::from_data(
            TensorData::new(bias, [5 * 263]),
            &dev,
        )));
        let inp = input(6, &[6, 4], &dev);
        let got = model.filtered_skip(&skip, &inp);
        let x = inp.x_t.clone();
        let row = |t: Tensor<3>, s: usize, f: usize| {
            t.narrow(0, s, 1)
                .narrow(1, f, 1)
                .into_data()
                .try_to_vec::<f32>()
                .unwrap()
        };
        // Sample 0 (6 valid frames): frame 3 reads frame 1, frame 0 repeats frame 0.
        assert_eq!(row(got.clone(), 0, 3), row(x.clone(), 0, 1));
        assert_eq!(row(got.clone(), 0, 0), row(x.clone(), 0, 0));
        // Sample 1 (4 valid): frame 5 (padding) reads the last valid frame, 3.
        assert_eq!(row(got.clone(), 1, 5), row(x.clone(), 1, 3));
        assert_eq!(row(got, 1, 2), row(x, 1, 0));
    }

    #[test]
    fn outer_taps_read_only_below_their_timestep() {
        let dev = Device::flex();
        let model = Mdm::new(
            &ModelConfig {
                skip_taps_below: Some(30),
                ..tiny(5)
            },
            8,
            &dev,
        );
        // Tap 0 (two frames back) and the centre tap pass their frames, gain 1 each.
        let mut bias = vec![0.0f32; 5 * 263];
        bias[..263].fill(1.0);
        bias[2 * 263..3 * 263].fill(1.0);
        let mut skip = zero_skip(16, 5 * 263, &dev);
        skip.bias = Some(burn::module::Param::from_tensor(Tensor::from_data(
            TensorData::new(bias, [5 * 263]),
            &dev,
        )));
        let mut inp = input(6, &[6, 6], &dev);
        inp.timesteps = vec![29, 30]; // sample 0 below, sample 1 at the threshold
        let got = model.filtered_skip(&skip, &inp);
        let x = inp.x_t.clone();
        let frame = |t: Tensor<3>, s: usize, f: usize| t.narrow(0, s, 1).narrow(1, f, 1);
        let diff = |a: Tensor<3>, b: Tensor<3>| (a - b).abs().max().into_scalar::<f32>();
        // Below: frame 3 is itself plus frame 1; at 30: itself alone.
        let both = frame(x.clone(), 0, 3) + frame(x.clone(), 0, 1);
        assert!(diff(frame(got.clone(), 0, 3), both) < 1e-6);
        assert!(diff(frame(got, 1, 3), frame(x, 1, 3)) < 1e-6);
        // The reported gains agree.
        let mut m = model;
        m.skip = Some(skip);
        let g = m.input_skip_gain(30).unwrap();
        assert!(g[..263].iter().all(|&v| v == 0.0) && g[2 * 263] == 1.0);
        assert_eq!(m.input_skip_gain(29).unwrap()[0], 1.0);
        // Only with several taps.
        let one = ModelConfig {
            skip_taps_below: Some(30),
            ..tiny(1)
        };
        assert!(one.check().unwrap_err().contains("skip_taps_below"));
    }

    fn sentence_input(v: Vec<f32>, m: Vec<f32>, keep: f32, dev: &Device) -> DenoiserInput {
        use crate::model::prompt::SentenceBatch;
        let vec = |x: Vec<f32>| Tensor::<2>::from_data(TensorData::new(x, [1, 8]), dev);
        DenoiserInput {
            x_t: NoiseSource::new(5).tensor([1, 6, 263], dev),
            timesteps: vec![300],
            text: TextBatch::Sentences(SentenceBatch {
                vectors: vec(v),
                mirrored: vec(m),
                tokens: None,
            }),
            keep_text: Tensor::full([1], keep, dev),
            padding: None,
        }
    }

    #[test]
    fn the_side_input_reads_only_the_difference_from_the_swapped_prompt() {
        let dev = Device::flex();
        let cfg = ModelConfig {
            text_encoder: TextEncoderKind::Sentence,
            side_input: true,
            ..tiny(1)
        };
        let plain = Mdm::new(
            &ModelConfig {
                side_input: false,
                ..cfg.clone()
            },
            0,
            &dev,
        );
        // Added at zero it changes nothing.
        let added = plain.clone().with_side_input(&dev);
        let v: Vec<f32> = (0..8).map(|i| i as f32 / 8.0).collect();
        let m: Vec<f32> = v.iter().rev().copied().collect();
        let predict = |model: &Mdm, v: &[f32], m: &[f32], keep: f32| {
            model
                .clone()
                .valid()
                .predict_x0(&sentence_input(v.to_vec(), m.to_vec(), keep, &dev))
        };
        let max_diff = |a: Tensor<3>, b: Tensor<3>| (a - b).abs().max().into_scalar::<f32>();
        assert_eq!(
            max_diff(predict(&plain, &v, &m, 1.0), predict(&added, &v, &m, 1.0)),
            0.0
        );
        // Trained (random here), it acts on a prompt that names a side ...
        let mut side = added;
        side.side_proj = Some(LinearConfig::new(8, 16).with_bias(false).init(&dev));
        assert!(max_diff(predict(&plain, &v, &m, 1.0), predict(&side, &v, &m, 1.0)) > 1e-4);
        // ... not on one that names none (swapping changes nothing), nor unconditioned.
        assert!(max_diff(predict(&plain, &v, &v, 1.0), predict(&side, &v, &v, 1.0)) < 1e-6);
        assert!(max_diff(predict(&plain, &v, &m, 0.0), predict(&side, &v, &m, 0.0)) < 1e-6);
        // A bag-of-words model cannot have one.
        let bad = ModelConfig {
            text_encoder: TextEncoderKind::BagOfWords,
            ..cfg
        };
        assert!(bad.check().unwrap_err().contains("side_input"));
    }
}
