//! A model bundle on disk: weights (SafeTensors, f16 for shipping, f32 for checkpoints),
//! config, text side and normalisation statistics, with version and shape checks.
//!
//! ```text
//! <dir>/manifest.json      format version, weights id, training summary
//! <dir>/config.toml        ModelConfig
//! <dir>/vocab.json         Vocabulary (bag-of-words models)
//! <dir>/captions.safetensors  training captions, embedded (sentence-encoder models)
//! <dir>/actions.json       what the training clips show, with clip counts (optional)
//! <dir>/lengths.json       median clip length per training caption (optional)
//! <dir>/envelope.json      how the training clips move, for plausibility reports
//!                          (optional; `mprog data envelope` measures it)
//! <dir>/coverage.bin       the poses the training clips hold, for `mprog::unseen_pose`
//!                          (optional; `mprog data coverage` builds it, and
//!                          `mprog::coverage::Coverage::for_bundle` reads it)
//! <dir>/mean.npy, std.npy  [263] normalisation statistics
//! <dir>/model.safetensors  denoiser weights
//! ```
//!
//! A sentence-encoder model names its encoder's weights id in the manifest; the encoder is
//! found in `<dir>/text-encoder`, `<dir>/../text-encoder` or the source tree's
//! `models/text-encoder`, and one with other weights is refused.

use super::config::{ModelConfig, TextEncoderKind};
use super::denoiser::Mdm;
use super::lengths::CaptionLengths;
use super::prompt::{PromptEncoder, SentencePrompts};
use super::sentence::{CaptionIndex, SentenceEncoder, default_encoder_dir};
use super::text::Vocabulary;
use crate::dataset::store::{read_f32_npy, write_f32_npy};
use crate::fsutil::write_bytes_atomic;
use burn::prelude::*;
use burn::store::{HalfPrecisionAdapter, ModuleSnapshot, SafetensorsStore};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Version of the bundle layout.
pub const BUNDLE_VERSION: u32 = 1;

/// Summary stored with the weights.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// [`BUNDLE_VERSION`].
    pub version: u32,
    /// Short id of these weights (saved next to every output for reproducibility).
    pub weights_id: String,
    /// Optimisation steps the weights saw.
    pub steps: usize,
    /// Wall seconds of training.
    pub train_seconds: f64,
    /// Whether the SafeTensors file holds f16 values.
    pub half_precision: bool,
    /// Weights id of the sentence encoder the model was trained with (sentence models).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub text_encoder_id: Option<String>,
    /// Id of the realism ControlNet beside the weights (`control.safetensors`), when the
    /// bundle has one: it changes what `guide` makes, so outputs record it too.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub control_id: Option<String>,
    /// Set when the weights are a consistency model distilled from a guided teacher:
    /// they sample in a few steps, at guidance scale 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub consistency: Option<Consistency>,
}

/// What a consistency-distilled bundle was distilled with (`model::train::distil`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Consistency {
    /// The teacher's classifier-free guidance scale, baked into the weights.
    pub guidance: f64,
    /// Steps of the teacher's DDIM grid; few-step chains pick their timesteps on it.
    pub grid: usize,
    /// The teacher's weights id.
    pub teacher: String,
}

/// Errors while loading or saving a bundle.
#[derive(Debug, thiserror::Error)]
pub enum WeightsError {
    /// Missing or unreadable file.
    #[error("cannot read {path}: {reason}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// The bundle does not fit this build.
    #[error("{path}: {reason}")]
    Mismatch {
        /// The file.
        path: PathBuf,
        /// What does not fit.
        reason: String,
    },
    /// Writing failed.
    #[error("cannot write {path}: {reason}")]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
}

/// A loaded model with everything needed to sample.
#[derive(Debug)]
pub struct ModelBundle {
    /// Denoiser shape.
    pub config: ModelConfig,
    /// What turns prompts into the denoiser's text condition.
    pub text: PromptEncoder,
    /// `[263]` feature mean.
    pub mean: Vec<f32>,
    /// `[263]` feature std.
    pub std: Vec<f32>,
    /// The denoiser.
    pub model: Mdm,
    /// Manifest.
    pub manifest: Manifest,
}

fn read_text(path: &Path) -> Result<String, WeightsError> {
    std::fs::read_to_string(path).map_err(|e| WeightsError::Read {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })
}

fn mismatch(path: &Path, reason: impl Into<String>) -> WeightsError {
    WeightsError::Mismatch {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

fn write_err(path: &Path, e: impl std::fmt::Display) -> WeightsError {
    WeightsError::Write {
        path: path.to_path_buf(),
        reason: e.to_string(),
    }
}

/// Serialises any module to SafeTensors bytes (f16 values when `half`).
pub fn module_to_safetensors<M: Module>(module: &M, half: bool) -> Result<Vec<u8>, String> {
    let mut store = SafetensorsStore::from_bytes(None);
    if half {
        store = store.with_to_adapter(HalfPrecisionAdapter::new());
    }
    module.save_into(&mut store).map_err(|e| e.to_string())?;
    store.get_bytes().map_err(|e| e.to_string())
}

/// Loads SafeTensors bytes into a freshly built module; every tensor must be present with
/// the right shape. `what` names the module in errors ("model", "evaluator").
pub fn module_from_safetensors<M: Module>(
    mut module: M,
    bytes: Vec<u8>,
    half: bool,
    what: &str,
) -> Result<M, String> {
    let mut store = SafetensorsStore::from_bytes(Some(bytes));
    if half {
        store = store.with_from_adapter(HalfPrecisionAdapter::new());
    }
    let result = module.load_from(&mut store).map_err(|e| {
        let text = e.to_string();
        let short: String = text.chars().take(400).collect();
        let more = if text.len() > short.len() { " …" } else { "" };
        format!("weights do not fit the configured {what}: {short}{more}")
    })?;
    if !result.errors.is_empty() || !result.missing.is_empty() {
        let first = |items: Vec<String>| items.into_iter().take(3).collect::<Vec<_>>().join("; ");
        return Err(format!(
            "weights do not fit the configured {what}: {} errors ({}), {} missing tensors ({})",
            result.errors.len(),
            first(result.errors.iter().map(|e| format!("{e:?}")).collect()),
            result.missing.len(),
            first(result.missing.iter().map(|m| format!("{m:?}")).collect()),
        ));
    }
    Ok(module)
}

/// Serialises a denoiser to SafeTensors bytes.
pub fn model_to_safetensors(model: &Mdm, half: bool) -> Result<Vec<u8>, String> {
    module_to_safetensors(model, half)
}

/// Loads SafeTensors bytes into a freshly built denoiser.
pub fn model_from_safetensors(model: Mdm, bytes: Vec<u8>, half: bool) -> Result<Mdm, String> {
    module_from_safetensors(model, bytes, half, "model")
}

impl Manifest {
    /// Reads a bundle's `manifest.json`.
    pub fn read(path: &Path) -> Result<Manifest, WeightsError> {
        serde_json::from_str(&read_text(path)?)
            .map_err(|e| mismatch(path, format!("bad manifest: {e}")))
    }
}

impl ModelBundle {
    /// Loads a bundle from `dir` onto `device`.
    pub fn load(dir: &Path, device: &Device) -> Result<ModelBundle, WeightsError> {
        let manifest_path = dir.join("manifest.json");
        let manifest = Manifest::read(&manifest_path)?;
        if manifest.version != BUNDLE_VERSION {
            return Err(mismatch(
                &manifest_path,
                format!(
                    "model bundle version {} but this mprog reads version {BUNDLE_VERSION}",
                    manifest.version
                ),
            ));
        }
        let config_path = dir.join("config.toml");
        let config: ModelConfig = toml::from_str(&read_text(&config_path)?)
            .map_err(|e| mismatch(&config_path, format!("bad model config: {e}")))?;
        config
            .check()
            .map_err(|e| mismatch(&config_path, format!("bad model config: {e}")))?;
        let text = load_prompt_encoder(dir, &config, &manifest, device)?;
        let vocab_size = text.vocab_size();
        let stat = |name: &str| -> Result<Vec<f32>, WeightsError> {
            let p = dir.join(name);
            let (_, v) = read_f32_npy(&p, &[]).map_err(|e| mismatch(&p, e.to_string()))?;
            if v.len() != config.features {
                return Err(mismatch(
                    &p,
                    format!(
                        "{} values, the model has {} features",
                        v.len(),
                        config.features
                    ),
                ));
            }
            Ok(v)
        };
        let mean = stat("mean.npy")?;
        let std = stat("std.npy")?;
        let weights_path = dir.join("model.safetensors");
        let bytes = std::fs::read(&weights_path).map_err(|e| WeightsError::Read {
            path: weights_path.clone(),
            reason: e.to_string(),
        })?;
        let fresh = Mdm::new(&config, vocab_size, device);
        let model = model_from_safetensors(fresh, bytes, manifest.half_precision)
            .map_err(|reason| mismatch(&weights_path, reason))?;
        Ok(ModelBundle {
            config,
            text,
            mean,
            std,
            model,
            manifest,
        })
    }

    /// Writes the bundle to `dir` (each file atomically).
    pub fn save(&self, dir: &Path) -> Result<(), WeightsError> {
        std::fs::create_dir_all(dir).map_err(|e| write_err(dir, e))?;
        save_bundle_parts(
            dir,
            &self.config,
            &self.text,
            &self.mean,
            &self.std,
            &self.manifest,
        )?;
        let p = dir.join("model.safetensors");
        let bytes = model_to_safetensors(&self.model, self.manifest.half_precision)
            .map_err(|e| write_err(&p, e))?;
        write_bytes_atomic(&p, &bytes).map_err(|e| write_err(&p, e))
    }
}

/// Writes everything of a bundle except the weights.
pub fn save_bundle_parts(
    dir: &Path,
    config: &ModelConfig,
    text: &PromptEncoder,
    mean: &[f32],
    std: &[f32],
    manifest: &Manifest,
) -> Result<(), WeightsError> {
    let put = |name: &str, text: String| {
        let p = dir.join(name);
        write_bytes_atomic(&p, text.as_bytes()).map_err(|e| write_err(&p, e))
    };
    put(
        "manifest.json",
        serde_json::to_string_pretty(manifest).expect("manifest serialises"),
    )?;
    put(
        "config.toml",
        toml::to_string(config).expect("config serialises"),
    )?;
    match text {
        PromptEncoder::Words(vocab) => put(
            "vocab.json",
            serde_json::to_string_pretty(vocab).expect("vocab serialises"),
        )?,
        PromptEncoder::Sentences(s) => {
            let p = dir.join("captions.safetensors");
            s.captions.save(&p).map_err(|e| write_err(&p, e))?;
            s.lengths.save(dir)?;
        }
    }
    for (name, v) in [("mean.npy", mean), ("std.npy", std)] {
        let p = dir.join(name);
        write_f32_npy(&p, &[v.len() as u64], v).map_err(|e| write_err(&p, e))?;
    }
    Ok(())
}

/// The text side of a bundle: its vocabulary, or its caption index and the sentence
/// encoder it was trained with.
fn load_prompt_encoder(
    dir: &Path,
    config: &ModelConfig,
    manifest: &Manifest,
    device: &Device,
) -> Result<PromptEncoder, WeightsError> {
    if config.text_encoder == TextEncoderKind::BagOfWords {
        let vocab_path = dir.join("vocab.json");
        let vocab: Vocabulary = serde_json::from_str(&read_text(&vocab_path)?)
            .map_err(|e| mismatch(&vocab_path, format!("bad vocabulary: {e}")))?;
        return Ok(PromptEncoder::Words(vocab));
    }
    let manifest_path = dir.join("manifest.json");
    let Some(want) = &manifest.text_encoder_id else {
        return Err(mismatch(
            &manifest_path,
            "a sentence-encoder model must name its encoder's `text_encoder_id`",
        ));
    };
    let enc_dir = text_encoder_dir(dir);
    let encoder =
        SentenceEncoder::load(&enc_dir, device).map_err(|e| mismatch(&enc_dir, e.to_string()))?;
    if encoder.id() != want {
        return Err(mismatch(
            &enc_dir,
            format!(
                "sentence encoder {} but the model was trained with {want}",
                encoder.id()
            ),
        ));
    }
    let config_path = dir.join("config.toml");
    if encoder.dim() != config.d_text {
        return Err(mismatch(
            &config_path,
            format!(
                "`d_text` is {} but the sentence encoder gives {}-d vectors",
                config.d_text,
                encoder.dim()
            ),
        ));
    }
    let captions_path = dir.join("captions.safetensors");
    let captions = CaptionIndex::load(&captions_path, device)
        .map_err(|e| mismatch(&captions_path, e.to_string()))?;
    let mut prompts = SentencePrompts::new(
        std::sync::Arc::new(encoder),
        captions,
        CaptionLengths::load(dir)?,
    );
    prompts.tokens = config.text_control.is_some();
    Ok(PromptEncoder::Sentences(Box::new(prompts)))
}

/// The sentence encoder folder for a bundle: `<dir>/text-encoder`, `<dir>/../text-encoder`,
/// else the source tree's `models/text-encoder`.
pub fn text_encoder_dir(bundle: &Path) -> PathBuf {
    let has = |d: &Path| d.join("encoder.safetensors").exists();
    let own = bundle.join("text-encoder");
    if has(&own) {
        return own;
    }
    if let Some(parent) = bundle.parent() {
        let sibling = parent.join("text-encoder");
        if has(&sibling) {
            return sibling;
        }
    }
    default_encoder_dir()
}

/// One action of a model's training data: a caption and how many training clips (mirrored
/// copies not counted) carry it as their first caption.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainedAction {
    /// The caption ("a person squats down and stands back up").
    pub caption: String,
    /// Training clips showing it.
    pub clips: usize,
}

/// The actions listed in `<dir>/actions.json`, most clips first; empty when the bundle has
/// no such file (bundles trained before it existed).
pub fn trained_actions(dir: &Path) -> Result<Vec<TrainedAction>, WeightsError> {
    let p = dir.join("actions.json");
    if !p.exists() {
        return Ok(Vec::new());
    }
    serde_json::from_str(&read_text(&p)?).map_err(|e| mismatch(&p, format!("bad action list: {e}")))
}

/// The shipped model's training actions as (caption, clips), for the prompt card; empty
/// when its bundle has no list or cannot be read (the card then goes without).
pub fn shipped_actions() -> Vec<(String, usize)> {
    trained_actions(&default_model_dir())
        .unwrap_or_default()
        .into_iter()
        .map(|a| (a.caption, a.clips))
        .collect()
}

/// `<dir>/envelope.json`, the plausibility envelope measured on the bundle's training
/// data; `None` when the bundle has none (reports then use [`Envelope::builtin`], the
/// one this binary was built with, and say so).
///
/// [`Envelope::builtin`]: crate::dataset::envelope::Envelope::builtin
pub fn bundle_envelope(
    dir: &Path,
) -> Result<Option<crate::dataset::envelope::Envelope>, WeightsError> {
    let p = dir.join("envelope.json");
    if !p.exists() {
        return Ok(None);
    }
    crate::dataset::envelope::Envelope::load(&p)
        .map(Some)
        .map_err(|e| mismatch(&p, e.to_string()))
}

/// The envelope outputs of the bundle in `dir` are checked against: its own, else the
/// built-in one (with a note in its `source`).
pub fn envelope_or_builtin(dir: &Path) -> Result<crate::dataset::envelope::Envelope, WeightsError> {
    Ok(bundle_envelope(dir)?.unwrap_or_else(|| {
        let mut env = crate::dataset::envelope::Envelope::builtin();
        env.source = format!("{} (the model has no envelope.json)", env.source);
        env
    }))
}

/// Writes `<dir>/actions.json`.
pub fn save_trained_actions(dir: &Path, actions: &[TrainedAction]) -> Result<(), WeightsError> {
    let p = dir.join("actions.json");
    let text = serde_json::to_string_pretty(actions).expect("actions serialise");
    write_bytes_atomic(&p, text.as_bytes()).map_err(|e| write_err(&p, e))
}

/// Where the shipped model lives: `$MPROG_MODEL`, else `models/default` under the current
/// directory, else the one in the source tree this binary was built from.
pub fn default_model_dir() -> PathBuf {
    if let Ok(p) = std::env::var("MPROG_MODEL") {
        return PathBuf::from(p);
    }
    shipped_dir("models/default")
}

/// Where the shipped few-step model lives (the default model consistency-distilled,
/// `models/train-distil.toml`): `$MPROG_FAST_MODEL`, else `models/fast` as
/// [`default_model_dir`] finds `models/default`.
pub fn fast_model_dir() -> PathBuf {
    if let Ok(p) = std::env::var("MPROG_FAST_MODEL") {
        return PathBuf::from(p);
    }
    shipped_dir("models/fast")
}

/// `rel` under the current directory when a bundle is there, else in the source tree.
fn shipped_dir(rel: &str) -> PathBuf {
    let local = PathBuf::from(rel);
    if local.join("manifest.json").exists() {
        return local;
    }
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(rel)
}

#[cfg(test)]
mod envelope_tests {
    use super::*;

    #[test]
    fn a_bundle_without_an_envelope_falls_back_to_the_builtin_one() {
        let dir = tempfile::tempdir().unwrap();
        assert!(bundle_envelope(dir.path()).unwrap().is_none());
        let env = envelope_or_builtin(dir.path()).unwrap();
        assert!(env.source.starts_with("built in: "), "{}", env.source);
        assert!(env.source.ends_with("(the model has no envelope.json)"));
        let mut own = crate::dataset::envelope::Envelope::builtin();
        own.source = "own".into();
        own.save(&dir.path().join("envelope.json")).unwrap();
        assert_eq!(envelope_or_builtin(dir.path()).unwrap().source, "own");
        std::fs::write(dir.path().join("envelope.json"), "{}").unwrap();
        assert!(bundle_envelope(dir.path()).is_err());
    }
}
