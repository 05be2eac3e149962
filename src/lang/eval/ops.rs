//! Tensor kernels of the evaluator that are more than one burn call: elementwise ops with
//! broadcasting, and the support-polygon distance.

use crate::lang::ir::{BinaryOp, UnaryOp};
use burn::tensor::Tensor;

/// The broadcast shape of 4-d tensors, with `channels` as the last axis.
pub fn common_shape(ts: &[&Tensor<4>], channels: usize) -> [usize; 4] {
    let mut shape = [1, 1, 1, channels];
    for t in ts {
        let d = t.dims();
        for k in 0..3 {
            shape[k] = shape[k].max(d[k]);
        }
    }
    shape
}

/// Elementwise unary op.
pub fn unary(op: UnaryOp, x: Tensor<4>) -> Tensor<4> {
    match op {
        UnaryOp::Neg => x.neg(),
        UnaryOp::Abs => x.abs(),
        UnaryOp::Sqrt => x.clamp_min(0.0).add_scalar(1e-12).sqrt(),
        // burn's relu, not clamp_min(0): its backward is one pass over the output, where
        // clamp_min's builds a comparison mask and then fills with it (two).
        UnaryOp::Relu => burn::tensor::activation::relu(x),
        UnaryOp::Sin => x.sin(),
        UnaryOp::Cos => x.cos(),
        UnaryOp::Square => x.square(),
        UnaryOp::OneMinus => x.neg().add_scalar(1.0),
    }
}

/// Elementwise binary op with broadcasting.
pub fn binary(op: BinaryOp, a: Tensor<4>, b: Tensor<4>) -> Tensor<4> {
    match op {
        BinaryOp::Add => a + b,
        BinaryOp::Sub => a - b,
        BinaryOp::Mul => a * b,
        BinaryOp::Div => a / b,
        // min(a, b) = a − max(a − b, 0); max(a, b) = a + max(b − a, 0): broadcasting ops only.
        BinaryOp::Min => a.clone() - burn::tensor::activation::relu(a - b),
        BinaryOp::Max => a.clone() + burn::tensor::activation::relu(b - a),
        BinaryOp::Atan2 => {
            let c = a.dims()[3].max(b.dims()[3]);
            let shape = common_shape(&[&a, &b], c);
            a.expand(shape).atan2(b.expand(shape))
        }
    }
}

/// Index pairs (i, j) of the 6 segments between the 4 foot points.
const PAIRS: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// Signed ground (xz) distance from `point` `[B, F, K|1, 3]` to the convex hull of the
/// 4 foot points of each lane, `feet` `[B, F, 4K, 3]` → `[B, F, K, 1]`.
///
/// Outside the hull the nearest hull point lies on some segment between two foot points
/// (segments inside the hull are never nearer), so the distance is the minimum over all 6
/// segments. Inside, it is minus the distance to the nearest hull edge, where a segment is
/// a hull edge when the other two points lie on one side of it. The hull and inside tests
/// are masks without gradient.
pub fn support_dist(point: Tensor<4>, feet: Tensor<4>, lanes: usize) -> Tensor<4> {
    let [b, f, _, _] = feet.dims();
    let device = feet.device();
    // Ground coordinates: x and z. [B, F, K, 4, 2]
    let feet: Tensor<5> = feet.reshape([b, f, lanes, 4, 3]);
    let fx = feet.clone().narrow(4, 0, 1);
    let fz = feet.narrow(4, 2, 1);
    let pts = Tensor::cat(vec![fx, fz], 4);
    let [pb, pf, pk, _] = point.dims();
    let p: Tensor<5> = point.reshape([pb, pf, pk, 1, 3]);
    let p = Tensor::cat(vec![p.clone().narrow(4, 0, 1), p.narrow(4, 2, 1)], 4); // [B, F, K, 1, 2]
    let sel = |ids: Vec<i64>| {
        Tensor::<1, burn::tensor::Int>::from_data(burn::tensor::TensorData::new(ids, [6]), &device)
    };
    let a = pts
        .clone()
        .select(3, sel(PAIRS.iter().map(|p| p.0 as i64).collect())); // [B, F, K, 6, 2]
    let e = pts
        .clone()
        .select(3, sel(PAIRS.iter().map(|p| p.1 as i64).collect()));
    let ab = e - a.clone();
    let ap = p.clone() - a.clone();
    // Distance to each segment: |ap − clamp(ap·ab / |ab|², 0, 1) ab|.
    let len2 = ab.clone().square().sum_dim(4).add_scalar(1e-12);
    let t = ((ap.clone() * ab.clone()).sum_dim(4) / len2).clamp(0.0, 1.0);
    let d = (ap.clone() - ab.clone() * t)
        .square()
        .sum_dim(4)
        .add_scalar(1e-12)
        .sqrt(); // [B, F, K, 6, 1]
    // Side of the point and of the other two foot points for each segment (no gradient).
    let cross = |u: Tensor<5>, v: Tensor<5>| {
        u.clone().narrow(4, 0, 1) * v.clone().narrow(4, 1, 1)
            - u.narrow(4, 1, 1) * v.narrow(4, 0, 1)
    };
    let others: [(usize, usize); 6] = [(2, 3), (1, 3), (1, 2), (0, 3), (0, 2), (0, 1)];
    let o1 = pts
        .clone()
        .select(3, sel(others.iter().map(|o| o.0 as i64).collect()));
    let o2 = pts.select(3, sel(others.iter().map(|o| o.1 as i64).collect()));
    let s1 = cross(ab.clone(), o1 - a.clone()).detach();
    let s2 = cross(ab.clone(), o2 - a).detach();
    let sp = cross(ab, ap).detach();
    // Hull edge: both other points on the same (closed) side.
    let hull = (s1.clone() * s2.clone()).greater_equal_elem(0.0).float(); // [B, F, K, 6, 1]
    // Inside: on the others' side of every hull edge.
    let side = s1.add(s2);
    // A hull edge with the other points on the line itself means a degenerate (flat) hull:
    // only points on that line are inside, so treat everything else as outside.
    let flat = side.clone().abs().lower_elem(1e-12).float();
    let wrong_side = (sp * side).lower_elem(0.0).float();
    let outside_edge = (wrong_side + flat).clamp_max(1.0) * hull.clone();
    let inside = outside_edge.sum_dim(3).lower_elem(0.5).float(); // [B, F, K, 1, 1]
    let big = 1e3;
    let d_out = d.clone().min_dim(3);
    let d_in = (d + (hull.neg().add_scalar(1.0)).mul_scalar(big)).min_dim(3);
    let signed = d_out * inside.clone().neg().add_scalar(1.0) - d_in * inside;
    signed.reshape([b.max(pb), f.max(pf), lanes, 1])
}
