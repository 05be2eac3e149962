//! The task benchmark (`mprog bench tasks`): PMG's program tasks, OmniControl-style
//! keyframe control on held-out test clips and InterControl-style two-person contacts,
//! each solved by every solver and by the unguided model, and measured the same way.
//!
//! | stage | module | input → output |
//! | --- | --- | --- |
//! | which tasks and settings | [`suite`] | programs, test clips → [`suite::Task`]s, solvers |
//! | keyframe targets, control metrics | [`keyframe`] | a test clip → batched goal; distances → [`keyframe::ControlErrors`] |
//! | PMG's HSI-1 on test clips | [`head_height`] | a test clip → its head-height program |
//! | solving and measuring | this module | tasks × solvers → [`RunRow`]s |
//! | the markdown | [`report`] | rows → tables |

pub mod head_height;
pub mod keyframe;
pub mod report;
pub mod sentences;
pub mod suite;

use crate::features::FEATURE_DIM;
use crate::metrics::per_motion::{
    PeakAcceleration, foot_skating_ratio, max_acceleration, max_bone_error, peak_acceleration,
};
use crate::motion::Motion;
use crate::solve::{Prior, Progress, SolveRequest, Solver, solve};
use burn::prelude::*;
use keyframe::ControlErrors;
use suite::{Family, Goal, Task};

/// A statement (or keyframe) counts as missed when its error exceeds this (m, or the
/// statement's own unit).
pub const MISS_THRESHOLD: f32 = 0.05;

/// What one (task, solver) run measured.
#[derive(Clone, Debug)]
pub struct RunRow {
    /// Family.
    pub family: Family,
    /// Task name.
    pub task: String,
    /// Solver name.
    pub solver: String,
    /// Motions measured (samples × people).
    pub motions: usize,
    /// Mean constraint error (program total, or mean keyframe distance in m).
    pub error: f32,
    /// Fraction of samples with any statement (keyframe) missed by more than 5 cm.
    pub unsuccess: f32,
    /// OmniControl's metrics (keyframe tasks).
    pub control: Option<ControlErrors>,
    /// Mean foot-skating ratio.
    pub skating: f32,
    /// Mean of the per-motion maximum joint acceleration (m/frame²).
    pub max_accel: f32,
    /// Mean of the per-motion largest bone-length error against the skeleton (m).
    pub bone_error: f32,
    /// Share of samples whose plausibility report (`metrics::plausibility`, against the
    /// built-in envelope) finds no problem.
    pub plausible: f32,
    /// Wall seconds per sample.
    pub seconds_per_sample: f64,
    /// Why the run failed (then the numbers are zero).
    pub failure: Option<String>,
    /// `[frames, 263]` de-normalised features of every motion, for the realism score.
    pub features: Vec<Vec<f32>>,
    /// Keyframe tasks: what each cell's sample did.
    pub cells: Vec<CellOutcome>,
}

impl RunRow {
    /// A row of (task, solver) with nothing measured yet: every number zero.
    pub fn unmeasured(family: Family, task: &str, solver: &str) -> Self {
        RunRow {
            family,
            task: task.to_string(),
            solver: solver.to_string(),
            motions: 0,
            error: 0.0,
            unsuccess: 0.0,
            control: None,
            skating: 0.0,
            max_accel: 0.0,
            bone_error: 0.0,
            plausible: 0.0,
            seconds_per_sample: 0.0,
            failure: None,
            features: Vec::new(),
            cells: Vec::new(),
        }
    }
}

/// One keyframe cell's sample, measured.
#[derive(Clone, Debug)]
pub struct CellOutcome {
    /// The controlled joint.
    pub joint: usize,
    /// The density's label.
    pub density: String,
    /// Distance at each keyframe (m).
    pub distances: Vec<f32>,
    /// The sample's foot-skating ratio.
    pub skating: f32,
    /// The sample's peak joint acceleration and where it is.
    pub accel: PeakAcceleration,
    /// Frames from the peak acceleration to the nearest keyframe.
    pub accel_to_keyframe: usize,
    /// The sample's length in frames.
    pub frames: usize,
}

/// One solve of `task` with `solver`, measured.
pub fn run_task(
    prior: &Prior,
    task: &Task,
    solver: &Solver,
    seed: u64,
    device: &Device,
    on_progress: &mut dyn FnMut(Progress),
) -> RunRow {
    let mut row = RunRow::unmeasured(task.family, &task.name, solver.name());
    let req = SolveRequest {
        samples: task.samples,
        placements: task.placements(),
        ..SolveRequest::new(task.prompts.clone(), task.frames, seed, solver.clone())
    };
    let error: &dyn crate::solve::MotionError = task;
    let result = match solve(prior, &req, error, device, on_progress) {
        Ok(r) => r,
        Err(e) => {
            row.failure = Some(e.to_string());
            return row;
        }
    };
    let all: Vec<&Motion> = result.motions.iter().flatten().collect();
    row.motions = all.len();
    row.skating = mean(all.iter().map(|m| foot_skating_ratio(m)));
    row.max_accel = mean(all.iter().map(|m| max_acceleration(m)));
    row.bone_error = mean(all.iter().map(|m| max_bone_error(m)));
    let envelope = crate::dataset::envelope::Envelope::builtin();
    let prompts: Vec<Option<String>> = task.prompts.iter().cloned().map(Some).collect();
    row.plausible = mean(result.motions.iter().map(|people| {
        f32::from(crate::metrics::plausibility::check(people, &prompts, &envelope).ok)
    }));
    row.seconds_per_sample = result.seconds / task.samples.max(1) as f64;
    let per_motion = task.frames * FEATURE_DIM;
    row.features = result
        .features
        .chunks_exact(per_motion)
        .map(<[f32]>::to_vec)
        .collect();
    match &task.goal {
        Goal::Program(program) => {
            let joints = world_tensor(&result.motions, device);
            let e = program.evaluate(joints);
            let totals = e
                .total
                .into_data()
                .try_into_vec::<f32>()
                .unwrap_or_default();
            let per = e
                .per_statement
                .into_data()
                .try_into_vec::<f32>()
                .unwrap_or_default();
            let statements = per.len() / totals.len().max(1);
            row.error = mean(totals.iter().copied());
            row.unsuccess = mean(
                per.chunks(statements.max(1))
                    .map(|s| f32::from(s.iter().any(|&v| v > MISS_THRESHOLD))),
            );
        }
        Goal::Keyframes(goal) => {
            let firsts: Vec<Motion> = result.motions.iter().map(|p| p[0].clone()).collect();
            let distances = goal.distances(&firsts);
            let c = ControlErrors::of(&distances);
            row.error = c.avg;
            row.unsuccess = c.unsuccess;
            row.control = Some(c);
            row.cells = goal
                .cells
                .iter()
                .zip(distances)
                .zip(&firsts)
                .map(|((cell, distances), motion)| {
                    let accel = peak_acceleration(motion);
                    CellOutcome {
                        joint: cell.joint,
                        density: cell.density.label(),
                        distances,
                        skating: foot_skating_ratio(motion),
                        accel,
                        accel_to_keyframe: cell
                            .frames
                            .iter()
                            .map(|f| f.abs_diff(accel.frame))
                            .min()
                            .unwrap_or(usize::MAX),
                        frames: motion.len(),
                    }
                })
                .collect();
        }
    }
    row
}

/// `[B, P, N, 22, 3]` of solved motions.
fn world_tensor(motions: &[Vec<Motion>], device: &Device) -> Tensor<5> {
    let (b, p) = (motions.len(), motions.first().map_or(0, Vec::len));
    let n = motions.iter().flatten().map(Motion::len).min().unwrap_or(0);
    let mut flat = Vec::with_capacity(b * p * n * 66);
    for m in motions.iter().flatten() {
        flat.extend_from_slice(&m.to_flat()[..n * 66]);
    }
    Tensor::from_data(TensorData::new(flat, [b, p, n, 22, 3]), device)
}

fn mean(values: impl Iterator<Item = f32>) -> f32 {
    let (s, n) = values.fold((0.0f64, 0usize), |(s, n), v| (s + v as f64, n + 1));
    if n == 0 { 0.0 } else { (s / n as f64) as f32 }
}
