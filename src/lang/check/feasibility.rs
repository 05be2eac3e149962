//! Constraints no motion can meet, found before anything runs by interval arithmetic
//! over the IR (`bounds.rs`).
//!
//! Propagating the joints' bounds through a statement's ops bounds its error from below;
//! a constraint whose error is bounded away from zero on every frame it applies to can
//! never be met (`at start { pelvis.x > 1 m }`, `head.y > 3 m`, `at 1s { pelvis.z > 20 m }`).
//! The bounds are generous, so a warning is certain; many impossible constraints (limb
//! lengths between two joints) go unnoticed. Each warning names its cause: the statement
//! is checked again with one assumption dropped, and the first one whose removal makes it
//! possible is the cause.

use super::bounds::{Limits, Pass, Pick, TOLERANCE, cone, lowest};
use crate::lang::ir::{Ir, Statement};
use crate::scene::Placement;

/// Why a constraint can never be met: the assumption that rules it out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cause {
    /// The pelvis is pinned to the start place at frame 0, and the constraint applies
    /// there: only on frame 0 (`at start`).
    AtStart,
    /// As [`Cause::AtStart`], but the constraint covers frame 0 and more (`always`,
    /// `during 0s..…`): frame 0 alone makes it impossible.
    IncludesStart,
    /// A height outside what a body reaches (-0.3 to 3 m).
    Height,
    /// Farther from the start than a person can run by then (10 m/s).
    Travel,
    /// None of those alone.
    Other,
}

/// A constraint no motion can meet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NeverMet {
    /// Index in [`Ir::statements`].
    pub statement: usize,
    /// Lowest possible value of its error.
    pub lowest: f64,
    /// What rules it out.
    pub cause: Cause,
    /// The last frame it applies to (for [`Cause::Travel`]'s message).
    pub last_frame: usize,
}

/// The lowest error `s` can have under `limits`, when that is above the tolerance.
///
/// A statement's error is the mean over its frames. With bounds valid on every frame, a
/// positive lower bound is the answer. Joints read on the statement's earliest frame are
/// bounded tighter (less time to travel); when the error can never be negative, a positive
/// bound on that one frame alone makes the mean positive too.
fn lowest_error(ir: &Ir, s: &Statement, starts: &[Placement], limits: Limits) -> Option<f64> {
    let ids = cone(ir, s);
    let error_of = |pick| {
        let pass = Pass {
            starts,
            limits,
            pick,
            fixed: &[],
        };
        lowest(pass.run(ir, &ids).last().expect("a cone holds its error"))
    };
    let anywhere = error_of(Pick::Latest);
    if anywhere.is_finite() && anywhere > TOLERANCE {
        return Some(anywhere);
    }
    let frames = ir.resolve_domain(s.domain, ir.length).len().max(1);
    let mean = error_of(Pick::Earliest) / frames as f64;
    (anywhere >= 0.0 && mean.is_finite() && mean > TOLERANCE).then_some(mean)
}

/// Every constraint no motion can meet, with its cause. Objectives (`minimize`),
/// statements under an `if` and weight-0 statements are skipped.
pub fn never_met(ir: &Ir) -> Vec<NeverMet> {
    let starts = ir.start_placements();
    let body = Limits::BODY;
    ir.statements
        .iter()
        .enumerate()
        .filter(|(_, s)| s.mask.is_none() && s.weight > 0.0 && !s.objective)
        .filter_map(|(i, s)| {
            let lowest = lowest_error(ir, s, &starts, body)?;
            let frames = ir.resolve_domain(s.domain, ir.length);
            let possible = |limits| lowest_error(ir, s, &starts, limits).is_none();
            let cause = if frames.contains(&0)
                && possible(Limits {
                    pinned: body.reach,
                    ..body
                }) {
                if frames.len() == 1 {
                    Cause::AtStart
                } else {
                    Cause::IncludesStart
                }
            } else if possible(Limits {
                height: (f64::NEG_INFINITY, f64::INFINITY),
                ..body
            }) {
                Cause::Height
            } else if possible(Limits {
                travel_per_frame: f64::INFINITY,
                ..body
            }) {
                Cause::Travel
            } else {
                Cause::Other
            };
            Some(NeverMet {
                statement: i,
                lowest,
                cause,
                last_frame: frames.iter().copied().max().unwrap_or(0),
            })
        })
        .collect()
}

/// The hint of a `mprog::never_met` warning: what to change, for its cause.
pub fn hint(cause: Cause, last_frame: usize) -> String {
    const UNITS: &str =
        "A number without a unit is in metres: `head.y + 15` is 15 m higher; write `15 cm`";
    match cause {
        Cause::AtStart => {
            "at frame 0 each person's pelvis is pinned to its start place (x = z = 0 \
             with one person unless placed; see `spacing` for two or more), so a ground \
             position at `start` can only restate it. Place the person there \
             (`start at [x, 0, z]`, or `at [x, 0, z]` after a person's prompt), put the \
             constraint at a later time (`at 1s`, `at end`), or write places relative to the \
             start (`pelvis@start + [0, 0, 3]`)"
                .to_string()
        }
        Cause::IncludesStart => "this block includes frame 0, where each person's pelvis is \
             still pinned to its start place (x = z = 0 with one person): frame 0 alone \
             breaks it. Start the block later (`during 1s..end` instead of `always`), ask \
             only at the end (`at end`), or write places relative to the start \
             (`pelvis@start + [0.5, 0, 0]`)"
            .to_string(),
        Cause::Height => format!(
            "heights (`.y`, up) lie between -0.3 and 3 m. Check the axis (`.y` is up, `.z` \
             ahead, `.x` to the left) and the direction of the comparison. {UNITS}"
        ),
        Cause::Travel => format!(
            "a person moves at most about 10 m/s, so by frame {last_frame} ({:.2} s) every \
             joint is within {:.1} m of its start place. Make the motion longer, the distance \
             shorter, or the time later. {UNITS}",
            last_frame as f64 / 20.0,
            Limits::BODY.travel_per_frame * last_frame as f64 + Limits::BODY.reach
        ),
        Cause::Other => format!(
            "heights (`.y`, up) lie between -0.3 and 3 m; each person's pelvis starts at its \
             start place (x = z = 0 with one person) and moves at most about 10 m/s. Check \
             the axis and the direction of the comparison, and write places relative to the \
             start (`pelvis@start + [0, 0, 3]`). {UNITS}"
        ),
    }
}

#[cfg(test)]
mod tests {
    use crate::lang::check_source;

    fn flagged(source: &str) -> usize {
        let d = check_source(source, "t.mprog", &[]);
        assert_eq!(d.error_count(), 0, "{}", d.render_plain());
        d.warnings()
            .filter(|w| w.code == crate::lang::codes::NEVER_MET)
            .count()
    }

    #[test]
    fn each_cause_is_named() {
        use super::{Cause, never_met};
        for (body, cause) in [
            ("at start { pelvis.x > 1 m }", Cause::AtStart),
            (
                "always { abs(pelvis.x - 0.5 m) < 5 cm }",
                Cause::IncludesStart,
            ),
            ("head.y > 3.5 m", Cause::Height),
            ("l_foot.y < -1 m", Cause::Height),
            ("at 1s { pelvis.z > 20 m }", Cause::Travel),
        ] {
            let p = crate::lang::compile(&format!("length 4s\n{body}\n"), "t.mprog", &[]).unwrap();
            let found = never_met(p.ir());
            assert_eq!(found.len(), 1, "{body}");
            assert_eq!(found[0].cause, cause, "{body}");
        }
    }

    #[test]
    fn impossible_constraints_are_flagged() {
        for body in [
            "at start { pelvis.x > 1 m }",
            "head.y > 3.5 m",
            "at 1s { pelvis.z > 20 m }",
            "at start { groundDist(pelvis, [-1.5, 0, 0]) < 30 cm }",
            "l_foot.y < -1 m",
            "at start, end { groundDist(pelvis, [-1.5, 0, 0]) < 30 cm }",
        ] {
            assert_eq!(flagged(&format!("length 4s\n{body}\n")), 1, "{body}");
        }
        let two = "length 4s\npeople a \"x\", b \"y\"\nat start { groundDist(a.pelvis, b.pelvis) < 1 m }\n";
        assert_eq!(flagged(two), 1);
        // Placed 0.8 m apart by `spacing`, the same start is possible.
        let close = two.replace("length 4s", "length 4s\nspacing 80 cm");
        assert_eq!(flagged(&close), 0);
    }

    #[test]
    fn possible_ones_objectives_and_conditionals_are_not() {
        for body in [
            "at 1s { pelvis.z > 5 m }",
            "at end { pelvis.x > 3 m }",
            "head.y > 1.5 m",
            "at start { r_hand.x < -0.5 m }",
            "minimize head.y + 10 m",
            "if head.y > 1 m { head.y > 5 m }",
            "weight 0 { head.y > 5 m }",
            "not (head.y > 5 m)",
            "head.y > 5 m or head.y < 1 m",
            "during 1s..end { groundDist(pelvis, [-1.5, 0, 0]) < 30 cm }",
            "at start { not (pelvis.x > 1 m) }",
        ] {
            assert_eq!(flagged(&format!("length 4s\n{body}\n")), 0, "{body}");
        }
    }

    #[test]
    fn no_shipped_program_is_flagged() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/programs");
        let mut n = 0;
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "mprog") {
                let source = std::fs::read_to_string(&path).unwrap();
                assert_eq!(flagged(&source), 0, "{}", path.display());
                n += 1;
            }
        }
        assert!(n >= 12);
    }
}
