//! Training a ControlNet on a frozen base (OmniControl §3.2): each step draws a batch as the
//! base's training does, takes the hint from the clean motions themselves (one random joint
//! of pelvis, feet, head and wrists per sample, on a random number of its frames, as
//! OmniControl's `random_mask_train`), noises the motions and fits the controlled
//! prediction to the clean motion with the masked x0 MSE, plus the base's geometric terms
//! (foot contact, velocity, bones) where the config weighs them. Only the ControlNet
//! learns.
//!
//! ```text
//! <out>/config.toml           ControlTrainConfig (fixed at the first start)
//! <out>/ckpt/state.json       step, seconds, last loss
//! <out>/ckpt/control.safetensors, optim.bpk   the training state (f32)
//! <out>/ckpt/ema/control.safetensors         the EMA of the ControlNet's weights (f32)
//! <out>/bundle/               the base bundle's files plus the EMA's control.safetensors (f16)
//! <out>/loss.csv              step, loss, learning rate, seconds
//! <out>/val.csv               step, hint error with / without the ControlNet (m), seconds
//! ```
//!
//! The training loss is the x0 error of all 263 features, of which a hint touches few, so
//! it barely moves while the ControlNet learns. What it is trained for is measured at
//! every checkpoint instead: on fixed validation crops with fixed hints, how far the hinted
//! joints of x̂0 lie from their targets, steered and not (`val.csv`).
//!
//! What ships, and what validation measures, is an exponential moving average of the
//! weights, as for the base: the raw weights' snapshots swung from one checkpoint to the
//! next by as much as they differ from the base (keyframe FID 1.238 at step 11,200, 1.300
//! at step 11,800). A checkpoint from before the EMA resumes with the EMA started at its
//! weights.

use super::checkpoint::swap_in;
use super::log::append;
use super::losses::{GeometricLosses, prediction_loss, q_sample, to_device};
use super::text::TrainText;
use super::{TrainError, TrainState, file_err};
use crate::dataset::{ClipInfo, Dataset, Split};
use crate::features::recover_from_ric_tensor;
use crate::fsutil::write_bytes_atomic;
use crate::interrupt::Interrupt;
use crate::model::batch::{HostBatch, draw_batch, step_rng};
use crate::model::config::TrainConfig;
use crate::model::control::{CONTROL_FILE, ControlNet, Controlled, Hint};
use crate::model::denoiser::{Denoiser, DenoiserInput, Mdm};
use crate::model::ema::ema_update;
use crate::model::prompt::PromptEncoder;
use crate::model::schedule::{DIFFUSION_STEPS, NoiseSchedule};
use crate::model::weights::{Manifest, ModelBundle, model_from_safetensors};
use crate::skeleton::NUM_JOINTS;
use burn::module::Module;
use burn::optim::grad_clipping::GradientClippingConfig;
use burn::optim::{AdamWConfig, GradientsParams, ModuleOptimizer};
use burn::prelude::*;
use rand::Rng;
use rand::seq::index::sample;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Folder of the EMA's weights inside a checkpoint.
const EMA_DIR: &str = "ema";

/// Joints a training hint controls (OmniControl's set): pelvis, feet, head, wrists.
pub const HINT_JOINTS: [usize; 6] = [0, 10, 11, 15, 20, 21];

/// Settings of a ControlNet run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControlTrainConfig {
    /// Clips per batch.
    pub batch_size: usize,
    /// Frames per crop.
    pub crop_frames: usize,
    /// Peak learning rate (AdamW; OmniControl 1e-5 at batch 64 over 400k steps).
    pub learning_rate: f64,
    /// Linear warm-up steps.
    pub warmup_steps: usize,
    /// Gradient norm clip.
    pub grad_clip: f64,
    /// Probability of dropping the text (the ControlNet must also steer unconditional
    /// passes of classifier-free guidance).
    pub cond_drop: f64,
    /// Total steps.
    pub steps: usize,
    /// Checkpoint every this many steps.
    pub checkpoint_every: usize,
    /// Seed of the data order, hints and noise.
    pub seed: u64,
    /// Weight of MDM's foot-contact term on the steered prediction (as the base's
    /// `foot_loss`; 0: the x0 MSE alone, as OmniControl). The MSE barely sees a foot
    /// that slides a few centimetres; this term does.
    #[serde(default)]
    pub foot_loss: f64,
    /// Weight of MDM's velocity term on the steered prediction (as the base's).
    #[serde(default)]
    pub velocity_loss: f64,
    /// Weight of the bone-length term on the steered prediction (as the base's).
    #[serde(default)]
    pub bone_loss: f64,
    /// Decay of the weights' exponential moving average (as the base's `ema_decay`).
    #[serde(default = "default_ema_decay")]
    pub ema_decay: f64,
}

fn default_ema_decay() -> f64 {
    TrainConfig::default().ema_decay
}

impl Default for ControlTrainConfig {
    fn default() -> Self {
        ControlTrainConfig {
            batch_size: 32,
            crop_frames: 120,
            learning_rate: 1e-4,
            warmup_steps: 200,
            grad_clip: 1.0,
            cond_drop: 0.1,
            steps: 100_000,
            checkpoint_every: 100,
            seed: 11,
            foot_loss: 0.0,
            velocity_loss: 0.0,
            bone_loss: 0.0,
            ema_decay: default_ema_decay(),
        }
    }
}

impl ControlTrainConfig {
    /// The base training settings that draw this run's batches.
    fn batches(&self) -> TrainConfig {
        TrainConfig {
            batch_size: self.batch_size,
            crop_frames: self.crop_frames,
            cond_drop: self.cond_drop,
            seed: self.seed,
            foot_loss: self.foot_loss,
            velocity_loss: self.velocity_loss,
            bone_loss: self.bone_loss,
            ema_decay: self.ema_decay,
            ..TrainConfig::default()
        }
    }

    fn check(&self) -> Result<(), String> {
        self.batches().check()?;
        if !(self.learning_rate.is_finite() && self.learning_rate > 0.0) {
            return Err(format!(
                "`learning_rate` is {}; it must be a positive number",
                self.learning_rate
            ));
        }
        if self.checkpoint_every == 0 {
            return Err("`checkpoint_every` must be at least 1".into());
        }
        Ok(())
    }
}

/// Hints of a batch from its clean joints `[B, N, 22, 3]`: per sample one joint of
/// [`HINT_JOINTS`] on k of its valid frames, k uniform in 1..=valid−1 (at least 1).
pub fn training_hint(joints: Tensor<4>, valid_frames: &[usize], rng: &mut impl Rng) -> Hint {
    let [b, n, _, _] = joints.dims();
    let mut mask = vec![0.0f32; b * n * NUM_JOINTS];
    for (i, &len) in valid_frames.iter().enumerate() {
        let joint = HINT_JOINTS[rng.random_range(0..HINT_JOINTS.len())];
        let len = len.clamp(1, n);
        let k = rng.random_range(1..=len.saturating_sub(1).max(1));
        for f in sample(rng, len, k) {
            mask[(i * n + f) * NUM_JOINTS + joint] = 1.0;
        }
    }
    let device = joints.device();
    let mask = Tensor::from_data(TensorData::new(mask, [b, n, NUM_JOINTS]), &device);
    Hint::new(joints, mask)
}

/// A ControlNet run on a frozen base bundle.
pub struct ControlTrainRun<'a> {
    /// The data (its statistics must be the base's).
    pub data: &'a Dataset,
    /// The base bundle's folder.
    pub base: PathBuf,
    /// Settings.
    pub config: ControlTrainConfig,
    /// Output folder.
    pub out: PathBuf,
    /// A bundle whose `control.safetensors` (f16) starts a new run instead of the zero
    /// ControlNet: refitting a shipped ControlNet to a retrained base. Ignored when `out`
    /// holds a checkpoint to resume.
    pub init_from: Option<PathBuf>,
    /// Stop after this many steps now (None: until `config.steps`).
    pub max_steps_now: Option<usize>,
    /// Read between steps: when set, the run checkpoints and returns.
    pub interrupt: Interrupt,
    /// Device (without autodiff; the run adds it).
    pub device: Device,
    /// Called with `out` after each checkpoint's `val.csv` row (e.g. to plot it); an error
    /// is printed as a warning, never stops training.
    pub after_checkpoint: Option<super::CheckpointHook>,
}

struct ControlState {
    control: ControlNet,
    /// The EMA of `control`'s weights, on the plain device.
    ema: ControlNet,
    optim: ModuleOptimizer,
    state: TrainState,
}

fn new_optimizer(cfg: &ControlTrainConfig) -> ModuleOptimizer {
    AdamWConfig::new()
        .with_grad_clipping(Some(GradientClippingConfig::Norm(cfg.grad_clip as f32)))
        .init()
}

impl ControlTrainRun<'_> {
    /// Trains until `config.steps` (or `max_steps_now` more), resuming from `out/ckpt`.
    pub fn run(&self, progress: &dyn Fn(&TrainState, f32, f64)) -> Result<TrainState, TrainError> {
        let cfg = &self.config;
        cfg.check()
            .map_err(|e| TrainError::Invalid(format!("ControlNet config: {e}")))?;
        let plain = self.device.clone();
        let bundle = ModelBundle::load(&self.base, &plain).map_err(|e| file_err(&self.base, e))?;
        self.check_statistics(&bundle)?;
        let train: Vec<&ClipInfo> = self.data.clips(Split::Train).collect();
        if train.is_empty() {
            return Err(TrainError::Invalid(
                "the dataset has no training clips".into(),
            ));
        }
        let device = plain.clone().autodiff();
        let base = self.frozen_base(&bundle, &device)?;
        let text = match &bundle.text {
            PromptEncoder::Words(v) => TrainText::Words(v.clone()),
            PromptEncoder::Sentences(s) => {
                TrainText::sentences(s.encoder.clone(), s.captions.clone(), s.lengths.clone())
            }
        };
        let mut ck = self.load_or_init(&base, &device)?;
        let schedule = NoiseSchedule::cosine(DIFFUSION_STEPS);
        let batches = cfg.batches();
        let stop_at = self
            .max_steps_now
            .map_or(cfg.steps, |n| (ck.state.step + n).min(cfg.steps));
        let (mean, std) = (stat(&bundle.mean, &device), stat(&bundle.std, &device));
        let geometric = GeometricLosses::new(&batches, &self.data.mean, &self.data.std, &device);
        let (mut pending, mut sum, mut count) = (String::new(), 0.0f64, 0usize);
        let mut clock = Instant::now();
        let mut saved_at = ck.state.step;
        while ck.state.step < stop_at && !self.interrupt.is_requested() {
            let step = ck.state.step;
            let batch = draw_batch(self.data, &train, &batches, step);
            let mut rng = step_rng(cfg.seed ^ 0xC0_17_20_1E, step);
            let (input, x0, valid, hint) =
                hinted_question(&batch, &text, &schedule, (&mean, &std), &mut rng);
            let pred = Controlled {
                base: &base,
                control: &ck.control,
                hint,
                shared_guidance: false,
            }
            .predict_x0(&input);
            let loss = prediction_loss(pred, x0, valid, &batch.timesteps, &schedule, &geometric);
            let value = loss.clone().into_scalar::<f32>();
            if !value.is_finite() {
                return Err(TrainError::Diverged { step, loss: value });
            }
            let grads = GradientsParams::from_grads(loss.backward(), &ck.control);
            let warm = ((step + 1) as f64 / cfg.warmup_steps.max(1) as f64).min(1.0);
            let lr = cfg.learning_rate * warm;
            ck.control = ck.optim.step(lr, ck.control, grads);
            let decay = (cfg.ema_decay as f32).min((1 + step) as f32 / (10 + step) as f32);
            ck.ema = ema_update(ck.ema, &ck.control.valid(), decay);
            ck.state.step += 1;
            let now = Instant::now();
            ck.state.seconds += (now - clock).as_secs_f64();
            clock = now;
            (sum, count) = (sum + value as f64, count + 1);
            pending.push_str(&format!(
                "{},{value},{lr},{:.1}\n",
                ck.state.step, ck.state.seconds
            ));
            progress(&ck.state, value, lr);
            if ck.state.step % cfg.checkpoint_every == 0 || ck.state.step == stop_at {
                ck.state.recent_loss = sum / count.max(1) as f64;
                (sum, count) = (0.0, 0);
                append(
                    &self.out.join("loss.csv"),
                    "step,loss,lr,seconds\n",
                    &pending,
                )?;
                pending.clear();
                self.log_validation(&base, &ck, &text, &schedule, (&mean, &std))?;
                if let Some(hook) = self.after_checkpoint
                    && let Err(e) = hook(&self.out)
                {
                    eprintln!("warning: after the checkpoint: {e}");
                }
                self.save(&ck)?;
                saved_at = ck.state.step;
                clock = Instant::now();
            }
        }
        if ck.state.step > saved_at {
            ck.state.recent_loss = sum / count.max(1) as f64;
            append(
                &self.out.join("loss.csv"),
                "step,loss,lr,seconds\n",
                &pending,
            )?;
            self.save(&ck)?;
        }
        Ok(ck.state)
    }

    /// Mean distance (m) from the hinted joints of x̂0 to their targets on fixed
    /// validation crops and hints, with the ControlNet and with the base alone; None
    /// without validation clips.
    pub fn hint_errors(
        &self,
        base: &Mdm,
        control: &ControlNet,
        text: &TrainText,
        schedule: &NoiseSchedule,
        (mean, std): (&Tensor<3>, &Tensor<3>),
    ) -> Option<(f32, f32)> {
        let clips: Vec<&ClipInfo> = self.data.clips(Split::Val).collect();
        if clips.is_empty() {
            return None;
        }
        let mut cfg = self.config.batches();
        cfg.cond_drop = 0.0;
        cfg.word_drop = 0.0;
        // Evaluation mode: no dropout in either network.
        let (base, control) = (&base.clone().freeze(), &control.clone().freeze());
        let (mut steered, mut alone) = (0.0, 0.0);
        let rounds = 2;
        for r in 0..rounds {
            // Fixed "steps" far beyond any real step keep the crops, noise and hints fixed.
            let batch = draw_batch(self.data, &clips, &cfg, usize::MAX - r);
            let mut rng = step_rng(cfg.seed ^ 0x7A_11D, r);
            let (input, _, _, hint) =
                hinted_question(&batch, text, schedule, (mean, std), &mut rng);
            let error = |pred: Tensor<3>| {
                let joints = recover_from_ric_tensor(pred * std.clone() + mean.clone());
                hint_distance(joints, &hint)
            };
            steered += error(
                Controlled {
                    base,
                    control,
                    hint: hint.clone(),
                    shared_guidance: false,
                }
                .predict_x0(&input),
            );
            alone += error(base.predict_x0(&input));
        }
        Some((steered / rounds as f32, alone / rounds as f32))
    }

    fn log_validation(
        &self,
        base: &Mdm,
        ck: &ControlState,
        text: &TrainText,
        schedule: &NoiseSchedule,
        stats: (&Tensor<3>, &Tensor<3>),
    ) -> Result<(), TrainError> {
        // The EMA is measured where the base runs (the training device).
        let ema = ck.ema.clone().to_device(&stats.0.device());
        if let Some((steered, alone)) = self.hint_errors(base, &ema, text, schedule, stats) {
            append(
                &self.out.join("val.csv"),
                "step,hint_err_control,hint_err_base,seconds\n",
                &format!(
                    "{},{steered},{alone},{:.1}\n",
                    ck.state.step, ck.state.seconds
                ),
            )?;
        }
        Ok(())
    }

    /// The ControlNet learns to steer the base as it was trained: on data normalised with
    /// the base's own statistics.
    fn check_statistics(&self, bundle: &ModelBundle) -> Result<(), TrainError> {
        let differs = |a: &[f32], b: &[f32]| {
            a.len() != b.len() || a.iter().zip(b).any(|(x, y)| (x - y).abs() > 1e-4)
        };
        if differs(&self.data.mean, &bundle.mean) || differs(&self.data.std, &bundle.std) {
            return Err(TrainError::Invalid(format!(
                "the dataset's mean/std are not the ones {} was trained with: train the ControlNet on its base's training set",
                self.base.display()
            )));
        }
        Ok(())
    }

    /// The base on the training device, its weights excluded from the gradients.
    fn frozen_base(&self, bundle: &ModelBundle, device: &Device) -> Result<Mdm, TrainError> {
        let path = self.base.join("model.safetensors");
        let bytes = std::fs::read(&path).map_err(|e| file_err(&path, e))?;
        let vocab_size = bundle.text.vocab_size();
        let fresh = Mdm::new(&bundle.config, vocab_size, device);
        let base = model_from_safetensors(fresh, bytes, bundle.manifest.half_precision)
            .map_err(|e| file_err(&path, e))?;
        // No gradients; its dropout stays on, as OmniControl and InterControl train with
        // the whole model in train mode (their frozen MDM included).
        Ok(base.no_grad())
    }

    fn load_or_init(&self, base: &Mdm, device: &Device) -> Result<ControlState, TrainError> {
        let dir = self.out.join("ckpt");
        let state_path = dir.join("state.json");
        let plain = &self.device;
        if !state_path.exists() {
            let control = match &self.init_from {
                None => ControlNet::from_base(base, device),
                Some(from) => {
                    let control = ControlNet::load(from, base, true, device)
                        .map_err(|e| file_err(from, e))?
                        .ok_or_else(|| {
                            file_err(from, format!("no {CONTROL_FILE} to start from"))
                        })?;
                    self.record_origin(from)?;
                    control
                }
            };
            return Ok(ControlState {
                ema: control.valid().to_device(plain),
                control,
                optim: new_optimizer(&self.config),
                state: TrainState::default(),
            });
        }
        let text = std::fs::read_to_string(&state_path).map_err(|e| file_err(&state_path, e))?;
        let state: TrainState =
            serde_json::from_str(&text).map_err(|e| file_err(&state_path, e))?;
        let control = ControlNet::load(&dir, base, false, device)
            .map_err(|e| file_err(&dir, e))?
            .ok_or_else(|| file_err(&dir, format!("no {CONTROL_FILE}")))?;
        let optim_path = dir.join("optim.bpk");
        let optim = new_optimizer(&self.config)
            .load(&optim_path)
            .map_err(|e| file_err(&optim_path, format!("{e:?}")))?;
        let ema_dir = dir.join(EMA_DIR);
        let ema = match ControlNet::load(&ema_dir, base, false, device)
            .map_err(|e| file_err(&ema_dir, e))?
        {
            Some(ema) => ema.valid().to_device(plain),
            // A checkpoint from before the EMA: it starts at the weights.
            None => control.valid().to_device(plain),
        };
        Ok(ControlState {
            control,
            ema,
            optim,
            state,
        })
    }

    /// Keeps the id of the ControlNet a refit starts from (`<out>/origin.txt`), so that the
    /// refit's bundles are named after it across resumes.
    fn record_origin(&self, from: &Path) -> Result<(), TrainError> {
        let origin = Manifest::read(&from.join("manifest.json"))?
            .control_id
            .unwrap_or_else(|| "controlnet".into());
        std::fs::create_dir_all(&self.out).map_err(|e| file_err(&self.out, e))?;
        let dst = self.out.join(ORIGIN_FILE);
        write_bytes_atomic(&dst, origin.as_bytes()).map_err(|e| file_err(&dst, e))
    }

    fn save(&self, ck: &ControlState) -> Result<(), TrainError> {
        let new = self.out.join("ckpt.new");
        if new.exists() {
            std::fs::remove_dir_all(&new).map_err(|e| file_err(&new, e))?;
        }
        std::fs::create_dir_all(&new).map_err(|e| file_err(&new, e))?;
        ck.control
            .save(&new, false)
            .map_err(|e| file_err(&new, e))?;
        let ema_dir = new.join(EMA_DIR);
        std::fs::create_dir_all(&ema_dir).map_err(|e| file_err(&ema_dir, e))?;
        ck.ema
            .save(&ema_dir, false)
            .map_err(|e| file_err(&ema_dir, e))?;
        let p = new.join("optim.bpk");
        let bytes = ck
            .optim
            .into_bytes()
            .map_err(|e| file_err(&p, format!("{e:?}")))?;
        write_bytes_atomic(&p, &bytes).map_err(|e| file_err(&p, e))?;
        let p = new.join("state.json");
        let json = serde_json::to_string_pretty(&ck.state).expect("state serialises");
        write_bytes_atomic(&p, json.as_bytes()).map_err(|e| file_err(&p, e))?;
        swap_in(&self.out, &new)?;
        // The shippable bundle: the base's files with the ControlNet's EMA beside them.
        let bundle = self.out.join("bundle");
        std::fs::create_dir_all(&bundle).map_err(|e| file_err(&bundle, e))?;
        copy_bundle_files(&self.base, &bundle)?;
        ck.ema
            .save(&bundle, true)
            .map_err(|e| file_err(&bundle, e))?;
        let origin = self.out.join(ORIGIN_FILE);
        let origin = if origin.exists() {
            Some(std::fs::read_to_string(&origin).map_err(|e| file_err(&origin, e))?)
        } else {
            None
        };
        name_control(&bundle, origin.as_deref(), ck.state.step)
    }
}

/// A batch as the ControlNet is asked it: the noised input, the clean motion, the valid
/// mask, and a training hint from the clean joints.
fn hinted_question(
    batch: &HostBatch,
    text: &TrainText,
    schedule: &NoiseSchedule,
    (mean, std): (&Tensor<3>, &Tensor<3>),
    rng: &mut impl Rng,
) -> (DenoiserInput, Tensor<3>, Tensor<3>, Hint) {
    let (mut input, x0, valid) = to_device(batch, text, &mean.device());
    let joints = recover_from_ric_tensor(x0.clone() * std.clone() + mean.clone());
    let hint = training_hint(joints, &valid_lengths(batch), rng);
    input.x_t = q_sample(schedule, x0.clone(), &batch.timesteps, batch.noise_seed);
    (input, x0, valid, hint)
}

/// Valid (not padding) frames of each clip of a batch.
fn valid_lengths(batch: &HostBatch) -> Vec<usize> {
    batch
        .padding
        .chunks(batch.frames)
        .map(|p| p.iter().filter(|&&pad| !pad).count())
        .collect()
}

/// Mean distance (m) between the joints `[B, N, 22, 3]` and the hint's targets, over the
/// hint's controlled joint-frames.
pub fn hint_distance(joints: Tensor<4>, hint: &Hint) -> f32 {
    let [b, n, j, _] = joints.dims();
    let values = hint.values.clone();
    let targets = values.clone().narrow(2, 0, j * 3).reshape([b, n, j, 3]);
    let mask = values.narrow(2, j * 3, j);
    let dist = (joints - targets)
        .powi_scalar(2)
        .sum_dim(3)
        .sqrt()
        .reshape([b, n, j]);
    let hinted = mask.clone().sum().into_scalar::<f32>();
    (dist * mask).sum().into_scalar::<f32>() / hinted.max(1.0)
}

fn stat(v: &[f32], device: &Device) -> Tensor<3> {
    Tensor::from_data(TensorData::new(v.to_vec(), [1, 1, v.len()]), device)
}

/// Where a refit keeps the id of the ControlNet it started from.
const ORIGIN_FILE: &str = "origin.txt";

/// Names the ControlNet in the bundle's manifest (`control_id`): outputs record it beside
/// the base's weights id. A refit is named after the ControlNet it started from.
fn name_control(bundle: &Path, origin: Option<&str>, step: usize) -> Result<(), TrainError> {
    let path = bundle.join("manifest.json");
    let mut manifest = Manifest::read(&path)?;
    manifest.control_id = Some(match origin {
        Some(origin) => format!("{}-refit-ema-step{step}", origin.trim()),
        None => format!("controlnet-ema-step{step}"),
    });
    let json = serde_json::to_string_pretty(&manifest).expect("manifest serialises");
    write_bytes_atomic(&path, json.as_bytes()).map_err(|e| file_err(&path, e))
}

/// Copies every file of a bundle folder (not its subfolders, not a ControlNet) to `to`.
fn copy_bundle_files(from: &Path, to: &Path) -> Result<(), TrainError> {
    let entries = std::fs::read_dir(from).map_err(|e| file_err(from, e))?;
    for entry in entries {
        let entry = entry.map_err(|e| file_err(from, e))?;
        let path = entry.path();
        let name = entry.file_name();
        if !path.is_file() || name == CONTROL_FILE {
            continue;
        }
        let bytes = std::fs::read(&path).map_err(|e| file_err(&path, e))?;
        let dst = to.join(&name);
        write_bytes_atomic(&dst, &bytes).map_err(|e| file_err(&dst, e))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::tests::{synthetic_dataset, tiny};
    use crate::model::train::TrainRun;

    #[test]
    fn training_hints_control_one_listed_joint_on_some_valid_frames() {
        let dev = Device::flex();
        let joints = crate::model::noise::NoiseSource::new(1).tensor([3, 10, NUM_JOINTS, 3], &dev);
        let mut rng = step_rng(4, 0);
        let hint = training_hint(joints, &[10, 6, 1], &mut rng);
        let v = hint.values.into_data().try_to_vec::<f32>().unwrap();
        for (i, len) in [10usize, 6, 1].into_iter().enumerate() {
            let mut frames = 0;
            let mut joints_seen = std::collections::BTreeSet::new();
            for f in 0..10 {
                let row = &v[(i * 10 + f) * 88..][..88];
                for (j, &m) in row[66..].iter().enumerate() {
                    if m == 1.0 {
                        assert!(f < len, "sample {i}: frame {f} is padding");
                        joints_seen.insert(j);
                        frames += 1;
                    } else {
                        assert_eq!(m, 0.0);
                        assert_eq!(&row[3 * j..3 * j + 3], &[0.0; 3], "free joints are zero");
                    }
                }
            }
            assert_eq!(joints_seen.len(), 1, "{joints_seen:?}");
            assert!(HINT_JOINTS.contains(joints_seen.first().unwrap()));
            assert!(
                frames >= 1 && frames <= len.saturating_sub(1).max(1),
                "{frames} of {len}"
            );
        }
    }

    /// A tiny base model trained `steps` steps on `data`; its bundle is `<dir>/bundle`.
    fn train_tiny_base(data: &Dataset, steps: usize, warmup_steps: usize) -> tempfile::TempDir {
        let base_run = tempfile::tempdir().unwrap();
        TrainRun {
            data,
            config: TrainConfig {
                model: tiny(),
                batch_size: 2,
                crop_frames: 8,
                warmup_steps,
                checkpoint_every: steps,
                steps,
                ..TrainConfig::default()
            },
            out: base_run.path().to_path_buf(),
            max_steps_now: None,
            interrupt: Default::default(),
            init_from: None,
            device: Device::flex(),
            after_checkpoint: None,
            text_encoder: None,
        }
        .run(&|_, _, _| {})
        .unwrap();
        base_run
    }

    /// Every float parameter of a module, in visiting order.
    fn values<M: Module>(m: &M) -> Vec<f32> {
        struct Collect(Vec<f32>);
        impl burn::module::ModuleVisitor for Collect {
            fn visit_float<const D: usize>(&mut self, param: &burn::module::Param<Tensor<D>>) {
                let t = param.val();
                self.0
                    .extend(t.into_data().convert::<f32>().try_to_vec::<f32>().unwrap());
            }
        }
        let mut c = Collect(Vec::new());
        m.visit(&mut c);
        c.0
    }

    #[test]
    fn a_control_net_trains_on_a_frozen_base_and_resumes() {
        let data = synthetic_dataset();
        let base_run = train_tiny_base(&data, 5, 1);
        let base = base_run.path().join("bundle");
        let before = std::fs::read(base.join("model.safetensors")).unwrap();
        let out = tempfile::tempdir().unwrap();
        let run = |steps| ControlTrainRun {
            data: &data,
            base: base.clone(),
            config: ControlTrainConfig {
                batch_size: 2,
                crop_frames: 8,
                learning_rate: 1e-3,
                warmup_steps: 1,
                checkpoint_every: 4,
                steps: 100,
                foot_loss: 0.01,
                velocity_loss: 0.01,
                bone_loss: 0.01,
                ..ControlTrainConfig::default()
            },
            out: out.path().to_path_buf(),
            init_from: None,
            max_steps_now: Some(steps),
            interrupt: Default::default(),
            device: Device::flex(),
            after_checkpoint: Some(|out: &Path| {
                // Each checkpoint's hook sees its val.csv row.
                let rows =
                    std::fs::read_to_string(out.join("val.csv")).map_err(|e| e.to_string())?;
                let mut seen = std::fs::read_to_string(out.join("hooked")).unwrap_or_default();
                seen.push_str(&format!("{}\n", rows.lines().count() - 1));
                std::fs::write(out.join("hooked"), seen).map_err(|e| e.to_string())
            }),
        };
        assert_eq!(run(6).run(&|_, _, _| {}).unwrap().step, 6);
        assert_eq!(run(4).run(&|_, _, _| {}).unwrap().step, 10, "resumed");
        let csv = std::fs::read_to_string(out.path().join("loss.csv")).unwrap();
        assert_eq!(csv.lines().count(), 1 + 10);
        // Every checkpoint (steps 4, 6, 8, 10) measured the hint error, steered and not.
        let val = std::fs::read_to_string(out.path().join("val.csv")).unwrap();
        let rows: Vec<Vec<f32>> = val
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect();
        assert_eq!(
            rows.iter().map(|r| r[0] as usize).collect::<Vec<_>>(),
            [4, 6, 8, 10]
        );
        for r in &rows {
            assert!(
                r[1].is_finite() && r[1] > 0.0 && r[2].is_finite() && r[2] > 0.0,
                "{r:?}"
            );
            assert_eq!(
                r[2], rows[0][2],
                "the base alone sees the same crops every time"
            );
        }
        // The base is untouched; the exported bundle is the base plus a ControlNet that
        // has learned something (its zero layers moved).
        assert_eq!(
            std::fs::read(base.join("model.safetensors")).unwrap(),
            before
        );
        let dev = Device::flex();
        let bundle = ModelBundle::load(&out.path().join("bundle"), &dev).unwrap();
        // Outputs name the ControlNet beside the base's weights id.
        let id = bundle.manifest.control_id.clone().unwrap_or_default();
        assert!(id.starts_with("controlnet-ema-step"), "control id {id:?}");
        let control = ControlNet::load(&out.path().join("bundle"), &bundle.model, true, &dev)
            .unwrap()
            .expect("the bundle has its ControlNet");
        let fresh = ControlNet::from_base(&bundle.model, &dev);
        let bytes = |c: &ControlNet| crate::model::weights::module_to_safetensors(c, true).unwrap();
        assert_ne!(bytes(&control), bytes(&fresh));
        // The bundle ships the EMA of the weights, not the last weights.
        let ckpt = out.path().join("ckpt");
        let ema = ControlNet::load(&ckpt.join(EMA_DIR), &bundle.model, false, &dev)
            .unwrap()
            .expect("the checkpoint has the EMA");
        let last = ControlNet::load(&ckpt, &bundle.model, false, &dev)
            .unwrap()
            .expect("the checkpoint has the weights");
        // Safetensors headers list tensors in no fixed order: compare the values.
        let bundled = ControlNet::load(&out.path().join("bundle"), &bundle.model, true, &dev)
            .unwrap()
            .unwrap();
        let (b, e, l) = (values(&bundled), values(&ema), values(&last));
        let largest = |x: &[f32], y: &[f32]| {
            x.iter()
                .zip(y)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0f32, f32::max)
        };
        // f16 rounding of weights of at most a few units.
        assert!(largest(&b, &e) < 5e-3, "the bundle holds the EMA");
        assert!(largest(&b, &l) > largest(&b, &e), "not the last weights");
        // A checkpoint from before the EMA resumes, its EMA started at its weights.
        std::fs::remove_dir_all(ckpt.join(EMA_DIR)).unwrap();
        assert_eq!(run(2).run(&|_, _, _| {}).unwrap().step, 12);
        assert!(ckpt.join(EMA_DIR).join(CONTROL_FILE).exists());
    }

    #[test]
    fn a_config_without_the_geometric_terms_reads_as_the_mse_alone() {
        // Run folders written before the terms existed resume unchanged.
        let old = "batch_size = 32\ncrop_frames = 120\nlearning_rate = 0.0001\nwarmup_steps = 200\n\
                   grad_clip = 1.0\ncond_drop = 0.1\nsteps = 100000\ncheckpoint_every = 100\nseed = 11\n";
        let cfg: ControlTrainConfig = toml::from_str(old).unwrap();
        assert_eq!(cfg, ControlTrainConfig::default());
        let g = GeometricLosses::new(&cfg.batches(), &[0.0; 263], &[1.0; 263], &Device::flex());
        assert!(g.foot.is_none() && g.velocity.is_none() && g.bones.is_none());
        let weighed = ControlTrainConfig {
            foot_loss: 0.01,
            bone_loss: 0.02,
            ..cfg
        };
        let g = GeometricLosses::new(
            &weighed.batches(),
            &[0.0; 263],
            &[1.0; 263],
            &Device::flex(),
        );
        assert_eq!(g.foot.map(|f| f.weight), Some(0.01));
        assert!(g.velocity.is_none());
        assert_eq!(g.bones.map(|b| b.weight), Some(0.02));
        let bad = ControlTrainConfig {
            foot_loss: -1.0,
            ..ControlTrainConfig::default()
        };
        assert!(bad.check().is_err(), "a negative weight is refused");
    }

    #[test]
    fn hint_distance_is_measured_on_the_hinted_joint_frames_only() {
        let dev = Device::flex();
        let targets = crate::model::noise::NoiseSource::new(2).tensor([2, 4, NUM_JOINTS, 3], &dev);
        let mut mask = vec![0.0f32; 2 * 4 * NUM_JOINTS];
        mask[NUM_JOINTS + 10] = 1.0; // sample 0, frame 1, left foot
        mask[(4 + 3) * NUM_JOINTS + 20] = 1.0; // sample 1, frame 3, left wrist
        let hint = Hint::new(
            targets.clone(),
            Tensor::from_data(TensorData::new(mask, [2, 4, NUM_JOINTS]), &dev),
        );
        assert!(hint_distance(targets.clone(), &hint) < 1e-6);
        // Every joint 3-4-0 cm off (5 cm): the hinted two count, the rest do not matter.
        let shift = Tensor::<1>::from_floats([0.03, 0.04, 0.0], &dev).reshape([1, 1, 1, 3]);
        let d = hint_distance(targets + shift, &hint);
        assert!((d - 0.05).abs() < 1e-5, "{d}");
    }

    #[test]
    fn a_fresh_control_net_leaves_the_hint_error_of_the_base() {
        let data = synthetic_dataset();
        let base_run = train_tiny_base(&data, 2, 1);
        let dir = base_run.path().join("bundle");
        let dev = Device::flex();
        let bundle = ModelBundle::load(&dir, &dev).unwrap();
        let run = ControlTrainRun {
            data: &data,
            base: dir,
            config: ControlTrainConfig {
                batch_size: 2,
                crop_frames: 8,
                ..ControlTrainConfig::default()
            },
            out: base_run.path().join("control"),
            init_from: None,
            max_steps_now: Some(1),
            interrupt: Default::default(),
            device: dev.clone(),
            after_checkpoint: None,
        };
        let text = match &bundle.text {
            PromptEncoder::Words(v) => TrainText::Words(v.clone()),
            PromptEncoder::Sentences(_) => unreachable!("the tiny base reads words"),
        };
        let (mean, std) = (stat(&bundle.mean, &dev), stat(&bundle.std, &dev));
        let fresh = ControlNet::from_base(&bundle.model, &dev);
        let schedule = NoiseSchedule::cosine(DIFFUSION_STEPS);
        let (steered, alone) = run
            .hint_errors(&bundle.model, &fresh, &text, &schedule, (&mean, &std))
            .unwrap();
        assert!(alone > 0.0);
        assert_eq!(steered, alone);
    }

    #[test]
    fn a_control_net_is_refused_data_with_other_statistics() {
        let mut data = synthetic_dataset();
        let base_run = train_tiny_base(&data, 2, TrainConfig::default().warmup_steps);
        data.std[5] = 2.0;
        let out = tempfile::tempdir().unwrap();
        let err = ControlTrainRun {
            data: &data,
            base: base_run.path().join("bundle"),
            config: ControlTrainConfig::default(),
            out: out.path().to_path_buf(),
            init_from: None,
            max_steps_now: Some(1),
            interrupt: Default::default(),
            device: Device::flex(),
            after_checkpoint: None,
        }
        .run(&|_, _, _| {})
        .unwrap_err();
        assert!(err.to_string().contains("mean/std"), "{err}");
    }

    #[test]
    fn a_control_net_starts_from_another_bundles_control_net() {
        let data = synthetic_dataset();
        let base_run = train_tiny_base(&data, 2, 1);
        let base = base_run.path().join("bundle");
        let config = ControlTrainConfig {
            batch_size: 2,
            crop_frames: 8,
            learning_rate: 1e-3,
            warmup_steps: 1,
            checkpoint_every: 100,
            steps: 100,
            ..ControlTrainConfig::default()
        };
        let (first, second) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
        let run = |out: &Path, init_from: Option<PathBuf>, learning_rate: f64| ControlTrainRun {
            data: &data,
            base: base.clone(),
            config: ControlTrainConfig {
                learning_rate,
                ..config.clone()
            },
            out: out.to_path_buf(),
            init_from,
            max_steps_now: Some(3),
            interrupt: Default::default(),
            device: Device::flex(),
            after_checkpoint: None,
        };
        run(first.path(), None, 1e-3).run(&|_, _, _| {}).unwrap();
        let shipped = first.path().join("bundle");
        // A base bundle without a ControlNet cannot start one: refused, the file named.
        let err = run(second.path(), Some(base.clone()), 1e-9)
            .run(&|_, _, _| {})
            .unwrap_err();
        assert!(err.to_string().contains(CONTROL_FILE), "{err}");
        // With a negligible step size the refit run keeps the shipped (f16) ControlNet.
        run(second.path(), Some(shipped.clone()), 1e-9)
            .run(&|_, _, _| {})
            .unwrap();
        let dev = Device::flex();
        let bundle = ModelBundle::load(&base, &dev).unwrap();
        let load = |dir: &Path, half| {
            ControlNet::load(dir, &bundle.model, half, &dev)
                .unwrap()
                .unwrap()
        };
        let first_id = ModelBundle::load(&shipped, &dev)
            .unwrap()
            .manifest
            .control_id;
        let refit_id = ModelBundle::load(&second.path().join("bundle"), &dev)
            .unwrap()
            .manifest
            .control_id;
        assert_eq!(first_id.as_deref(), Some("controlnet-ema-step3"));
        assert_eq!(
            refit_id.as_deref(),
            Some("controlnet-ema-step3-refit-ema-step3")
        );
        let started = values(&load(&shipped, true));
        let refit = values(&load(&second.path().join("ckpt"), false));
        let gap = |a: &[f32], b: &[f32]| {
            assert_eq!(a.len(), b.len());
            a.iter()
                .zip(b)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f32::max)
        };
        assert!(gap(&refit, &started) < 1e-6, "{}", gap(&refit, &started));
        let fresh = values(&ControlNet::from_base(&bundle.model, &dev));
        assert!(
            gap(&started, &fresh) > 1e-4,
            "the first run moved its ControlNet"
        );
    }
}
