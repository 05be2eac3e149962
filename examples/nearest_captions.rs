//! Nearest known caption of each prompt with the shipped sentence encoder, plus its
//! timings: load, one prompt, and the whole caption list in one call.
//!
//! ```text
//! cargo run --release --example nearest_captions -- <captions.txt, one per line> [prompt…]
//! ```
//! `python scripts/text_encoder_captions.py > captions.txt` writes the measured caption set.

use burn::prelude::*;
use mprog::model::sentence::{CaptionIndex, FAR_COSINE, SentenceEncoder, default_encoder_dir};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .ok_or("usage: nearest_captions <captions.txt> [prompt…]")?;
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{path}: {e}"))?;
    let captions: Vec<&str> = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    let mut prompts: Vec<String> = args.collect();
    if prompts.is_empty() {
        prompts = [
            "a person strolls",
            "someone jogs ahead",
            "a person elevates both arms",
            "a man kicks forward with his right leg",
            "a person crouches down low and stands back up",
            "a person plays the piano",
            "the stock market fell today",
        ]
        .map(String::from)
        .to_vec();
    }
    let device = Device::flex();
    let t = Instant::now();
    let encoder = SentenceEncoder::load(&default_encoder_dir(), &device)?;
    println!("load: {:.2} s", t.elapsed().as_secs_f64());
    let mut single = Vec::new();
    for p in &prompts {
        let t = Instant::now();
        let _ = encoder.encode(&[p.as_str()]).into_data();
        single.push(t.elapsed().as_secs_f64() * 1e3);
    }
    single.sort_by(f64::total_cmp);
    println!(
        "one prompt: median {:.1} ms over {}",
        single[single.len() / 2],
        single.len()
    );
    let t = Instant::now();
    let index = CaptionIndex::build(&encoder, &captions);
    println!(
        "{} captions in one call: {:.2} s",
        index.captions().len(),
        t.elapsed().as_secs_f64()
    );
    let refs: Vec<&str> = prompts.iter().map(String::as_str).collect();
    for (p, n) in refs.iter().zip(index.nearest(&encoder, &refs)) {
        let far = if n.cosine < FAR_COSINE { "  [far]" } else { "" };
        println!("{p:?} -> {:?} ({:.2}){far}", n.caption, n.cosine);
    }
    Ok(())
}
