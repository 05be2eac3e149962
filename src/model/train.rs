//! The training loop: masked x0-MSE on random crops, AdamW with warm-up and gradient
//! clipping, EMA weights, periodic atomic checkpoints, resume, loss curves.
//!
//! ```text
//! <out>/config.toml        the run's TrainConfig (fixed at the first start)
//! <out>/vocab.json         the run's vocabulary (fixed at the first start)
//! <out>/ckpt/state.json    step, wall seconds, last losses
//! <out>/ckpt/model.bpk     training weights (burnpack, keeps parameter ids)
//! <out>/ckpt/optim.bpk     AdamW state
//! <out>/ckpt/ema.safetensors  EMA weights, f32
//! <out>/bundle/            the EMA weights as a shippable model bundle (f16)
//! <out>/loss.csv           step, train loss, learning rate, seconds
//! <out>/val.csv            step, validation loss of the EMA weights
//! <out>/loss.png           both curves (plotted by the CLI after every checkpoint)
//! ```
//!
//! A checkpoint is written whole into `ckpt.new/` and then swapped in by renames, so a
//! kill at any moment leaves either the old or the new checkpoint complete.

use super::batch::{HostBatch, draw_batch};
use super::config::{ModelConfig, TrainConfig};
use super::denoiser::{Denoiser, DenoiserInput, Mdm};
use super::ema::ema_update;
use super::noise::NoiseSource;
use super::schedule::{DIFFUSION_STEPS, NoiseSchedule};
use super::text::{TokenBatch, Vocabulary};
use super::weights::{
    BUNDLE_VERSION, Manifest, ModelBundle, model_from_safetensors, model_to_safetensors,
    save_bundle_parts,
};
use crate::dataset::{ClipInfo, Dataset, FEATURE_DIM, Split};
use crate::features::layout::{CONTACT, RIC, ROOT_Y, ROOT_YAW_VEL};
use crate::features::recover_from_ric_tensor;
use crate::fsutil::write_bytes_atomic;
use crate::interrupt::Interrupt;
use crate::skeleton::{FOOT_LEFT, FOOT_RIGHT};
use burn::module::Module;
use burn::optim::{
    AdamWConfig, GradientsParams, ModuleOptimizer, grad_clipping::GradientClippingConfig,
};
use burn::prelude::*;
use burn::store::ModuleRecord;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Progress saved with every checkpoint.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct TrainState {
    /// Steps done.
    pub step: usize,
    /// Wall seconds over all sessions.
    pub seconds: f64,
    /// Mean training loss over the last checkpoint interval.
    pub recent_loss: f64,
    /// Validation loss of the EMA weights at the last checkpoint.
    pub val_loss: Option<f64>,
    /// Step at which this run's optimizer started (a run begun `--init-from` a bundle
    /// restarts AdamW at the bundle's step); the warm-up counts from here.
    #[serde(default)]
    pub optimizer_started_at: usize,
}

/// Errors of a training run.
#[derive(Debug, thiserror::Error)]
pub enum TrainError {
    /// Reading or writing a run file failed.
    #[error("{path}: {reason}")]
    File {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// The loss became NaN or infinite.
    #[error(
        "training diverged at step {step}: loss is {loss}; the last checkpoint is intact, lower the learning rate and resume"
    )]
    Diverged {
        /// Step.
        step: usize,
        /// Value.
        loss: f32,
    },
    /// The run's settings do not allow training.
    #[error("{0}")]
    Invalid(String),
}

fn file_err(path: &Path, e: impl std::fmt::Display) -> TrainError {
    TrainError::File {
        path: path.to_path_buf(),
        reason: e.to_string(),
    }
}

/// A batch moved to tensors.
fn to_device(
    batch: &HostBatch,
    vocab: &Vocabulary,
    device: &Device,
) -> (DenoiserInput, Tensor<3>, Tensor<3>) {
    let b = batch.captions.len();
    let n = batch.frames;
    let x0: Tensor<3> = Tensor::from_data(
        TensorData::new(batch.x0.clone(), [b, n, FEATURE_DIM]),
        device,
    );
    let valid: Vec<f32> = batch
        .padding
        .iter()
        .map(|&p| if p { 0.0 } else { 1.0 })
        .collect();
    let valid: Tensor<3> = Tensor::from_data(TensorData::new(valid, [b, n, 1]), device);
    let captions: Vec<&str> = batch.captions.iter().map(String::as_str).collect();
    let input = DenoiserInput {
        x_t: x0.clone(),
        timesteps: batch.timesteps.clone(),
        tokens: TokenBatch::new(vocab, &captions, device),
        keep_text: Tensor::from_data(TensorData::new(batch.keep_text.clone(), [b]), device),
        padding: Some(Tensor::from_data(
            TensorData::new(batch.padding.clone(), [b, n]),
            device,
        )),
    };
    (input, x0, valid)
}

/// Noises x0 to each sample's timestep: x_t = √ᾱ x0 + √(1−ᾱ) ε.
fn q_sample(schedule: &NoiseSchedule, x0: Tensor<3>, timesteps: &[usize], seed: u64) -> Tensor<3> {
    let device = x0.device();
    let dims = x0.dims();
    let (a, s): (Vec<f32>, Vec<f32>) = timesteps
        .iter()
        .map(|&t| {
            let ab = schedule.alphas_cumprod[t];
            (ab.sqrt() as f32, (1.0 - ab).sqrt() as f32)
        })
        .unzip();
    let b = timesteps.len();
    let a: Tensor<3> = Tensor::from_data(TensorData::new(a, [b, 1, 1]), &device);
    let s: Tensor<3> = Tensor::from_data(TensorData::new(s, [b, 1, 1]), &device);
    let eps = NoiseSource::new(seed).tensor(dims, &device);
    x0 * a + eps * s
}

/// Masked x0 MSE: Σ over valid frames and features / (#valid frames · F).
pub fn masked_mse(pred: Tensor<3>, x0: Tensor<3>, valid: Tensor<3>) -> Tensor<1> {
    let f = pred.dims()[2] as f32;
    let err = (pred - x0).powi_scalar(2) * valid.clone();
    err.sum() / (valid.sum() * f)
}

/// Masked x0 MSE of the root columns alone (yaw velocity, XZ velocity, height).
pub fn root_mse(pred: Tensor<3>, x0: Tensor<3>, valid: Tensor<3>) -> Tensor<1> {
    let root = ROOT_YAW_VEL.start..ROOT_Y.end;
    let cols = |t: Tensor<3>| t.narrow(2, root.start, root.len());
    masked_mse(cols(pred), cols(x0), valid)
}

/// Foot-contact loss (MDM's L_foot): the squared per-frame displacement, in cm², of each
/// foot joint (ankles and toes) of the predicted motion on the frame pairs where the
/// data's contact label says that joint is planted, averaged over those pairs.
pub struct FootLoss {
    /// Weight of the term in the training loss.
    pub weight: f32,
    /// `[1, 1, 263]` feature mean, to de-normalise predictions.
    pub mean: Tensor<3>,
    /// `[1, 1, 263]` feature std.
    pub std: Tensor<3>,
}

impl FootLoss {
    /// The loss for a dataset's statistics, or None when `weight` is 0.
    pub fn new(weight: f64, mean: &[f32], std: &[f32], device: &Device) -> Option<Self> {
        let stat =
            |v: &[f32]| Tensor::from_data(TensorData::new(v.to_vec(), [1, 1, v.len()]), device);
        (weight > 0.0).then(|| FootLoss {
            weight: weight as f32,
            mean: stat(mean),
            std: stat(std),
        })
    }

    /// The term for normalised prediction and target `[B, N, 263]`, `valid` `[B, N, 1]`.
    pub fn term(&self, pred: Tensor<3>, x0: Tensor<3>, valid: Tensor<3>) -> Tensor<1> {
        let [b, n, _] = pred.dims();
        if n < 2 {
            return Tensor::zeros([1], &pred.device());
        }
        let device = pred.device();
        let joints = recover_from_ric_tensor(pred * self.std.clone() + self.mean.clone());
        let feet: Vec<i64> = FOOT_LEFT
            .iter()
            .chain(FOOT_RIGHT.iter())
            .map(|&j| j as i64)
            .collect();
        let feet = joints.select(2, Tensor::from_data(TensorData::new(feet, [4]), &device)); // [B, N, 4, 3]
        let step = (feet.clone().narrow(1, 1, n - 1) - feet.narrow(1, 0, n - 1)).mul_scalar(100.0);
        let slide = step.powi_scalar(2).sum_dim(3).reshape([b, n - 1, 4]);
        let c = CONTACT.start;
        let label = x0.narrow(2, c, 4) * self.std.clone().narrow(2, c, 4)
            + self.mean.clone().narrow(2, c, 4);
        let both_valid = valid.clone().narrow(1, 0, n - 1) * valid.narrow(1, 1, n - 1);
        let planted = label.narrow(1, 0, n - 1).greater_elem(0.5).float() * both_valid;
        (slide * planted.clone()).sum() / (planted.sum() + 1.0)
    }
}

/// Velocity loss (MDM's L_vel) on the joint positions the features store (root height and
/// the 21 root-relative joints): the squared error, in cm² per joint, of the predicted
/// per-frame displacement against the data's, averaged over valid frame pairs. The x0 MSE
/// treats every frame alone, so an undertrained model's errors are independent from frame
/// to frame and show as jitter; this term penalises exactly that high-frequency part.
pub struct VelocityLoss {
    /// Weight of the term in the training loss.
    pub weight: f32,
    /// `[1, 1, 64]` feature std of the position block, to de-normalise the error (the
    /// mean cancels in a difference).
    pub std: Tensor<3>,
}

/// The feature columns the velocity loss reads: root height then the 21 joints' x, y, z.
const POSITION_COLUMNS: std::ops::Range<usize> = ROOT_Y.start..RIC.end;

impl VelocityLoss {
    /// The loss for a dataset's statistics, or None when `weight` is 0.
    pub fn new(weight: f64, std: &[f32], device: &Device) -> Option<Self> {
        let cols = std[POSITION_COLUMNS].to_vec();
        let len = cols.len();
        (weight > 0.0).then(|| VelocityLoss {
            weight: weight as f32,
            std: Tensor::from_data(TensorData::new(cols, [1, 1, len]), device),
        })
    }

    /// The term for normalised prediction and target `[B, N, 263]`, `valid` `[B, N, 1]`.
    pub fn term(&self, pred: Tensor<3>, x0: Tensor<3>, valid: Tensor<3>) -> Tensor<1> {
        let n = pred.dims()[1];
        if n < 2 {
            return Tensor::zeros([1], &pred.device());
        }
        let cols = POSITION_COLUMNS;
        let err = (pred.narrow(2, cols.start, cols.len()) - x0.narrow(2, cols.start, cols.len()))
            * self.std.clone()
            * 100.0;
        let step = err.clone().narrow(1, 1, n - 1) - err.narrow(1, 0, n - 1);
        let both_valid = valid.clone().narrow(1, 0, n - 1) * valid.narrow(1, 1, n - 1);
        // Sum over the columns / 3 = squared displacement error per joint (root height
        // counts as a third of a joint).
        let per_pair =
            step.powi_scalar(2).sum_dim(2) * both_valid.clone() / (cols.len() as f32 / 3.0);
        per_pair.sum() / (both_valid.sum() + 1.0)
    }
}

/// The geometric terms added to the x0 MSE in training (each None when its weight is 0).
#[derive(Default)]
pub struct GeometricLosses {
    /// MDM's foot-contact term.
    pub foot: Option<FootLoss>,
    /// MDM's velocity term.
    pub velocity: Option<VelocityLoss>,
    /// Weight of the extra root-column MSE (None when 0).
    pub root: Option<f32>,
}

impl GeometricLosses {
    /// The terms a training config asks for, with the dataset's statistics.
    pub fn new(cfg: &TrainConfig, mean: &[f32], std: &[f32], device: &Device) -> Self {
        GeometricLosses {
            foot: FootLoss::new(cfg.foot_loss, mean, std, device),
            velocity: VelocityLoss::new(cfg.velocity_loss, std, device),
            root: (cfg.root_loss > 0.0).then_some(cfg.root_loss as f32),
        }
    }
}

/// Loss of one batch: the x0 MSE plus the geometric terms that are on.
fn batch_loss(
    model: &Mdm,
    schedule: &NoiseSchedule,
    batch: &HostBatch,
    vocab: &Vocabulary,
    geometric: &GeometricLosses,
    device: &Device,
) -> Tensor<1> {
    let (mut input, x0, valid) = to_device(batch, vocab, device);
    input.x_t = q_sample(schedule, x0.clone(), &batch.timesteps, batch.noise_seed);
    let pred = model.predict_x0(&input);
    let mut loss = masked_mse(pred.clone(), x0.clone(), valid.clone());
    if let Some(f) = &geometric.foot {
        loss = loss
            + f.term(pred.clone(), x0.clone(), valid.clone())
                .mul_scalar(f.weight);
    }
    if let Some(v) = &geometric.velocity {
        loss = loss
            + v.term(pred.clone(), x0.clone(), valid.clone())
                .mul_scalar(v.weight);
    }
    if let Some(w) = geometric.root {
        loss = loss + root_mse(pred, x0, valid).mul_scalar(w);
    }
    loss
}

/// Run with the output folder after each checkpoint; an error is reported, not fatal.
pub type CheckpointHook = fn(&Path) -> Result<(), String>;

/// Everything a run needs besides the model.
pub struct TrainRun<'a> {
    /// The data.
    pub data: &'a Dataset,
    /// Settings.
    pub config: TrainConfig,
    /// Output folder.
    pub out: PathBuf,
    /// Stop after this many steps in this session (None = until `config.steps`).
    pub max_steps_now: Option<usize>,
    /// Read between steps: when set, the run saves a checkpoint and returns.
    pub interrupt: Interrupt,
    /// A model bundle to start from when `out` has no checkpoint yet (e.g. the shipped
    /// weights, when a run's checkpoints were lost): its weights seed both the model and
    /// the EMA, its vocabulary is kept, and its step count carries on; AdamW starts fresh.
    pub init_from: Option<PathBuf>,
    /// The device to train on (without autodiff; the run adds it).
    pub device: Device,
    /// Called with the output folder after every checkpoint (the CLI plots `loss.png`).
    pub after_checkpoint: Option<CheckpointHook>,
}

struct Checkpoint {
    model: Mdm,
    ema: Mdm,
    optim: ModuleOptimizer,
    state: TrainState,
}

/// Linear warm-up over the first `warmup_steps` of the optimizer's life: a restarted
/// AdamW's first updates are ±lr on every weight (its moment estimates are one gradient
/// old), which at full rate shakes a trained model.
fn learning_rate(cfg: &TrainConfig, state: &TrainState) -> f64 {
    let since_start = state.step.saturating_sub(state.optimizer_started_at);
    cfg.learning_rate * ((since_start + 1) as f64 / cfg.warmup_steps.max(1) as f64).min(1.0)
}

fn new_optimizer(cfg: &TrainConfig) -> ModuleOptimizer {
    AdamWConfig::new()
        .with_weight_decay(cfg.weight_decay as f32)
        .with_grad_clipping(Some(GradientClippingConfig::Norm(cfg.grad_clip as f32)))
        .init()
}

impl TrainRun<'_> {
    fn ckpt(&self) -> PathBuf {
        self.out.join("ckpt")
    }

    /// The complete checkpoint to resume from: `ckpt/`, or `ckpt.old/` when a kill hit
    /// the swap between the two renames.
    fn existing_checkpoint(&self) -> Option<PathBuf> {
        ["ckpt", "ckpt.old"]
            .iter()
            .map(|d| self.out.join(d))
            .find(|d| d.join("state.json").exists())
    }

    fn load_or_init(
        &self,
        vocab: &Vocabulary,
        train_dev: &Device,
        plain: &Device,
    ) -> Result<Checkpoint, TrainError> {
        let cfg = &self.config;
        let Some(dir) = self.existing_checkpoint() else {
            if let Some(init) = &self.init_from {
                let bundle = ModelBundle::load(init, plain).map_err(|e| file_err(init, e))?;
                // A bundle without the input skip may start a run with it (added at zero);
                // one with a learned skip cannot start a run without it.
                let add_skip = cfg.model.input_skip && !bundle.config.input_skip;
                let as_run = ModelConfig {
                    input_skip: bundle.config.input_skip || cfg.model.input_skip,
                    ..bundle.config.clone()
                };
                if as_run != cfg.model || bundle.vocab != *vocab {
                    return Err(TrainError::Invalid(format!(
                        "{} does not match this run: its model config or vocabulary differs from the training config's",
                        init.display()
                    )));
                }
                // Load into a fresh training module so its parameters track gradients.
                let weights = init.join("model.safetensors");
                let bytes = std::fs::read(&weights).map_err(|e| file_err(&weights, e))?;
                let fresh = Mdm::new(&bundle.config, vocab.len(), train_dev);
                let mut model =
                    model_from_safetensors(fresh, bytes, bundle.manifest.half_precision)
                        .map_err(|e| file_err(&weights, e))?;
                let mut ema = bundle.model;
                if add_skip {
                    model = model.with_input_skip(train_dev);
                    ema = ema.with_input_skip(plain);
                }
                return Ok(Checkpoint {
                    model,
                    ema,
                    optim: new_optimizer(cfg),
                    state: TrainState {
                        step: bundle.manifest.steps,
                        seconds: bundle.manifest.train_seconds,
                        optimizer_started_at: bundle.manifest.steps,
                        ..TrainState::default()
                    },
                });
            }
            let model = Mdm::new(&cfg.model, vocab.len(), train_dev);
            let ema = model.valid().to_device(plain);
            return Ok(Checkpoint {
                model,
                ema,
                optim: new_optimizer(cfg),
                state: TrainState::default(),
            });
        };
        let state_path = dir.join("state.json");
        let state: TrainState = serde_json::from_str(
            &std::fs::read_to_string(&state_path).map_err(|e| file_err(&state_path, e))?,
        )
        .map_err(|e| file_err(&state_path, e))?;
        let model_path = dir.join("model.bpk");
        let record =
            ModuleRecord::load(&model_path).map_err(|e| file_err(&model_path, format!("{e:?}")))?;
        let model = Mdm::new(&cfg.model, vocab.len(), train_dev).load_record(record);
        let optim_path = dir.join("optim.bpk");
        let optim = new_optimizer(cfg)
            .load(&optim_path)
            .map_err(|e| file_err(&optim_path, format!("{e:?}")))?;
        let ema_path = dir.join("ema.safetensors");
        let bytes = std::fs::read(&ema_path).map_err(|e| file_err(&ema_path, e))?;
        let ema = model_from_safetensors(Mdm::new(&cfg.model, vocab.len(), plain), bytes, false)
            .map_err(|e| file_err(&ema_path, e))?;
        Ok(Checkpoint {
            model,
            ema,
            optim,
            state,
        })
    }

    fn save(&self, ck: &Checkpoint, vocab: &Vocabulary) -> Result<(), TrainError> {
        let dir = self.out.join("ckpt.new");
        if dir.exists() {
            std::fs::remove_dir_all(&dir).map_err(|e| file_err(&dir, e))?;
        }
        std::fs::create_dir_all(&dir).map_err(|e| file_err(&dir, e))?;
        let p = dir.join("model.bpk");
        let bytes = ck
            .model
            .clone()
            .into_record()
            .into_bytes()
            .map_err(|e| file_err(&p, format!("{e:?}")))?;
        write_bytes_atomic(&p, &bytes).map_err(|e| file_err(&p, e))?;
        let p = dir.join("optim.bpk");
        let bytes = ck
            .optim
            .into_bytes()
            .map_err(|e| file_err(&p, format!("{e:?}")))?;
        write_bytes_atomic(&p, &bytes).map_err(|e| file_err(&p, e))?;
        let p = dir.join("ema.safetensors");
        let bytes = model_to_safetensors(&ck.ema, false).map_err(|e| file_err(&p, e))?;
        write_bytes_atomic(&p, &bytes).map_err(|e| file_err(&p, e))?;
        // The shippable bundle (EMA, f16).
        let bundle = self.out.join("bundle");
        std::fs::create_dir_all(&bundle).map_err(|e| file_err(&bundle, e))?;
        let manifest = Manifest {
            version: BUNDLE_VERSION,
            weights_id: format!(
                "mdm-{}x{}-step{}",
                self.config.model.d_model, self.config.model.layers, ck.state.step
            ),
            steps: ck.state.step,
            train_seconds: ck.state.seconds,
            half_precision: true,
        };
        save_bundle_parts(
            &bundle,
            &self.config.model,
            vocab,
            &self.data.mean,
            &self.data.std,
            &manifest,
        )
        .map_err(|e| file_err(&bundle, e))?;
        let p = bundle.join("model.safetensors");
        let bytes = model_to_safetensors(&ck.ema, true).map_err(|e| file_err(&p, e))?;
        write_bytes_atomic(&p, &bytes).map_err(|e| file_err(&p, e))?;
        let p = dir.join("state.json");
        write_bytes_atomic(
            &p,
            serde_json::to_string_pretty(&ck.state)
                .expect("state")
                .as_bytes(),
        )
        .map_err(|e| file_err(&p, e))?;
        let (cur, old) = (self.ckpt(), self.out.join("ckpt.old"));
        if old.exists() {
            std::fs::remove_dir_all(&old).map_err(|e| file_err(&old, e))?;
        }
        if cur.exists() {
            std::fs::rename(&cur, &old).map_err(|e| file_err(&cur, e))?;
        }
        std::fs::rename(&dir, &cur).map_err(|e| file_err(&dir, e))?;
        if old.exists() {
            std::fs::remove_dir_all(&old).map_err(|e| file_err(&old, e))?;
        }
        Ok(())
    }

    /// The run's vocabulary: read back when resuming, else built from the captions and saved.
    fn vocabulary(&self) -> Result<Vocabulary, TrainError> {
        let p = self.out.join("vocab.json");
        if p.exists() {
            let text = std::fs::read_to_string(&p).map_err(|e| file_err(&p, e))?;
            return serde_json::from_str(&text).map_err(|e| file_err(&p, e));
        }
        if let Some(init) = &self.init_from {
            let v = init.join("vocab.json");
            let text = std::fs::read_to_string(&v).map_err(|e| file_err(&v, e))?;
            std::fs::create_dir_all(&self.out).map_err(|e| file_err(&self.out, e))?;
            write_bytes_atomic(&p, text.as_bytes()).map_err(|e| file_err(&p, e))?;
            return serde_json::from_str(&text).map_err(|e| file_err(&v, e));
        }
        let captions = self
            .data
            .index
            .clips
            .iter()
            .flat_map(|c| c.captions.iter().map(String::as_str));
        let vocab = Vocabulary::from_captions(captions, 16);
        std::fs::create_dir_all(&self.out).map_err(|e| file_err(&self.out, e))?;
        write_bytes_atomic(
            &p,
            serde_json::to_string_pretty(&vocab)
                .expect("vocab")
                .as_bytes(),
        )
        .map_err(|e| file_err(&p, e))?;
        Ok(vocab)
    }

    /// Validation loss of the EMA weights on fixed crops of the validation split.
    fn validate(
        &self,
        ema: &Mdm,
        vocab: &Vocabulary,
        schedule: &NoiseSchedule,
        device: &Device,
    ) -> Option<f64> {
        let clips: Vec<&ClipInfo> = self.data.clips(Split::Val).collect();
        if clips.is_empty() {
            return None;
        }
        let mut cfg = self.config.clone();
        cfg.cond_drop = 0.0;
        cfg.word_drop = 0.0;
        let mut total = 0.0;
        let rounds = 4;
        for r in 0..rounds {
            // Fixed "steps" far beyond any real step keep validation batches constant.
            let batch = draw_batch(self.data, &clips, &cfg, usize::MAX - r);
            let none = GeometricLosses::default();
            let loss = batch_loss(ema, schedule, &batch, vocab, &none, device);
            total += loss.into_scalar::<f32>() as f64;
        }
        Some(total / rounds as f64)
    }

    /// Trains until `config.steps` (or `max_steps_now` more steps), resuming from the
    /// last checkpoint in `out` if there is one.
    pub fn run(&self, progress: &dyn Fn(&TrainState, f32, f64)) -> Result<TrainState, TrainError> {
        let cfg = &self.config;
        cfg.check()
            .map_err(|e| TrainError::Invalid(format!("training config: {e}")))?;
        let train: Vec<&ClipInfo> = self.data.clips(Split::Train).collect();
        if train.is_empty() {
            return Err(TrainError::Invalid(
                "the dataset has no training clips".into(),
            ));
        }
        let vocab = self.vocabulary()?;
        let plain = self.device.clone();
        let device = plain.clone().autodiff();
        let schedule = NoiseSchedule::cosine(DIFFUSION_STEPS);
        let mut ck = self.load_or_init(&vocab, &device, &plain)?;
        let geometric = GeometricLosses::new(cfg, &self.data.mean, &self.data.std, &device);
        let stop_at = match self.max_steps_now {
            Some(n) => (ck.state.step + n).min(cfg.steps),
            None => cfg.steps,
        };
        let mut pending = String::new();
        let mut since_ckpt = (0.0f64, 0usize);
        let mut clock = Instant::now();
        let mut saved_at = ck.state.step;
        while ck.state.step < stop_at {
            if self.interrupt.is_requested() {
                break;
            }
            let step = ck.state.step;
            let batch = draw_batch(self.data, &train, cfg, step);
            let loss = batch_loss(&ck.model, &schedule, &batch, &vocab, &geometric, &device);
            let value = loss.clone().into_scalar::<f32>();
            if !value.is_finite() {
                return Err(TrainError::Diverged { step, loss: value });
            }
            let grads = GradientsParams::from_grads(loss.backward(), &ck.model);
            let lr = learning_rate(cfg, &ck.state);
            ck.model = ck.optim.step(lr, ck.model, grads);
            let decay = (cfg.ema_decay as f32).min((1 + step) as f32 / (10 + step) as f32);
            ck.ema = ema_update(ck.ema, &ck.model.valid(), decay);
            ck.state.step += 1;
            let now = Instant::now();
            ck.state.seconds += (now - clock).as_secs_f64();
            clock = now;
            since_ckpt = (since_ckpt.0 + value as f64, since_ckpt.1 + 1);
            pending.push_str(&format!(
                "{},{value},{lr},{:.1}\n",
                ck.state.step, ck.state.seconds
            ));
            progress(&ck.state, value, lr);
            if ck.state.step % cfg.checkpoint_every == 0 || ck.state.step == stop_at {
                self.checkpoint(
                    &mut ck,
                    &mut since_ckpt,
                    &mut pending,
                    &vocab,
                    &schedule,
                    &plain,
                )?;
                saved_at = ck.state.step;
                clock = Instant::now();
            }
        }
        if ck.state.step > saved_at {
            // Interrupted between checkpoints: keep every finished step.
            self.checkpoint(
                &mut ck,
                &mut since_ckpt,
                &mut pending,
                &vocab,
                &schedule,
                &plain,
            )?;
        }
        Ok(ck.state)
    }

    /// Validates, appends the loss rows and saves the checkpoint.
    fn checkpoint(
        &self,
        ck: &mut Checkpoint,
        since_ckpt: &mut (f64, usize),
        pending: &mut String,
        vocab: &Vocabulary,
        schedule: &NoiseSchedule,
        plain: &Device,
    ) -> Result<(), TrainError> {
        ck.state.recent_loss = since_ckpt.0 / since_ckpt.1.max(1) as f64;
        *since_ckpt = (0.0, 0);
        ck.state.val_loss = self.validate(&ck.ema, vocab, schedule, plain);
        append(
            &self.out.join("loss.csv"),
            "step,loss,lr,seconds\n",
            pending,
        )?;
        pending.clear();
        if let Some(v) = ck.state.val_loss {
            append(
                &self.out.join("val.csv"),
                "step,val_loss,seconds\n",
                &format!("{},{v},{:.1}\n", ck.state.step, ck.state.seconds),
            )?;
        }
        // E.g. a picture of the curves; a plotting problem must not stop training.
        if let Some(hook) = self.after_checkpoint
            && let Err(e) = hook(&self.out)
        {
            eprintln!("warning: after the checkpoint: {e}");
        }
        self.save(ck, vocab)
    }
}

/// `(step, value)` pairs of column `col` of a CSV written by [`append`] (`loss.csv`,
/// `val.csv`).
pub fn read_curve(path: &Path, col: usize) -> Vec<(f32, f32)> {
    let Ok(text) = std::fs::read_to_string(path) else {
        return Vec::new();
    };
    text.lines()
        .skip(1)
        .filter_map(|l| {
            let mut f = l.split(',');
            let step = f.next()?.parse().ok()?;
            let v = f.nth(col - 1)?.parse().ok()?;
            Some((step, v))
        })
        .collect()
}

fn append(path: &Path, header: &str, rows: &str) -> Result<(), TrainError> {
    let new = !path.exists();
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .map_err(|e| file_err(path, e))?;
    if new {
        f.write_all(header.as_bytes())
            .map_err(|e| file_err(path, e))?;
    }
    f.write_all(rows.as_bytes()).map_err(|e| file_err(path, e))
}

#[cfg(test)]
mod warmup_tests {
    use super::*;

    #[test]
    fn warm_up_restarts_with_the_optimizer() {
        let cfg = TrainConfig {
            learning_rate: 3e-4,
            warmup_steps: 300,
            ..TrainConfig::default()
        };
        let at = |step, optimizer_started_at| {
            learning_rate(
                &cfg,
                &TrainState {
                    step,
                    optimizer_started_at,
                    ..TrainState::default()
                },
            )
        };
        // A fresh run warms up from step 0.
        assert!((at(0, 0) - 1e-6).abs() < 1e-12);
        assert!((at(299, 0) - 3e-4).abs() < 1e-12);
        // A run begun from a step-6,550 bundle warms up again, not at full rate.
        assert!((at(6_550, 6_550) - 1e-6).abs() < 1e-12);
        assert!((at(6_700, 6_550) - 1.51e-4).abs() < 1e-12);
        assert!((at(6_900, 6_550) - 3e-4).abs() < 1e-12);
    }
}
