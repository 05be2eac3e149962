//! `mprog data coverage`: the poses a training set holds, for `mprog::unseen_pose`
//! (`mprog::coverage`), with the measurements its threshold is chosen against.

use miette::{IntoDiagnostic, Result, WrapErr};
use mprog::coverage::build::{ClipInput, build};
use mprog::coverage::measure::{Query, held_out_violations, one_leg_runs, percentiles};
use mprog::coverage::{Coverage, Pose, file};
use mprog::dataset::{Dataset, Split};
use std::path::PathBuf;

/// Arguments of `mprog data coverage`.
#[derive(clap::Args)]
pub struct CoverageArgs {
    /// Training set folder (`mprog data build`'s output; every split, mirrored copies
    /// read as the stored poses mirrored).
    #[arg(long)]
    data: PathBuf,
    /// Where to write it; a model bundle reads `<bundle>/coverage.bin`.
    #[arg(short, long)]
    out: PathBuf,
    /// Cover distance in metres: every training frame lies within it (largest joint
    /// distance) of a kept pose.
    #[arg(long, default_value_t = 0.04)]
    cover: f32,
    /// Also build a set without the test split and measure how near it comes to the test
    /// clips' own poses (what the warning's threshold is held against).
    #[arg(long)]
    held_out: bool,
}

/// The clips of `data` that are not mirrored copies, in `splits`.
fn inputs<'a>(data: &'a Dataset, splits: &[Split]) -> Vec<ClipInput<'a>> {
    data.index
        .clips
        .iter()
        .filter(|c| !c.mirrored && splits.contains(&c.split))
        .map(|c| ClipInput {
            name: &c.name,
            caption: c.captions.first().map_or("", String::as_str),
            joints: data.clip_joints(c),
        })
        .collect()
}

/// Runs `mprog data coverage`.
pub fn run(args: CoverageArgs) -> Result<()> {
    let data = Dataset::load(&args.data).into_diagnostic()?;
    let mirrored = data.index.clips.iter().any(|c| c.mirrored);
    let all = [Split::Train, Split::Val, Split::Test];
    let clips = inputs(&data, &all);
    let started = std::time::Instant::now();
    let source = format!(
        "{}: {} clips, {} frames{}",
        args.data.display(),
        clips.len(),
        clips.iter().map(|c| c.joints.len() / 66).sum::<usize>(),
        if mirrored {
            ", and their mirror images"
        } else {
            ""
        }
    );
    let set = build(&clips, &source, args.cover, mirrored);
    file::save(&set, &args.out)
        .into_diagnostic()
        .wrap_err_with(|| format!("writing {}", args.out.display()))?;
    let size = std::fs::metadata(&args.out).map_or(0, |m| m.len());
    println!("{}", set.source);
    println!(
        "{} poses within {:.0} cm of every frame ({:.1} s); {} written ({:.2} MB)",
        set.poses.len(),
        set.cover * 100.0,
        started.elapsed().as_secs_f32(),
        args.out.display(),
        size as f64 / 1e6
    );
    println!(
        "standing on one leg (one foot's lowest joint under 5 cm, the other's above), in the set's poses [in the frames themselves]:"
    );
    let raw = build(&clips, "frames", 0.001, mirrored);
    let raw_runs = one_leg_runs(&raw, &[0.1, 0.2, 0.3, 0.5]);
    for ((h, run), (_, truth)) in one_leg_runs(&set, &[0.1, 0.2, 0.3, 0.5])
        .into_iter()
        .zip(raw_runs)
    {
        let truth = truth.map_or("never".to_string(), |r| {
            format!("{:.2} s, {}", r.frames as f32 / 20.0, r.name)
        });
        match run {
            Some(r) => println!(
                "  {:.0} cm: longest {:.2} s ({} frames, {} from frame {}{}) [{truth}]",
                h * 100.0,
                r.frames as f32 / 20.0,
                r.frames,
                r.name,
                r.start,
                if r.whole_clip { ", the whole clip" } else { "" }
            ),
            None => println!("  {:.0} cm: never [{truth}]", h * 100.0),
        }
    }
    if args.held_out {
        held_out(&data, args.cover, mirrored);
    }
    Ok(())
}

/// Builds a set without the test split and prints how near it comes to the test clips'
/// poses (every 8th frame).
fn held_out(data: &Dataset, cover: f32, mirrored: bool) {
    let train = build(
        &inputs(data, &[Split::Train, Split::Val]),
        "train and val",
        cover,
        mirrored,
    );
    let test: Vec<Pose> = inputs(data, &[Split::Test])
        .iter()
        .flat_map(|c| {
            let n = c.joints.len() / 66;
            (0..n)
                .step_by(8)
                .map(|t| {
                    mprog::coverage::pose::canonical(&mprog::coverage::pose::frame_pose(
                        c.joints, t,
                    ))
                })
                .collect::<Vec<_>>()
        })
        .collect();
    let mut nearest: Vec<f32> = test.iter().map(|p| nearest_distance(&train, p)).collect();
    let q = percentiles(&mut nearest);
    println!(
        "held out: {} test frames against {} poses of train and val; nearest pose (largest joint distance, m): p50 {:.3}, p90 {:.3}, p99 {:.3}, p99.9 {:.3}, max {:.3}",
        test.len(),
        train.poses.len(),
        q[0],
        q[1],
        q[2],
        q[3],
        q[4]
    );
    let test_set = build(&inputs(data, &[Split::Test]), "test", cover, mirrored);
    let lifts = [0.1, 0.2, 0.3];
    for ((h, a), (_, b)) in one_leg_runs(&train, &lifts)
        .into_iter()
        .zip(one_leg_runs(&test_set, &lifts))
    {
        let secs =
            |r: Option<mprog::coverage::search::Run>| r.map_or(0.0, |r| r.frames as f32 / 20.0);
        println!(
            "  one leg, the other foot above {:.0} cm: longest {:.2} s in train and val, {:.2} s in test",
            h * 100.0,
            secs(a),
            secs(b)
        );
    }
    for (what, query) in [
        ("height", Query::Heights),
        ("joint distance", Query::Distances),
    ] {
        for k in [1, 2, 3, 4, 8] {
            let mut v = held_out_violations(&train, &test, query, k, 7 + k as u64);
            let q = percentiles(&mut v);
            println!(
                "  {k} {what} bound(s) each test pose meets, away from the median: least violation (m) p50 {:.3}, p90 {:.3}, p99 {:.3}, p99.9 {:.3}, max {:.3}",
                q[0], q[1], q[2], q[3], q[4]
            );
        }
    }
}

/// The largest joint distance from `p` to the nearest pose of `set` (either side).
fn nearest_distance(set: &Coverage, p: &Pose) -> f32 {
    (0..set.variants())
        .map(|v| mprog::coverage::pose::joint_distance(&set.variant(v), p))
        .fold(f32::INFINITY, f32::min)
}
