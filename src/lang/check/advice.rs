//! The checker's warnings about what no motion (or no plausible motion) can do, as
//! diagnostics: `mprog::never_met` (`feasibility.rs`), `mprog::out_of_reach` and
//! `mprog::frame_jump` (`reach.rs`). They read only the IR, so they also run on the
//! statements that checked cleanly in a program with errors elsewhere: a repair round sees
//! every problem at once.

use super::{feasibility, reach};
use crate::lang::diag::Diagnostic;
use crate::lang::ir::Ir;
use crate::skeleton::FPS;

/// Every such warning of `ir`.
pub fn warnings(ir: &Ir) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for n in feasibility::never_met(ir) {
        let s = &ir.statements[n.statement];
        out.push(
            Diagnostic::warning(
                crate::lang::codes::NEVER_MET,
                s.span,
                format!(
                    "no motion can meet this constraint: its error is at least {:.3} {}",
                    n.lowest, s.unit
                ),
            )
            .label(match n.cause {
                feasibility::Cause::AtStart | feasibility::Cause::IncludesStart => {
                    "impossible at frame 0"
                }
                feasibility::Cause::Height => "impossible height",
                feasibility::Cause::Travel => "too far to get to in time",
                feasibility::Cause::Other => "impossible",
            })
            .help(feasibility::hint(n.cause, n.last_frame)),
        );
    }
    for r in reach::out_of_reach(ir) {
        let s = &ir.statements[r.statement];
        out.push(
            Diagnostic::warning(
                crate::lang::codes::OUT_OF_REACH,
                s.span,
                format!(
                    "without a step, the {} cannot get here: the place is {:.2} m beyond its \
                     reach from the {}, and nothing in the program moves the pelvis",
                    r.joint, r.beyond, r.anchor
                ),
            )
            .label("out of reach from the start")
            .help(format!(
                "without a step, the {} reaches {:.2} m along the ground from the {} (which \
                 leans or sways about {:.1} m; heights are free: crouching and jumping are not \
                 steps). Bring the place closer to where the person starts, or \
                 ask for the step: say where the pelvis goes by then, e.g. \
                 `at end {{ groundDist(pelvis, [0, 0, 0.5]) < 20 cm }}`",
                r.joint,
                r.reach,
                r.anchor,
                reach::SWAY
            )),
        );
    }
    for j in reach::frame_jumps(ir) {
        let s = &ir.statements[j.statement];
        let other = match j.other {
            Some(o) => format!("the constraint on line {}", ir.statements[o].line),
            None => "the start place (the pelvis is pinned there at frame 0)".to_string(),
        };
        let (a, b) = j.frames;
        out.push(
            Diagnostic::warning(
                crate::lang::codes::FRAME_JUMP,
                s.span,
                format!(
                    "this and {other} make the {} move at least {:.2} m between frame {a} \
                     ({:.2} s) and frame {b} ({:.2} s): {:.1} m/s",
                    j.joint,
                    j.distance,
                    a as f64 / f64::from(FPS),
                    b as f64 / f64::from(FPS),
                    j.speed()
                ),
            )
            .label("a jump")
            .help(format!(
                "a frame is 0.05 s: faster than {:.0} m/s a joint jumps, or the solver gives up \
                 one of the two. Leave more time between the two places (`at 1s` and `at 2s`, \
                 not `at 1s` and `at 1.05s`), or bring them closer",
                reach::JUMP_PER_FRAME * f64::from(FPS)
            )),
        );
    }
    out
}
