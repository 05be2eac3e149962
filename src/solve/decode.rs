//! From model space to the world, in burn ops: normalised features `[B·P, N, 263]` →
//! de-normalise → `recover_from_ric_tensor` → `[B, P, N, 22, 3]` → optional per-sample
//! rigid relaxation → each person's [`Placement`]. Differentiable on an autodiff device;
//! used where gradients go through more than the joints (latent, L-BFGS) and as the
//! reference the fused host path ([`super::host`]) is tested against.

use crate::features::{FEATURE_DIM, denormalize, recover_from_ric_tensor};
use crate::scene::Placement;
use crate::skeleton::NUM_JOINTS;
use burn::prelude::*;

/// Per (sample, person) rigid XZ transforms `[B, P]` (yaw in radians, x and z in metres),
/// applied in the person's own frame before its placement.
#[derive(Clone, Debug)]
pub struct RigidTensors {
    /// Yaw about +Y.
    pub yaw: Tensor<2>,
    /// X translation.
    pub x: Tensor<2>,
    /// Z translation.
    pub z: Tensor<2>,
}

/// Decodes normalised model samples into world joints.
#[derive(Clone, Debug)]
pub struct Decoder {
    /// People per sample.
    pub people: usize,
    /// `[263]` feature mean.
    pub mean: Vec<f32>,
    /// `[263]` feature std.
    pub std: Vec<f32>,
    /// One placement per person.
    pub placements: Vec<Placement>,
}

/// `x' = c·x + s·z + tx`, `z' = −s·x + c·z + tz` with `c, s, tx, tz` of shape `[b, P]`
/// (b = B or 1) broadcast over frames and joints.
fn rigid(j: Tensor<5>, c: Tensor<2>, s: Tensor<2>, tx: Tensor<2>, tz: Tensor<2>) -> Tensor<5> {
    let [b, p] = c.dims();
    let r = |t: Tensor<2>| t.reshape([b, p, 1, 1, 1]);
    let (c, s, tx, tz) = (r(c), r(s), r(tx), r(tz));
    let x = j.clone().narrow(4, 0, 1);
    let y = j.clone().narrow(4, 1, 1);
    let z = j.narrow(4, 2, 1);
    let nx = x.clone() * c.clone() + z.clone() * s.clone() + tx;
    let nz = z * c - x * s + tz;
    Tensor::cat(vec![nx, y, nz], 4)
}

impl Decoder {
    /// A decoder for `people` people with their placements (one each).
    ///
    /// # Panics
    /// If the statistics are not 263 wide or the placements do not match `people`.
    pub fn new(mean: &[f32], std: &[f32], placements: &[Placement]) -> Self {
        assert_eq!(mean.len(), FEATURE_DIM, "mean width");
        assert_eq!(std.len(), FEATURE_DIM, "std width");
        assert!(!placements.is_empty(), "at least one person");
        Decoder {
            people: placements.len(),
            mean: mean.to_vec(),
            std: std.to_vec(),
            placements: placements.to_vec(),
        }
    }

    /// World joints `[B, P, N, 22, 3]` of normalised samples `[B·P, N, 263]`, with an
    /// optional relaxation transform per (sample, person).
    pub fn joints(&self, x: Tensor<3>, relax: Option<&RigidTensors>) -> Tensor<5> {
        let device = x.device();
        let [bp, n, _] = x.dims();
        let p = self.people;
        let b = bp / p;
        let stat =
            |v: &[f32]| Tensor::<1>::from_data(TensorData::new(v.to_vec(), [v.len()]), &device);
        let feats = denormalize(x, stat(&self.mean), stat(&self.std));
        let mut j = recover_from_ric_tensor(feats).reshape([b, p, n, NUM_JOINTS, 3]);
        if let Some(r) = relax {
            j = rigid(
                j,
                r.yaw.clone().cos(),
                r.yaw.clone().sin(),
                r.x.clone(),
                r.z.clone(),
            );
        }
        if self.placements.iter().any(|q| *q != Placement::IDENTITY) {
            let row = |f: &dyn Fn(&Placement) -> f32| {
                let v: Vec<f32> = self.placements.iter().map(f).collect();
                Tensor::<2>::from_data(TensorData::new(v, [1, p]), &device)
            };
            j = rigid(
                j,
                row(&|q| q.cos_sin().0),
                row(&|q| q.cos_sin().1),
                row(&|q| q.x),
                row(&|q| q.z),
            );
        }
        j
    }
}
