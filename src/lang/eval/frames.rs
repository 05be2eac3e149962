//! Per-frame errors: the same graph as [`super::evaluate`], but each statement's error is
//! kept per frame instead of being averaged, for summaries, sparklines and plots (the
//! REPL's `:eval`). Host values, no gradient.
//!
//! For statement s and frame t of its domain, the value is `weight · Σ_lanes e·m`: the
//! error the frame contributes before the mean over frames (`m` is the `if` mask, 1 when
//! there is none). The mean of the values over the frames where the statement applies is
//! its column of `per_statement`.

use super::{CachedIndices, EvalError, with_node_values};
use crate::lang::ir::{Ir, Statement};
use burn::tensor::Tensor;

/// One statement's error at each frame it is evaluated on.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameErrors {
    /// Frame indices of the statement's time block, in order.
    pub frames: Vec<usize>,
    /// Weighted error summed over loop lanes, `[batch][frames.len()]`.
    pub errors: Vec<Vec<f32>>,
    /// Whether the statement applies at that frame (its `if` conditions hold in at least
    /// one lane; always true without `if`), `[batch][frames.len()]`.
    pub applies: Vec<Vec<bool>>,
}

/// Evaluates `ir` on joint positions `[batch, people, frames, 22, 3]` and returns each
/// statement's errors per frame, in statement order.
pub fn evaluate_frames(
    ir: &Ir,
    joints: Tensor<5>,
    cache: &super::IndexCache,
) -> Result<Vec<FrameErrors>, EvalError> {
    let frames = joints.dims()[2];
    with_node_values(ir, joints, cache, |values, idx, batch, _| {
        ir.statements
            .iter()
            .map(|s| statement_frames(ir, s, values, idx, batch, frames))
            .collect()
    })
}

fn statement_frames(
    ir: &Ir,
    s: &Statement,
    values: &[Option<Tensor<4>>],
    idx: &CachedIndices,
    batch: usize,
    frames: usize,
) -> FrameErrors {
    let list = ir.resolve_domain(s.domain, frames);
    let n = idx.domain_sizes[s.domain];
    if n == 0 {
        return FrameErrors {
            frames: list,
            errors: vec![Vec::new(); batch],
            applies: vec![Vec::new(); batch],
        };
    }
    let err = values[s.error].clone().expect("statement error is kept");
    let lanes = err.dims()[2];
    // [batch or 1, n or 1, lanes, 1] → [batch, n, lanes, 1]
    let err = err.expand([batch, n, lanes, 1]);
    let (weighted, applies, used_lanes) = match s.mask.and_then(|m| values[m].clone()) {
        Some(mask) => {
            let ml = mask.dims()[2].max(lanes);
            let mask = mask.expand([batch, n, ml, 1]);
            let err = err.expand([batch, n, ml, 1]);
            // [batch, n, 1, 1]: a frame applies when any lane's condition holds.
            let any = mask.clone().max_dim(2);
            ((err * mask).sum_dim(2), Some(host(any)), ml)
        }
        None => (err.sum_dim(2), None, lanes),
    };
    // Lanes the tensor does not carry (lane-constant errors) count as copies, as in
    // `statement_error`.
    let factor = s.weight * (s.lanes / used_lanes.max(1)) as f64;
    let errors = host(weighted.mul_scalar(factor));
    let rows = |v: Vec<f32>| -> Vec<Vec<f32>> { v.chunks(n).map(<[f32]>::to_vec).collect() };
    let errors = rows(errors);
    let applies = match applies {
        Some(a) => rows(a)
            .into_iter()
            .map(|r| r.into_iter().map(|m| m > 0.5).collect())
            .collect(),
        None => vec![vec![true; n]; batch],
    };
    FrameErrors {
        frames: list,
        errors,
        applies,
    }
}

fn host(t: Tensor<4>) -> Vec<f32> {
    t.into_data().try_into_vec::<f32>().unwrap_or_default()
}
