//! Editing real takes with the shipped model (issue 30's "done when"), slow, so `--ignored`:
//!
//! ```sh
//! cargo test --release --test edit_walk -- --ignored --nocapture
//! ```
//!
//! * **A real walk** of the test split (Bandai `dataset-1_walk_happy_001`) edited with "the
//!   left hand within 15 cm of the head for the second half", at several strengths and
//!   with the first half kept: how far the root path moves from the take, the travelled
//!   distance, how far the first half moves, and the program's error on the second half.
//! * **Untouched time**: the same walk and program (the hand on the head from frame 70)
//!   with the frames the program does not read held, at several margins, against
//!   `--free-time`: how far the held frames and the first half move, the program's error,
//!   and the accelerations around the seam against the take's own.
//! * **An in-between** of two real clips (the end of that walk, the start of
//!   `dataset-1_run_happy_001`): the largest frame-to-frame joint jump against the
//!   clips' own, and foot skating against theirs.
//!
//! The takes come from `data/raw` (or `$MPROG_BVH_DIR`); without them the tests say so and
//! pass. Pictures of each run land in `target/edit_walk/`.

// A list of one frame range is what `hold_weights` takes, not a range to collect.
#![allow(clippy::single_range_in_vec_init)]

use burn::prelude::*;
use glam::Vec3;
use mprog::formats::{LoadedMotion, Meta, read_motion, write_motion};
use mprog::lang::{Program, compile};
use mprog::metrics::per_motion::{foot_skating_ratio, max_bone_error};
use mprog::model::ModelBundle;
use mprog::model::control::ControlNet;
use mprog::model::sampler::SamplerKind;
use mprog::model::weights::default_model_dir;
use mprog::motion::Motion;
use mprog::solve::take::frames_of;
use mprog::solve::{
    DEFAULT_BLEND, DEFAULT_RESAMPLE, DEFAULT_STRENGTH, Edit, GuideConfig, LatentConfig, Prior,
    SolveRequest, Solver, TIME_MARGIN, Take, auto_hold, hold_weights, in_between_hold, solve,
};
use std::path::PathBuf;

const WALK: &str = "dataset-1_walk_happy_001";
const RUN: &str = "dataset-1_run_happy_001";

/// A Bandai take of the test split, or `None` (with a message) when the archive is absent.
fn bandai(name: &str) -> Option<Motion> {
    let root = std::env::var_os("MPROG_BVH_DIR").map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("data/raw"),
        PathBuf::from,
    );
    let path = root.join(format!(
        "dataset/Bandai-Namco-Research-Motiondataset-1/data/{name}.bvh"
    ));
    if !path.exists() {
        eprintln!(
            "skipping: {} is missing (unpack the Bandai archive into data/raw)",
            path.display()
        );
        return None;
    }
    match read_motion(&path).unwrap() {
        LoadedMotion::Joints { mut people, .. } => Some(people.remove(0).motion),
        LoadedMotion::Features(_) => panic!("a BVH gives joints"),
    }
}

fn out_dir() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/edit_walk");
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn save(name: &str, people: &[Motion]) {
    for ext in ["json", "png"] {
        write_motion(
            &out_dir().join(format!("{name}.{ext}")),
            people,
            &Meta::new(),
        )
        .unwrap();
    }
}

/// Horizontal distance between two points.
fn flat(a: Vec3, b: Vec3) -> f32 {
    Vec3::new(a.x - b.x, 0.0, a.z - b.z).length()
}

/// Root path length over the horizontal plane.
fn travelled(m: &Motion) -> f32 {
    m.frames.windows(2).map(|w| flat(w[1][0], w[0][0])).sum()
}

/// How an edit holds the path and the body.
#[derive(Clone, Copy, PartialEq)]
enum Holds {
    /// Nothing held but kept frames.
    None,
    /// The path (`--keep-path --free-body`).
    Path,
    /// What `auto_hold` finds for the path and the body (the default of
    /// `mprog run --from --free-time`; untouched time is measured by
    /// `untouched_time_of_a_real_walk`).
    Auto,
}

/// One measured edit: label, solver, strength, kept frames, holds.
type Run = (String, Solver, f32, Vec<std::ops::Range<usize>>, Holds);

/// How one edit compares with its take.
struct Row {
    label: String,
    root_dev: f32,
    distance_ratio: f32,
    first_half_mean: f32,
    first_half_max: f32,
    program: f32,
    hand_head_max: f32,
    skating: f32,
    bone: f32,
}

fn measure(label: &str, take: &Motion, edit: &Motion, program: &Program) -> Row {
    let n = edit.len();
    let half = n / 2;
    let root_dev = (0..n)
        .map(|t| flat(edit.frames[t][0], take.frames[t][0]))
        .fold(0.0, f32::max);
    let per_frame = |t: usize| -> (f32, f32) {
        let d: Vec<f32> = (0..22)
            .map(|j| (edit.frames[t][j] - take.frames[t][j]).length())
            .collect();
        (
            d.iter().sum::<f32>() / 22.0,
            d.iter().copied().fold(0.0, f32::max),
        )
    };
    let (first_half_mean, first_half_max) = (0..half)
        .map(per_frame)
        .fold((0.0f32, 0.0f32), |(a, b), (m, x)| (a.max(m), b.max(x)));
    let joints = Tensor::<5>::from_data(
        TensorData::new(edit.to_flat(), [1, 1, n, 22, 3]),
        &Device::flex(),
    );
    let program_error = program.evaluate(joints).total.into_scalar::<f32>();
    let hand_head_max = (half..n)
        .map(|t| (edit.frames[t][20] - edit.frames[t][15]).length())
        .fold(0.0, f32::max);
    Row {
        label: label.into(),
        root_dev,
        distance_ratio: travelled(edit) / travelled(take),
        first_half_mean,
        first_half_max,
        program: program_error,
        hand_head_max,
        skating: foot_skating_ratio(edit),
        bone: max_bone_error(edit),
    }
}

fn print(rows: &[Row]) {
    println!(
        "| run | root path, max dev (m) | distance / take's | first half: max per-frame mean joint dev (m) | first half: max joint dev (m) | program error, 2nd half (m) | max hand–head, 2nd half (m) | foot skating | largest bone error (m) |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    for r in rows {
        println!(
            "| {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.4} | {:.3} | {:.3} | {:.3} |",
            r.label,
            r.root_dev,
            r.distance_ratio,
            r.first_half_mean,
            r.first_half_max,
            r.program,
            r.hand_head_max,
            r.skating,
            r.bone
        );
    }
}

fn edit_once(
    bundle: &ModelBundle,
    program: &Program,
    prompt: &str,
    solver: Solver,
    edit: Edit,
) -> Motion {
    let req = SolveRequest::new(vec![prompt.into()], edit.take.frames, 1, solver).editing(edit);
    let out = solve(
        &Prior::from_bundle(bundle),
        &req,
        program,
        &Device::flex(),
        |_| {},
    )
    .expect("the edit runs");
    out.motions[0][0].clone()
}

#[test]
#[ignore = "minutes with the shipped model: cargo test --release --test edit_walk -- --ignored --nocapture"]
fn editing_a_real_walk() {
    let Some(walk) = bandai(WALK) else { return };
    let bundle = ModelBundle::load(&default_model_dir(), &Device::flex()).unwrap();
    let take = Take::encode(std::slice::from_ref(&walk)).unwrap();
    let n = take.frames;
    let source = format!(
        "prompt \"a happy person walks forward\"\nlength {n} frames\nduring 50%..100% {{ dist(l_hand, head) < 15 cm }}\n"
    );
    let program = compile(&source, "hand_on_head_second_half.mprog", &[]).unwrap();
    let prompt = "a happy person walks forward";
    let retargeted = take.motions().unwrap().remove(0);
    save("take", std::slice::from_ref(&retargeted));
    let mut rows = vec![measure(
        "take (strength 0)",
        &retargeted,
        &retargeted,
        &program,
    )];
    let mut at_default = None;
    let guide = || Solver::new(GuideConfig::default());
    let runs: Vec<Run> = vec![
        (
            "guide (default holds)".into(),
            guide(),
            0.3,
            vec![],
            Holds::Auto,
        ),
        (
            "guide (default holds)".into(),
            guide(),
            0.5,
            vec![],
            Holds::Auto,
        ),
        (
            "guide (default holds)".into(),
            guide(),
            0.7,
            vec![],
            Holds::Auto,
        ),
        (
            "guide (default holds)".into(),
            guide(),
            1.0,
            vec![],
            Holds::Auto,
        ),
        (
            format!("guide (default holds), --keep ..{}", n / 2 - 10),
            guide(),
            0.5,
            vec![0..n / 2 - 10],
            Holds::Auto,
        ),
        (
            "guide, --free-path --free-body".into(),
            guide(),
            0.5,
            vec![],
            Holds::None,
        ),
        (
            "guide, --keep-path --free-body".into(),
            guide(),
            0.5,
            vec![],
            Holds::Path,
        ),
        (
            "plain (unguided), default holds".into(),
            Solver::plain(SamplerKind::Ddpm(1000)),
            0.5,
            vec![],
            Holds::Auto,
        ),
        (
            "latent, DDIM-50 inversion, no update, default holds".into(),
            latent(1),
            0.5,
            vec![],
            Holds::Auto,
        ),
        (
            "latent, 20 iterations, default holds".into(),
            latent(20),
            0.5,
            vec![],
            Holds::Auto,
        ),
        (
            "latent, 20 iterations, --free-path --free-body".into(),
            latent(20),
            0.5,
            vec![],
            Holds::None,
        ),
    ];
    let auto = auto_hold(&take, &program, &Device::flex()).unwrap();
    println!("default holds: path {}, parts {:?}", auto.path, auto.parts);
    for (i, (label, solver, s, keep, holds)) in runs.into_iter().enumerate() {
        let e = Edit {
            take: take.clone(),
            strength: s,
            hold: if keep.is_empty() {
                Vec::new()
            } else {
                hold_weights(n, &keep, DEFAULT_BLEND)
            },
            hold_path: match holds {
                Holds::None => false,
                Holds::Path => true,
                Holds::Auto => auto.path,
            },
            hold_joints: if holds == Holds::Auto {
                auto.joints()
            } else {
                [false; 22]
            },
            resample: if keep.is_empty() { 0 } else { DEFAULT_RESAMPLE },
            clean_feet: true,
        };
        let default = s == DEFAULT_STRENGTH
            && holds == Holds::Auto
            && keep.is_empty()
            && label.starts_with("guide");
        let m = edit_once(&bundle, &program, prompt, solver, e);
        save(&format!("edit_{i}"), std::slice::from_ref(&m));
        let row = measure(
            &format!("{label}, strength {s} (edit_{i})"),
            &retargeted,
            &m,
            &program,
        );
        if default {
            at_default = Some(measure("default", &retargeted, &m, &program));
        }
        rows.push(row);
    }
    print(&rows);
    let r = at_default.expect("the default strength is measured");
    assert!(
        r.root_dev <= 0.2,
        "root path {:.3} m from the take",
        r.root_dev
    );
    assert!(
        (r.distance_ratio - 1.0).abs() <= 0.1,
        "distance ratio {:.3}",
        r.distance_ratio
    );
    assert!(
        r.first_half_mean <= 0.15,
        "first half {:.3} m from the take",
        r.first_half_mean
    );
    assert!(
        r.program <= 0.01,
        "second half: program error {:.4} m",
        r.program
    );
}

/// `latent` on a 50-step DDIM chain with `iterations` forward passes (PMG's lr).
fn latent(iterations: usize) -> Solver {
    Solver::new(LatentConfig {
        ddim_steps: 50,
        iterations,
        ..LatentConfig::default()
    })
}

/// Largest frame-to-frame move of any joint.
fn largest_jump(m: &Motion) -> f32 {
    m.frames
        .windows(2)
        .flat_map(|w| (0..22).map(move |j| (w[1][j] - w[0][j]).length()))
        .fold(0.0, f32::max)
}

#[test]
#[ignore = "a minute with the shipped model: cargo test --release --test edit_walk -- --ignored --nocapture"]
fn in_between_two_real_clips() {
    let (Some(walk), Some(run)) = (bandai(WALK), bandai(RUN)) else {
        return;
    };
    let bundle = ModelBundle::load(&default_model_dir(), &Device::flex()).unwrap();
    let (context, frames) = (20, 100);
    let a = frames_of(&walk, walk.len() - context - 1, walk.len()).unwrap();
    let b = frames_of(&run, 0, context + 1).unwrap();
    let take = Take::splice(
        &Take::encode(&[a]).unwrap(),
        &Take::encode(&[b]).unwrap(),
        frames,
        &bundle.mean,
    )
    .unwrap();
    // The clips as the model's skeleton draws them.
    let clip = |m: &Motion| {
        Take::encode(std::slice::from_ref(m))
            .unwrap()
            .motions()
            .unwrap()
            .remove(0)
    };
    let (walk_r, run_r) = (clip(&walk), clip(&run));
    let own = largest_jump(&walk_r).max(largest_jump(&run_r));
    let real_skating = (foot_skating_ratio(&walk_r) + foot_skating_ratio(&run_r)) / 2.0;
    println!("| blend (frames) | seam 1 jump (m/frame) | seam 2 jump | whole | foot skating |");
    println!("| --- | --- | --- | --- | --- |");
    println!("| clips' own (walk, run) | | | {own:.3} | {real_skating:.3} |");
    let mut at_default = None;
    for blend in [DEFAULT_BLEND, 2 * DEFAULT_BLEND] {
        let edit = Edit {
            take: take.clone(),
            strength: 1.0,
            hold: in_between_hold(frames, context, blend),
            hold_path: false,
            hold_joints: [false; 22],
            resample: DEFAULT_RESAMPLE,
            clean_feet: true,
        };
        let none = |j: Tensor<5>| j.sum_dim(4).sum_dim(3).sum_dim(2).sum_dim(1).reshape([1]) * 0.0;
        let req = SolveRequest::new(
            vec!["a happy person walks forward then runs forward".into()],
            frames,
            1,
            Solver::plain(SamplerKind::Ddpm(1000)),
        )
        .editing(edit);
        let out = solve(
            &Prior::from_bundle(&bundle),
            &req,
            &none,
            &Device::flex(),
            |_| {},
        )
        .unwrap();
        let m = out.motions[0][0].clone();
        save(
            &format!("in_between_blend{blend}"),
            std::slice::from_ref(&m),
        );
        println!(
            "| {blend} | {:.3} | {:.3} | {:.3} | {:.3} |",
            seam_jump(&m, context),
            seam_jump(&m, frames - context),
            largest_jump(&m),
            foot_skating_ratio(&m)
        );
        if blend == DEFAULT_BLEND {
            at_default = Some(m);
        }
    }
    let m = &at_default.unwrap();
    // The seams: no pop where the gap meets either clip. (The gap's own motion is the
    // model's; its largest jump is printed above as "whole".)
    let seams = seam_jump(m, context).max(seam_jump(m, frames - context));
    assert!(seams <= own, "seam jump {seams:.3} vs the clips' {own:.3}");
    assert!(foot_skating_ratio(m) <= 1.5 * real_skating.max(1e-3));
}

/// The largest joint jump within 5 frames of frame `t`.
fn seam_jump(m: &Motion, t: usize) -> f32 {
    let frames = m.len();
    (t.saturating_sub(5)..(t + 5).min(frames - 1))
        .flat_map(|u| (0..22).map(move |j| (u, j)))
        .map(|(u, j)| (m.frames[u + 1][j] - m.frames[u][j]).length())
        .fold(0.0, f32::max)
}

/// Largest acceleration `|p[t+1] − 2p[t] + p[t−1]|` of joint `j` (m/frame², 20 fps) over
/// the frames `frames` (clipped to the motion's inner frames).
fn max_accel(m: &Motion, j: usize, frames: std::ops::Range<usize>) -> f32 {
    (frames.start.max(1)..frames.end.min(m.len() - 1))
        .map(|t| (m.frames[t + 1][j] - 2.0 * m.frames[t][j] + m.frames[t - 1][j]).length())
        .fold(0.0, f32::max)
}

/// The largest distance of any of `joints` from the take's over `frames`.
fn joint_gap(a: &Motion, b: &Motion, frames: std::ops::Range<usize>, joints: &[usize]) -> f32 {
    frames
        .flat_map(|t| {
            joints
                .iter()
                .map(move |&j| (a.frames[t][j] - b.frames[t][j]).length())
        })
        .fold(0.0, f32::max)
}

#[test]
#[ignore = "minutes with the shipped model: cargo test --release --test edit_walk -- --ignored --nocapture untouched_time"]
fn untouched_time_of_a_real_walk() {
    let Some(walk) = bandai(WALK) else { return };
    let dir = default_model_dir();
    let device = Device::flex();
    let bundle = ModelBundle::load(&dir, &device).unwrap();
    // As `mprog run` does: the realism ControlNet beside the weights steers `guide`.
    let control =
        ControlNet::load(&dir, &bundle.model, bundle.manifest.half_precision, &device).unwrap();
    let take = Take::encode(std::slice::from_ref(&walk)).unwrap();
    let n = take.frames;
    let source = format!(
        "prompt \"a happy person walks forward\"\nlength {n} frames\nduring 50%..end + 1 {{ dist(l_hand, head) < 15 cm }}\n"
    );
    let program = compile(&source, "hand_on_head_second_half.mprog", &[]).unwrap();
    let retargeted = take.motions().unwrap().remove(0);
    let auto = auto_hold(&take, &program, &device).unwrap();
    let seam = auto.untouched.iter().position(|u| !u).unwrap();
    println!(
        "the program reads frames {seam}..{n}; parts held: {:?}",
        auto.parts
    );
    let all: Vec<usize> = (0..22).collect();
    // (label, hold weights)
    let mut runs: Vec<(String, Vec<f32>)> = vec![("--free-time".into(), vec![])];
    for margin in [5, 10, 15, 20] {
        runs.push((
            format!(
                "held, margin {margin}{}",
                if margin == TIME_MARGIN {
                    " (the default)"
                } else {
                    ""
                }
            ),
            auto.time_weights(margin),
        ));
    }
    runs.push((
        format!("held to frame {seam}, the {TIME_MARGIN}-frame blend inside the window"),
        hold_weights(n, &[0..seam], TIME_MARGIN),
    ));
    println!(
        "| run | first half (0..{seam}): largest joint gap (m) | pelvis | frames held exactly: largest joint gap | program error, 2nd half (m) | largest hand–head, 2nd half (m) | pelvis accel ±10 of {seam} (m/frame²) | head | left wrist | largest bone error (m) |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    let around = seam - 10..seam + 11;
    let hand_head = |m: &Motion| {
        (seam..n)
            .map(|t| (m.frames[t][20] - m.frames[t][15]).length())
            .fold(0.0, f32::max)
    };
    println!(
        "| the take | 0 | 0 | 0 | {:.4} | {:.3} | {:.4} ({:.4} in the whole take) | {:.4} ({:.4}) | {:.4} ({:.4}) | 0 |",
        measure("", &retargeted, &retargeted, &program).program,
        hand_head(&retargeted),
        max_accel(&retargeted, 0, around.clone()),
        max_accel(&retargeted, 0, 0..n),
        max_accel(&retargeted, 15, around.clone()),
        max_accel(&retargeted, 15, 0..n),
        max_accel(&retargeted, 20, around.clone()),
        max_accel(&retargeted, 20, 0..n),
    );
    let mut at_default = None;
    for (i, (label, hold)) in runs.into_iter().enumerate() {
        let exact = hold.iter().take_while(|w| **w >= 1.0).count();
        let e = Edit {
            take: take.clone(),
            strength: DEFAULT_STRENGTH,
            hold,
            hold_path: auto.path,
            hold_joints: auto.joints(),
            resample: 0,
            clean_feet: true,
        };
        let req = SolveRequest::new(
            vec!["a happy person walks forward".into()],
            n,
            1,
            Solver::new(GuideConfig::default()),
        )
        .editing(e);
        let out = solve(
            &Prior::from_bundle(&bundle).with_control(control.as_ref()),
            &req,
            &program,
            &device,
            |_| {},
        )
        .expect("the edit runs");
        let m = out.motions[0][0].clone();
        save(&format!("untouched_time_{i}"), std::slice::from_ref(&m));
        let r = measure("", &retargeted, &m, &program);
        let held = joint_gap(&m, &retargeted, 0..exact, &all);
        println!(
            "| {label} (untouched_time_{i}) | {:.3} | {:.3} | {} | {:.4} | {:.3} | {:.4} | {:.4} | {:.4} | {:.3} |",
            joint_gap(&m, &retargeted, 0..seam, &all),
            joint_gap(&m, &retargeted, 0..seam, &[0]),
            if exact == 0 {
                "—".into()
            } else {
                format!("{held:.4} (0..{exact})")
            },
            r.program,
            hand_head(&m),
            max_accel(&m, 0, around.clone()),
            max_accel(&m, 15, around.clone()),
            max_accel(&m, 20, around.clone()),
            r.bone,
        );
        if label.ends_with("(the default)") {
            at_default = Some((held, r.program, max_accel(&m, 20, around.clone())));
        }
    }
    let (held, program_error, wrist) = at_default.expect("the default margin is measured");
    assert!(held <= 0.02, "held untouched time moved {held:.3} m");
    assert!(
        program_error <= 0.01,
        "second half: program error {program_error:.4} m"
    );
    let own = max_accel(&retargeted, 20, 0..n);
    assert!(
        wrist <= 1.5 * own,
        "the wrist pops at the seam: {wrist:.3} m/frame² against the take's largest {own:.3}"
    );
}
