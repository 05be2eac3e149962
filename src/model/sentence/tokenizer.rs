//! WordPiece tokenizer read from a Hugging Face `tokenizer.json` (BERT uncased): the basic
//! tokenizer of [`super::normalize`], then greedy longest-match WordPiece with `##`
//! continuations, wrapped in `[CLS]` … `[SEP]` and cut to a maximum length.
//!
//! Special tokens written literally in the text ("[MASK]") are read as plain text,
//! unlike `tokenizers`, which matches them before normalising.

use super::SentenceError;
use super::normalize::basic_tokens;
use serde::Deserialize;
use std::collections::HashMap;
use std::path::Path;

/// sentence-transformers' `max_seq_length` for all-MiniLM-L6-v2, `[CLS]` and `[SEP]` included.
pub const MAX_TOKENS: usize = 256;

#[derive(Deserialize)]
struct TokenizerFile {
    model: WordPieceModel,
}

#[derive(Deserialize)]
struct WordPieceModel {
    #[serde(rename = "type")]
    kind: String,
    unk_token: String,
    continuing_subword_prefix: String,
    max_input_chars_per_word: usize,
    vocab: HashMap<String, u32>,
}

/// A WordPiece vocabulary with BERT's special tokens.
#[derive(Clone, Debug)]
pub struct WordPiece {
    vocab: HashMap<String, u32>,
    prefix: String,
    max_word_chars: usize,
    unk: u32,
    cls: u32,
    sep: u32,
}

impl WordPiece {
    /// Reads `tokenizer.json`; errors name the file and what is wrong with it.
    pub fn load(path: &Path) -> Result<WordPiece, SentenceError> {
        let text = std::fs::read_to_string(path).map_err(|e| SentenceError::read(path, e))?;
        Self::from_json(&text).map_err(|reason| SentenceError::invalid(path, reason))
    }

    /// Parses the contents of a `tokenizer.json`.
    pub fn from_json(text: &str) -> Result<WordPiece, String> {
        let file: TokenizerFile =
            serde_json::from_str(text).map_err(|e| format!("not a tokenizer.json: {e}"))?;
        let m = file.model;
        if m.kind != "WordPiece" {
            return Err(format!("model type {:?}, expected \"WordPiece\"", m.kind));
        }
        let id = |token: &str| {
            m.vocab
                .get(token)
                .copied()
                .ok_or_else(|| format!("vocabulary has no {token}"))
        };
        Ok(WordPiece {
            unk: id(&m.unk_token)?,
            cls: id("[CLS]")?,
            sep: id("[SEP]")?,
            prefix: m.continuing_subword_prefix,
            max_word_chars: m.max_input_chars_per_word,
            vocab: m.vocab,
        })
    }

    /// Number of token ids (the largest id plus one).
    pub fn vocab_size(&self) -> usize {
        self.vocab.values().max().map_or(0, |&m| m as usize + 1)
    }

    /// Token ids of one word: greedy longest match; `[UNK]` for the whole word when some
    /// part matches nothing, as BERT does.
    fn word_ids(&self, word: &str, out: &mut Vec<u32>) {
        let chars: Vec<char> = word.chars().collect();
        if chars.len() > self.max_word_chars {
            out.push(self.unk);
            return;
        }
        let start_len = out.len();
        let mut start = 0;
        let mut piece = String::new();
        while start < chars.len() {
            let mut end = chars.len();
            let found = loop {
                piece.clear();
                if start > 0 {
                    piece.push_str(&self.prefix);
                }
                piece.extend(&chars[start..end]);
                if let Some(&id) = self.vocab.get(&piece) {
                    break Some(id);
                }
                end -= 1;
                if end == start {
                    break None;
                }
            };
            match found {
                Some(id) => out.push(id),
                None => {
                    out.truncate(start_len);
                    out.push(self.unk);
                    return;
                }
            }
            start = end;
        }
    }

    /// `[CLS] pieces… [SEP]`, at most [`MAX_TOKENS`] ids.
    pub fn encode(&self, text: &str) -> Vec<u32> {
        let mut ids = vec![self.cls];
        for word in basic_tokens(text) {
            self.word_ids(&word, &mut ids);
            if ids.len() >= MAX_TOKENS - 1 {
                break;
            }
        }
        ids.truncate(MAX_TOKENS - 1);
        ids.push(self.sep);
        ids
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tiny() -> WordPiece {
        let vocab = r###"{"[UNK]":0,"[CLS]":1,"[SEP]":2,"walk":3,"##s":4,"##ing":5,"un":6,"##walk":7,"a":8,".":9}"###;
        let json = format!(
            r###"{{"model":{{"type":"WordPiece","unk_token":"[UNK]","continuing_subword_prefix":"##","max_input_chars_per_word":8,"vocab":{vocab}}}}}"###
        );
        WordPiece::from_json(&json).unwrap()
    }

    #[test]
    fn greedy_longest_match_with_continuations() {
        let t = tiny();
        assert_eq!(
            t.encode("Walks walking unwalk."),
            [1, 3, 4, 3, 5, 6, 7, 9, 2]
        );
        // "walkx": "##x" matches nothing, so the whole word is unknown.
        assert_eq!(t.encode("a walkx a"), [1, 8, 0, 8, 2]);
        // Longer than max_input_chars_per_word.
        assert_eq!(t.encode("walkingwalking"), [1, 0, 2]);
        assert_eq!(t.vocab_size(), 10);
    }

    #[test]
    fn cuts_to_the_maximum_length() {
        let ids = tiny().encode(&format!("a {}", "walking ".repeat(400)));
        assert_eq!(ids.len(), MAX_TOKENS);
        assert_eq!((ids[0], ids[MAX_TOKENS - 1]), (1, 2));
        assert_eq!(ids[MAX_TOKENS - 2], 3); // cut mid-word, like tokenizers' truncation
    }

    #[test]
    fn malformed_files_say_what_is_wrong() {
        let e = WordPiece::from_json("{}").unwrap_err();
        assert!(e.contains("not a tokenizer.json"), "{e}");
        let bpe = r###"{"model":{"type":"BPE","unk_token":"x","continuing_subword_prefix":"","max_input_chars_per_word":1,"vocab":{}}}"###;
        assert!(WordPiece::from_json(bpe).unwrap_err().contains("BPE"));
        let no_cls = r###"{"model":{"type":"WordPiece","unk_token":"[UNK]","continuing_subword_prefix":"##","max_input_chars_per_word":9,"vocab":{"[UNK]":0}}}"###;
        assert!(WordPiece::from_json(no_cls).unwrap_err().contains("[CLS]"));
    }
}
