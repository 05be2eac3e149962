//! `mprog data build`: convert a folder of BVH (and ASF/AMC) files into a training set.

use indicatif::{ProgressBar, ProgressStyle};
use miette::{IntoDiagnostic, Result, WrapErr};
use mprog::dataset::build::{BuildOptions, build_dataset_report, find_motion_files};
use std::path::PathBuf;

/// `mprog data …`
#[derive(clap::Subcommand)]
pub enum DataCommand {
    /// Convert every BVH and ASF/AMC file under a folder into one training set.
    Build(BuildArgs),
    /// Write one clip of a training set as a motion file or picture.
    Show(ShowArgs),
    /// Measure how a training set's clips move (per-joint speed and acceleration, floor,
    /// foot skating, rigid distances): the envelope plausibility reports check against.
    Envelope(EnvelopeArgs),
    /// Keep the poses the training set holds (and how long each is held): what `check`
    /// and `run` search when a program asks for a pose no clip comes near.
    Coverage(super::coverage::CoverageArgs),
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
        DataCommand::Envelope(args) => envelope(args),
        DataCommand::Coverage(args) => super::coverage::run(args),
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

/// Arguments of `mprog data envelope`.
#[derive(clap::Args)]
pub struct EnvelopeArgs {
    /// Training set folder (`mprog data build`'s output; every clip of every split is
    /// measured, mirrored copies included).
    #[arg(long)]
    data: PathBuf,
    /// Where to write it (JSON, atomically); a model bundle reads `<bundle>/envelope.json`.
    #[arg(short, long)]
    out: PathBuf,
}

fn envelope(args: EnvelopeArgs) -> Result<()> {
    use mprog::metrics::plausibility::measure_envelope;
    let data = mprog::dataset::Dataset::load(&args.data).into_diagnostic()?;
    let clips: Vec<mprog::motion::Motion> = data
        .index
        .clips
        .iter()
        .map(|c| mprog::motion::Motion::from_flat(data.clip_joints(c)))
        .collect();
    let source = args.data.display().to_string();
    let env = measure_envelope(clips.iter(), &source);
    env.save(&args.out)
        .into_diagnostic()
        .wrap_err_with(|| format!("writing {}", args.out.display()))?;
    println!("{}", env.source);
    println!(
        "| joint | accel p50 | p99.9 | clip peak p50 | p99 | max (m/frame²) | speed p99.9 | clip peak p99 | max (m/s) |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    for (j, name) in mprog::skeleton::JOINT_NAMES.iter().enumerate() {
        let (a, ap, v, vp) = (
            &env.accel[j],
            &env.accel_peak[j],
            &env.speed[j],
            &env.speed_peak[j],
        );
        println!(
            "| {name} | {:.4} | {:.4} | {:.4} | {:.4} | {:.3} | {:.2} | {:.2} | {:.1} |",
            a.p50, a.p99_9, ap.p50, ap.p99, a.max, v.p99_9, vp.p99, v.max
        );
    }
    let f = &env.floor;
    println!(
        "lowest joint height (m): min {:.3}, p0.1 {:.3}, p1 {:.3}, p50 {:.3}",
        f.min, f.p0_1, f.p1, f.p50
    );
    for (what, s) in [
        ("every clip", &env.skating),
        ("clips moving > 0.5 m/s", &env.skating_moving),
    ] {
        println!(
            "foot skating per clip ({what}): mean {:.4}, p50 {:.4}, p95 {:.4}, p99 {:.4}, max {:.4}",
            s.mean, s.p50, s.p95, s.p99, s.max
        );
    }
    for r in &env.rigid {
        println!(
            "{:48} rest {:.3} m; ratio min {:.3}, p0.1 {:.3}, p50 {:.3}, p99.9 {:.3}, max {:.3}",
            r.name, r.rest, r.ratio.min, r.ratio.p0_1, r.ratio.p50, r.ratio.p99_9, r.ratio.max
        );
    }
    println!("wrote {}", args.out.display());
    Ok(())
}
