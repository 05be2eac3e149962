//! Bytes → checked text → tokens with line numbers.
//!
//! In: the raw bytes of a BVH file. Out: a `&str` known to be UTF-8 text without NUL bytes,
//! and the HIERARCHY section as [`Token`]s (whitespace-separated words, with `{` and `}`
//! always split off), each tagged with its 1-based line. `\r\n`, tabs and trailing spaces
//! are all just whitespace. Lines starting with `#` are comments (mprog's own exporter
//! states units, axes and fps in one; Blender skips them too).

use super::error::{BvhError, BvhErrorKind};

/// One word of the hierarchy and the line it is on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Token<'a> {
    pub text: &'a str,
    pub line: usize,
}

/// Checks that `bytes` is text: no NUL byte (binary files), valid UTF-8.
pub fn decode<'a>(origin: &str, bytes: &'a [u8]) -> Result<&'a str, BvhError> {
    if let Some(pos) = bytes.iter().position(|&b| b == 0) {
        return Err(BvhError::at(
            origin,
            line_of(bytes, pos),
            BvhErrorKind::Binary,
        ));
    }
    std::str::from_utf8(bytes).map_err(|e| {
        BvhError::at(
            origin,
            line_of(bytes, e.valid_up_to()),
            BvhErrorKind::NotUtf8,
        )
    })
}

/// 1-based line number of byte offset `pos`.
fn line_of(bytes: &[u8], pos: usize) -> usize {
    1 + bytes[..pos].iter().filter(|&&b| b == b'\n').count()
}

/// Splits lines (1-based numbers given by `first_line`) into tokens.
pub fn tokenize<'a>(lines: impl Iterator<Item = (usize, &'a str)>) -> Vec<Token<'a>> {
    let mut tokens = Vec::new();
    for (line, text) in lines {
        if text.trim_start().starts_with('#') {
            continue;
        }
        for word in text.split_whitespace() {
            split_braces(word, line, &mut tokens);
        }
    }
    tokens
}

/// Pushes `word`, with any `{` / `}` glued to it (`Hips{`) as tokens of their own.
fn split_braces<'a>(word: &'a str, line: usize, out: &mut Vec<Token<'a>>) {
    let mut start = 0;
    for (i, c) in word.char_indices() {
        if c == '{' || c == '}' {
            if i > start {
                out.push(Token {
                    text: &word[start..i],
                    line,
                });
            }
            out.push(Token {
                text: &word[i..i + 1],
                line,
            });
            start = i + 1;
        }
    }
    if start < word.len() {
        out.push(Token {
            text: &word[start..],
            line,
        });
    }
}

/// Parses a finite number, or says which problem `text` has.
pub fn parse_number(text: &str) -> Result<f32, BvhErrorKind> {
    match text.parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(BvhErrorKind::NonFinite(text.to_string())),
        Err(_) => Err(BvhErrorKind::BadNumber(text.to_string())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn braces_split_and_lines_kept() {
        let toks = tokenize([(1, "ROOT Hips{"), (2, "\tOFFSET 0 1 2 }")].into_iter());
        let texts: Vec<_> = toks.iter().map(|t| (t.text, t.line)).collect();
        assert_eq!(
            texts,
            [
                ("ROOT", 1),
                ("Hips", 1),
                ("{", 1),
                ("OFFSET", 2),
                ("0", 2),
                ("1", 2),
                ("2", 2),
                ("}", 2)
            ]
        );
    }

    #[test]
    fn comment_lines_are_skipped() {
        let toks =
            tokenize([(1, "HIERARCHY"), (2, "  # units metres { }"), (3, "ROOT a")].into_iter());
        let texts: Vec<_> = toks.iter().map(|t| (t.text, t.line)).collect();
        assert_eq!(texts, [("HIERARCHY", 1), ("ROOT", 3), ("a", 3)]);
    }

    #[test]
    fn numbers_reject_nan_inf_and_garbage() {
        assert_eq!(parse_number("1.87007e-05"), Ok(1.87007e-05));
        assert_eq!(parse_number("-0"), Ok(0.0));
        assert!(matches!(
            parse_number("nan"),
            Err(BvhErrorKind::NonFinite(_))
        ));
        assert!(matches!(
            parse_number("inf"),
            Err(BvhErrorKind::NonFinite(_))
        ));
        assert!(matches!(
            parse_number("1e99"),
            Err(BvhErrorKind::NonFinite(_))
        ));
        assert!(matches!(
            parse_number("1.#IND"),
            Err(BvhErrorKind::BadNumber(_))
        ));
    }

    #[test]
    fn binary_and_bad_utf8_name_the_line() {
        let err = decode("x.bvh", b"HIERARCHY\nROOT a\n\0\0").unwrap_err();
        assert_eq!((err.line, err.kind), (Some(3), BvhErrorKind::Binary));
        let err = decode("x.bvh", b"HIERARCHY\n\xff\xfe").unwrap_err();
        assert_eq!((err.line, err.kind), (Some(2), BvhErrorKind::NotUtf8));
    }
}
