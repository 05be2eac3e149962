//! Text conditioning: a vocabulary built from the training captions and a small word
//! encoder trained with the denoiser (mean of learned word embeddings).
//!
//! The encoder sits behind [`TextEncoder`] so a pretrained sentence encoder can replace
//! it. Words outside the vocabulary are dropped and reported, never an error: a prompt
//! with unseen words still generates.

use burn::nn::{Embedding, EmbeddingConfig};
use burn::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Token id reserved for padding (and for prompts with no known word).
pub const PAD: usize = 0;

/// Words seen in the training captions, with stable ids (1..).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Vocabulary {
    /// Word → id; ids start at 1.
    pub words: BTreeMap<String, usize>,
    /// Longest token sequence fed to the encoder.
    pub max_tokens: usize,
}

/// Lower-cases and splits a caption into words (letters, digits and apostrophes).
pub fn words_of(text: &str) -> Vec<String> {
    text.split(|c: char| !(c.is_alphanumeric() || c == '\''))
        .filter(|w| !w.is_empty())
        .map(|w| w.to_lowercase())
        .collect()
}

/// Function words that carry no motion meaning; kept out of the vocabulary so they
/// neither dilute the mean embedding nor show up as "ignored".
const STOP_WORDS: &[&str] = &[
    "a", "an", "the", "is", "are", "and", "in", "of", "to", "way", "manner", "while", "their",
    "his", "her", "with",
];

/// Whether `word` (lower case) is a function word the vocabulary leaves out.
pub fn is_function_word(word: &str) -> bool {
    STOP_WORDS.contains(&word)
}

impl Vocabulary {
    /// Builds the vocabulary from every caption (sorted, so ids are deterministic).
    pub fn from_captions<'a>(
        captions: impl IntoIterator<Item = &'a str>,
        max_tokens: usize,
    ) -> Self {
        let mut set: Vec<String> = captions
            .into_iter()
            .flat_map(words_of)
            .filter(|w| !STOP_WORDS.contains(&w.as_str()))
            .collect();
        set.sort();
        set.dedup();
        let words = set
            .into_iter()
            .enumerate()
            .map(|(i, w)| (w, i + 1))
            .collect();
        Vocabulary { words, max_tokens }
    }

    /// Size including the padding id.
    pub fn len(&self) -> usize {
        self.words.len() + 1
    }

    /// True when no word is known.
    pub fn is_empty(&self) -> bool {
        self.words.is_empty()
    }

    /// Token ids of a prompt, and the words it did not know (stop words are silently
    /// skipped; they are not "unknown"). An unseen inflection of a known word is read as
    /// that word ([`Self::known_form`]).
    pub fn tokenize(&self, text: &str) -> (Vec<usize>, Vec<String>) {
        let mut ids = Vec::new();
        let mut unknown = Vec::new();
        for w in words_of(text) {
            match self.words.get(&w) {
                Some(&id) => ids.push(id),
                None if STOP_WORDS.contains(&w.as_str()) => {}
                None => match self.known_form(&w) {
                    Some(known) => ids.push(self.words[known]),
                    None => unknown.push(w),
                },
            }
        }
        ids.truncate(self.max_tokens);
        (ids, unknown)
    }

    /// `(word, known word it is read as)` for each word of a prompt that is not in the
    /// vocabulary but is an inflection of a word that is.
    pub fn respellings(&self, text: &str) -> Vec<(String, String)> {
        words_of(text)
            .into_iter()
            .filter(|w| !self.words.contains_key(w))
            .filter_map(|w| {
                let known = self.known_form(&w)?.to_string();
                Some((w, known))
            })
            .collect()
    }

    /// What the model makes of a prompt's words, as lines for the user: the words read
    /// as a known inflection and the words ignored (none when every word is known).
    pub fn word_report(&self, text: &str) -> Vec<String> {
        let mut lines = Vec::new();
        let read_as: Vec<String> = self
            .respellings(text)
            .into_iter()
            .map(|(word, known)| format!("{word} → {known}"))
            .collect();
        if !read_as.is_empty() {
            lines.push(format!(
                "read as words the model knows: {}",
                read_as.join(", ")
            ));
        }
        let unknown = self.tokenize(text).1;
        if !unknown.is_empty() {
            lines.push(format!(
                "ignored words the model does not know: {}",
                unknown.join(", ")
            ));
        }
        lines
    }

    /// The vocabulary word an unseen inflection stands for: captions say "walks forward"
    /// and "walking", prompts "walked forwards" or "jogging". Tries the word with a plural
    /// or verb ending taken off or swapped ("forwards" → "forward", "walked" → "walks",
    /// "jogging" → "jogs", "waving" → "waves", "turning" → "turn"); `None` if no
    /// candidate is known. Short words are left alone (too easy to mis-read).
    pub fn known_form(&self, word: &str) -> Option<&str> {
        if word.len() < 4 || !word.is_ascii() {
            return None;
        }
        let mut candidates = Vec::new();
        let mut stems = |stem: &str| {
            // "jogg" → "jog", "stepp" → "step": a doubled last consonant.
            let b = stem.as_bytes();
            let undoubled = (b.len() >= 3 && b[b.len() - 1] == b[b.len() - 2])
                .then(|| stem[..stem.len() - 1].to_string());
            for s in std::iter::once(stem.to_string()).chain(undoubled) {
                candidates.push(s.clone());
                candidates.push(format!("{s}s"));
                candidates.push(format!("{s}es"));
                candidates.push(format!("{s}ing"));
            }
        };
        if let Some(stem) = word.strip_suffix("ing") {
            stems(stem);
            stems(&format!("{stem}e"));
        } else if let Some(stem) = word.strip_suffix("ed") {
            stems(stem);
            stems(&format!("{stem}e"));
        } else if let Some(stem) = word.strip_suffix("ly") {
            stems(stem);
        } else if let Some(stem) = word.strip_suffix('s') {
            stems(stem);
        } else {
            stems(word);
        }
        candidates.iter().find_map(|c| {
            self.words
                .get_key_value(c.as_str())
                .map(|(k, _)| k.as_str())
        })
    }
}

/// Token ids of a batch of prompts, padded: `[B, L]` ids and a `[B, L]` 0/1 mask.
#[derive(Clone, Debug)]
pub struct TokenBatch {
    /// `[B, L]` token ids.
    pub ids: Tensor<2, Int>,
    /// `[B, L]` 1.0 for a real token, 0.0 for padding.
    pub mask: Tensor<2>,
    /// Words of each prompt that were not in the vocabulary.
    pub unknown: Vec<Vec<String>>,
}

impl TokenBatch {
    /// Tokenises prompts against a vocabulary.
    pub fn new(vocab: &Vocabulary, prompts: &[&str], device: &Device) -> Self {
        let tokenized: Vec<(Vec<usize>, Vec<String>)> =
            prompts.iter().map(|p| vocab.tokenize(p)).collect();
        let len = tokenized
            .iter()
            .map(|(t, _)| t.len())
            .max()
            .unwrap_or(0)
            .max(1);
        let b = prompts.len();
        let mut ids = vec![PAD as i64; b * len];
        let mut mask = vec![0.0f32; b * len];
        for (i, (toks, _)) in tokenized.iter().enumerate() {
            for (k, &t) in toks.iter().enumerate() {
                ids[i * len + k] = t as i64;
                mask[i * len + k] = 1.0;
            }
        }
        TokenBatch {
            ids: Tensor::from_data(TensorData::new(ids, [b, len]), device),
            mask: Tensor::from_data(TensorData::new(mask, [b, len]), device),
            unknown: tokenized.into_iter().map(|(_, u)| u).collect(),
        }
    }
}

/// Anything that turns tokenised prompts into one condition vector per prompt.
pub trait TextEncoder {
    /// Width of the output vector.
    fn output_dim(&self) -> usize;
    /// `[B, output_dim]` embedding of each prompt.
    fn encode(&self, tokens: &TokenBatch) -> Tensor<2>;
}

/// Mean of learned word embeddings (a bag of words), trained with the denoiser.
#[derive(Module, Debug)]
pub struct BagOfWords {
    embedding: Embedding,
    dim: usize,
}

impl BagOfWords {
    /// A fresh encoder for `vocab_size` ids.
    pub fn new(vocab_size: usize, dim: usize, device: &Device) -> Self {
        BagOfWords {
            embedding: EmbeddingConfig::new(vocab_size, dim).init(device),
            dim,
        }
    }
}

impl TextEncoder for BagOfWords {
    fn output_dim(&self) -> usize {
        self.dim
    }

    fn encode(&self, tokens: &TokenBatch) -> Tensor<2> {
        let emb = self.embedding.forward(tokens.ids.clone()); // [B, L, D]
        let mask = tokens.mask.clone().unsqueeze_dim::<3>(2); // [B, L, 1]
        let count = tokens.mask.clone().sum_dim(1).clamp_min(1.0); // [B, 1]
        (emb * mask).sum_dim(1).squeeze_dim::<2>(1) / count
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_words_are_reported_not_fatal() {
        let v = Vocabulary::from_captions(["a person walks forward", "someone runs"], 16);
        let (ids, unknown) = v.tokenize("A person moonwalks forward!");
        assert_eq!(ids.len(), 2);
        assert_eq!(unknown, vec!["moonwalks".to_string()]);
        assert!(!v.words.contains_key("a"));
    }

    #[test]
    fn unseen_inflections_read_as_known_words() {
        let v = Vocabulary::from_captions(
            [
                "a person walks forward",
                "a man jogs",
                "someone waves",
                "a person turns left",
                "a person is walking",
            ],
            16,
        );
        for (word, known) in [
            ("forwards", "forward"),
            ("walked", "walks"),
            ("walk", "walks"),
            ("jogging", "jogs"),
            ("waving", "waves"),
            ("waved", "waves"),
            ("turning", "turns"),
        ] {
            assert_eq!(v.known_form(word), Some(known), "{word}");
        }
        for word in ["moonwalks", "sits", "slowly", "jogger", "act"] {
            assert_eq!(v.known_form(word), None, "{word}");
        }
        let (ids, unknown) = v.tokenize("A man walked forwards, slowly");
        assert_eq!(ids.len(), 3);
        assert_eq!(unknown, vec!["slowly".to_string()]);
        assert_eq!(
            v.word_report("A man walked forwards, slowly"),
            vec![
                "read as words the model knows: walked → walks, forwards → forward",
                "ignored words the model does not know: slowly"
            ]
        );
        assert!(v.word_report("a man walks forward").is_empty());
        assert_eq!(
            v.respellings("A man walked forwards"),
            vec![
                ("walked".to_string(), "walks".to_string()),
                ("forwards".to_string(), "forward".to_string())
            ]
        );
    }

    #[test]
    fn encoder_ignores_padding() {
        let dev = Device::flex();
        let v = Vocabulary::from_captions(["walk run jump"], 8);
        let enc = BagOfWords::new(v.len(), 4, &dev);
        let batch = TokenBatch::new(&v, &["walk", "walk zzz"], &dev);
        let e = enc
            .encode(&batch)
            .into_data()
            .try_into_vec::<f32>()
            .unwrap();
        assert_eq!(e[..4], e[4..]);
        assert_eq!(batch.unknown[1], vec!["zzz".to_string()]);
    }
}
