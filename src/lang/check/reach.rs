//! Warnings about constraints that put one joint in a place: `mprog::out_of_reach` (the
//! place is, on the ground, farther than a limb reaches from where it starts, so it needs a
//! step, and nothing in the program moves the pelvis) and `mprog::frame_jump` (two such places, or one and the pinned start place,
//! that the joint can only get between faster than 4 m/s, e.g. 24 cm in one frame).
//!
//! A statement's *target* is a box holding every place its joint can be with the
//! statement met. It is found by shaving: each face of the box the body can reach moves
//! inward, by bisection, while the slab it cuts off provably breaks the statement (the
//! interval bounds of `bounds.rs`). Only statements whose error reads exactly one joint on
//! their own frames have a target; other reads (`pelvis@start`) stay intervals.

use super::bounds::{Bounds, Iv, Limits, Pass, Pick, TOLERANCE, cone, joint_bounds, lowest};
use crate::lang::ir::{Ir, NodeId, Op};
use crate::scene::Placement;
use crate::skeleton::{BONE_LENGTHS, FPS, JOINT_NAMES, PARENTS};

/// Most nodes a statement's error may read for it to be shaved.
const MAX_CONE: usize = 400;
/// Most bounds passes one program's shaving may take (bounds the checker's time).
const MAX_PASSES: usize = 20_000;
/// Bisection steps per face: 40 m halved 16 times is under 1 mm.
const STEPS: usize = 16;
/// Fastest a joint is expected to move between two places (m per frame: 4 m/s at 20 fps).
pub const JUMP_PER_FRAME: f64 = 0.2;
/// How far a standing person's shoulders and hips move sideways without a step (m): lean,
/// sway and turning in place.
pub const SWAY: f64 = 0.2;

/// A box of places one joint must be in on some frames.
#[derive(Clone, Debug, PartialEq)]
struct Target {
    /// The statement (None: the pelvis pinned to its start place at frame 0).
    statement: Option<usize>,
    person: usize,
    joint: usize,
    /// Frames, ascending.
    frames: Vec<usize>,
    lo: [f64; 3],
    hi: [f64; 3],
}

/// Distance between two boxes (0 when they meet).
fn gap(a: (&[f64; 3], &[f64; 3]), b: (&[f64; 3], &[f64; 3])) -> f64 {
    (0..3)
        .map(|k| (a.0[k] - b.1[k]).max(b.0[k] - a.1[k]).max(0.0))
        .map(|d| d * d)
        .sum::<f64>()
        .sqrt()
}

/// The targets of `ir`'s statements.
fn targets(ir: &Ir) -> Vec<Target> {
    let starts = ir.start_placements();
    let passes = std::cell::Cell::new(0usize);
    let mut out = Vec::new();
    for (i, s) in ir.statements.iter().enumerate() {
        if s.mask.is_some() || s.weight <= 0.0 || s.objective {
            continue;
        }
        let ids = cone(ir, s);
        let frames = ir.resolve_domain(s.domain, ir.length);
        if ids.len() > MAX_CONE || frames.is_empty() {
            continue;
        }
        // The joint read on the statement's own frames: one, the same in every such read.
        let mut free: Vec<NodeId> = Vec::new();
        let mut point = None;
        let mut single = true;
        for &id in &ids {
            match &ir.nodes[id].op {
                Op::Gather { domain, points }
                    if ir.resolve_domain(*domain, ir.length) == frames =>
                {
                    single &= points.len() == 1 && point.is_none_or(|p| p == points[0]);
                    point = points.first().copied();
                    free.push(id);
                }
                Op::MassCenter { .. } => single = false,
                _ => {}
            }
        }
        let Some((person, joint)) = point.filter(|_| single) else {
            continue;
        };
        let last = *frames.iter().max().expect("not empty");
        let reach = joint_bounds(&[(person, joint)], last, &starts, &Limits::BODY);
        let mut lo = [reach[0].lo, reach[1].lo, reach[2].lo];
        let mut hi = [reach[0].hi, reach[1].hi, reach[2].hi];
        let broken = |lo: &[f64; 3], hi: &[f64; 3]| {
            passes.set(passes.get() + 1);
            let b: Bounds = (0..3).map(|k| Iv::new(lo[k], hi[k])).collect();
            let fixed: Vec<(NodeId, Bounds)> = free.iter().map(|&n| (n, b.clone())).collect();
            let pass = Pass {
                starts: &starts,
                limits: Limits::BODY,
                pick: Pick::Latest,
                fixed: &fixed,
            };
            lowest(pass.run(ir, &ids).last().expect("a cone holds its error")) > TOLERANCE
        };
        if passes.get() + 12 * STEPS + 1 > MAX_PASSES || broken(&lo, &hi) {
            continue;
        }
        for _round in 0..2 {
            for k in 0..3 {
                // Lower face: the largest cut [lo, t] known to break the statement.
                let (mut cut, mut keep) = (lo[k], hi[k]);
                for _ in 0..STEPS {
                    let t = 0.5 * (cut + keep);
                    let mut h = hi;
                    h[k] = t;
                    if broken(&lo, &h) { cut = t } else { keep = t }
                }
                lo[k] = cut;
                let (mut cut, mut keep) = (hi[k], lo[k]);
                for _ in 0..STEPS {
                    let t = 0.5 * (cut + keep);
                    let mut l = lo;
                    l[k] = t;
                    if broken(&l, &hi) { cut = t } else { keep = t }
                }
                hi[k] = cut;
            }
        }
        out.push(Target {
            statement: Some(i),
            person,
            joint,
            frames,
            lo,
            hi,
        });
    }
    out
}

/// A place a joint cannot get to without a step.
#[derive(Clone, Debug, PartialEq)]
pub struct OutOfReach {
    /// Index in [`Ir::statements`].
    pub statement: usize,
    /// The joint's canonical name.
    pub joint: &'static str,
    /// The joint its reach is measured from (shoulder, hip or pelvis).
    pub anchor: &'static str,
    /// How far the joint reaches from its anchor (m).
    pub reach: f64,
    /// How far beyond that the place is (m).
    pub beyond: f64,
}

/// The joint a limb's reach is measured from (the shoulder for an arm's elbow and wrist,
/// the hip for a leg's knee, ankle and foot, else the pelvis) and where it is when the
/// person stands at the origin facing +Z: `(x, height)`, from a real standing frame (the
/// skeleton's rest offsets are not a standing pose).
fn anchor(joint: usize) -> (usize, f64, f64) {
    match joint {
        18 | 20 => (16, 0.17, 1.34),
        19 | 21 => (17, -0.17, 1.34),
        4 | 7 | 10 => (1, 0.09, 0.84),
        5 | 8 | 11 => (2, -0.09, 0.84),
        _ => (0, 0.0, 0.92),
    }
}

/// Sum of the bone lengths from `joint` up to `anchor`.
fn chain_length(mut joint: usize, anchor: usize) -> f64 {
    let mut len = 0.0;
    while joint != anchor && joint != 0 {
        len += f64::from(BONE_LENGTHS[joint]);
        joint = PARENTS[joint];
    }
    len
}

/// Keyframe places no standing person reaches, in programs that never move the pelvis.
pub fn out_of_reach(ir: &Ir) -> Vec<OutOfReach> {
    let starts = ir.start_placements();
    // A person steps when the program reads their pelvis or centre of mass after frame 0.
    let steps = |person: usize| {
        ir.nodes.iter().any(|n| match &n.op {
            Op::Gather { domain, points } => {
                points.contains(&(person, 0))
                    && ir.resolve_domain(*domain, ir.length).iter().any(|&f| f > 0)
            }
            Op::MassCenter { persons, .. } => persons.contains(&person),
            _ => false,
        })
    };
    targets(ir)
        .into_iter()
        .filter(|t| t.joint != 0 && !steps(t.person))
        .filter_map(|t| {
            let (a, x, height) = anchor(t.joint);
            let start = starts.get(t.person).copied().unwrap_or(Placement::IDENTITY);
            let at = start.apply(glam::Vec3::new(x as f32, height as f32, 0.0));
            // On the ground only: crouching, bending and jumping change heights, and only
            // a step moves the shoulders or hips farther than a lean.
            let (x, z) = (f64::from(at.x), f64::from(at.z));
            let region_lo = [x - SWAY, f64::NEG_INFINITY, z - SWAY];
            let region_hi = [x + SWAY, f64::INFINITY, z + SWAY];
            let reach = chain_length(t.joint, a);
            let beyond = gap((&t.lo, &t.hi), (&region_lo, &region_hi)) - reach;
            (beyond > 0.01).then(|| OutOfReach {
                statement: t.statement.expect("statements only"),
                joint: JOINT_NAMES[t.joint],
                anchor: JOINT_NAMES[a],
                reach,
                beyond,
            })
        })
        .collect()
}

/// Two places one joint must be in too close in time.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameJump {
    /// The later statement, in [`Ir::statements`].
    pub statement: usize,
    /// The earlier one (None: the start place the pelvis is pinned to at frame 0).
    pub other: Option<usize>,
    /// The joint's canonical name.
    pub joint: &'static str,
    /// The two closest frames, one of each.
    pub frames: (usize, usize),
    /// The least distance between the two places (m).
    pub distance: f64,
}

impl FrameJump {
    /// The speed it asks for (m/s).
    pub fn speed(&self) -> f64 {
        self.distance * f64::from(FPS) / self.frames.1.abs_diff(self.frames.0).max(1) as f64
    }
}

/// The closest frames of two disjoint ascending frame lists (None when they share one).
fn closest(a: &[usize], b: &[usize]) -> Option<(usize, usize)> {
    let (mut i, mut j) = (0, 0);
    let mut best: Option<(usize, usize)> = None;
    while i < a.len() && j < b.len() {
        if a[i] == b[j] {
            return None;
        }
        if best.is_none_or(|(x, y)| a[i].abs_diff(b[j]) < x.abs_diff(y)) {
            best = Some((a[i], b[j]));
        }
        if a[i] < b[j] { i += 1 } else { j += 1 }
    }
    best
}

/// Pairs of places a joint can only get between faster than [`JUMP_PER_FRAME`]; each
/// statement is reported once, against its worst partner.
pub fn frame_jumps(ir: &Ir) -> Vec<FrameJump> {
    let mut all = targets(ir);
    for (person, start) in ir.start_placements().iter().enumerate() {
        let (x, z) = (f64::from(start.x), f64::from(start.z));
        let p = Limits::BODY.pinned;
        all.push(Target {
            statement: None,
            person,
            joint: 0,
            frames: vec![0],
            lo: [x - p, Limits::BODY.height.0, z - p],
            hi: [x + p, Limits::BODY.height.1, z + p],
        });
    }
    for t in &mut all {
        t.frames.sort_unstable();
    }
    let mut out: Vec<FrameJump> = Vec::new();
    for (i, a) in all.iter().enumerate() {
        for b in &all[i + 1..] {
            if (a.person, a.joint) != (b.person, b.joint) {
                continue;
            }
            let Some((fa, fb)) = closest(&a.frames, &b.frames) else {
                continue;
            };
            let distance = gap((&a.lo, &a.hi), (&b.lo, &b.hi));
            if distance <= JUMP_PER_FRAME * fa.abs_diff(fb) as f64 {
                continue;
            }
            // Reported on the later statement (a start pin is never the later one).
            let (later, earlier, frames) = match (a.statement, b.statement) {
                (Some(x), None) => (x, None, (fb, fa)),
                (None, Some(y)) => (y, None, (fa, fb)),
                (Some(x), Some(y)) if fa > fb => (x, Some(y), (fb, fa)),
                (Some(x), Some(y)) => (y, Some(x), (fa, fb)),
                (None, None) => continue,
            };
            let jump = FrameJump {
                statement: later,
                other: earlier,
                joint: JOINT_NAMES[a.joint],
                frames,
                distance,
            };
            match out.iter_mut().find(|j| j.statement == later) {
                Some(j) if j.speed() < jump.speed() => *j = jump,
                Some(_) => {}
                None => out.push(jump),
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use crate::lang::check_source;

    fn codes(body: &str) -> Vec<&'static str> {
        let d = check_source(&format!("length 4s\n{body}\n"), "t.mprog", &[]);
        assert_eq!(d.error_count(), 0, "{}", d.render_plain());
        d.warnings().map(|w| w.code).collect()
    }

    #[test]
    fn a_wrist_out_of_reach_without_a_step_is_flagged() {
        // The right shoulder starts at (-0.17, 1.34, 0); 0.79 m ahead of it is too far.
        let far = "at 2s { r_wrist == [-0.17, 1.34, 0.79] }";
        assert_eq!(codes(far), [crate::lang::codes::OUT_OF_REACH]);
        // Within the arm's reach, or with a step asked for, it is not.
        assert!(codes("at 2s { dist(r_wrist, [-0.17, 1.34, 0.6]) < 5 cm }").is_empty());
        let walk = format!("{far}\nat 2s {{ groundDist(pelvis, [0, 0, 0.5]) < 20 cm }}");
        assert!(codes(&walk).is_empty(), "{:?}", codes(&walk));
        // Picking something up from the floor in front is a crouch, not a step.
        assert!(codes("at 2s { dist(r_wrist, [-0.2, 0.1, 0.4]) < 5 cm }").is_empty());
    }

    #[test]
    fn a_jump_between_consecutive_frames_is_flagged() {
        let jump =
            "at 1s { abs(r_wrist.x - 0.3 m) < 1 cm }\nat 1.05s { abs(r_wrist.x + 0.3 m) < 1 cm }";
        assert_eq!(codes(jump), [crate::lang::codes::FRAME_JUMP]);
        let slow =
            "at 1s { abs(r_wrist.x - 0.3 m) < 1 cm }\nat 2s { abs(r_wrist.x + 0.3 m) < 1 cm }";
        assert!(codes(slow).is_empty());
        // 24 cm from the pinned start place in one frame.
        assert_eq!(
            codes("at 1 { pelvis.x > 26 cm }"),
            [crate::lang::codes::FRAME_JUMP]
        );
        assert!(codes("at 1s { pelvis.x > 26 cm }").is_empty());
    }

    #[test]
    fn no_shipped_program_is_flagged() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/programs");
        let sources: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "mprog"))
            .map(|p| std::fs::read_to_string(p).unwrap())
            .collect();
        assert!(sources.len() >= 12);
        for source in sources {
            let d = check_source(&source, "t.mprog", &[]);
            let new: Vec<_> = d
                .warnings()
                .filter(|w| {
                    matches!(
                        w.code,
                        crate::lang::codes::OUT_OF_REACH | crate::lang::codes::FRAME_JUMP
                    )
                })
                .collect();
            assert!(new.is_empty(), "{source}\n{}", d.render_plain());
        }
    }
}
