//! Editing a take on the tiny seeded denoiser: strength 0 returns the take, strength 1
//! is a solve without one, kept frames come back exactly, solvers that cannot edit say so,
//! and bad edits are refused.

// A list of one frame range is what `hold_weights` takes, not a range to collect.
#![allow(clippy::single_range_in_vec_init)]

use super::tests::{tiny_bundle, wrist_up};
use super::*;
use crate::features::FEATURE_DIM;
use crate::motion::Motion;
use crate::skeleton::rest_pose;
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

fn request(solver: Solver, e: Edit) -> SolveRequest {
    SolveRequest::new(vec!["a person walks forward".into()], N, 3, solver).editing(e)
}

fn solve_ok(req: &SolveRequest) -> SolveResult {
    let bundle = tiny_bundle();
    solve(
        &Prior::from_bundle(&bundle),
        req,
        &wrist_up,
        &Device::flex(),
        |_| {},
    )
    .unwrap_or_else(|e| panic!("{}: {e}", req.solver.name()))
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
        if name == "guide" {
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
    let bundle = tiny_bundle();
    for (s, steps) in [(0.0, 0), (0.25, 10), (0.5, 20), (1.0, 40)] {
        let req = request(
            Solver::plain(crate::model::sampler::SamplerKind::Ddpm(40)),
            edit(s, Vec::new()),
        );
        let mut reports = Vec::new();
        solve(
            &Prior::from_bundle(&bundle),
            &req,
            &wrist_up,
            &Device::flex(),
            |p| reports.push((p.done, p.total)),
        )
        .unwrap();
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
    for name in ["latent", "ik", "ik-reg", "lbfgs"] {
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
