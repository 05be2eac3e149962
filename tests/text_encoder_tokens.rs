//! The WordPiece tokenizer against Hugging Face `tokenizers` on 300 seeded random strings
//! mixing caption words with accents, combining marks, CJK, Hangul, symbols, controls,
//! zero-width and full-width characters (`tests/fixtures/text-encoder-tokens.json`,
//! written by `scripts/derive-text-encoder.py`).

use mprog::model::sentence::WordPiece;
use serde::Deserialize;
use std::path::Path;

#[derive(Deserialize)]
struct Case {
    text: String,
    ids: Vec<u32>,
}

#[test]
fn token_ids_equal_hugging_face_tokenizers() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tokenizer = WordPiece::load(&root.join("models/text-encoder/tokenizer.json")).unwrap();
    let text = std::fs::read_to_string(root.join("tests/fixtures/text-encoder-tokens.json"));
    let cases: Vec<Case> = serde_json::from_str(&text.unwrap()).unwrap();
    assert_eq!(cases.len(), 300);
    let wrong: Vec<String> = cases
        .iter()
        .filter(|c| tokenizer.encode(&c.text) != c.ids)
        .map(|c| {
            format!(
                "{:?}: got {:?}, want {:?}",
                c.text,
                tokenizer.encode(&c.text),
                c.ids
            )
        })
        .collect();
    assert!(
        wrong.is_empty(),
        "{} of 300 differ:\n{}",
        wrong.len(),
        wrong.join("\n")
    );
}
