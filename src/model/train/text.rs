//! The text side of a training run: a vocabulary for a bag-of-words model, or the frozen
//! sentence encoder with every training caption embedded once (`captions.safetensors` in
//! the run folder), so a step looks its captions up instead of running BERT.

use super::{TrainError, TrainRun, file_err};
use crate::dataset::{Dataset, Split};
use crate::fsutil::write_bytes_atomic;
use crate::model::config::TextEncoderKind;
use crate::model::lengths::CaptionLengths;
use crate::model::prompt::{
    PromptEncoder, SentenceBatch, SentencePrompts, TextBatch, swap_side_words,
};
use crate::model::sentence::{CaptionIndex, SentenceEncoder, default_encoder_dir};
use crate::model::text::{TokenBatch, Vocabulary};
use crate::model::weights::TrainedAction;
use burn::prelude::*;
use std::collections::HashMap;
use std::sync::Arc;

/// How a run turns its captions into the denoiser's text condition.
#[derive(Clone, Debug)]
pub enum TrainText {
    /// Bag of words over the run's vocabulary.
    Words(Vocabulary),
    /// Frozen sentence encoder; `rows` maps each indexed caption to its row.
    Sentences {
        /// Encoder and caption index (also what the bundle ships).
        prompts: Box<SentencePrompts>,
        /// Caption (or paraphrase) → row of `table`.
        rows: HashMap<String, usize>,
        /// `prompts.captions`' vectors, then the paraphrases' ([`TrainText::add_wordings`]).
        table: Box<Tensor<2>>,
    },
}

impl TrainText {
    /// A sentence-encoder run's text side.
    pub fn sentences(
        encoder: Arc<SentenceEncoder>,
        captions: CaptionIndex,
        lengths: CaptionLengths,
    ) -> TrainText {
        let rows = captions
            .captions()
            .iter()
            .enumerate()
            .map(|(i, c)| (c.clone(), i))
            .collect();
        let table = Box::new(captions.embeddings().clone());
        TrainText::Sentences {
            prompts: Box::new(SentencePrompts::new(encoder, captions, lengths)),
            rows,
            table,
        }
    }

    /// Adds the rows of `extra` (paraphrases and their side-swapped twins) to the
    /// sentence table, so a step looks them up instead of running the encoder.
    pub fn add_wordings(&mut self, extra: &CaptionIndex) {
        if let TrainText::Sentences { rows, table, .. } = self {
            let base = table.dims()[0];
            let mut added = 0;
            for (i, c) in extra.captions().iter().enumerate() {
                if !rows.contains_key(c) {
                    added += 1;
                }
                rows.entry(c.clone()).or_insert(base + i);
            }
            if added > 0 {
                let more = extra.embeddings().clone().to_device(&table.device());
                **table = Tensor::cat(vec![(**table).clone(), more], 0);
            }
        }
    }

    /// Ids of the bag-of-words embedding (0 for a sentence run, which has none).
    pub fn vocab_size(&self) -> usize {
        match self {
            TrainText::Words(v) => v.len(),
            TrainText::Sentences { .. } => 0,
        }
    }

    /// What the run's bundles ship to read prompts.
    pub fn prompt_encoder(&self) -> PromptEncoder {
        match self {
            TrainText::Words(v) => PromptEncoder::Words(v.clone()),
            TrainText::Sentences { prompts, .. } => PromptEncoder::Sentences(prompts.clone()),
        }
    }

    /// The condition of a batch of captions on `device`. Captions outside the index (word
    /// dropout's shortened captions) are encoded on the spot.
    pub fn batch(&self, captions: &[&str], device: &Device) -> TextBatch {
        match self {
            TrainText::Words(v) => TextBatch::Words(TokenBatch::new(v, captions, device)),
            TrainText::Sentences {
                prompts,
                rows,
                table: known,
            } => {
                // Each caption, then each caption with its sides swapped (the side input's
                // other half; the data's mirrored copies hold most of them).
                let swapped: Vec<String> = captions.iter().map(|c| swap_side_words(c)).collect();
                let all: Vec<&str> = captions
                    .iter()
                    .copied()
                    .chain(swapped.iter().map(String::as_str))
                    .collect();
                let n_known = known.dims()[0];
                let mut extra: Vec<&str> = Vec::new();
                let ids: Vec<i64> = all
                    .iter()
                    .map(|c| match rows.get(*c) {
                        Some(&r) => r as i64,
                        None => {
                            let k = extra.iter().position(|e| e == c).unwrap_or_else(|| {
                                extra.push(c);
                                extra.len() - 1
                            });
                            (n_known + k) as i64
                        }
                    })
                    .collect();
                let known: &Tensor<2> = known;
                let table = if extra.is_empty() {
                    known.clone()
                } else {
                    let fresh = prompts.encoder.encode(&extra).to_device(&known.device());
                    Tensor::cat(vec![known.clone(), fresh], 0)
                };
                let n = ids.len();
                let ids = Tensor::<1, Int>::from_data(TensorData::new(ids, [n]), &known.device());
                let both = table.select(0, ids).to_device(device);
                let b = captions.len();
                TextBatch::Sentences(SentenceBatch {
                    vectors: both.clone().narrow(0, 0, b),
                    mirrored: both.narrow(0, b, b),
                    tokens: prompts
                        .tokens
                        .then(|| Box::new(prompts.tokens_of(captions, device))),
                })
            }
        }
    }
}

impl TrainRun<'_> {
    /// The run's text side: a vocabulary for a bag-of-words model, else the sentence
    /// encoder with every caption of the data embedded (read back when it covers them).
    pub(super) fn train_text(&self, plain: &Device) -> Result<TrainText, TrainError> {
        if self.config.model.text_encoder == TextEncoderKind::BagOfWords {
            return self.vocabulary().map(TrainText::Words);
        }
        let dir = self
            .text_encoder
            .clone()
            .unwrap_or_else(default_encoder_dir);
        let encoder = SentenceEncoder::load(&dir, plain).map_err(|e| file_err(&dir, e))?;
        if encoder.dim() != self.config.model.d_text {
            return Err(TrainError::Invalid(format!(
                "[model] `d_text` is {} but the sentence encoder in {} gives {}-d vectors",
                self.config.model.d_text,
                dir.display(),
                encoder.dim()
            )));
        }
        let captions: Vec<&str> = self
            .data
            .index
            .clips
            .iter()
            .flat_map(|c| c.captions.iter().map(String::as_str))
            .collect();
        let p = self.out.join("captions.safetensors");
        let cached = CaptionIndex::load(&p, plain)
            .ok()
            .filter(|index| index.covers(&captions));
        let index = match cached {
            Some(index) => index,
            None => {
                eprintln!(
                    "embedding {} captions with the sentence encoder ...",
                    captions.len()
                );
                let index = CaptionIndex::build(&encoder, &captions);
                std::fs::create_dir_all(&self.out).map_err(|e| file_err(&self.out, e))?;
                index.save(&p).map_err(|e| file_err(&p, e))?;
                index
            }
        };
        let mut text = TrainText::sentences(
            Arc::new(encoder),
            index,
            CaptionLengths::of_dataset(self.data),
        );
        if let TrainText::Sentences { prompts, .. } = &mut text {
            // A text ControlNet reads each caption's token states, encoded per batch.
            prompts.tokens = self.config.model.text_control.is_some();
        }
        Ok(text)
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
}

/// The first caption of every training clip (mirrored copies not counted), with how many
/// clips carry it, most first.
pub fn trained_actions_of(data: &Dataset) -> Vec<TrainedAction> {
    let mut counts: std::collections::BTreeMap<&str, usize> = Default::default();
    for clip in data.clips(Split::Train).filter(|c| !c.mirrored) {
        if let Some(caption) = clip.captions.first() {
            *counts.entry(caption.as_str()).or_default() += 1;
        }
    }
    let mut actions: Vec<TrainedAction> = counts
        .into_iter()
        .map(|(caption, clips)| TrainedAction {
            caption: caption.to_string(),
            clips,
        })
        .collect();
    actions.sort_by(|a, b| b.clips.cmp(&a.clips).then(a.caption.cmp(&b.caption)));
    actions
}
