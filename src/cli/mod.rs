//! Subcommands of the `mprog` binary, one file each.

pub mod bench;
pub mod bench_paraphrases;
pub mod bench_sentences;
pub mod bench_solvers;
pub mod bench_tasks;
pub mod check;
pub mod convert;
pub mod coverage;
pub mod data;
pub mod doc;
pub mod eval;
pub mod export;
pub mod generate;
pub mod io;
pub mod mcp;
pub mod plausible;
pub mod repl;
pub mod run;
pub mod score;
pub mod take;
pub mod train;
pub mod train_control;
pub mod view;

/// The burn device of this command: flex, or the GPU backend named by `MPROG_DEVICE`.
pub fn device() -> miette::Result<burn::prelude::Device> {
    mprog::backend::device_from_env().map_err(|e| miette::miette!("{e}"))
}

/// Parses a classifier-free guidance scale: a finite number from 0 (no text) to 20.
pub fn parse_guidance(s: &str) -> Result<f32, String> {
    let v: f32 = s
        .parse()
        .map_err(|_| format!("`{s}` is not a number (try 2.5)"))?;
    if !v.is_finite() || !(0.0..=20.0).contains(&v) {
        return Err(format!(
            "the guidance scale must lie in 0..=20 (0: ignore the text, 1: plain conditional, 2.5: the default), not {s}"
        ));
    }
    Ok(v)
}
