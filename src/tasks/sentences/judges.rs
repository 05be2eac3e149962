//! One numeric judge per sentence of `bench/sentences/tasks.toml`, each written from its
//! sentence alone before anything was generated (as `scripts/llm-trial/judges.py` was for
//! the older set). Every number has a comment saying where in the sentence it comes from.
//!
//! Every judge first applies the common checks of [`super::measure::common`] (number of people,
//! finite values, duration, floor, people apart). Positions the sentence gives ("3 metres
//! ahead", "to the left") are in the person's own frame at the start
//! ([`super::measure::StartFrame`]). An end state is checked over the whole window the sentence
//! names: "for the last 2 seconds" is every frame of the last 2 s, "by 2 seconds" every
//! frame from 2 s on. People are in the order the sentence names them.
//!
//! Shared figures: a person standing has the pelvis joint ≈ 0.92 m up and the head ≈ 1.48 m;
//! the wrist is ≈ 0.08 m short of the palm and ≈ 0.18 m of the fingertips; walking is
//! ≈ 1.3 m/s, running ≈ 3 m/s. "Still" or "held" is the pelvis wandering at most 0.15 m from
//! its mean over the window; "in place" (a sentence with no walking) the pelvis never more
//! than 0.4 m from where it started.

use super::Verdict;
use super::measure::*;
use crate::motion::Motion;
use std::panic::{AssertUnwindSafe, catch_unwind};

mod contacts;
mod paths;
mod people;
mod poses;
#[cfg(test)]
mod tests;

use contacts::*;
use paths::*;
use people::*;
use poses::*;

/// A judge's own checks, on motions that passed the common ones.
type JudgeFn = fn(&[Motion]) -> Checks;

/// One task: its id, how many people and seconds the sentence has, its judge.
struct Task {
    id: &'static str,
    people: usize,
    seconds: f32,
    judge: JudgeFn,
}

const fn task(id: &'static str, people: usize, seconds: f32, judge: JudgeFn) -> Task {
    Task {
        id,
        people,
        seconds,
        judge,
    }
}

/// Every task, in order (the ids and numbers of `bench/sentences/tasks.toml`).
const TASKS: [Task; 28] = [
    task("s01", 1, 5.0, s01),
    task("s02", 1, 7.0, s02),
    task("s03", 1, 5.0, s03),
    task("s04", 1, 5.0, s04),
    task("s05", 1, 5.0, s05),
    task("s06", 1, 5.0, s06),
    task("s07", 1, 8.0, s07),
    task("s08", 1, 4.0, s08),
    task("s09", 1, 7.0, s09),
    task("s10", 1, 6.0, s10),
    task("s11", 1, 5.0, s11),
    task("s12", 1, 5.0, s12),
    task("s13", 1, 6.0, s13),
    task("s14", 1, 7.0, s14),
    task("s15", 1, 5.0, s15),
    task("s16", 1, 6.0, s16),
    task("s17", 1, 5.0, s17),
    task("s18", 1, 4.0, s18),
    task("s19", 1, 5.0, s19),
    task("s20", 1, 5.0, s20),
    task("s21", 1, 4.0, s21),
    task("s22", 1, 5.0, s22),
    task("s23", 2, 6.0, s23),
    task("s24", 2, 6.0, s24),
    task("s25", 2, 6.0, s25),
    task("s26", 2, 7.0, s26),
    task("s27", 2, 6.0, s27),
    task("s28", 3, 5.0, s28),
];

/// Judges the people of task `id`; `None` for an id no judge knows. Never panics: a judge
/// that fails on an odd motion answers wrong.
pub fn judge(id: &str, people: &[Motion]) -> Option<Verdict> {
    let task = TASKS.iter().find(|t| t.id == id)?;
    let ms = match common(people, task.people, task.seconds) {
        Ok(ms) => ms,
        Err(why) => return Some(Verdict::wrong(why)),
    };
    Some(match catch_unwind(AssertUnwindSafe(|| (task.judge)(&ms))) {
        Ok(checks) => checks.verdict(),
        Err(_) => Verdict::wrong("the judge could not measure this motion"),
    })
}

/// Every task id that has a judge, in order.
pub fn ids() -> Vec<&'static str> {
    TASKS.iter().map(|t| t.id).collect()
}

/// The people and seconds the judge of `id` expects (for the runner and the tests).
pub fn shape(id: &str) -> Option<(usize, f32)> {
    TASKS
        .iter()
        .find(|t| t.id == id)
        .map(|t| (t.people, t.seconds))
}

// ------------------------------------------------------------------ shared checks

/// The lowest of the four foot joints at frame `t`.
fn foot_height(m: &Motion, t: usize) -> f32 {
    FEET.iter()
        .map(|&j| m.frames[t][j].y)
        .fold(f32::INFINITY, f32::min)
}

/// "Still" over `w`: the pelvis within 0.15 m of its mean on the ground.
fn still(c: &mut Checks, m: &Motion, w: std::ops::Range<usize>, what: &str) {
    let d = drift_xz(m, PELVIS, w);
    c.add(
        d <= 0.15,
        format!("{what}pelvis wanders {d:.2} m (≤ 0.15, still)"),
    );
}

/// "In place": the pelvis never more than `limit` from where it started.
fn in_place(c: &mut Checks, m: &Motion, limit: f32) {
    let d = max_disp(m);
    c.add(
        d <= limit,
        format!("pelvis at most {d:.2} m from its start (≤ {limit:.2}, in place)"),
    );
}

/// The pelvis stays at least `least` metres up over the frames `w` (standing).
fn stands(c: &mut Checks, m: &Motion, w: std::ops::Range<usize>, least: f32) {
    let lo = min_over(w, |t| m.frames[t][PELVIS].y);
    c.add(
        lo >= least,
        format!("pelvis down to {lo:.2} m (≥ {least:.2}, standing)"),
    );
}

/// Facing along the path while walking: at least 75 % of the frames moving faster than
/// 0.4 m/s face within 45° of the travel (judges.py's rule).
fn walks_facing(c: &mut Checks, m: &Motion, who: &str) {
    let (f, k) = faces_travel(m);
    c.add(
        f >= 0.75 && k >= 10,
        format!(
            "{who}faces the way it goes on {:.0} % of {k} moving frames (≥ 75 %)",
            100.0 * f
        ),
    );
}

/// Mean yaw (degrees, + = left of the start) over the last ten frames.
fn end_yaw(m: &Motion) -> f32 {
    let y = yaw_track(m);
    let w = last(y.len(), 0.5);
    let k = w.len().max(1) as f32;
    y[w].iter().sum::<f32>() / k
}
