//! `mprog data build`: convert a folder of BVH files into a training set.

use indicatif::{ProgressBar, ProgressStyle};
use miette::{IntoDiagnostic, Result};
use mprog::dataset::build::{BuildOptions, build_dataset, find_bvh_files};
use std::path::PathBuf;

/// `mprog data …`
#[derive(clap::Subcommand)]
pub enum DataCommand {
    /// Convert every BVH file under a folder into one training set.
    Build(BuildArgs),
}

/// Arguments of `mprog data build`.
#[derive(clap::Args)]
pub struct BuildArgs {
    /// Folder searched recursively for `.bvh` files (e.g. the unpacked Bandai Namco archive).
    #[arg(long)]
    bvh: PathBuf,
    /// Output folder (replaced atomically when the build succeeds).
    #[arg(long)]
    out: PathBuf,
    /// Do not add left/right mirrored copies.
    #[arg(long)]
    no_mirror: bool,
}

/// Runs `mprog data …`.
pub fn run(cmd: DataCommand) -> Result<()> {
    match cmd {
        DataCommand::Build(args) => build(args),
    }
}

fn build(args: BuildArgs) -> Result<()> {
    let count = find_bvh_files(&args.bvh).len();
    let bar = ProgressBar::new(count as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {pos}/{len} files  [{elapsed_precise}, eta {eta}]")
            .expect("valid template"),
    );
    let opts = BuildOptions {
        mirror: !args.no_mirror,
        ..BuildOptions::default()
    };
    let index = build_dataset(&args.bvh, &args.out, &opts, &|_| bar.inc(1)).into_diagnostic()?;
    bar.finish_and_clear();
    for (path, reason) in &index.skipped {
        eprintln!("skipped {path}: {reason}");
    }
    println!(
        "built {} in {:.1} s",
        args.out.display(),
        index.build_seconds
    );
    println!(
        "{:6} {:>6} {:>9} {:>7}",
        "split", "clips", "frames", "hours"
    );
    for (name, s) in ["train", "val", "test"].iter().zip(&index.stats) {
        println!("{name:6} {:>6} {:>9} {:>7.3}", s.clips, s.frames, s.hours);
    }
    println!(
        "{} files skipped; clips include left/right mirrored copies: {}",
        index.skipped.len(),
        opts.mirror
    );
    Ok(())
}
