//! Nearest known caption of a prompt: the training captions embedded once, kept as
//! `[N, 384]` unit vectors, searched by dot product (cosine). Backs the planned
//! `mprog check` hint "prompt far from every training caption; nearest known: …".
//!
//! The cache file is SafeTensors: one f16 tensor `embeddings` `[N, dim]`, the captions as
//! a JSON array in the header's `__metadata__.captions`.

use super::{SentenceEncoder, SentenceError};
use burn::prelude::*;
use half::f16;
use std::collections::HashMap;
use std::path::Path;

/// Suggested threshold: a prompt whose best cosine is below this is far from every
/// caption. Measured on the caption set of `scripts/text_encoder_captions.py` (see
/// `models/text-encoder/README.md`): 34 paraphrases of known actions score 0.59 and up,
/// unrelated text 0.32 at most, motions outside the data 0.32–0.55.
pub const FAR_COSINE: f32 = 0.5;

/// Below this best cosine a prompt is not given to the model as written: it is replaced by
/// the mean of its nearest captions (see [`CaptionIndex::snap`]). Between `FAR_COSINE` and
/// here lie paraphrases the model has never read ("a person hurries": best 0.56, a walk);
/// their raw vectors sit off the few hundred points the denoiser was trained on, and it
/// answers them with a standing pose instead of what their neighbours do.
pub const SNAP_COSINE: f32 = 0.7;

/// Captions this close to a prompt's best cosine are its neighbours (the length prior's and
/// snapping's rule).
pub const NEIGHBOUR_MARGIN: f32 = 0.05;

/// A prompt replaced by its neighbours.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapped {
    /// The prompt's best cosine with a training caption.
    pub best: f32,
    /// The neighbours whose mean vector stands in for the prompt, nearest first.
    pub neighbours: Vec<String>,
}

/// The closest caption and its cosine.
#[derive(Clone, Debug, PartialEq)]
pub struct Nearest {
    /// The caption.
    pub caption: String,
    /// Cosine similarity in [-1, 1].
    pub cosine: f32,
}

/// Captions with their sentence vectors.
#[derive(Clone, Debug)]
pub struct CaptionIndex {
    captions: Vec<String>,
    embeddings: Tensor<2>,
}

impl CaptionIndex {
    /// Embeds `captions` (duplicates are kept once).
    pub fn build(encoder: &SentenceEncoder, captions: &[&str]) -> CaptionIndex {
        let mut unique: Vec<&str> = captions.to_vec();
        unique.sort_unstable();
        unique.dedup();
        CaptionIndex {
            embeddings: encoder.encode(&unique),
            captions: unique.into_iter().map(String::from).collect(),
        }
    }

    /// `[N, dim]` unit vectors, one row per caption in [`Self::captions`]' order.
    pub fn embeddings(&self) -> &Tensor<2> {
        &self.embeddings
    }

    /// The captions, sorted.
    pub fn captions(&self) -> &[String] {
        &self.captions
    }

    /// Whether this index holds exactly the distinct `captions` (else rebuild it).
    pub fn covers(&self, captions: &[&str]) -> bool {
        let mut want: Vec<&str> = captions.to_vec();
        want.sort_unstable();
        want.dedup();
        want.iter().eq(self.captions.iter())
    }

    /// Nearest caption of each prompt; empty when the index is.
    pub fn nearest(&self, encoder: &SentenceEncoder, prompts: &[&str]) -> Vec<Nearest> {
        if self.captions.is_empty() || prompts.is_empty() {
            return Vec::new();
        }
        let sims = encoder
            .encode(prompts)
            .matmul(self.embeddings.clone().transpose());
        let best = sims.clone().argmax(1).into_data().try_to_vec_as::<i64>();
        let cos = sims.max_dim(1).into_data().try_to_vec_as::<f32>();
        match (best, cos) {
            (Ok(best), Ok(cos)) => best
                .into_iter()
                .zip(cos)
                .map(|(i, cosine)| Nearest {
                    caption: self.captions[i as usize].clone(),
                    cosine,
                })
                .collect(),
            _ => unreachable!("argmax and max_dim read back as converted"),
        }
    }

    /// Cosine of `prompt` with every caption, in [`Self::captions`]' order.
    pub fn similarities(&self, encoder: &SentenceEncoder, prompt: &str) -> Vec<f32> {
        if self.captions.is_empty() {
            return Vec::new();
        }
        encoder
            .encode(&[prompt])
            .matmul(self.embeddings.clone().transpose())
            .into_data()
            .try_to_vec_as::<f32>()
            .expect("float tensors read back as f32")
    }

    /// Each row of `vectors` (`[B, dim]` unit prompt vectors) whose best cosine with a
    /// caption is below `below`, replaced by the normalised mean of its neighbours' vectors
    /// (the captions within [`NEIGHBOUR_MARGIN`] of the best); rows at or above it, and
    /// every row when the index is empty, are returned unchanged. The model is then
    /// conditioned on a point it was trained on, so an unseen paraphrase does what its
    /// neighbours do.
    pub fn snap(&self, vectors: Tensor<2>, below: f32) -> (Tensor<2>, Vec<Option<Snapped>>) {
        let [b, dim] = vectors.dims();
        if self.captions.is_empty() || b == 0 {
            return (vectors, vec![None; b]);
        }
        let n = self.captions.len();
        let device = vectors.device();
        let sims = vectors
            .clone()
            .matmul(self.embeddings.clone().to_device(&device).transpose())
            .into_data()
            .try_to_vec_as::<f32>()
            .expect("float tensors read back as f32");
        let mut rows = vectors
            .to_data()
            .try_to_vec_as::<f32>()
            .expect("float tensors read back as f32");
        let mut table: Option<Vec<f32>> = None;
        let mut report = Vec::with_capacity(b);
        for (i, row_sims) in sims.chunks_exact(n).enumerate() {
            let best = row_sims.iter().copied().fold(f32::NEG_INFINITY, f32::max);
            if best >= below {
                report.push(None);
                continue;
            }
            let mut near: Vec<usize> = (0..n)
                .filter(|&c| row_sims[c] >= best - NEIGHBOUR_MARGIN)
                .collect();
            near.sort_by(|&a, &c| row_sims[c].total_cmp(&row_sims[a]));
            let table = table.get_or_insert_with(|| {
                self.embeddings
                    .to_data()
                    .try_to_vec_as::<f32>()
                    .expect("float tensors read back as f32")
            });
            let row = &mut rows[i * dim..(i + 1) * dim];
            row.fill(0.0);
            for &c in &near {
                for (r, e) in row.iter_mut().zip(&table[c * dim..(c + 1) * dim]) {
                    *r += e;
                }
            }
            let norm = row.iter().map(|v| v * v).sum::<f32>().sqrt().max(1e-12);
            row.iter_mut().for_each(|v| *v /= norm);
            report.push(Some(Snapped {
                best,
                neighbours: near.iter().map(|&c| self.captions[c].clone()).collect(),
            }));
        }
        (
            Tensor::from_data(TensorData::new(rows, [b, dim]), &device),
            report,
        )
    }

    /// Writes the index as SafeTensors (f16).
    pub fn save(&self, path: &Path) -> Result<(), SentenceError> {
        let [n, dim] = self.embeddings.dims();
        let values = self.embeddings.to_data().try_to_vec_as::<f32>();
        let values = values.expect("float tensors read back as f32");
        let mut data = Vec::with_capacity(values.len() * 2);
        for v in &values {
            data.extend_from_slice(&f16::from_f32(*v).to_le_bytes());
        }
        let captions = serde_json::to_string(&self.captions).expect("strings serialise");
        let header = serde_json::json!({
            "__metadata__": { "captions": captions },
            "embeddings": { "dtype": "F16", "shape": [n, dim], "data_offsets": [0, data.len()] },
        })
        .to_string();
        let mut bytes = (header.len() as u64).to_le_bytes().to_vec();
        bytes.extend_from_slice(header.as_bytes());
        bytes.extend_from_slice(&data);
        crate::fsutil::write_bytes_atomic(path, &bytes).map_err(|e| SentenceError::Write {
            path: path.to_path_buf(),
            reason: e.to_string(),
        })
    }

    /// Reads an index written by [`CaptionIndex::save`].
    pub fn load(path: &Path, device: &Device) -> Result<CaptionIndex, SentenceError> {
        let bytes = std::fs::read(path).map_err(|e| SentenceError::read(path, e))?;
        let (captions, n, dim, data) =
            parse(&bytes).map_err(|r| SentenceError::invalid(path, r))?;
        let values: Vec<f32> = data
            .chunks_exact(2)
            .map(|b| f16::from_le_bytes([b[0], b[1]]).to_f32())
            .collect();
        Ok(CaptionIndex {
            captions,
            embeddings: Tensor::from_data(TensorData::new(values, [n, dim]), device),
        })
    }
}

#[derive(serde::Deserialize)]
struct TensorEntry {
    dtype: String,
    shape: Vec<usize>,
    data_offsets: [usize; 2],
}

/// Captions, rows, width and the f16 bytes of a cache file.
type Parsed<'a> = (Vec<String>, usize, usize, &'a [u8]);

fn parse(bytes: &[u8]) -> Result<Parsed<'_>, String> {
    let too_short = || "too short for a SafeTensors file".to_string();
    let len = u64::from_le_bytes(bytes.get(..8).ok_or_else(too_short)?.try_into().unwrap());
    let end = usize::try_from(len).ok().and_then(|l| l.checked_add(8));
    let header = end.and_then(|e| bytes.get(8..e)).ok_or_else(too_short)?;
    let mut header: HashMap<String, serde_json::Value> =
        serde_json::from_slice(header).map_err(|e| format!("bad SafeTensors header: {e}"))?;
    let captions: Vec<String> = header
        .remove("__metadata__")
        .and_then(|m| m.get("captions")?.as_str().map(String::from))
        .and_then(|c| serde_json::from_str(&c).ok())
        .ok_or("no captions in the header metadata")?;
    let entry: TensorEntry = header
        .remove("embeddings")
        .ok_or("no tensor \"embeddings\"")
        .and_then(|v| serde_json::from_value(v).map_err(|_| "bad \"embeddings\" entry"))?;
    let [n, dim] = entry.shape[..] else {
        return Err(format!(
            "embeddings have shape {:?}, expected [N, dim]",
            entry.shape
        ));
    };
    if entry.dtype != "F16" || n != captions.len() {
        return Err(format!(
            "embeddings are {} {:?} for {} captions, expected F16 [{}, dim]",
            entry.dtype,
            entry.shape,
            captions.len(),
            captions.len()
        ));
    }
    let body = &bytes[end.unwrap_or(8)..];
    let [a, b] = entry.data_offsets;
    match body.get(a..b) {
        Some(data) if b - a == n * dim * 2 => Ok((captions, n, dim, data)),
        _ => Err(format!(
            "tensor data {a}..{b} does not hold {n}×{dim} f16 values"
        )),
    }
}
