//! Editing a take on the tiny seeded denoiser: strength 0 returns the take, strength 1
//! is a solve without one, kept frames come back exactly, solvers that cannot edit say so,
//! and bad edits are refused.

// A list of one frame range is what `hold_weights` takes, not a range to collect.
#![allow(clippy::single_range_in_vec_init)]

use super::edit::ChainSteps;
use super::tests::{tiny_bundle, wrist_up};
use super::*;
use crate::features::FEATURE_DIM;
use crate::features::layout::RIC;
use crate::motion::Motion;
use crate::skeleton::{NUM_JOINTS, rest_pose};
use burn::prelude::*;
use glam::{Quat, Vec3};

/// Feature frames of the takes here (the tiny model's requests are short).
const N: usize = 16;

/// A rest pose walking 4 cm a frame with its arms swinging, turned and moved.
fn take_walk() -> Motion {
    let turn = Quat::from_rotation_y(0.6);
    Motion::new(
        (0..=N)
            .map(|t| {
                let mut p = rest_pose();
                let swing = 0.15 * (t as f32 * 0.4).sin();
                p[18].z += swing;
                p[20].z += 2.0 * swing;
                p[19].z -= swing;
                p[21].z -= 2.0 * swing;
                p.map(|v| {
                    turn * (v + Vec3::new(0.0, 0.0, 0.04 * t as f32)) + Vec3::new(1.0, 0.0, -2.0)
                })
            })
            .collect(),
    )
}

fn edit(strength: f32, hold: Vec<f32>) -> Edit {
    Edit {
        take: Take::encode(&[take_walk()]).unwrap(),
        strength,
        hold,
        hold_path: false,
        hold_joints: [false; NUM_JOINTS],
        resample: 0,
        clean_feet: false,
    }
}

fn guide() -> Solver {
    Solver::new(GuideConfig {
        steps: 40,
        k_late: 30,
        late_steps: 5,
        ..GuideConfig::default()
    })
}

/// `lbfgs` at a size the tiny model runs in a moment.
fn lbfgs() -> Solver {
    Solver::new(LbfgsConfig {
        steps: 40,
        late_steps: 5,
        k_last: 10,
        ..LbfgsConfig::default()
    })
}

/// `latent` at a size the tiny model runs in a moment.
fn latent() -> Solver {
    Solver::new(LatentConfig {
        ddim_steps: 10,
        iterations: 3,
        lr: 0.05,
        ..LatentConfig::default()
    })
}

fn request(solver: Solver, e: Edit) -> SolveRequest {
    SolveRequest::new(vec!["a person walks forward".into()], N, 3, solver).editing(e)
}

fn solve_ok(req: &SolveRequest) -> SolveResult {
    solve_reporting(req).0
}

/// The solve and its progress reports, `(done, total)` each.
fn solve_reporting(req: &SolveRequest) -> (SolveResult, Vec<(usize, usize)>) {
    let bundle = tiny_bundle();
    let mut reports = Vec::new();
    let r = solve(
        &Prior::from_bundle(&bundle),
        req,
        &wrist_up,
        &Device::flex(),
        |p| reports.push((p.done, p.total)),
    )
    .unwrap_or_else(|e| panic!("{}: {e}", req.solver.name()));
    (r, reports)
}

/// Largest difference between two feature rows ranges (de-normalised).
fn row_gap(a: &[f32], b: &[f32], rows: std::ops::Range<usize>) -> f32 {
    let r = rows.start * FEATURE_DIM..rows.end * FEATURE_DIM;
    a[r.clone()]
        .iter()
        .zip(&b[r])
        .fold(0.0f32, |m, (x, y)| m.max((x - y).abs()))
}

#[test]
fn strength_zero_returns_the_take() {
    for solver in [
        guide(),
        latent(),
        Solver::plain(crate::model::sampler::SamplerKind::Ddpm(40)),
    ] {
        let e = edit(0.0, Vec::new());
        let want = e.take.motions().unwrap();
        let r = solve_ok(&request(solver, e.clone()));
        assert!(row_gap(&r.features, &e.take.features[0], 0..N) < 1e-4);
        for (a, b) in r.motions[0][0].frames.iter().zip(&want[0].frames) {
            for (p, q) in a.iter().zip(b) {
                assert!((*p - *q).length() < 1e-4, "{p} vs {q}");
            }
        }
        // The take stands where it stood: frame 0's root at (1, ·, −2).
        let root = r.motions[0][0].frames[0][0];
        assert!(
            (root.x - 1.0).abs() < 1e-4 && (root.z + 2.0).abs() < 1e-4,
            "{root}"
        );
    }
}

#[test]
fn strength_one_is_a_solve_without_a_take() {
    let with = solve_ok(&request(guide(), edit(1.0, Vec::new())));
    let mut req = request(guide(), edit(1.0, Vec::new()));
    req.edit = None;
    req.placements = Some(vec![edit(1.0, Vec::new()).take.placements[0]]);
    let without = solve_ok(&req);
    assert_eq!(with.features, without.features);
}

#[test]
fn kept_frames_come_back_exactly_and_the_rest_is_edited() {
    for solver in [
        guide(),
        latent(),
        lbfgs(),
        Solver::plain(crate::model::sampler::SamplerKind::Ddim(20)),
    ] {
        let name = solver.name();
        let e = edit(1.0, hold_weights(N, &[0..6], 3));
        let take_error = {
            let m = &e.take.motions().unwrap()[0];
            let j = crate::motion::Motion::to_flat(m);
            host_error(&j)
        };
        let r = solve_ok(&request(solver, e.clone()));
        let take = &e.take.features[0];
        assert!(
            row_gap(&r.features, take, 0..6) < 1e-4,
            "{name}: kept frames moved"
        );
        assert!(
            row_gap(&r.features, take, 9..N) > 1e-2,
            "{name}: nothing edited"
        );
        // Kept frames before the edit stay where the take put them, in the world too.
        let want = e.take.motions().unwrap();
        for t in 0..6 {
            let d = (r.motions[0][0].frames[t][20] - want[0].frames[t][20]).length();
            assert!(d < 1e-4, "{name}: frame {t} moved {d} m");
        }
        if name != "plain" {
            assert!(
                r.error[0] < take_error,
                "{name}: {} vs the take's {take_error}",
                r.error[0]
            );
        }
    }
}

/// The wrist error of one motion's flat joints.
fn host_error(flat: &[f32]) -> f32 {
    let n = flat.len() / 66;
    let j = Tensor::<5>::from_data(
        TensorData::new(flat.to_vec(), [1, 1, n, 22, 3]),
        &Device::flex(),
    );
    wrist_up(j).into_scalar::<f32>()
}

#[test]
fn strength_sets_how_much_of_the_chain_runs() {
    for (s, steps) in [(0.0, 0), (0.25, 10), (0.5, 20), (1.0, 40)] {
        let req = request(
            Solver::plain(crate::model::sampler::SamplerKind::Ddpm(40)),
            edit(s, Vec::new()),
        );
        let (_, reports) = solve_reporting(&req);
        assert_eq!(reports.len(), steps, "strength {s}");
        assert!(reports.iter().all(|&(_, total)| total == steps));
    }
}

#[test]
fn a_held_path_is_the_takes_and_the_pose_is_edited() {
    let e = Edit {
        hold_path: true,
        ..edit(0.7, Vec::new())
    };
    let r = solve_ok(&request(guide(), e.clone()));
    let take = &e.take.features[0];
    let mut path_gap = 0.0f32;
    for (row, want) in r
        .features
        .chunks_exact(FEATURE_DIM)
        .zip(take.chunks_exact(FEATURE_DIM))
    {
        for c in 0..3 {
            path_gap = path_gap.max((row[c] - want[c]).abs());
        }
    }
    assert!(path_gap < 1e-4, "the path moved by {path_gap}");
    assert!(
        row_gap(&r.features, take, 0..N) > 1e-2,
        "the pose was not edited"
    );
    let want = e.take.motions().unwrap();
    for (a, b) in r.motions[0][0].frames.iter().zip(&want[0].frames) {
        // The path is horizontal: the height is the edited body's.
        let d = (a[0] - b[0]) * Vec3::new(1.0, 0.0, 1.0);
        assert!(d.length() < 1e-3, "root {} vs {}", a[0], b[0]);
    }
}

#[test]
fn edits_are_deterministic() {
    let req = request(guide(), edit(0.6, hold_weights(N, &[10..N], 2)));
    let a = solve_ok(&req);
    let b = solve_ok(&req);
    assert_eq!(a.features, b.features);
    let mut other = req.clone();
    other.seed += 1;
    assert_ne!(solve_ok(&other).features, a.features);
}

#[test]
fn solvers_that_cannot_edit_say_so_and_bad_edits_are_refused() {
    let bundle = tiny_bundle();
    let refused = |req: &SolveRequest| -> String {
        match solve(
            &Prior::from_bundle(&bundle),
            req,
            &wrist_up,
            &Device::flex(),
            |_| {},
        ) {
            Err(SolveError::Invalid(m)) => m,
            Err(e) => panic!("{e}"),
            Ok(_) => panic!("{} accepted a bad edit", req.solver.name()),
        }
    };
    for name in ["ik", "ik-reg"] {
        let m = refused(&request(
            Solver::by_name(name).unwrap(),
            edit(0.5, Vec::new()),
        ));
        assert!(
            m.contains("cannot edit a take") && m.contains("guide"),
            "{name}: {m}"
        );
    }
    for s in [-0.1, 1.5, f32::NAN] {
        let m = refused(&request(guide(), edit(s, Vec::new())));
        assert!(m.contains("strength"), "{m}");
    }
    let mut two = request(guide(), edit(0.5, Vec::new()));
    two.prompts.push("a person waves".into());
    assert!(refused(&two).contains("holds 1 motion"));
    let mut short = request(guide(), edit(0.5, Vec::new()));
    short.frames = N - 1;
    assert!(refused(&short).contains("sets the length"));
    let m = refused(&request(guide(), edit(0.5, vec![1.0; 3])));
    assert!(m.contains("hold weights"), "{m}");
}

/// A program about where the pelvis stands: 5 m along x.
fn pelvis_at_x5(j: Tensor<5>) -> Tensor<1> {
    let [b, _, _, _, _] = j.dims();
    (j.narrow(3, 0, 1).narrow(4, 0, 1) - 5.0)
        .abs()
        .sum_dim(4)
        .sum_dim(3)
        .sum_dim(2)
        .sum_dim(1)
        .reshape([b])
}

#[test]
fn default_holds_free_only_what_the_program_touches() {
    let take = Take::encode(&[take_walk()]).unwrap();
    let device = Device::flex();
    // A left-wrist height target: the left arm changes, the path (a height does not care
    // where the body stands) and every other part keep the take's.
    let auto = auto_hold(&take, &wrist_up, &device).unwrap();
    assert!(auto.path);
    assert_eq!(
        auto.parts,
        ["torso", "head", "right arm", "left leg", "right leg"]
    );
    let held = auto.joints();
    assert!(!held[20] && !held[18] && held[21] && held[10] && held[0]);
    // A place on the floor frees the path and the torso.
    let auto = auto_hold(&take, &pelvis_at_x5, &device).unwrap();
    assert!(!auto.path);
    assert!(!auto.parts.contains(&"torso") && auto.parts.contains(&"left arm"));
    // A program the take already meets touches nothing: everything is held.
    let met = |j: Tensor<5>| wrist_up(j) * 0.0;
    let auto = auto_hold(&take, &met, &device).unwrap();
    assert!(auto.path && auto.parts.len() == BODY_PARTS.len());
}

#[test]
fn held_body_parts_keep_the_takes_features_and_the_rest_is_edited() {
    let e = Edit {
        hold_path: true,
        hold_joints: parts_joints(&["torso", "left leg", "right leg", "right arm", "head"]),
        ..edit(0.7, Vec::new())
    };
    let r = solve_ok(&request(guide(), e.clone()));
    let take = &e.take.features[0];
    let ric = |j: usize| RIC.start + 3 * (j - 1)..RIC.start + 3 * j;
    let gap = |cols: std::ops::Range<usize>| {
        r.features
            .chunks_exact(FEATURE_DIM)
            .zip(take.chunks_exact(FEATURE_DIM))
            .flat_map(|(a, b)| cols.clone().map(move |c| (a[c] - b[c]).abs()))
            .fold(0.0f32, f32::max)
    };
    for j in [4, 10, 11, 9, 21, 15] {
        assert!(
            gap(ric(j)) < 1e-3,
            "held joint {j} moved by {}",
            gap(ric(j))
        );
    }
    assert!(gap(ric(20)) > 1e-2, "the left wrist was not edited");
}

#[test]
fn resampling_reruns_every_block_but_the_last() {
    let schedule = crate::model::schedule::NoiseSchedule::cosine(1000).respaced(40);
    let mut noise = crate::model::noise::NoiseSource::new(1);
    let device = Device::flex();
    let mut steps = ChainSteps::new(40, 2);
    let mut seen = vec![0usize; 40];
    let mut x = Tensor::<3>::zeros([1, 2, FEATURE_DIM], &device);
    while let Some(i) = steps.next_step() {
        seen[i] += 1;
        x = steps.after(&schedule, x, &mut noise, &device);
    }
    assert_eq!(steps.ran(), steps.total());
    assert_eq!(steps.total(), 40 + 2 * 30);
    assert!(seen[..10].iter().all(|&c| c == 1), "{seen:?}");
    assert!(seen[10..].iter().all(|&c| c == 3), "{seen:?}");
    // Without rounds: straight down.
    let mut plain = ChainSteps::new(7, 0);
    let order: Vec<usize> = std::iter::from_fn(|| plain.next_step()).collect();
    assert_eq!(order, [6, 5, 4, 3, 2, 1, 0]);
}

#[test]
fn a_resampled_edit_reports_every_step_and_is_deterministic() {
    let e = Edit {
        resample: 2,
        clean_feet: false,
        ..edit(1.0, hold_weights(N, &[0..4, N - 4..N], 2))
    };
    let req = request(guide(), e);
    let (a, reports) = solve_reporting(&req);
    let total = 40 + 2 * 30;
    assert_eq!(reports.len(), total);
    assert_eq!(reports.last(), Some(&(total, total)));
    assert_eq!(solve_ok(&req).features, a.features);
}

#[test]
fn foot_cleanup_leaves_what_is_held_exactly() {
    // Frames 0..6 kept: with the cleanup on they still come back exactly, and an edit
    // whose feet the model made is changed by it.
    let mut e = edit(1.0, hold_weights(N, &[0..6], 3));
    let raw = solve_ok(&request(guide(), e.clone()));
    e.clean_feet = true;
    let clean = solve_ok(&request(guide(), e.clone()));
    let take = &e.take.features[0];
    assert!(
        row_gap(&clean.features, take, 0..6) < 1e-4,
        "kept frames moved"
    );
    assert!(row_gap(&clean.features, &raw.features, 6..N) > 0.0);
}

/// The left wrist above 1.6 m on frames `from..` only: a program about the second half,
/// which says which frames it reads as a program does.
struct WristUpFrom(usize);

impl MotionError for WristUpFrom {
    fn error(&self, j: Tensor<5>) -> Tensor<1> {
        let n = j.dims()[2];
        wrist_up(j.narrow(2, self.0, n - self.0))
    }

    fn active_frames(&self, frames: usize) -> Option<Vec<bool>> {
        Some((0..frames).map(|t| t >= self.0).collect())
    }
}

#[test]
fn untouched_time_is_the_frames_no_statement_reads() {
    let take = Take::encode(&[take_walk()]).unwrap();
    let device = Device::flex();
    let auto = auto_hold(&take, &WristUpFrom(8), &device).unwrap();
    let want: Vec<bool> = (0..N).map(|t| t < 8).collect();
    assert_eq!(auto.untouched, want);
    // Held exactly 2 frames short of frame 8; the 2 frames before it ease into the edit.
    assert_eq!(auto.kept_time(2), [0..6]);
    let w = auto.time_weights(2);
    assert_eq!(&w[..6], &[1.0; 6]);
    assert!(
        w[6] > w[7] && w[7] > 0.0 && w[8..].iter().all(|v| *v == 0.0),
        "{w:?}"
    );
    // Frames a statement reads are not untouched even where the take already meets it (no
    // gradient there): the edit may need them.
    struct Met(WristUpFrom);
    impl MotionError for Met {
        fn error(&self, j: Tensor<5>) -> Tensor<1> {
            self.0.error(j) * 0.0
        }
        fn active_frames(&self, frames: usize) -> Option<Vec<bool>> {
            self.0.active_frames(frames)
        }
    }
    let auto = auto_hold(&take, &Met(WristUpFrom(8)), &device).unwrap();
    assert_eq!(auto.untouched, want);
    // An error that cannot say which frames it reads holds no time, even where its
    // gradient is zero; nor does one that reads every frame.
    let auto = auto_hold(&take, &|j: Tensor<5>| WristUpFrom(8).error(j), &device).unwrap();
    assert!(auto.untouched.iter().all(|u| !u) && auto.time_weights(2).is_empty());
    let auto = auto_hold(&take, &WristUpFrom(0), &device).unwrap();
    assert!(auto.kept_time(2).is_empty());
}

/// The largest distance of any joint from the take's on frames `frames`, in the world.
fn world_gap(got: &Motion, want: &Motion, frames: std::ops::Range<usize>) -> f32 {
    frames
        .flat_map(|t| (0..NUM_JOINTS).map(move |j| (t, j)))
        .map(|(t, j)| (got.frames[t][j] - want.frames[t][j]).length())
        .fold(0.0, f32::max)
}

#[test]
fn untouched_time_stays_the_takes_and_free_time_lets_it_move() {
    let bundle = tiny_bundle();
    let error = WristUpFrom(8);
    let e = edit(1.0, Vec::new());
    let want = e.take.motions().unwrap().remove(0);
    let auto = auto_hold(&e.take, &error, &Device::flex()).unwrap();
    let margin = 2;
    let run = |hold: Vec<f32>| {
        let req = request(guide(), Edit { hold, ..e.clone() });
        solve(
            &Prior::from_bundle(&bundle),
            &req,
            &error,
            &Device::flex(),
            |_| {},
        )
        .unwrap()
    };
    // Held (the default of `run --from`): frames 0..6 are the take's, to the millimetre
    // (the 2 cm the issue allows is far above it), and the frames the program reads move.
    let held = run(auto.time_weights(margin));
    let m = &held.motions[0][0];
    let kept = auto.kept_time(margin)[0].clone();
    assert_eq!(kept, 0..6);
    let gap = world_gap(m, &want, kept.clone());
    assert!(gap < 0.02, "untouched time moved {gap} m");
    assert!(gap < 1e-3, "untouched time moved {gap} m");
    assert!(
        world_gap(m, &want, 8..N) > 1e-2,
        "the second half was not edited"
    );
    let take_error = error
        .error(Tensor::from_data(
            TensorData::new(want.to_flat(), [1, 1, N, NUM_JOINTS, 3]),
            &Device::flex(),
        ))
        .into_scalar::<f32>();
    assert!(
        held.error[0] < take_error,
        "{} vs {take_error}",
        held.error[0]
    );
    // `--free-time` (no time held): the untouched frames are the model's again.
    let free = run(Vec::new());
    let gap = world_gap(&free.motions[0][0], &want, kept);
    assert!(gap > 0.02, "free time moved only {gap} m");
}
