//! A trained evaluator on disk and in memory: embeds motions and captions for FID,
//! diversity and R-precision.
//!
//! ```text
//! <dir>/manifest.json      format version, EncoderConfig, vocabulary size, training summary
//! <dir>/vocab.json         Vocabulary of the caption encoder
//! <dir>/mean.npy, std.npy  [263] feature statistics the motion encoder normalises with
//! <dir>/model.safetensors  both encoders (f16)
//! <dir>/README.md          model card
//! ```

use super::encoder::{EncoderConfig, EvaluatorNet, motion_batch, rows_of};
use super::error::{MetricsError, file_error};
use crate::dataset::store::{read_f32_npy, write_f32_npy};
use crate::fsutil::write_bytes_atomic;
use crate::model::text::{TokenBatch, Vocabulary};
use burn::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Version of the evaluator layout.
pub const EVALUATOR_VERSION: u32 = 1;

/// Motions or captions encoded per forward pass.
const EMBED_BATCH: usize = 64;

/// What is stored next to the weights.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EvaluatorManifest {
    /// [`EVALUATOR_VERSION`].
    pub version: u32,
    /// Network shape.
    pub config: EncoderConfig,
    /// Token ids of the caption encoder (vocabulary size + padding).
    pub vocab_size: usize,
    /// Optimisation steps.
    pub steps: usize,
    /// Wall seconds of training.
    pub train_seconds: f64,
    /// Mean contrastive loss over the last training steps.
    pub final_loss: f64,
    /// Top-1/2/3 R-precision of real validation clips with their own captions.
    pub val_r_precision: Option<[f64; 3]>,
    /// Training clips seen (train split, mirrored copies included).
    pub train_clips: usize,
    /// Whether the SafeTensors file holds f16 values.
    pub half_precision: bool,
}

/// A loaded evaluator.
#[derive(Debug)]
pub struct Evaluator {
    /// Manifest.
    pub manifest: EvaluatorManifest,
    /// Caption vocabulary.
    pub vocab: Vocabulary,
    /// `[F]` feature mean.
    pub mean: Vec<f32>,
    /// `[F]` feature std.
    pub std: Vec<f32>,
    /// The networks (inference copy).
    pub net: EvaluatorNet,
}

/// Where the shipped evaluator lives: `$MPROG_EVALUATOR`, else `models/evaluator` under
/// the current directory, else the one in the source tree this binary was built from.
pub fn default_evaluator_dir() -> PathBuf {
    if let Ok(p) = std::env::var("MPROG_EVALUATOR") {
        return PathBuf::from(p);
    }
    let local = PathBuf::from("models/evaluator");
    if local.join("manifest.json").exists() {
        return local;
    }
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models/evaluator")
}

fn read_text(path: &Path) -> Result<String, MetricsError> {
    std::fs::read_to_string(path).map_err(|e| file_error(path, e))
}

/// SafeTensors bytes of the networks.
pub fn net_to_safetensors(net: &EvaluatorNet, half: bool) -> Result<Vec<u8>, String> {
    crate::model::weights::module_to_safetensors(net, half)
}

/// Loads SafeTensors bytes into fresh networks; every tensor must be there, shaped right.
pub fn net_from_safetensors(
    net: EvaluatorNet,
    bytes: Vec<u8>,
    half: bool,
) -> Result<EvaluatorNet, String> {
    crate::model::weights::module_from_safetensors(net, bytes, half, "evaluator")
}

impl Evaluator {
    /// Loads an evaluator, checking its version and every shape.
    pub fn load(dir: &Path, device: &Device) -> Result<Evaluator, MetricsError> {
        let manifest_path = dir.join("manifest.json");
        let manifest: EvaluatorManifest = serde_json::from_str(&read_text(&manifest_path)?)
            .map_err(|e| file_error(&manifest_path, format!("bad evaluator manifest: {e}")))?;
        if manifest.version != EVALUATOR_VERSION {
            return Err(file_error(
                &manifest_path,
                format!(
                    "evaluator version {} but this mprog reads version {EVALUATOR_VERSION}; retrain it with `mprog eval train-encoder`",
                    manifest.version
                ),
            ));
        }
        manifest
            .config
            .validate()
            .map_err(|e| file_error(&manifest_path, e))?;
        let vocab_path = dir.join("vocab.json");
        let vocab: Vocabulary = serde_json::from_str(&read_text(&vocab_path)?)
            .map_err(|e| file_error(&vocab_path, format!("bad vocabulary: {e}")))?;
        if vocab.len() != manifest.vocab_size {
            return Err(file_error(
                &vocab_path,
                format!(
                    "{} token ids but the manifest says {}",
                    vocab.len(),
                    manifest.vocab_size
                ),
            ));
        }
        let stat = |name: &str| -> Result<Vec<f32>, MetricsError> {
            let p = dir.join(name);
            let (_, v) = read_f32_npy(&p, &[]).map_err(|e| file_error(&p, e))?;
            if v.len() != manifest.config.features || v.iter().any(|x| !x.is_finite()) {
                return Err(file_error(
                    &p,
                    format!(
                        "{} values (finite ones expected), the evaluator reads {} features",
                        v.len(),
                        manifest.config.features
                    ),
                ));
            }
            Ok(v)
        };
        let mean = stat("mean.npy")?;
        let std = stat("std.npy")?;
        if std.iter().any(|s| *s <= 0.0) {
            return Err(file_error(&dir.join("std.npy"), "std must be positive"));
        }
        let weights_path = dir.join("model.safetensors");
        let bytes = std::fs::read(&weights_path).map_err(|e| file_error(&weights_path, e))?;
        let fresh = EvaluatorNet::new(&manifest.config, manifest.vocab_size, device);
        let net = net_from_safetensors(fresh, bytes, manifest.half_precision)
            .map_err(|e| file_error(&weights_path, e))?;
        Ok(Evaluator {
            manifest,
            vocab,
            mean,
            std,
            net: net.valid(),
        })
    }

    /// Writes the evaluator to `dir` (each file atomically), with its model card.
    pub fn save(&self, dir: &Path) -> Result<(), MetricsError> {
        std::fs::create_dir_all(dir).map_err(|e| file_error(dir, e))?;
        let put = |name: &str, bytes: &[u8]| {
            let p = dir.join(name);
            write_bytes_atomic(&p, bytes).map_err(|e| file_error(&p, e))
        };
        let manifest = serde_json::to_string_pretty(&self.manifest)
            .map_err(|e| file_error(&dir.join("manifest.json"), e))?;
        put("manifest.json", manifest.as_bytes())?;
        let vocab = serde_json::to_string_pretty(&self.vocab)
            .map_err(|e| file_error(&dir.join("vocab.json"), e))?;
        put("vocab.json", vocab.as_bytes())?;
        for (name, v) in [("mean.npy", &self.mean), ("std.npy", &self.std)] {
            let p = dir.join(name);
            write_f32_npy(&p, &[v.len() as u64], v).map_err(|e| file_error(&p, e))?;
        }
        let p = dir.join("model.safetensors");
        let bytes = net_to_safetensors(&self.net, self.manifest.half_precision)
            .map_err(|e| file_error(&p, e))?;
        put("model.safetensors", &bytes)?;
        put(
            "README.md",
            super::card::model_card(&self.manifest).as_bytes(),
        )
    }

    /// Embeds motions given as de-normalised feature rows (`[frames, F]` each).
    pub fn embed_motions(
        &self,
        motions: &[&[f32]],
        device: &Device,
    ) -> Result<Vec<Vec<f32>>, MetricsError> {
        let f = self.manifest.config.features;
        if let Some(bad) = motions
            .iter()
            .position(|m| m.is_empty() || !m.len().is_multiple_of(f))
        {
            return Err(MetricsError::Invalid(format!(
                "motion {bad} has {} values, not a positive multiple of {f} features",
                motions[bad].len()
            )));
        }
        let mut out = Vec::with_capacity(motions.len());
        for chunk in motions.chunks(EMBED_BATCH) {
            let (x, valid) = motion_batch(
                chunk,
                &self.mean,
                &self.std,
                self.manifest.config.max_frames,
                device,
            );
            out.extend(rows_of(self.net.motion.forward(x, valid)).map_err(MetricsError::Invalid)?);
        }
        Ok(out)
    }

    /// Embeds captions (unknown words are ignored, as in generation).
    pub fn embed_captions(
        &self,
        captions: &[&str],
        device: &Device,
    ) -> Result<Vec<Vec<f32>>, MetricsError> {
        let mut out = Vec::with_capacity(captions.len());
        for chunk in captions.chunks(EMBED_BATCH) {
            let tokens = TokenBatch::new(&self.vocab, chunk, device);
            out.extend(rows_of(self.net.text.forward(&tokens)).map_err(MetricsError::Invalid)?);
        }
        Ok(out)
    }
}
