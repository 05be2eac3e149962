//! `recover_from_ric` as a batched, differentiable burn function, and Mean/Std
//! (de)normalisation of feature tensors.
//!
//! In: de-normalised features `[B, N, 263]` on any burn device, with or without autodiff.
//! Out: joint positions `[B, N, 22, 3]`. Same maths as [`super::recover_from_ric`], in the
//! cheap 2-D yaw form (cumulative sums of the half-angles, cos/sin of twice them), with
//! whole-tensor ops only: the solvers call this hundreds of times per sample.

use super::layout::{FEATURE_DIM, RIC};
use crate::skeleton::NUM_JOINTS;
use burn::tensor::Tensor;

/// Joint positions `[B, N, 22, 3]` from de-normalised features `[B, N, 263]`.
///
/// Frame t's root displacement (features 1–2) is expressed in the facing of frame t + 1,
/// whose yaw is the inclusive cumulative sum of the half-angles; frame t's own facing (for
/// the ric block) is the exclusive one. Both come from one `cumsum`, so no shifted copy of
/// the yaw column is needed.
///
/// # Panics
/// If the last axis is not 263 wide (a programming error: the model produces this tensor).
pub fn recover_from_ric_tensor(features: Tensor<3>) -> Tensor<4> {
    let [b, n, d] = features.dims();
    assert_eq!(
        d, FEATURE_DIM,
        "recover_from_ric_tensor: features must be [B, N, 263], got [{b}, {n}, {d}]"
    );
    // Only the root and ric blocks are read; one narrow keeps the backward scatter small.
    let head = features.narrow(2, 0, RIC.end); // [B, N, 67]
    let yaw_vel = head.clone().narrow(2, 0, 1); // [B, N, 1]
    let yaw_next = yaw_vel.clone().cumsum(1); // [B, N, 1]  a[t + 1]
    let yaw_now = yaw_next.clone() - yaw_vel; // [B, N, 1]  a[t]

    // Root XZ: exclusive cumulative sum of the velocities turned by R_y(−2a[t + 1]).
    let ang_next = yaw_next.mul_scalar(2.0);
    let (c1, s1) = (ang_next.clone().cos(), ang_next.sin()); // [B, N, 1]
    let vx = head.clone().narrow(2, 1, 1); // [B, N, 1]
    let vz = head.clone().narrow(2, 2, 1);
    let step_x = vx.clone() * c1.clone() - vz.clone() * s1.clone();
    let step_z = vx * s1 + vz * c1;
    let root_x = step_x.clone().cumsum(1) - step_x; // [B, N, 1]
    let root_z = step_z.clone().cumsum(1) - step_z;
    let root_y = head.clone().narrow(2, 3, 1);

    // Joints 1..21: ric turned by R_y(−2a[t]), plus the root's XZ.
    let ang = yaw_now.mul_scalar(2.0);
    let c = ang.clone().cos().reshape([b, n, 1, 1]);
    let s = ang.sin().reshape([b, n, 1, 1]);
    let ric = head
        .narrow(2, RIC.start, RIC.len())
        .reshape([b, n, NUM_JOINTS - 1, 3]); // [B, N, 21, 3]
    let x = ric.clone().narrow(3, 0, 1); // [B, N, 21, 1]
    let y = ric.clone().narrow(3, 1, 1);
    let z = ric.narrow(3, 2, 1);
    let rx = root_x.clone().reshape([b, n, 1, 1]);
    let rz = root_z.clone().reshape([b, n, 1, 1]);
    let jx = x.clone() * c.clone() - z.clone() * s.clone() + rx;
    let jz = x * s + z * c + rz;
    let joints = Tensor::cat(vec![jx, y, jz], 3); // [B, N, 21, 3]
    let root = Tensor::cat(vec![root_x, root_y, root_z], 2).reshape([b, n, 1, 3]); // [B, N, 1, 3]
    Tensor::cat(vec![root, joints], 2) // [B, N, 22, 3]
}

/// `(x − Mean)/Std` for features `[B, N, 263]` with Mean and Std `[263]`.
pub fn normalize(x: Tensor<3>, mean: Tensor<1>, std: Tensor<1>) -> Tensor<3> {
    (x - mean.reshape([1, 1, FEATURE_DIM])) / std.reshape([1, 1, FEATURE_DIM])
}

/// `x·Std + Mean` for features `[B, N, 263]` with Mean and Std `[263]`.
pub fn denormalize(x: Tensor<3>, mean: Tensor<1>, std: Tensor<1>) -> Tensor<3> {
    x * std.reshape([1, 1, FEATURE_DIM]) + mean.reshape([1, 1, FEATURE_DIM])
}
