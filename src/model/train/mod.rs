//! The training loop: masked x0-MSE on random crops, AdamW with warm-up and gradient
//! clipping, EMA weights, periodic atomic checkpoints, resume, loss curves.
//!
//! ```text
//! <out>/config.toml        the run's TrainConfig (fixed at the first start)
//! <out>/vocab.json         the run's vocabulary (bag-of-words runs; fixed at the first start)
//! <out>/captions.safetensors  every caption, embedded (sentence-encoder runs; rebuilt when
//!                          the data brings captions it lacks)
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
//! | file | what |
//! | --- | --- |
//! | `mod.rs` | the run: settings, the loop, validation |
//! | `losses.rs` | the x0 MSE and the geometric terms of one batch |
//! | `checkpoint.rs` | where a run starts (fresh, a bundle, its checkpoint); atomic saves |
//! | `text.rs` | the run's text side: a vocabulary or the embedded captions |
//! | `log.rs` | `loss.csv` and `val.csv` |
//! | `control.rs` | a ControlNet trained on a frozen base |
//! | `distil.rs` | consistency distillation of a teacher bundle (`[distil]` in the config) |
//!
//! A checkpoint is written whole into `ckpt.new/` and then swapped in by renames, so a
//! kill at any moment leaves either the old or the new checkpoint complete.

pub mod augment;
mod checkpoint;
pub mod control;
mod distil;
mod log;
mod losses;
pub mod paraphrase;
pub mod text;

pub use log::read_curve;
pub use losses::{FootLoss, GeometricLosses, VelocityLoss, masked_mse, root_mse};
pub use text::{TrainText, trained_actions_of};

use super::batch::draw_batch;
use super::config::TrainConfig;
use super::denoiser::Mdm;
use super::ema::ema_update;
use super::schedule::{DIFFUSION_STEPS, NoiseSchedule};
use crate::dataset::{ClipInfo, Dataset, Split};
use crate::interrupt::Interrupt;
use burn::module::Module;
use burn::optim::GradientsParams;
use burn::prelude::*;
use checkpoint::Checkpoint;
use distil::{Teacher, distil_loss};
use log::append;
use losses::batch_loss;
use serde::{Deserialize, Serialize};
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

/// A bundle file that cannot be read or does not fit, named once.
impl From<crate::model::weights::WeightsError> for TrainError {
    fn from(e: crate::model::weights::WeightsError) -> Self {
        use crate::model::weights::WeightsError as W;
        match e {
            W::Read { path, reason } => TrainError::File {
                path,
                reason: format!("cannot read: {reason}"),
            },
            W::Mismatch { path, reason } => TrainError::File { path, reason },
            W::Write { path, reason } => TrainError::File {
                path,
                reason: format!("cannot write: {reason}"),
            },
        }
    }
}

pub(super) fn file_err(path: &Path, e: impl std::fmt::Display) -> TrainError {
    TrainError::File {
        path: path.to_path_buf(),
        reason: e.to_string(),
    }
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
    /// A bag-of-words bundle may also start a sentence-encoder run of the same shape: every
    /// weight but the text encoder's and its projection carries over.
    pub init_from: Option<PathBuf>,
    /// The device to train on (without autodiff; the run adds it).
    pub device: Device,
    /// Called with the output folder after every checkpoint (the CLI plots `loss.png`).
    pub after_checkpoint: Option<CheckpointHook>,
    /// The sentence encoder of a sentence-encoder run (`models/text-encoder` when None).
    pub text_encoder: Option<PathBuf>,
}

/// Linear warm-up over the first `warmup_steps` of the optimizer's life: a restarted
/// AdamW's first updates are ±lr on every weight (its moment estimates are one gradient
/// old), which at full rate shakes a trained model.
pub(super) fn learning_rate(cfg: &TrainConfig, state: &TrainState) -> f64 {
    let since_start = state.step.saturating_sub(state.optimizer_started_at);
    cfg.learning_rate * ((since_start + 1) as f64 / cfg.warmup_steps.max(1) as f64).min(1.0)
}

impl TrainRun<'_> {
    /// Validation loss of the EMA weights on fixed crops of the validation split.
    fn validate(
        &self,
        ema: &Mdm,
        text: &TrainText,
        schedule: &NoiseSchedule,
        teacher: Option<&Teacher>,
        device: &Device,
    ) -> Option<f64> {
        let clips: Vec<&ClipInfo> = self.data.clips(Split::Val).collect();
        if clips.is_empty() {
            return None;
        }
        let mut cfg = self.config.clone();
        cfg.cond_drop = 0.0;
        cfg.word_drop = 0.0;
        cfg.text_noise = 0.0;
        cfg.hold_pad = 0.0;
        let mut total = 0.0;
        let rounds = 4;
        for r in 0..rounds {
            // Fixed "steps" far beyond any real step keep validation batches constant.
            let batch = draw_batch(self.data, &clips, &cfg, usize::MAX - r);
            let none = GeometricLosses::default();
            let loss = match teacher {
                // The EMA is both student and target: how far it is from consistent.
                Some(t) => distil_loss(ema, ema, t, schedule, &batch, text, None, device, device),
                None => batch_loss(ema, schedule, &batch, text, &none, device),
            };
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
        let plain = self.device.clone();
        let mut text = self.train_text(&plain)?;
        let augment = self.caption_augment(&mut text, &plain)?;
        let device = plain.clone().autodiff();
        let schedule = NoiseSchedule::cosine(DIFFUSION_STEPS);
        let mut ck = self.load_or_init(&text, &device, &plain)?;
        if cfg.model.text_control.is_some() {
            // OMG's second stage: only the text ControlNet learns.
            ck.model = ck.model.freeze_all_but_text_control();
        }
        let teacher = self.teacher(&plain)?;
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
            let mut batch = draw_batch(self.data, &train, cfg, step);
            if let Some(a) = &augment {
                a.apply(&mut batch.captions, cfg.seed, step);
            }
            let loss = match &teacher {
                Some(t) => distil_loss(
                    &ck.model,
                    &ck.ema,
                    t,
                    &schedule,
                    &batch,
                    &text,
                    geometric.bones.as_ref(),
                    &device,
                    &plain,
                ),
                None => batch_loss(&ck.model, &schedule, &batch, &text, &geometric, &device),
            };
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
                    &text,
                    &schedule,
                    teacher.as_ref(),
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
                &text,
                &schedule,
                teacher.as_ref(),
                &plain,
            )?;
        }
        Ok(ck.state)
    }

    /// The frozen teacher of a distillation run (None for a plain run).
    fn teacher(&self, plain: &Device) -> Result<Option<Teacher>, TrainError> {
        let Some(cfg) = &self.config.distil else {
            return Ok(None);
        };
        let path = PathBuf::from(&cfg.teacher);
        let bundle = crate::model::weights::ModelBundle::load(&path, plain)?;
        // Dropout has no weights (the run may train without it, the teacher never uses it).
        let run_shape = crate::model::config::ModelConfig {
            dropout: bundle.config.dropout,
            ..self.config.model.clone()
        };
        if bundle.config != run_shape {
            return Err(TrainError::Invalid(format!(
                "the teacher {} has another denoiser config than the run's [model]",
                path.display()
            )));
        }
        if bundle.manifest.consistency.is_some() {
            return Err(TrainError::Invalid(format!(
                "the teacher {} is itself a few-step model; distil from a diffusion model",
                path.display()
            )));
        }
        Ok(Some(Teacher::new(bundle.model, cfg)))
    }

    /// Validates, appends the loss rows and saves the checkpoint.
    #[allow(clippy::too_many_arguments)]
    fn checkpoint(
        &self,
        ck: &mut Checkpoint,
        since_ckpt: &mut (f64, usize),
        pending: &mut String,
        text: &TrainText,
        schedule: &NoiseSchedule,
        teacher: Option<&Teacher>,
        plain: &Device,
    ) -> Result<(), TrainError> {
        ck.state.recent_loss = since_ckpt.0 / since_ckpt.1.max(1) as f64;
        *since_ckpt = (0.0, 0);
        ck.state.val_loss = self.validate(&ck.ema, text, schedule, teacher, plain);
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
        self.save(ck, text)
    }
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
