//! Sentence-level tasks judged like a reviewer (issue 48, ask 4): each task is a sentence, a
//! program written from it, and a numeric judge written from the sentence alone, before
//! anything was generated. `mprog bench sentences` runs each program as `mprog run` does and
//! reports, per task, met by the error table, right by the judge, plausible by the report,
//! and inside the real envelope by measurement.
//!
//! The tasks live in `bench/sentences/` (`tasks.toml` and one program per task); the judges
//! are here, so a judge cannot be tuned by editing a data file beside the outputs.

pub mod inside;
pub mod judges;
pub mod measure;
pub mod report;
pub mod set;

use crate::motion::Motion;

/// A judge's decision on one motion.
#[derive(Clone, Debug, PartialEq)]
pub struct Verdict {
    /// Whether the motion does what the sentence says.
    pub right: bool,
    /// The figures the decision rests on, in words ("pelvis 0.31 m over the last 2 s").
    pub reason: String,
}

impl Verdict {
    /// A right motion, with the figures that made it so.
    pub fn right(reason: impl Into<String>) -> Self {
        Verdict {
            right: true,
            reason: reason.into(),
        }
    }

    /// A wrong motion, with the figure that failed.
    pub fn wrong(reason: impl Into<String>) -> Self {
        Verdict {
            right: false,
            reason: reason.into(),
        }
    }
}

/// Judges the people of task `id` (in the order the sentence names them); `None` for an id
/// no judge knows.
pub fn judge(id: &str, people: &[Motion]) -> Option<Verdict> {
    judges::judge(id, people)
}

/// Every task id that has a judge, in order.
pub fn judged_ids() -> Vec<&'static str> {
    judges::ids()
}
