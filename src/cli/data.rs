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
    /// Write one clip of a training set as a motion file or picture.
    Show(ShowArgs),
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
        DataCommand::Show(args) => show(args),
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

/// Arguments of `mprog data show`.
#[derive(clap::Args)]
pub struct ShowArgs {
    /// Training set folder.
    #[arg(long)]
    data: PathBuf,
    /// Clip name (file stem, `_mirror` suffix for mirrored copies).
    #[arg(long)]
    clip: String,
    /// Outputs; each one's extension picks its kind (`--help` lists them).
    #[arg(short, long, num_args = 1.., required = true, long_help = super::io::outputs_help())]
    out: Vec<PathBuf>,
}

fn show(args: ShowArgs) -> Result<()> {
    let data = mprog::dataset::Dataset::load(&args.data).into_diagnostic()?;
    let clip = data
        .index
        .clips
        .iter()
        .find(|c| c.name == args.clip)
        .ok_or_else(|| {
            miette::miette!("no clip named `{}` in {}", args.clip, args.data.display())
        })?;
    let motion = mprog::motion::Motion::from_flat(data.clip_joints(clip));
    let title = format!("{} ({:?}): {}", clip.name, clip.split, clip.captions[0]);
    super::io::write_outputs(&args.out, &[motion], &Default::default(), &title)
}
