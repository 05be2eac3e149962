//! Realism guidance's network (OmniControl §3.2, InterControl's Motion ControlNet): a
//! trainable copy of the denoiser's encoder that reads a spatial hint (target joint
//! positions, masked per joint and frame) and adds into the frozen denoiser's stream after
//! each of its layers through zero-initialised linear layers, so a fresh one changes
//! nothing.
//!
//! The hint of a frame is 88 numbers: the 22 joints' target positions in metres in the
//! person's canonical frame (the model's own: start at the origin facing +Z), zero where
//! free, then the 22 joints' 0/1 mask. It is embedded by one zero-initialised linear layer
//! and added to that frame's token of the copy (not to the condition token), as OmniControl
//! adds its hint block's output. Positions are not normalised: the linear layer learns the
//! scale, and a controlled joint at exactly the origin is still marked by its mask (the
//! reference code, which infers the mask from non-zero values, cannot tell).
//!
//! Saved next to the denoiser as `<bundle>/control.safetensors`; bundles without it load as
//! before ([`ControlNet::load`] returns None).

use super::denoiser::{Denoiser, DenoiserInput, Mdm};
use super::weights::{WeightsError, module_from_safetensors, module_to_safetensors};
use crate::fsutil::write_bytes_atomic;
use crate::skeleton::NUM_JOINTS;
use burn::nn::transformer::TransformerEncoder;
use burn::nn::{Initializer, Linear, LinearConfig};
use burn::prelude::*;
use std::path::Path;

/// Numbers per frame of a hint: 22 × xyz targets, then 22 mask values.
pub const HINT_DIM: usize = NUM_JOINTS * 3 + NUM_JOINTS;

/// File of a bundle's ControlNet.
pub const CONTROL_FILE: &str = "control.safetensors";

/// Target joint positions with their mask, per sample and frame.
#[derive(Clone, Debug)]
pub struct Hint {
    /// `[B, N, HINT_DIM]`.
    pub values: Tensor<3>,
}

impl Hint {
    /// A hint from targets `[B, N, 22, 3]` (metres, canonical frame) and a mask
    /// `[B, N, 22]` (1 where the joint is controlled on that frame).
    pub fn new(targets: Tensor<4>, mask: Tensor<3>) -> Hint {
        let [b, n, j, _] = targets.dims();
        let masked = targets * mask.clone().unsqueeze_dim::<4>(3);
        Hint {
            values: Tensor::cat(vec![masked.reshape([b, n, j * 3]), mask], 2),
        }
    }

    /// A hint that controls nothing.
    pub fn empty(batch: usize, frames: usize, device: &Device) -> Hint {
        Hint {
            values: Tensor::zeros([batch, frames, HINT_DIM], device),
        }
    }

    /// This hint for a batch of `batch` samples: classifier-free guidance and mirror
    /// averaging stack copies of the same samples, so the hint is repeated to match.
    fn for_batch(&self, batch: usize) -> Tensor<3> {
        let own = self.values.dims()[0];
        assert!(
            own > 0 && batch.is_multiple_of(own),
            "a hint for {own} samples cannot condition a batch of {batch}"
        );
        if batch == own {
            self.values.clone()
        } else {
            Tensor::cat(vec![self.values.clone(); batch / own], 0)
        }
    }
}

/// The trainable copy of the encoder with its hint input and zero outputs.
#[derive(Module, Debug)]
pub struct ControlNet {
    hint_in: Linear,
    encoder: TransformerEncoder,
    zero_out: Vec<Linear>,
}

fn zero_linear(d_in: usize, d_out: usize, device: &Device) -> Linear {
    LinearConfig::new(d_in, d_out)
        .with_initializer(Initializer::Zeros)
        .init(device)
}

impl ControlNet {
    /// A fresh ControlNet for `base`: its encoder copied (InterControl initialises the copy
    /// from the denoiser's weights), hint input and outputs at zero.
    pub fn from_base(base: &Mdm, device: &Device) -> ControlNet {
        let encoder = base.encoder().clone().to_device(device);
        let d = encoder.d_model;
        let layers = encoder.layers.len();
        ControlNet {
            hint_in: zero_linear(HINT_DIM, d, device),
            zero_out: (0..layers).map(|_| zero_linear(d, d, device)).collect(),
            encoder,
        }
    }

    /// This ControlNet with random (non-zero) hint input and outputs, so that it steers:
    /// for tests of the solvers that must see it act.
    #[cfg(test)]
    pub(crate) fn randomised(mut self, device: &Device) -> ControlNet {
        let d = self.encoder.d_model;
        self.hint_in = LinearConfig::new(HINT_DIM, d).init(device);
        for out in &mut self.zero_out {
            *out = LinearConfig::new(d, d).init(device);
        }
        self
    }

    /// What to add into the denoiser's stream after each of its layers, `[B, N+1, d]`
    /// each, for the denoiser's embedded sequence `seq` and a hint.
    fn controls(
        &self,
        seq: Tensor<3>,
        hint: Tensor<3>,
        mask: Option<Tensor<2, Bool>>,
    ) -> Vec<Tensor<3>> {
        let [b, _, d] = seq.dims();
        let frames = self.hint_in.forward(hint); // [B, N, d]
        let none = Tensor::zeros([b, 1, d], &frames.device());
        let mut x = seq + Tensor::cat(vec![none, frames], 1);
        let mut out = Vec::with_capacity(self.zero_out.len());
        for (layer, zero) in self.encoder.layers.iter().zip(&self.zero_out) {
            x = layer.forward(x, mask.clone(), None);
            out.push(zero.forward(x.clone()));
        }
        out
    }

    /// Loads `<dir>/control.safetensors` for `base` (f16 when `half`); None when the bundle
    /// has none. A file whose tensors do not fit `base` is refused, naming the tensor.
    pub fn load(
        dir: &Path,
        base: &Mdm,
        half: bool,
        device: &Device,
    ) -> Result<Option<ControlNet>, WeightsError> {
        let path = dir.join(CONTROL_FILE);
        if !path.exists() {
            return Ok(None);
        }
        let bytes = std::fs::read(&path).map_err(|e| WeightsError::Read {
            path: path.clone(),
            reason: e.to_string(),
        })?;
        module_from_safetensors(
            ControlNet::from_base(base, device),
            bytes,
            half,
            "ControlNet",
        )
        .map(Some)
        .map_err(|reason| WeightsError::Mismatch { path, reason })
    }

    /// Writes `<dir>/control.safetensors` atomically (f16 when `half`).
    pub fn save(&self, dir: &Path, half: bool) -> Result<(), WeightsError> {
        let path = dir.join(CONTROL_FILE);
        let write = |reason: String| WeightsError::Write {
            path: path.clone(),
            reason,
        };
        let bytes = module_to_safetensors(self, half).map_err(write)?;
        write_bytes_atomic(&path, &bytes).map_err(|e| write(e.to_string()))
    }
}

/// The denoiser steered by a ControlNet and a hint: a [`Denoiser`] like any other.
pub struct Controlled<'a> {
    /// The frozen denoiser.
    pub base: &'a Mdm,
    /// Its ControlNet.
    pub control: &'a ControlNet,
    /// What to steer towards (one row per sample of the solve).
    pub hint: Hint,
    /// When the batch is a classifier-free guidance pair (conditioned samples first, then
    /// the same samples without text, as [`crate::model::sampler::guided_x0`] stacks
    /// them): run the ControlNet on the conditioned half only and add its output to both
    /// halves. Half the ControlNet's cost; OmniControl runs it on each half.
    pub shared_guidance: bool,
}

impl Controlled<'_> {
    /// x̂0 for `input`, and the ControlNet's additions it used (one `[B, N+1, d]` per base
    /// layer), which [`WithControls`] can reuse.
    pub fn predict_x0_and_controls(&self, input: &DenoiserInput) -> (Tensor<3>, Vec<Tensor<3>>) {
        let (seq, mask) = self.base.embed(input);
        let batch = seq.dims()[0];
        let own = self.hint.values.dims()[0];
        let controls: Vec<Tensor<3>> = if self.shared_guidance && batch == 2 * own {
            let half = |m: Tensor<2, Bool>| m.narrow(0, 0, own);
            self.control
                .controls(
                    seq.clone().narrow(0, 0, own),
                    self.hint.values.clone(),
                    mask.clone().map(half),
                )
                .into_iter()
                .map(|c| Tensor::cat(vec![c.clone(), c], 0))
                .collect()
        } else {
            let hint = self.hint.for_batch(batch);
            self.control.controls(seq.clone(), hint, mask.clone())
        };
        let x0 = with_controls(self.base, seq, mask, &controls, input);
        (x0, controls)
    }
}

impl Denoiser for Controlled<'_> {
    fn predict_x0(&self, input: &DenoiserInput) -> Tensor<3> {
        self.predict_x0_and_controls(input).0
    }
}

/// The frozen denoiser with a ControlNet's additions computed earlier (for a batch of the
/// same size): a step that reuses the previous step's steering without running the
/// ControlNet again.
pub struct WithControls<'a> {
    /// The frozen denoiser.
    pub base: &'a Mdm,
    /// One `[B, N+1, d]` per layer, from [`Controlled::predict_x0_and_controls`].
    pub controls: &'a [Tensor<3>],
}

impl Denoiser for WithControls<'_> {
    fn predict_x0(&self, input: &DenoiserInput) -> Tensor<3> {
        let (seq, mask) = self.base.embed(input);
        with_controls(self.base, seq, mask, self.controls, input)
    }
}

/// The base's encoder over the embedded `seq` with `controls` added after each layer, and
/// its output head.
fn with_controls(
    base: &Mdm,
    seq: Tensor<3>,
    mask: Option<Tensor<2, Bool>>,
    controls: &[Tensor<3>],
    input: &DenoiserInput,
) -> Tensor<3> {
    let x = base.layers(seq, mask, input, Some(controls));
    base.output(x, input)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::config::ModelConfig;
    use crate::model::noise::NoiseSource;
    use crate::model::prompt::TextBatch;
    use crate::model::text::{TokenBatch, Vocabulary};

    fn config(d_model: usize) -> ModelConfig {
        ModelConfig {
            d_model,
            layers: 2,
            heads: 2,
            d_ff: 64,
            d_text: 8,
            max_frames: 40,
            ..ModelConfig::default()
        }
    }

    fn vocab() -> Vocabulary {
        Vocabulary::from_captions(["a person walks forward"], 8)
    }

    fn question(b: usize, n: usize, dev: &Device) -> DenoiserInput {
        let vocab = vocab();
        DenoiserInput {
            x_t: NoiseSource::new(4).tensor([b, n, 263], dev),
            timesteps: vec![400; b],
            text: TextBatch::Words(TokenBatch::new(&vocab, &vec!["a person walks"; b], dev)),
            keep_text: Tensor::ones([b], dev),
            padding: None,
        }
    }

    fn hint(b: usize, n: usize, dev: &Device) -> Hint {
        let targets = NoiseSource::new(5).tensor([b, n, NUM_JOINTS, 3], dev);
        let mut mask = vec![0.0f32; b * n * NUM_JOINTS];
        mask[3 * NUM_JOINTS + 20] = 1.0; // the left wrist on frame 3 of sample 0
        Hint::new(
            targets,
            Tensor::from_data(TensorData::new(mask, [b, n, NUM_JOINTS]), dev),
        )
    }

    /// A small random denoiser and a ControlNet for it with random (non-zero) weights.
    fn steering(seed: u64, dev: &Device) -> (Mdm, ControlNet) {
        let base = Mdm::new(&config(32), vocab().len(), dev).valid();
        let control = ControlNet::from_base(&base, dev).map(&mut Randomise(NoiseSource::new(seed)));
        (base, control)
    }

    /// `input` stacked twice, as classifier-free guidance asks: `keep` says which rows read
    /// their text.
    fn guidance_pair(input: &DenoiserInput, keep: [f32; 4], dev: &Device) -> DenoiserInput {
        DenoiserInput {
            x_t: Tensor::cat(vec![input.x_t.clone(); 2], 0),
            timesteps: vec![400; 4],
            text: input.text.doubled(),
            keep_text: Tensor::from_floats(keep, dev),
            padding: None,
        }
    }

    fn max_diff(a: Tensor<3>, b: Tensor<3>) -> f32 {
        (a - b).abs().max().into_scalar::<f32>()
    }

    #[test]
    fn a_fresh_control_net_changes_nothing() {
        let dev = Device::flex();
        let base = Mdm::new(&config(32), vocab().len(), &dev).valid();
        let control = ControlNet::from_base(&base, &dev);
        let input = question(2, 6, &dev);
        let steered = Controlled {
            base: &base,
            control: &control,
            hint: hint(2, 6, &dev),
            shared_guidance: false,
        };
        assert_eq!(
            max_diff(steered.predict_x0(&input), base.predict_x0(&input)),
            0.0
        );
        // A batch doubled for classifier-free guidance repeats the hint.
        let doubled = guidance_pair(&input, [1.0; 4], &dev);
        assert_eq!(steered.predict_x0(&doubled).dims(), [4, 6, 263]);
    }

    #[test]
    fn a_trained_control_net_reads_the_hint() {
        let dev = Device::flex();
        let base = Mdm::new(&config(32), vocab().len(), &dev).valid();
        // Non-zero input and output layers stand in for training.
        let control = ControlNet::from_base(&base, &dev).map(&mut Randomise(NoiseSource::new(8)));
        let input = question(1, 6, &dev);
        let with = |h: Hint| {
            Controlled {
                base: &base,
                control: &control,
                hint: h,
                shared_guidance: false,
            }
            .predict_x0(&input)
        };
        let empty = with(Hint::empty(1, 6, &dev));
        let steered = with(hint(1, 6, &dev));
        assert!(max_diff(empty.clone(), steered) > 1e-4);
        assert!(max_diff(empty, base.predict_x0(&input)) > 1e-4);
    }

    #[test]
    fn a_shared_control_steers_both_guidance_halves_with_the_conditioned_pass() {
        let dev = Device::flex();
        let (base, control) = steering(3, &dev);
        let input = question(2, 6, &dev);
        // A guidance pair: the samples with their text, then without.
        let pair = guidance_pair(&input, [1.0, 1.0, 0.0, 0.0], &dev);
        let run = |shared_guidance| {
            Controlled {
                base: &base,
                control: &control,
                hint: hint(2, 6, &dev),
                shared_guidance,
            }
            .predict_x0(&pair)
        };
        let (own, shared) = (run(false), run(true));
        // The conditioned half is the same either way; the unconditioned half differs,
        // because its ControlNet pass read the text-free token before.
        let half = |t: Tensor<3>, h: usize| t.narrow(0, 2 * h, 2);
        assert!(max_diff(half(own.clone(), 0), half(shared.clone(), 0)) < 1e-5);
        assert!(max_diff(half(own, 1), half(shared.clone(), 1)) > 1e-4);
        // It is the base's text-free pass plus the conditioned pass's controls.
        let embedded = base.embed(&pair);
        let controls = control.controls(
            embedded.0.clone().narrow(0, 0, 2),
            hint(2, 6, &dev).values,
            None,
        );
        let uncond = DenoiserInput {
            x_t: input.x_t.clone(),
            timesteps: vec![400; 2],
            text: input.text.clone(),
            keep_text: Tensor::zeros([2], &dev),
            padding: None,
        };
        let x0 = with_controls(&base, embedded.0.narrow(0, 2, 2), None, &controls, &uncond);
        assert!(max_diff(x0, half(shared, 1)) < 1e-5);
    }

    #[test]
    fn reused_controls_give_the_steered_prediction_without_the_control_net() {
        let dev = Device::flex();
        let (base, control) = steering(5, &dev);
        let input = question(2, 6, &dev);
        let steered = Controlled {
            base: &base,
            control: &control,
            hint: hint(2, 6, &dev),
            shared_guidance: false,
        };
        let (x0, controls) = steered.predict_x0_and_controls(&input);
        assert_eq!(controls.len(), 2, "one per base layer");
        let reused = WithControls {
            base: &base,
            controls: &controls,
        };
        assert_eq!(max_diff(reused.predict_x0(&input), x0.clone()), 0.0);
        assert!(max_diff(base.predict_x0(&input), x0) > 1e-4);
    }

    #[test]
    fn a_saved_control_net_loads_and_a_mismatched_one_is_refused() {
        let dev = Device::flex();
        let dir = tempfile::tempdir().unwrap();
        let base = Mdm::new(&config(32), vocab().len(), &dev).valid();
        assert!(
            ControlNet::load(dir.path(), &base, false, &dev)
                .unwrap()
                .is_none()
        );
        let control = ControlNet::from_base(&base, &dev).map(&mut Randomise(NoiseSource::new(9)));
        control.save(dir.path(), true).unwrap();
        let loaded = ControlNet::load(dir.path(), &base, true, &dev)
            .unwrap()
            .unwrap();
        let input = question(1, 5, &dev);
        let out = |c: &ControlNet| {
            Controlled {
                base: &base,
                control: c,
                hint: hint(1, 5, &dev),
                shared_guidance: false,
            }
            .predict_x0(&input)
        };
        assert!(
            max_diff(out(&control), out(&loaded)) < 5e-2,
            "f16 round trip"
        );
        // A ControlNet made for a wider denoiser does not fit this one.
        let wide = Mdm::new(&config(48), vocab().len(), &dev).valid();
        ControlNet::from_base(&wide, &dev)
            .save(dir.path(), true)
            .unwrap();
        let err = ControlNet::load(dir.path(), &base, true, &dev)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(CONTROL_FILE) && err.contains("hint_in"),
            "the error names the file and a tensor: {err}"
        );
    }

    /// Overwrites every float parameter with small random values.
    struct Randomise(NoiseSource);
    impl burn::module::ModuleMapper for Randomise {
        fn map_float<const D: usize>(
            &mut self,
            param: burn::module::Param<Tensor<D>>,
        ) -> burn::module::Param<Tensor<D>> {
            let src = &mut self.0;
            param.map(|t| {
                let dims = t.dims();
                src.tensor(dims, &t.device()) * 0.1
            })
        }
    }
}
