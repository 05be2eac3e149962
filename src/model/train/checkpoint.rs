//! Where a run starts (a fresh model, a model bundle, or its last checkpoint) and how a
//! checkpoint and the shippable bundle are written: whole into `ckpt.new/`, then swapped in
//! by renames.

use super::text::{TrainText, trained_actions_of};
use super::{TrainError, TrainRun, TrainState, file_err};
use crate::fsutil::write_bytes_atomic;
use crate::model::config::{ModelConfig, TextEncoderKind, TrainConfig};
use crate::model::denoiser::Mdm;
use crate::model::prompt::PromptEncoder;
use crate::model::weights::{
    BUNDLE_VERSION, Consistency, Manifest, ModelBundle, model_from_safetensors,
    model_to_safetensors, save_bundle_parts, save_trained_actions,
};
use burn::module::Module;
use burn::optim::{AdamWConfig, ModuleOptimizer, grad_clipping::GradientClippingConfig};
use burn::prelude::*;
use burn::store::{HalfPrecisionAdapter, ModuleRecord, ModuleSnapshot, SafetensorsStore};
use std::path::{Path, PathBuf};

/// Training weights, EMA weights, optimizer and progress.
pub(super) struct Checkpoint {
    pub(super) model: Mdm,
    pub(super) ema: Mdm,
    pub(super) optim: ModuleOptimizer,
    pub(super) state: TrainState,
}

fn new_optimizer(cfg: &TrainConfig) -> ModuleOptimizer {
    AdamWConfig::new()
        .with_weight_decay(cfg.weight_decay as f32)
        .with_grad_clipping(Some(GradientClippingConfig::Norm(cfg.grad_clip as f32)))
        .init()
}

impl TrainRun<'_> {
    /// The complete checkpoint to resume from: `ckpt/`, or `ckpt.old/` when a kill hit
    /// the swap between the two renames.
    fn existing_checkpoint(&self) -> Option<PathBuf> {
        ["ckpt", "ckpt.old"]
            .iter()
            .map(|d| self.out.join(d))
            .find(|d| d.join("state.json").exists())
    }

    pub(super) fn load_or_init(
        &self,
        text: &TrainText,
        train_dev: &Device,
        plain: &Device,
    ) -> Result<Checkpoint, TrainError> {
        let vocab_size = text.vocab_size();
        let cfg = &self.config;
        let Some(dir) = self.existing_checkpoint() else {
            if let Some(init) = &self.init_from {
                let bundle = ModelBundle::load(init, plain).map_err(|e| file_err(init, e))?;
                // A bundle without the input skip may start a run with it (added at zero);
                // one with a learned skip cannot start a run without it.
                let add_skip = cfg.model.input_skip && !bundle.config.input_skip;
                // A one-frame skip may widen to several taps (the old gain becomes the
                // centre tap); a wider one cannot narrow.
                let widen_skip = (bundle.config.skip_taps == 1 && cfg.model.skip_taps > 1)
                    .then_some(cfg.model.skip_taps);
                // A sentence model without the side input may start a run with it (added
                // at zero).
                let add_side = cfg.model.side_input && !bundle.config.side_input;
                let as_run = ModelConfig {
                    input_skip: bundle.config.input_skip || cfg.model.input_skip,
                    skip_taps: widen_skip.unwrap_or(bundle.config.skip_taps),
                    side_input: bundle.config.side_input || cfg.model.side_input,
                    // When the outer taps read is the run's choice; it has no weights.
                    skip_taps_below: cfg.model.skip_taps_below,
                    // Dropout has no weights either: a fine-tune may change it.
                    dropout: cfg.model.dropout,
                    // An unconditional prior may start OMG's second stage (its text
                    // ControlNet added at zero).
                    text_control: bundle
                        .config
                        .text_control
                        .clone()
                        .or_else(|| cfg.model.text_control.clone()),
                    ..bundle.config.clone()
                };
                let weights = init.join("model.safetensors");
                let bytes = std::fs::read(&weights).map_err(|e| file_err(&weights, e))?;
                let half = bundle.manifest.half_precision;
                let new_text = as_run.text_encoder == TextEncoderKind::BagOfWords
                    && cfg.model.text_encoder == TextEncoderKind::Sentence
                    && ModelConfig {
                        text_encoder: cfg.model.text_encoder,
                        d_text: cfg.model.d_text,
                        ..as_run.clone()
                    } == cfg.model;
                let (mut model, mut ema) = if new_text {
                    // Everything but the text side carries over; the projection of the
                    // sentence vectors starts fresh.
                    let model = load_without_text(Mdm::new(&cfg.model, 0, train_dev), &bytes, half)
                        .map_err(|e| file_err(&weights, e))?;
                    // The EMA starts as this very model, fresh projection included.
                    let ema = model.valid().to_device(plain);
                    (model, ema)
                } else {
                    let same_text = match (&bundle.text, text) {
                        (PromptEncoder::Words(a), TrainText::Words(b)) => a == b,
                        (PromptEncoder::Sentences(a), TrainText::Sentences { prompts, .. }) => {
                            a.encoder.id() == prompts.encoder.id()
                        }
                        _ => false,
                    };
                    if as_run != cfg.model || !same_text {
                        return Err(TrainError::Invalid(format!(
                            "{} does not match this run: its model config or text encoder differs from the training config's",
                            init.display()
                        )));
                    }
                    // Load into a fresh training module so its parameters track gradients.
                    let shape = ModelConfig {
                        dropout: cfg.model.dropout,
                        ..bundle.config.clone()
                    };
                    let fresh = Mdm::new(&shape, vocab_size, train_dev);
                    let model = model_from_safetensors(fresh, bytes, half)
                        .map_err(|e| file_err(&weights, e))?;
                    (model, bundle.model)
                };
                if add_skip {
                    model = model.with_input_skip(train_dev);
                    ema = ema.with_input_skip(plain);
                }
                if add_side {
                    model = model.with_side_input(train_dev);
                    ema = ema.with_side_input(plain);
                }
                if let Some(taps) = widen_skip {
                    model = model.with_skip_taps(taps);
                    ema = ema.with_skip_taps(taps);
                }
                let (model, ema) = match &cfg.model.text_control {
                    // A fresh text ControlNet: the EMA starts as the very same one.
                    Some(_) if !model.has_text_control() => {
                        let model =
                            model.with_text_control(cfg.model.text_control.as_ref(), train_dev);
                        let ema = model.valid().to_device(plain);
                        (model, ema)
                    }
                    _ => (model, ema),
                };
                let below = cfg.model.skip_taps_below;
                let (model, ema) = (
                    model.with_skip_taps_below(below),
                    ema.with_skip_taps_below(below),
                );
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
            let model = Mdm::new(&cfg.model, vocab_size, train_dev);
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
        let model = Mdm::new(&cfg.model, vocab_size, train_dev).load_record(record);
        let optim_path = dir.join("optim.bpk");
        let optim = new_optimizer(cfg)
            .load(&optim_path)
            .map_err(|e| file_err(&optim_path, format!("{e:?}")))?;
        let ema_path = dir.join("ema.safetensors");
        let bytes = std::fs::read(&ema_path).map_err(|e| file_err(&ema_path, e))?;
        let ema = model_from_safetensors(Mdm::new(&cfg.model, vocab_size, plain), bytes, false)
            .map_err(|e| file_err(&ema_path, e))?;
        Ok(Checkpoint {
            model,
            ema,
            optim,
            state,
        })
    }

    pub(super) fn save(&self, ck: &Checkpoint, text: &TrainText) -> Result<(), TrainError> {
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
                "{}-{}x{}-step{}",
                if self.config.distil.is_some() {
                    "lcm"
                } else {
                    "mdm"
                },
                self.config.model.d_model,
                self.config.model.layers,
                ck.state.step
            ),
            steps: ck.state.step,
            train_seconds: ck.state.seconds,
            half_precision: true,
            text_encoder_id: match text {
                TrainText::Words(_) => None,
                TrainText::Sentences { prompts, .. } => Some(prompts.encoder.id().to_string()),
            },
            control_id: None,
            consistency: self.config.distil.as_ref().map(|d| Consistency {
                guidance: d.guidance,
                grid: d.grid,
                teacher: Manifest::read(&Path::new(&d.teacher).join("manifest.json"))
                    .map(|m| m.weights_id)
                    .unwrap_or_else(|_| d.teacher.clone()),
            }),
        };
        save_bundle_parts(
            &bundle,
            &self.config.model,
            &text.prompt_encoder(),
            &self.data.mean,
            &self.data.std,
            &manifest,
        )
        .map_err(|e| file_err(&bundle, e))?;
        save_trained_actions(&bundle, &trained_actions_of(self.data))
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
        swap_in(&self.out, &dir)
    }
}

/// Loads every tensor of a saved denoiser except the text encoder's and its projection.
fn load_without_text(model: Mdm, bytes: &[u8], half: bool) -> Result<Mdm, String> {
    let mut store = SafetensorsStore::from_bytes(Some(bytes.to_vec()))
        .with_regexes([
            r"^input_proj\.",
            r"^time_[12]\.",
            r"^encoder\.",
            r"^output_proj\.",
            r"^skip\.",
        ])
        .allow_partial(true);
    if half {
        store = store.with_from_adapter(HalfPrecisionAdapter::new());
    }
    let mut model = model;
    let result = model.load_from(&mut store).map_err(|e| e.to_string())?;
    if !result.errors.is_empty() {
        return Err(format!(
            "weights do not fit the configured model: {:?}",
            result.errors
        ));
    }
    Ok(model)
}

/// Makes the complete checkpoint folder `new` the run's `ckpt/` by renames: the old one
/// goes to `ckpt.old/` first, so a kill at any moment leaves one complete checkpoint.
pub(super) fn swap_in(out: &Path, new: &Path) -> Result<(), TrainError> {
    let (cur, old) = (out.join("ckpt"), out.join("ckpt.old"));
    if old.exists() {
        std::fs::remove_dir_all(&old).map_err(|e| file_err(&old, e))?;
    }
    if cur.exists() {
        std::fs::rename(&cur, &old).map_err(|e| file_err(&cur, e))?;
    }
    std::fs::rename(new, &cur).map_err(|e| file_err(new, e))?;
    if old.exists() {
        std::fs::remove_dir_all(&old).map_err(|e| file_err(&old, e))?;
    }
    Ok(())
}
