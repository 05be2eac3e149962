//! Evaluation: checked [`Ir`] + joint positions → error per sample and per statement,
//! with burn tensor ops on any device, with or without autodiff. Everything is vectorised
//! over batch, frames and lanes: time blocks are index selections, `if`s are masks.
//!
//! # Shapes
//! * input `[batch, people, frames, 22, 3]`;
//! * every node `[batch or 1, frames of its domain or 1, lanes or 1, channels]`;
//! * output `total [batch]`, `per_statement [batch, statements]`.

mod frames;
mod ops;

pub use frames::{FrameErrors, evaluate_frames};

use crate::lang::ir::*;
use crate::skeleton::NUM_JOINTS;
use burn::tensor::{Int, Tensor, TensorData};
use std::collections::{HashMap, HashSet};
use std::sync::Mutex;

/// Errors of one evaluation.
pub struct Evaluation {
    /// Σ over statements of weight × mean error, per sample `[batch]`.
    pub total: Tensor<1>,
    /// Each statement's weighted mean error `[batch, statements]`.
    pub per_statement: Tensor<2>,
}

/// Why a tensor cannot be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EvalError {
    /// The input does not have the expected shape.
    #[error("joint tensor has shape {got:?}; expected [batch, {people}, frames ≥ 1, 22, 3]")]
    BadShape {
        /// Shape given.
        got: Vec<usize>,
        /// People the program declares.
        people: usize,
    },
    /// The evaluation is estimated above the element limit; nothing was computed.
    #[error(
        "{program}: evaluating on {batch} motion(s) of {frames} frames is estimated at \
         {elements} tensor elements ({ops} ops per motion); the limit is {limit} elements"
    )]
    TooCostly {
        /// The program's name.
        program: String,
        /// Motions in the batch.
        batch: usize,
        /// Frames per motion.
        frames: usize,
        /// Estimated tensor ops of one motion.
        ops: usize,
        /// Estimated tensor elements of the whole batch (forward pass).
        elements: usize,
        /// The limit it exceeds.
        limit: usize,
    },
}

/// Default limit on the estimated tensor elements of one evaluation (forward pass, whole
/// batch): 2.7·10⁸ elements, about 1 GiB of `f32`. That is a batch of 13 motions at the
/// checker's per-motion limit ([`crate::lang::check::MAX_ELEMENTS_PER_SAMPLE`] at the
/// declared length) and thousands of motions of a typical program; longer motions or
/// bigger batches than that are refused before any tensor work.
pub const MAX_EVAL_ELEMENTS: usize = 1 << 28;

/// Frame-index tensors for one frame count and device, reused across evaluations.
#[derive(Default)]
pub struct IndexCache {
    inner: Mutex<Option<CachedIndices>>,
}

struct CachedIndices {
    frames: usize,
    device: burn::tensor::Device,
    gathers: HashMap<NodeId, Tensor<1, Int>>,
    /// Gathers that read every row in order (every joint of every person on every
    /// frame, as `for j in joints` over `always` does): the rows themselves, with no
    /// copy forward and no scatter into zeros backward.
    whole: HashSet<NodeId>,
    /// Every other gather's rows in one index list, and where each gather's rows sit in
    /// it, when there are two or more: one `select` of the motion, each gather a slice of
    /// it. Separate selects each scatter their gradient into motion-sized zeros that are
    /// then summed; sliced, only the merged rows are written back to the motion.
    merged: Option<MergedGather>,
    consts: HashMap<NodeId, Tensor<4>>,
    domain_sizes: Vec<usize>,
}

/// The rows of several gathers as one index list, and each gather's (start, length) in it.
struct MergedGather {
    rows: Tensor<1, Int>,
    slices: HashMap<NodeId, (usize, usize)>,
}

impl Clone for IndexCache {
    fn clone(&self) -> Self {
        IndexCache::default()
    }
}

impl std::fmt::Debug for IndexCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("IndexCache")
    }
}

/// The rows gather `node` reads: `rows` itself when it reads every row in order, a slice
/// of `merged` (the merged gather's rows) when it is part of it.
fn gather_rows(
    rows: &Tensor<3>,
    merged: Option<&Tensor<3>>,
    idx: &CachedIndices,
    node: NodeId,
) -> Tensor<3> {
    if idx.whole.contains(&node) {
        return rows.clone();
    }
    match (merged, &idx.merged) {
        (Some(all), Some(m)) if m.slices.contains_key(&node) => {
            let (start, len) = m.slices[&node];
            all.clone().narrow(1, start, len)
        }
        _ => rows.clone().select(1, idx.gathers[&node].clone()),
    }
}

/// Flat row index of (person, frame, joint) in the `[batch, people·frames·22, 3]` view.
fn flat(person: usize, frame: usize, joint: usize, frames: usize) -> i64 {
    ((person * frames + frame) * NUM_JOINTS + joint) as i64
}

fn build_indices(ir: &Ir, frames: usize, device: &burn::tensor::Device) -> CachedIndices {
    let domain_sizes: Vec<usize> = (0..ir.domains.len())
        .map(|d| ir.resolve_domain(d, frames).len())
        .collect();
    let mut gathers = HashMap::new();
    let mut whole = HashSet::new();
    let mut consts = HashMap::new();
    let mut parts: Vec<(NodeId, Vec<i64>)> = Vec::new();
    let rows = ir.people * frames * NUM_JOINTS;
    for (i, node) in ir.nodes.iter().enumerate() {
        if let Op::Const(v) = &node.op {
            let c = v.len();
            let t = Tensor::<1>::from_data(TensorData::new(v.clone(), [c]), device)
                .reshape([1, 1, 1, c]);
            consts.insert(i, t);
        }
        if let Op::Time { domain } = &node.op {
            // Seconds at each frame of the domain: one small constant tensor per frame count.
            let fps = crate::skeleton::FPS;
            let mut secs: Vec<f32> = ir
                .resolve_domain(*domain, frames)
                .into_iter()
                .map(|t| t as f32 / fps)
                .collect();
            if secs.is_empty() {
                secs.push(0.0);
            }
            let n = secs.len();
            let t =
                Tensor::<1>::from_data(TensorData::new(secs, [n]), device).reshape([1, n, 1, 1]);
            consts.insert(i, t);
            continue;
        }
        let (domain, points): (DomainId, Vec<(usize, usize)>) = match &node.op {
            Op::Gather { domain, points } => (*domain, points.clone()),
            Op::MassCenter {
                domain, persons, ..
            } => (
                *domain,
                persons
                    .iter()
                    .flat_map(|&p| (0..NUM_JOINTS).map(move |j| (p, j)))
                    .collect(),
            ),
            _ => continue,
        };
        let mut ts = ir.resolve_domain(domain, frames);
        if ts.is_empty() {
            // An empty domain still needs a well-formed tensor; its statement reads 0.
            ts.push(0);
        }
        let idx: Vec<i64> = ts
            .iter()
            .flat_map(|&t| points.iter().map(move |&(p, j)| flat(p, t, j, frames)))
            .collect();
        let n = idx.len();
        if n == rows && idx.iter().enumerate().all(|(k, &r)| r == k as i64) {
            whole.insert(i);
        }
        if !whole.contains(&i) {
            parts.push((i, idx.clone()));
        }
        gathers.insert(
            i,
            Tensor::<1, Int>::from_data(TensorData::new(idx, [n]), device),
        );
    }
    let merged = (parts.len() >= 2).then(|| {
        let mut at = HashMap::new();
        let mut all = Vec::new();
        for (node, idx) in parts {
            at.insert(node, (all.len(), idx.len()));
            all.extend(idx);
        }
        let n = all.len();
        MergedGather {
            rows: Tensor::<1, Int>::from_data(TensorData::new(all, [n]), device),
            slices: at,
        }
    });
    CachedIndices {
        frames,
        device: device.clone(),
        gathers,
        whole,
        merged,
        consts,
        domain_sizes,
    }
}

/// Evaluates `ir` on joint positions `[batch, people, frames, 22, 3]`.
pub fn evaluate(ir: &Ir, joints: Tensor<5>, cache: &IndexCache) -> Result<Evaluation, EvalError> {
    let frames = joints.dims()[2];
    evaluate_until(ir, joints, cache, frames)
}

/// [`evaluate`] counting only the frames before `until`: each statement's mean runs over
/// the frames of its block that come before it, and a statement with none adds 0. A long
/// motion is made window by window, and a window's error must not see the frames that are
/// not made yet (they are placeholders). `until ≥ frames` is [`evaluate`].
pub fn evaluate_until(
    ir: &Ir,
    joints: Tensor<5>,
    cache: &IndexCache,
    until: usize,
) -> Result<Evaluation, EvalError> {
    let frames = joints.dims()[2];
    with_node_values(ir, joints, cache, |values, idx, batch, device| {
        let mut columns = Vec::with_capacity(ir.statements.len());
        for s in &ir.statements {
            let col = match frames_before(ir, s, values, frames, until) {
                Before::All => statement_error(s, values, idx, batch, device),
                Before::None => Tensor::<2>::zeros([batch, 1], device),
                Before::Some(keep) => {
                    let n = keep.len();
                    let keep = Tensor::<4>::from_data(TensorData::new(keep, [1, n, 1, 1]), device);
                    statement_error_masked(s, values, batch, Some(keep))
                }
            };
            columns.push(col);
        }
        let per_statement = match columns.len() {
            // A timeline alone has no statement: nothing to satisfy.
            0 => Tensor::<2>::zeros([batch, 0], device),
            1 => columns.remove(0),
            _ => Tensor::cat(columns, 1),
        };
        let total = per_statement.clone().sum_dim(1).reshape([batch]);
        Evaluation {
            total,
            per_statement,
        }
    })
}

/// Checks the input, computes every node, and hands the values the statements read to
/// `reduce` (with the index cache, the batch size and the device).
fn with_node_values<T>(
    ir: &Ir,
    joints: Tensor<5>,
    cache: &IndexCache,
    reduce: impl FnOnce(&[Option<Tensor<4>>], &CachedIndices, usize, &burn::tensor::Device) -> T,
) -> Result<T, EvalError> {
    let [batch, people, frames, nj, nc] = joints.dims();
    if people != ir.people || nj != NUM_JOINTS || nc != 3 || frames == 0 || batch == 0 {
        return Err(EvalError::BadShape {
            got: vec![batch, people, frames, nj, nc],
            people: ir.people,
        });
    }
    let device = joints.device();
    let mut guard = cache.inner.lock().unwrap_or_else(|e| e.into_inner());
    let stale = guard
        .as_ref()
        .is_none_or(|c| c.frames != frames || c.device != device);
    if stale {
        *guard = Some(build_indices(ir, frames, &device));
    }
    let Some(idx) = guard.as_ref() else {
        unreachable!("cache filled above")
    };
    // [batch, people·frames·22, 3]
    let rows = joints.reshape([batch, people * frames * NUM_JOINTS, 3]);
    let merged = idx
        .merged
        .as_ref()
        .map(|m| rows.clone().select(1, m.rows.clone()));
    let mut values: Vec<Option<Tensor<4>>> = vec![None; ir.nodes.len()];
    let last_use = last_uses(ir);
    for (i, node) in ir.nodes.iter().enumerate() {
        let get = |values: &Vec<Option<Tensor<4>>>, a: NodeId| {
            values[a].clone().expect("nodes are in SSA order")
        };
        let frames_of = |n: &Node| match n.frames {
            Frames::Const => 1,
            Frames::Domain(d) => idx.domain_sizes[d].max(1),
        };
        let t = match &node.op {
            Op::Const(_) | Op::Time { .. } => idx.consts[&i].clone(),
            Op::Gather { .. } => {
                // [batch, |D|·K, 3] → [batch, |D|, K, 3]
                let g = gather_rows(&rows, merged.as_ref(), idx, i);
                g.reshape([batch, frames_of(node), node.lanes, 3])
            }
            Op::MassCenter { weights, .. } => {
                let g = gather_rows(&rows, merged.as_ref(), idx, i);
                // [batch, |D|, K, 22, 3] weighted over joints → [batch, |D|, K, 3]
                let g: Tensor<5> = g.reshape([batch, frames_of(node), node.lanes, NUM_JOINTS, 3]);
                let w =
                    Tensor::<1>::from_data(TensorData::new(weights.clone(), [NUM_JOINTS]), &device)
                        .reshape([1, 1, 1, NUM_JOINTS, 1]);
                (g * w)
                    .sum_dim(3)
                    .reshape([batch, frames_of(node), node.lanes, 3])
            }
            Op::Component { arg, axis } => get(&values, *arg).narrow(3, *axis, 1),
            Op::Compose(parts) => {
                let ts: Vec<Tensor<4>> = parts.iter().map(|&p| get(&values, p)).collect();
                let shape = ops::common_shape(&ts.iter().collect::<Vec<_>>(), 1);
                Tensor::cat(ts.into_iter().map(|t| t.expand(shape)).collect(), 3)
            }
            Op::Unary { op, arg } => ops::unary(*op, get(&values, *arg)),
            Op::Binary { op, a, b } => ops::binary(*op, get(&values, *a), get(&values, *b)),
            Op::SumChannels(a) => get(&values, *a).sum_dim(3),
            Op::Norm(a) => get(&values, *a)
                .square()
                .sum_dim(3)
                .add_scalar(1e-12)
                .sqrt(),
            Op::Cross(a, b) => {
                let (x, y) = (get(&values, *a), get(&values, *b));
                let shape = ops::common_shape(&[&x, &y], 3);
                x.expand(shape).cross(y.expand(shape), 3)
            }
            Op::Relabel(a) => get(&values, *a),
            Op::SupportDist { point, feet } => {
                ops::support_dist(get(&values, *point), get(&values, *feet), node.lanes)
            }
            Op::Less { a, b } => {
                let (x, y) = (get(&values, *a), get(&values, *b));
                let c = x.dims()[3].max(y.dims()[3]);
                let shape = ops::common_shape(&[&x, &y], c);
                x.expand(shape).lower(y.expand(shape)).float().min_dim(3)
            }
        };
        values[i] = Some(t);
        // Free inputs whose last reader this was (keeps memory flat for long programs).
        for a in node.op.args() {
            if last_use[a] == i {
                values[a] = None;
            }
        }
    }
    let out = reduce(&values, idx, batch, &device);
    drop(guard);
    Ok(out)
}

/// For each node, the last node that reads it (statements count as reading at the end).
fn last_uses(ir: &Ir) -> Vec<usize> {
    let mut last = vec![0usize; ir.nodes.len()];
    for (i, n) in ir.nodes.iter().enumerate() {
        for a in n.op.args() {
            last[a] = i;
        }
    }
    for s in &ir.statements {
        last[s.error] = usize::MAX;
        if let Some(m) = s.mask {
            last[m] = usize::MAX;
        }
    }
    last
}

/// Which of a statement's frames come before a frame limit.
enum Before {
    All,
    None,
    /// Per frame of the statement's block: 1 before the limit, 0 after.
    Some(Vec<f32>),
}

fn frames_before(
    ir: &Ir,
    s: &Statement,
    values: &[Option<Tensor<4>>],
    frames: usize,
    until: usize,
) -> Before {
    if until >= frames {
        return Before::All;
    }
    let list = ir.resolve_domain(s.domain, frames);
    let kept = list.iter().filter(|&&t| t < until).count();
    let per_frame = values[s.error]
        .as_ref()
        .is_some_and(|e| e.dims()[1] == list.len() && list.len() > 1);
    if kept == list.len() {
        Before::All
    } else if kept == 0 {
        Before::None
    } else if !per_frame {
        // The same value on every frame: its mean over the kept frames is itself.
        Before::All
    } else {
        Before::Some(
            list.iter()
                .map(|&t| if t < until { 1.0 } else { 0.0 })
                .collect(),
        )
    }
}

/// weight × mean over the statement's frames (masked), summed over lanes → `[batch, 1]`.
fn statement_error(
    s: &Statement,
    values: &[Option<Tensor<4>>],
    idx: &CachedIndices,
    batch: usize,
    device: &burn::tensor::Device,
) -> Tensor<2> {
    if idx.domain_sizes[s.domain] == 0 {
        return Tensor::<2>::zeros([batch, 1], device);
    }
    let err = values[s.error].clone().expect("statement error is kept");
    if s.mask.is_none() {
        // Mean over frames summed over lanes is one sum over the contiguous frames × lanes
        // of each sample, then a scale: a single pass, where `mean_dim(1)` reads
        // frame-strided.
        let [b, f, lanes, c] = err.dims();
        let factor = s.weight * (s.lanes / lanes.max(1)) as f64 / f as f64;
        let col = err.reshape([b, f * lanes * c]).sum_dim(1);
        let col = if factor == 1.0 {
            col
        } else {
            col.mul_scalar(factor)
        };
        return if b == batch {
            col
        } else {
            col.expand([batch, 1])
        };
    }
    statement_error_masked(s, values, batch, None)
}

/// [`statement_error`] on its masked path, with `keep` (`[1, |D|, 1, 1]`, 0/1) multiplied
/// into the statement's own `if` mask.
fn statement_error_masked(
    s: &Statement,
    values: &[Option<Tensor<4>>],
    batch: usize,
    keep: Option<Tensor<4>>,
) -> Tensor<2> {
    let err = values[s.error].clone().expect("statement error is kept");
    let mask = match (s.mask.and_then(|m| values[m].clone()), keep) {
        (Some(m), Some(k)) => Some(m * k),
        (m, k) => m.or(k),
    };
    let (reduced, lanes) = match mask {
        Some(mask) => {
            let lanes = err.dims()[2].max(mask.dims()[2]);
            // Σ_t e·m / max(Σ_t m, 1): mean over the frames where the condition holds.
            let num = (err * mask.clone()).sum_dim(1);
            let den = mask.sum_dim(1).clamp_min(1.0);
            (num / den, lanes)
        }
        None => {
            let lanes = err.dims()[2];
            (err.mean_dim(1), lanes)
        }
    };
    let factor = s.weight * (s.lanes / lanes.max(1)) as f64;
    let b = reduced.dims()[0];
    // Skip no-op tensor ops: each costs a few µs of dispatch and tape at small sizes.
    let reduced = if lanes > 1 {
        reduced.sum_dim(2)
    } else {
        reduced
    };
    let col = reduced.reshape([b, 1]);
    let col = if factor == 1.0 {
        col
    } else {
        col.mul_scalar(factor)
    };
    if b == batch {
        col
    } else {
        col.expand([batch, 1])
    }
}

#[cfg(test)]
mod tests {
    use crate::lang::compile;
    use crate::skeleton::{JOINT_NAMES, NUM_JOINTS};
    use burn::prelude::*;

    /// Error and gradient of `for j in LIST { j.x < 0.1 m  j.z > -0.1 m }` on a seeded motion.
    fn error_and_grad(list: &str) -> (Vec<f32>, Vec<f32>) {
        let src = format!(
            "length 9 frames\nfor j in {list} {{ always {{ j.x < 0.1 m\n j.z > -0.1 m }} }}\n"
        );
        let program = compile(&src, "all_joints.mprog", &[]).expect("compiles");
        let dims = [2, 1, 9, NUM_JOINTS, 3];
        let n: usize = dims.iter().product();
        let v: Vec<f32> = (0..n)
            .map(|k| ((k * 7919) % 113) as f32 / 113.0 - 0.5)
            .collect();
        let ad = Device::flex().autodiff();
        let x = Tensor::<5>::from_data(TensorData::new(v, dims), &ad).require_grad();
        let e = program.evaluate(x.clone()).total;
        let g = x.grad(&e.clone().sum().backward()).expect("a gradient");
        let host = |t: Tensor<1>| t.into_data().try_to_vec::<f32>().unwrap();
        (host(e), host(g.reshape([n])))
    }

    #[test]
    fn a_gather_of_every_joint_in_order_reads_the_motion_itself() {
        // `joints` gathers every row in order (no copy); the same joints listed in reverse
        // are a real gather. The error and its gradient must agree.
        let whole = error_and_grad("joints");
        let reversed: Vec<&str> = JOINT_NAMES.iter().rev().copied().collect();
        let listed = error_and_grad(&format!("[{}]", reversed.join(", ")));
        for (a, b) in whole.0.iter().zip(&listed.0) {
            assert!((a - b).abs() <= 1e-6 * (1.0 + b.abs()), "{a} vs {b}");
        }
        assert!(whole.0.iter().any(|e| *e > 0.0));
        for (a, b) in whole.1.iter().zip(&listed.1) {
            assert!((a - b).abs() <= 1e-6, "{a} vs {b}");
        }
    }
}
