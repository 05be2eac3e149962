//! What a prompt becomes for the denoiser, for either text encoder: token ids for a
//! bag-of-words model, sentence vectors for a model conditioned on the frozen sentence
//! encoder. [`PromptEncoder`] is the bundle's side (prompts → [`TextBatch`], and what to
//! tell the user about a prompt); [`TextBatch`] is what travels in a `DenoiserInput`.

use super::lengths::CaptionLengths;
use super::sentence::{
    CaptionIndex, FAR_COSINE, Nearest, SNAP_COSINE, SentenceEncoder, Snapped, TokenStates,
};
use super::text::{TokenBatch, Vocabulary};
use burn::prelude::*;
use std::sync::Arc;

/// Words that name a side; the mirrored question swaps them.
pub const SIDE_WORDS: [(&str, &str); 2] = [("left", "right"), ("clockwise", "counterclockwise")];

/// A prompt with its side words swapped ("turns left" → "turns right"), as the training
/// data's mirrored copies are captioned.
pub fn swap_side_words(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut word = String::new();
    let flush = |word: &mut String, out: &mut String| {
        let lower = word.to_lowercase();
        let swapped = SIDE_WORDS
            .iter()
            .find_map(|&(a, b)| (lower == a).then_some(b).or((lower == b).then_some(a)));
        out.push_str(swapped.unwrap_or(word));
        word.clear();
    };
    for c in text.chars() {
        if c.is_alphanumeric() {
            word.push(c);
        } else {
            flush(&mut word, &mut out);
            out.push(c);
        }
    }
    flush(&mut word, &mut out);
    out
}

/// Sentence vectors of a batch of prompts and of their side-swapped versions.
#[derive(Clone, Debug)]
pub struct SentenceBatch {
    /// `[B, D]` unit vectors.
    pub vectors: Tensor<2>,
    /// `[B, D]` vectors of the prompts with left and right swapped (for mirror averaging).
    pub mirrored: Tensor<2>,
    /// The prompts' token states, for a model with a text ControlNet (`model::moc`); None
    /// for a model that reads the vectors alone.
    pub tokens: Option<Box<PromptTokens>>,
}

/// Token states of a batch of prompts and of their side-swapped versions.
#[derive(Clone, Debug)]
pub struct PromptTokens {
    /// The prompts as written.
    pub own: TokenStates,
    /// The prompts with left and right swapped (for mirror averaging).
    pub mirrored: TokenStates,
}

impl PromptTokens {
    /// `self` then `other`, along the batch.
    pub fn concat(self, other: PromptTokens) -> PromptTokens {
        PromptTokens {
            own: self.own.concat(other.own),
            mirrored: self.mirrored.concat(other.mirrored),
        }
    }

    /// The same batch with each prompt's sides swapped.
    pub fn swapped(self) -> PromptTokens {
        PromptTokens {
            own: self.mirrored,
            mirrored: self.own,
        }
    }
}

/// Both optional token batches concatenated; a model reads tokens for every sample or none.
fn concat_tokens(
    a: Option<Box<PromptTokens>>,
    b: Option<Box<PromptTokens>>,
) -> Option<Box<PromptTokens>> {
    match (a, b) {
        (Some(a), Some(b)) => Some(Box::new(a.concat(*b))),
        (None, None) => None,
        _ => unreachable!("one prompt encoder builds every text batch of a run"),
    }
}

/// The text condition of a batch, in the form the model's encoder reads.
#[derive(Clone, Debug)]
pub enum TextBatch {
    /// Token ids for a bag-of-words model.
    Words(TokenBatch),
    /// Sentence vectors for a sentence-encoder model.
    Sentences(SentenceBatch),
}

impl TextBatch {
    /// This batch followed by itself (the unconditional half of classifier-free guidance).
    pub fn doubled(&self) -> TextBatch {
        self.clone().concat(self.clone())
    }

    /// `self` then `other`, along the batch.
    pub fn concat(self, other: TextBatch) -> TextBatch {
        match (self, other) {
            (TextBatch::Words(a), TextBatch::Words(b)) => {
                let len = pad_width(a.ids.dims()[1], b.ids.dims()[1]);
                TextBatch::Words(TokenBatch {
                    ids: Tensor::cat(vec![pad_ids(a.ids, len), pad_ids(b.ids, len)], 0),
                    mask: Tensor::cat(vec![pad_mask(a.mask, len), pad_mask(b.mask, len)], 0),
                    unknown: [a.unknown, b.unknown].concat(),
                })
            }
            (TextBatch::Sentences(a), TextBatch::Sentences(b)) => {
                TextBatch::Sentences(SentenceBatch {
                    vectors: Tensor::cat(vec![a.vectors, b.vectors], 0),
                    mirrored: Tensor::cat(vec![a.mirrored, b.mirrored], 0),
                    tokens: concat_tokens(a.tokens, b.tokens),
                })
            }
            _ => unreachable!("one prompt encoder builds every text batch of a run"),
        }
    }
}

/// Widths padded to the longer of two `[B, L]` token batches, with PAD ids and mask 0.
fn pad_width(a: usize, b: usize) -> usize {
    a.max(b)
}

fn pad_ids(t: Tensor<2, Int>, len: usize) -> Tensor<2, Int> {
    let [rows, l] = t.dims();
    if l == len {
        return t;
    }
    let zeros = Tensor::<2, Int>::zeros([rows, len - l], &t.device());
    Tensor::cat(vec![t, zeros], 1)
}

fn pad_mask(t: Tensor<2>, len: usize) -> Tensor<2> {
    let [rows, l] = t.dims();
    if l == len {
        return t;
    }
    let zeros = Tensor::<2>::zeros([rows, len - l], &t.device());
    Tensor::cat(vec![t, zeros], 1)
}

/// The sentence encoder with the captions a model was trained on.
#[derive(Clone, Debug)]
pub struct SentencePrompts {
    /// The frozen encoder.
    pub encoder: Arc<SentenceEncoder>,
    /// The training captions, embedded (for "nearest known caption").
    pub captions: CaptionIndex,
    /// Median clip length of each training caption (empty for older bundles).
    pub lengths: CaptionLengths,
    /// A prompt whose best cosine with a caption is below this is conditioned on its
    /// neighbours instead ([`CaptionIndex::snap`]); 0 reads every prompt as written.
    pub snap_below: f32,
    /// Whether the model reads the prompts' token states too (a text ControlNet,
    /// `model::moc`). Tokens are never snapped: reading unseen wordings token by token is
    /// what OMG's design is for.
    pub tokens: bool,
}

impl SentencePrompts {
    /// Encoder, captions and lengths, snapping far prompts at [`SNAP_COSINE`].
    pub fn new(
        encoder: Arc<SentenceEncoder>,
        captions: CaptionIndex,
        lengths: CaptionLengths,
    ) -> SentencePrompts {
        SentencePrompts {
            encoder,
            captions,
            lengths,
            snap_below: SNAP_COSINE,
            tokens: false,
        }
    }

    /// The token states of `prompts` and of their side-swapped versions, on `device`.
    pub fn tokens_of(&self, prompts: &[&str], device: &Device) -> PromptTokens {
        let swapped: Vec<String> = prompts.iter().map(|p| swap_side_words(p)).collect();
        // Each distinct sentence once (most prompts name no side, and a batch repeats).
        let mut distinct: Vec<&str> = Vec::new();
        let rows: Vec<i64> = prompts
            .iter()
            .copied()
            .chain(swapped.iter().map(String::as_str))
            .map(|s| {
                let at = distinct.iter().position(|d| *d == s);
                at.unwrap_or_else(|| {
                    distinct.push(s);
                    distinct.len() - 1
                }) as i64
            })
            .collect();
        let states = self.encoder.encode_tokens(&distinct).to_device(device);
        let b = prompts.len();
        let pick = |from: usize| {
            let ids = Tensor::<1, Int>::from_data(
                TensorData::new(rows[from..from + b].to_vec(), [b]),
                device,
            );
            TokenStates {
                states: states.states.clone().select(0, ids.clone()),
                mask: states.mask.clone().select(0, ids),
            }
        };
        PromptTokens {
            own: pick(0),
            mirrored: pick(b),
        }
    }
}

/// Turns prompts into a model's text condition.
#[derive(Clone, Debug)]
pub enum PromptEncoder {
    /// A bag-of-words model's vocabulary.
    Words(Vocabulary),
    /// A sentence-encoder model's encoder and training captions.
    Sentences(Box<SentencePrompts>),
}

impl PromptEncoder {
    /// Ids of the denoiser's word table (0 for a sentence model, which has none).
    pub fn vocab_size(&self) -> usize {
        match self {
            PromptEncoder::Words(vocab) => vocab.len(),
            PromptEncoder::Sentences(_) => 0,
        }
    }

    /// The text condition of `prompts`, one per sample.
    pub fn batch(&self, prompts: &[&str], device: &Device) -> TextBatch {
        match self {
            PromptEncoder::Words(vocab) => {
                TextBatch::Words(TokenBatch::new(vocab, prompts, device))
            }
            PromptEncoder::Sentences(s) => {
                let b = prompts.len();
                let swapped: Vec<String> = prompts.iter().map(|p| swap_side_words(p)).collect();
                let mut all: Vec<&str> = prompts.to_vec();
                all.extend(swapped.iter().map(String::as_str));
                let both = s.encoder.encode(&all).to_device(device);
                let (both, _) = s.captions.snap(both, s.snap_below);
                TextBatch::Sentences(SentenceBatch {
                    vectors: both.clone().narrow(0, 0, b),
                    mirrored: both.narrow(0, b, b),
                    tokens: s.tokens.then(|| Box::new(s.tokens_of(prompts, device))),
                })
            }
        }
    }

    /// Reads every prompt as written (`--literal-prompt`): no snapping to the nearest
    /// captions. Nothing changes for a bag-of-words model.
    pub fn read_literally(&mut self) {
        if let PromptEncoder::Sentences(s) = self {
            s.snap_below = 0.0;
        }
    }

    /// The neighbours that stand in for `prompt` when it is snapped; None when it is read
    /// as written (or the model reads words).
    pub fn snapped(&self, prompt: &str) -> Option<Snapped> {
        let PromptEncoder::Sentences(s) = self else {
            return None;
        };
        let vectors = s.encoder.encode(&[prompt]);
        s.captions.snap(vectors, s.snap_below).1.pop().flatten()
    }

    /// Words of `prompt` the model cannot read (always none for a sentence encoder).
    pub fn unknown_words(&self, prompt: &str) -> Vec<String> {
        match self {
            PromptEncoder::Words(vocab) => vocab.tokenize(prompt).1,
            PromptEncoder::Sentences(_) => Vec::new(),
        }
    }

    /// The training caption nearest to `prompt` (None for a bag-of-words model).
    pub fn nearest_caption(&self, prompt: &str) -> Option<Nearest> {
        match self {
            PromptEncoder::Words(_) => None,
            PromptEncoder::Sentences(s) => s.captions.nearest(&s.encoder, &[prompt]).pop(),
        }
    }

    /// The length prior's proposal for `prompt` ([`super::lengths`]) in frames, with the
    /// nearest training caption. None for a bag-of-words model or a bundle without lengths.
    pub fn natural_frames(&self, prompt: &str, max_frames: usize) -> Option<(usize, Nearest)> {
        let PromptEncoder::Sentences(s) = self else {
            return None;
        };
        if s.lengths.is_empty() {
            return None;
        }
        s.lengths
            .propose(&s.captions, &s.encoder, prompt, max_frames)
    }

    /// What the model makes of a prompt, as lines for the user: for a bag-of-words model
    /// the words read as a known inflection and the words ignored; for a sentence-encoder
    /// model a warning when the prompt lies far from every training caption, with the
    /// nearest one. Empty when there is nothing to say.
    pub fn report(&self, prompt: &str) -> Vec<String> {
        match self {
            PromptEncoder::Words(vocab) => vocab.word_report(prompt),
            PromptEncoder::Sentences(_) => {
                let mut lines = match self.nearest_caption(prompt) {
                    Some(n) if n.cosine < FAR_COSINE => vec![far_prompt_line(&n)],
                    _ => Vec::new(),
                };
                lines.extend(self.snapped(prompt).map(|s| snapped_line(&s)));
                lines
            }
        }
    }
}

/// The user-facing line for a prompt far from every training caption.
pub fn far_prompt_line(n: &Nearest) -> String {
    format!(
        "the prompt is far from every caption the model was trained on (cosine {:.2} < {FAR_COSINE}); nearest known: \"{}\"",
        n.cosine, n.caption
    )
}

/// The user-facing line for a prompt conditioned on its neighbours.
pub fn snapped_line(s: &Snapped) -> String {
    let shown: Vec<String> = s
        .neighbours
        .iter()
        .take(3)
        .map(|c| format!("\"{c}\""))
        .collect();
    let more = match s.neighbours.len().saturating_sub(3) {
        0 => String::new(),
        k => format!(" and {k} more"),
    };
    format!(
        "the model has not read a caption like this (best cosine {:.2} < {SNAP_COSINE}): it is conditioned on the mean of its nearest captions, {}{more}; --literal-prompt reads it as written",
        s.best,
        shown.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn side_words_swap_as_whole_words() {
        assert_eq!(
            swap_side_words("A person turns Left, then right; upright"),
            "A person turns right, then left; upright"
        );
        assert_eq!(swap_side_words("walks clockwise"), "walks counterclockwise");
        assert_eq!(swap_side_words(""), "");
    }

    #[test]
    fn word_batches_of_different_lengths_concatenate() {
        let dev = Device::flex();
        let v = Vocabulary::from_captions(["walk run jump"], 8);
        let a = TextBatch::Words(TokenBatch::new(&v, &["walk"], &dev));
        let b = TextBatch::Words(TokenBatch::new(&v, &["walk run jump"], &dev));
        let TextBatch::Words(t) = a.concat(b) else {
            panic!("words stay words")
        };
        assert_eq!(t.ids.dims(), [2, 3]);
        let mask = t.mask.into_data().try_into_vec::<f32>().unwrap();
        assert_eq!(mask, vec![1.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
    }
}
