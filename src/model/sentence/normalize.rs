//! BERT's basic tokenizer as Hugging Face `tokenizers` runs it for all-MiniLM-L6-v2
//! (`BertNormalizer` with lowercase and accent stripping, then `BertPreTokenizer`):
//! drop control and format characters, map whitespace to spaces, space out CJK
//! ideographs, strip accents (NFD without Mn marks), lower-case, then split on whitespace
//! and punctuation. The per-character tables are read off `tokenizers` itself, whose
//! Unicode data is older than Rust's or Python's.

use super::unicode_tables::{MAP, PUNCTUATION, REMOVED};

fn in_ranges(table: &[(u32, u32)], c: char) -> bool {
    let c = c as u32;
    table
        .binary_search_by(|&(lo, hi)| {
            if hi < c {
                std::cmp::Ordering::Less
            } else if lo > c {
                std::cmp::Ordering::Greater
            } else {
                std::cmp::Ordering::Equal
            }
        })
        .is_ok()
}

/// The CJK blocks of BERT's `_is_chinese_char` (each ideograph becomes its own word).
fn is_cjk(c: char) -> bool {
    matches!(c as u32,
        0x4E00..=0x9FFF | 0x3400..=0x4DBF | 0x20000..=0x2A6DF | 0x2A700..=0x2B73F
        | 0x2B740..=0x2B81F | 0x2B820..=0x2CEAF | 0xF900..=0xFAFF | 0x2F800..=0x2FA1F)
}

/// Pushes the normalised form of one character (the normaliser works per character).
fn push_normalized(c: char, out: &mut String) {
    const S_BASE: u32 = 0xAC00;
    let code = c as u32;
    if in_ranges(REMOVED, c) {
    } else if let Ok(i) = MAP.binary_search_by_key(&code, |&(k, _)| k) {
        out.push_str(MAP[i].1);
    } else if (S_BASE..S_BASE + 11172).contains(&code) {
        // Hangul syllables decompose arithmetically into conjoining jamo (NFD).
        let s = code - S_BASE;
        let jamo = [0x1100 + s / 588, 0x1161 + (s % 588) / 28, 0x11A7 + s % 28];
        let n = if s.is_multiple_of(28) { 2 } else { 3 };
        out.extend(jamo[..n].iter().filter_map(|&j| char::from_u32(j)));
    } else if is_cjk(c) {
        out.push(' ');
        out.push(c);
        out.push(' ');
    } else if c.is_whitespace() {
        out.push(' ');
    } else {
        out.push(c);
    }
}

/// The normalised text of `text` (before splitting).
pub fn normalize(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        push_normalized(c, &mut out);
    }
    out
}

/// Normalises `text` and splits it into words: runs of non-space, non-punctuation
/// characters, and each punctuation character alone.
pub fn basic_tokens(text: &str) -> Vec<String> {
    let mut words = Vec::new();
    let mut word = String::new();
    for c in normalize(text).chars() {
        let punct = in_ranges(PUNCTUATION, c);
        if c.is_whitespace() || punct {
            if !word.is_empty() {
                words.push(std::mem::take(&mut word));
            }
            if punct {
                words.push(c.to_string());
            }
        } else {
            word.push(c);
        }
    }
    if !word.is_empty() {
        words.push(word);
    }
    words
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lowercases_strips_accents_and_splits_punctuation() {
        assert_eq!(
            basic_tokens("Très  ÉLÉGANT, naïve café-style!"),
            ["tres", "elegant", ",", "naive", "cafe", "-", "style", "!"]
        );
    }

    #[test]
    fn drops_controls_and_spaces_out_ideographs() {
        assert_eq!(
            basic_tokens("a\u{200B}b\tc\u{0007}跳d"),
            ["ab", "c", "跳", "d"]
        );
        assert_eq!(basic_tokens("$5+x"), ["$", "5", "+", "x"]);
        assert!(basic_tokens(" \n\t\u{3000} ").is_empty());
    }

    #[test]
    fn decomposes_hangul_and_drops_combining_marks() {
        assert_eq!(normalize("한"), "\u{1112}\u{1161}\u{11AB}");
        assert_eq!(normalize("e\u{0301}"), "e");
        assert_eq!(normalize("İẞΣ"), "ißσ");
    }

    #[test]
    fn tables_are_sorted_for_binary_search() {
        for t in [PUNCTUATION, REMOVED] {
            assert!(t.windows(2).all(|w| w[0].1 < w[1].0));
        }
        assert!(MAP.windows(2).all(|w| w[0].0 < w[1].0));
    }
}
