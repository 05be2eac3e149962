//! Golden test against the NumPy reference (`scripts/minilm_ref.py`, f32 weights), the
//! shipped encoder's load errors, and nearest-caption lookup.

use super::*;
use serde::Deserialize;
use std::sync::OnceLock;

#[derive(Deserialize)]
struct Golden {
    sentences: Vec<GoldenSentence>,
}

#[derive(Deserialize)]
struct GoldenSentence {
    text: String,
    ids: Vec<u32>,
    embedding: Vec<f32>,
}

fn golden() -> Golden {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/text-encoder-golden.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn encoder() -> &'static SentenceEncoder {
    static ENCODER: OnceLock<SentenceEncoder> = OnceLock::new();
    ENCODER.get_or_init(|| SentenceEncoder::load(&default_encoder_dir(), &Device::flex()).unwrap())
}

fn rows(t: Tensor<2>) -> Vec<Vec<f32>> {
    let [_, d] = t.dims();
    let v = t.into_data().try_to_vec_as::<f32>().unwrap();
    v.chunks(d).map(<[f32]>::to_vec).collect()
}

#[test]
fn token_ids_match_the_reference_tokenizer() {
    let g = golden();
    assert!(g.sentences.len() >= 10);
    for s in &g.sentences {
        assert_eq!(encoder().tokenizer().encode(&s.text), s.ids, "{:?}", s.text);
    }
}

#[test]
fn embeddings_match_the_reference_within_1e_3() {
    let g = golden();
    let texts: Vec<&str> = g.sentences.iter().map(|s| s.text.as_str()).collect();
    let got = rows(encoder().encode(&texts));
    let mut worst = 0.0f32;
    for (s, row) in g.sentences.iter().zip(&got) {
        assert_eq!(row.len(), 384);
        let err = row
            .iter()
            .zip(&s.embedding)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f32::max);
        assert!(err < 1e-3, "{:?}: max error {err}", s.text);
        worst = worst.max(err);
        let norm: f32 = row.iter().map(|x| x * x).sum::<f32>().sqrt();
        assert!((norm - 1.0).abs() < 1e-4, "{:?}: norm {norm}", s.text);
    }
    eprintln!("largest difference from the f32 reference: {worst:.2e}");
    // Batching and padding do not change a sentence's vector.
    let alone = rows(encoder().encode(&[texts[3]]));
    let diff = alone[0].iter().zip(&got[3]).map(|(a, b)| (a - b).abs());
    assert!(diff.fold(0.0, f32::max) < 1e-5);
    assert_eq!(encoder().encode(&[]).dims(), [0, 384]);
}

#[test]
fn missing_and_malformed_files_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let src = default_encoder_dir();
    let err = |d: &Path| {
        SentenceEncoder::load(d, &Device::flex())
            .unwrap_err()
            .to_string()
    };
    let e = err(dir.path());
    assert!(
        e.contains("config.json") && e.contains("cannot read"),
        "{e}"
    );
    std::fs::copy(src.join("config.json"), dir.path().join("config.json")).unwrap();
    std::fs::write(dir.path().join("tokenizer.json"), "{\"model\": 3}").unwrap();
    let e = err(dir.path());
    assert!(
        e.contains("tokenizer.json") && e.contains("not a tokenizer.json"),
        "{e}"
    );
    std::fs::copy(
        src.join("tokenizer.json"),
        dir.path().join("tokenizer.json"),
    )
    .unwrap();
    let e = err(dir.path());
    assert!(
        e.contains("encoder.safetensors") && e.contains("cannot read"),
        "{e}"
    );
    std::fs::write(
        dir.path().join("encoder.safetensors"),
        b"\x08\0\0\0\0\0\0\0{}",
    )
    .unwrap();
    let e = err(dir.path());
    assert!(
        e.contains("encoder.safetensors") && e.contains("do not fit"),
        "{e}"
    );
    std::fs::write(dir.path().join("config.json"), "{\"hidden_size\": 384}").unwrap();
    let e = err(dir.path());
    assert!(
        e.contains("config.json") && e.contains("bad BERT config"),
        "{e}"
    );
}

#[test]
fn nearest_caption_of_paraphrases_and_unrelated_text() {
    let captions = [
        "a person walks forward",
        "a person runs forward",
        "a person raises both hands",
        "a person kicks",
        "a person jumps in place",
        "a person sits down",
    ];
    let index = CaptionIndex::build(encoder(), &captions);
    let found = index.nearest(
        encoder(),
        &[
            "a person strolls",
            "someone jogs ahead",
            "a person elevates both arms",
            "a man kicks forward with his right leg",
            "someone leaps into the air",
            "a person takes a seat",
            "the stock market fell today",
        ],
    );
    let names: Vec<&str> = found.iter().map(|n| n.caption.as_str()).collect();
    assert_eq!(
        names[..6],
        [
            "a person walks forward",
            "a person runs forward",
            "a person raises both hands",
            "a person kicks",
            "a person jumps in place",
            "a person sits down",
        ]
    );
    assert!((found[0].cosine - 0.787).abs() < 0.01, "{:?}", found[0]);
    assert!(
        found[..6].iter().all(|n| n.cosine > FAR_COSINE),
        "{found:?}"
    );
    assert!(found[6].cosine < FAR_COSINE, "{:?}", found[6]);
}

#[test]
fn caption_index_round_trips_through_its_file() {
    let index = CaptionIndex::build(
        encoder(),
        &["a person bows", "a person waves", "a person bows"],
    );
    assert_eq!(index.captions(), ["a person bows", "a person waves"]);
    assert!(index.covers(&["a person waves", "a person bows"]));
    assert!(!index.covers(&["a person waves"]));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("captions.safetensors");
    index.save(&path).unwrap();
    let back = CaptionIndex::load(&path, &Device::flex()).unwrap();
    assert_eq!(back.captions(), index.captions());
    let a = back.nearest(encoder(), &["someone bows deeply"]);
    let b = index.nearest(encoder(), &["someone bows deeply"]);
    assert_eq!(a[0].caption, b[0].caption);
    assert!((a[0].cosine - b[0].cosine).abs() < 2e-3);
    std::fs::write(&path, b"\x02\0\0\0\0\0\0\0{}").unwrap();
    let e = CaptionIndex::load(&path, &Device::flex())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("captions.safetensors") && e.contains("no captions"),
        "{e}"
    );
}

#[test]
fn far_prompts_snap_to_the_mean_of_their_neighbours() {
    let captions = [
        "a person walks forward",
        "a person walks forward quickly",
        "a person raises both hands",
        "a person kicks",
    ];
    let index = CaptionIndex::build(encoder(), &captions);
    let prompts = ["a person walks forward", "a person hurries"];
    let vectors = encoder().encode(&prompts);
    let before = rows(vectors.clone());
    let (snapped, report) = index.snap(vectors, SNAP_COSINE);
    let after = rows(snapped);
    // A training caption is read as written.
    assert_eq!(report[0], None);
    assert_eq!(after[0], before[0]);
    // A far paraphrase becomes the normalised mean of its neighbours' vectors.
    let s = report[1]
        .clone()
        .expect("\"a person hurries\" is far from every caption");
    assert!(s.best < SNAP_COSINE, "{s:?}");
    assert!(s.neighbours.iter().all(|n| n.contains("walks")), "{s:?}");
    let table = rows(index.embeddings().clone());
    let mut mean = vec![0.0f32; after[1].len()];
    for n in &s.neighbours {
        let i = index.captions().iter().position(|c| c == n).unwrap();
        mean.iter_mut().zip(&table[i]).for_each(|(m, e)| *m += e);
    }
    let norm = mean.iter().map(|v| v * v).sum::<f32>().sqrt();
    for (a, m) in after[1].iter().zip(&mean) {
        assert!((a - m / norm).abs() < 1e-5);
    }
    // Threshold 0 (`--literal-prompt`) reads every prompt as written.
    let (literal, report) = index.snap(encoder().encode(&prompts), 0.0);
    assert!(report.iter().all(Option::is_none));
    assert_eq!(rows(literal), before);
}
