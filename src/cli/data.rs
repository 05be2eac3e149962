//! `mprog data build`: convert a folder of BVH (and ASF/AMC) files into a training set.

use indicatif::{ProgressBar, ProgressStyle};
use miette::{IntoDiagnostic, Result};
use mprog::dataset::build::{BuildOptions, build_dataset_report, find_motion_files};
use std::path::PathBuf;

/// `mprog data …`
#[derive(clap::Subcommand)]
pub enum DataCommand {
    /// Convert every BVH and ASF/AMC file under a folder into one training set.
    Build(BuildArgs),
    /// Write one clip of a training set as a motion file or picture.
    Show(ShowArgs),
}

/// Arguments of `mprog data build`.
#[derive(clap::Args)]
pub struct BuildArgs {
    /// Folder searched recursively for `.bvh` and `.amc` files (the unpacked Bandai Namco,
    /// CMU and HDM05 archives, together or alone; CMU captions need the
    /// `cmu_trial_index.csv` somewhere under it).
    #[arg(long)]
    bvh: PathBuf,
    /// Output folder (replaced atomically when the build succeeds).
    #[arg(long)]
    out: PathBuf,
    /// Do not add left/right mirrored copies.
    #[arg(long)]
    no_mirror: bool,
    /// Shortest clip kept, in frames at 20 fps (HDM05's single hops and kicks last
    /// 10–20 frames: `--min-frames 10` keeps them).
    #[arg(long, default_value_t = 20)]
    min_frames: usize,
}

/// Runs `mprog data …`.
pub fn run(cmd: DataCommand) -> Result<()> {
    match cmd {
        DataCommand::Build(args) => build(args),
        DataCommand::Show(args) => show(args),
    }
}

fn build(args: BuildArgs) -> Result<()> {
    let count = find_motion_files(&args.bvh).len();
    let bar = ProgressBar::new(count as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {pos}/{len} files  [{elapsed_precise}, eta {eta}]")
            .expect("valid template"),
    );
    let opts = BuildOptions {
        mirror: !args.no_mirror,
        min_frames: args.min_frames,
    };
    let built =
        build_dataset_report(&args.bvh, &args.out, &opts, &|_| bar.inc(1)).into_diagnostic()?;
    let index = built.index;
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
    println!(
        "\n{:10} {:16} {:>6} {:>8} {:>8}",
        "source", "rig", "read", "skipped", "minutes"
    );
    for r in &built.rigs {
        println!(
            "{:10} {:16} {:>6} {:>8} {:>8.1}",
            r.family, r.rig, r.read, r.skipped, r.minutes
        );
        for (reason, n) in &r.reasons {
            println!("    {n} × {reason}");
        }
    }
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
