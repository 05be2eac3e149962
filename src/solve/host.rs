//! The fused host path of the inner loops (guide, IK): `recover_from_ric` and the world
//! placement as plain-array code with a hand-written backward (vector–Jacobian product),
//! so each inner iteration costs one evaluation of the error graph and nothing else.
//!
//! Only the first 67 feature columns (root yaw velocity, root XZ velocity, root height and
//! the ric block) reach the joints, so the fused path works on that "head" `[M, N, 67]`;
//! the error's gradient with respect to every other column is exactly zero.
//!
//! Per motion (`a` is the root facing as a half-angle, frames t = 0..N−1):
//! * `a_next[t] = Σ_{k≤t} yaw[k]`, `a[t] = a_next[t] − yaw[t]`;
//! * root XZ `r[t] = Σ_{k<t} R(−2·a_next[k])·v[k]`, root y = column 3;
//! * joint j ≥ 1: `R(−2·a[t])·ric_j[t] + (r_x, 0, r_z)`, where `R(θ)(x, z) = (x cos θ − z sin θ,
//!   x sin θ + z cos θ)`.
//!
//! The backward runs these in reverse (reverse cumulative sums for the two prefix sums).
//! Tests check forward and gradient against the burn graph ([`super::Decoder`]).

use super::accel::AccelHold;
use super::bones::SkeletonProjection;
use super::decode::Decoder;
use super::driver::host;
use super::envelope::EnvelopeGuard;
use super::feet::FootLock;
use super::{MotionError, SolveError};
use crate::features::layout::RIC;
use crate::scene::Placement;
use crate::skeleton::{FOOT_LEFT, FOOT_RIGHT, NUM_JOINTS};
use burn::prelude::*;

/// Feature columns that reach the joints.
pub const HEAD: usize = RIC.end;

const J3: usize = NUM_JOINTS * 3;

/// Plain-array `recover_from_ric` on de-normalised heads `[M, N, 67]` → joints `[M, N, 22, 3]`,
/// and its backward. Keeps the rotation angles of the last forward for the backward.
#[derive(Clone, Debug, Default)]
pub struct HostFk {
    frames: usize,
    /// cos/sin of 2·a_next (root velocity turn) and of 2·a (ric turn), `[M, N]` each.
    c1: Vec<f32>,
    s1: Vec<f32>,
    c0: Vec<f32>,
    s0: Vec<f32>,
}

impl HostFk {
    /// Joints of de-normalised heads; `joints` must hold `M·N·66` values.
    pub fn forward(&mut self, head: &[f32], frames: usize, joints: &mut [f32]) {
        let m = head.len() / (frames * HEAD);
        assert_eq!(head.len(), m * frames * HEAD, "head length");
        assert_eq!(joints.len(), m * frames * J3, "joints length");
        self.frames = frames;
        for v in [&mut self.c1, &mut self.s1, &mut self.c0, &mut self.s0] {
            v.resize(m * frames, 0.0);
        }
        for mi in 0..m {
            let (mut a_next, mut rx, mut rz) = (0.0f64, 0.0f64, 0.0f64);
            for t in 0..frames {
                let k = mi * frames + t;
                let h = &head[k * HEAD..(k + 1) * HEAD];
                let a_now = a_next;
                a_next += h[0] as f64;
                let (s1, c1) = (2.0 * a_next).sin_cos();
                let (s0, c0) = (2.0 * a_now).sin_cos();
                self.c1[k] = c1 as f32;
                self.s1[k] = s1 as f32;
                self.c0[k] = c0 as f32;
                self.s0[k] = s0 as f32;
                let out = &mut joints[k * J3..(k + 1) * J3];
                out[0] = rx as f32;
                out[1] = h[3];
                out[2] = rz as f32;
                let (c, s) = (c0 as f32, s0 as f32);
                for j in 1..NUM_JOINTS {
                    let r = &h[RIC.start + 3 * (j - 1)..RIC.start + 3 * j];
                    out[3 * j] = r[0] * c - r[2] * s + rx as f32;
                    out[3 * j + 1] = r[1];
                    out[3 * j + 2] = r[0] * s + r[2] * c + rz as f32;
                }
                // The root moves after this frame by its velocity turned into the next facing.
                let (vx, vz) = (h[1] as f64, h[2] as f64);
                rx += vx * c1 - vz * s1;
                rz += vx * s1 + vz * c1;
            }
        }
    }

    /// Gradient with respect to the de-normalised head of the last [`forward`](Self::forward),
    /// given the gradient with respect to its joints. Overwrites `g_head`.
    pub fn backward(&self, head: &[f32], g_joints: &[f32], g_head: &mut [f32]) {
        let n = self.frames;
        let m = head.len() / (n * HEAD);
        assert_eq!(g_joints.len(), m * n * J3, "joint gradient length");
        assert_eq!(g_head.len(), head.len(), "head gradient length");
        for mi in 0..m {
            // Reverse sweeps: Σ_{t'>t} of the root gradient, Σ_{t'≥t} of the a_next gradient.
            let (mut g_rx_after, mut g_rz_after, mut g_anext_from) = (0.0f64, 0.0f64, 0.0f64);
            for t in (0..n).rev() {
                let k = mi * n + t;
                let h = &head[k * HEAD..(k + 1) * HEAD];
                let g = &g_joints[k * J3..(k + 1) * J3];
                let gh = &mut g_head[k * HEAD..(k + 1) * HEAD];
                // The root velocity of frame t moves the root of every later frame.
                let (c1, s1) = (self.c1[k] as f64, self.s1[k] as f64);
                let (vx, vz) = (h[1] as f64, h[2] as f64);
                let (gsx, gsz) = (g_rx_after, g_rz_after);
                gh[1] = (gsx * c1 + gsz * s1) as f32;
                gh[2] = (-gsx * s1 + gsz * c1) as f32;
                let g_theta1 = gsx * (-vx * s1 - vz * c1) + gsz * (vx * c1 - vz * s1);
                // This frame's joints: ric turned by 2a, root XZ added to all 22.
                let (c, s) = (self.c0[k], self.s0[k]);
                let (mut g_rx, mut g_rz) = (g[0] as f64, g[2] as f64);
                gh[3] = g[1];
                let mut g_theta0 = 0.0f64;
                for j in 1..NUM_JOINTS {
                    let (gx, gy, gz) = (g[3 * j], g[3 * j + 1], g[3 * j + 2]);
                    let base = RIC.start + 3 * (j - 1);
                    let (x, z) = (h[base], h[base + 2]);
                    gh[base] = gx * c + gz * s;
                    gh[base + 1] = gy;
                    gh[base + 2] = -gx * s + gz * c;
                    g_theta0 += (gx * (-x * s - z * c) + gz * (x * c - z * s)) as f64;
                    g_rx += gx as f64;
                    g_rz += gz as f64;
                }
                g_rx_after += g_rx;
                g_rz_after += g_rz;
                // θ1 = 2·a_next[t], θ0 = 2·a[t] = 2·(a_next[t] − yaw[t]).
                let g_anext = 2.0 * g_theta1 + 2.0 * g_theta0;
                g_anext_from += g_anext;
                gh[0] = (g_anext_from - 2.0 * g_theta0) as f32;
            }
        }
    }
}

/// Error and gradient of normalised heads through the fused path: heads `[B·P, N, 67]`
/// (normalised) → world joints → the error graph (burn, autodiff) → gradient back to the
/// normalised heads.
pub struct HostObjective<'a> {
    error: &'a dyn MotionError,
    device: Device,
    batch: usize,
    frames: usize,
    mean: Vec<f32>,
    std: Vec<f32>,
    placements: Vec<Placement>,
    fk: HostFk,
    /// De-normalised heads of the last evaluation (after the projection, if any).
    head: Vec<f32>,
    joints: Vec<f32>,
    /// Skeleton projection applied before the FK ([`Self::project_skeleton`]).
    projection: Option<SkeletonProjection>,
    /// Slide penalty on planted feet ([`Self::lock_feet`]).
    feet: Option<FootLock>,
    /// Penalty on added acceleration ([`Self::hold_accel`]).
    accel: Option<AccelHold>,
    /// Penalty on leaving the real envelope ([`Self::keep_in_envelope`]).
    envelope: Option<EnvelopeGuard>,
    /// The two penalties per sample at the last evaluation (zeros without them).
    penalty: Vec<f32>,
    /// The envelope's share of `penalty` per sample (zeros without the guard).
    outside: Vec<f32>,
    /// Rigid XZ transform per motion `[B·P]`, applied in the person's frame before its
    /// placement (`latent`'s relaxation, [`Self::set_rigid`]).
    rigid: Option<Vec<Placement>>,
    /// Joints before the rigid transform (its yaw gradient needs them); only with `rigid`.
    local: Vec<f32>,
    /// `∂E/∂(yaw, x, z)` of each motion's rigid transform at the last [`Self::eval`], laid
    /// out `[yaw × M, x × M, z × M]`.
    g_rigid: Vec<f32>,
}

impl<'a> HostObjective<'a> {
    /// For `batch` samples of `frames` frames; `device` is where the error graph runs
    /// (made autodiff here).
    pub fn new(
        error: &'a dyn MotionError,
        decoder: &Decoder,
        batch: usize,
        frames: usize,
        device: &Device,
    ) -> Self {
        HostObjective {
            error,
            device: device.clone().autodiff(),
            batch,
            frames,
            mean: decoder.mean[..HEAD].to_vec(),
            std: decoder.std[..HEAD].to_vec(),
            placements: decoder.placements.clone(),
            fk: HostFk::default(),
            head: Vec::new(),
            joints: Vec::new(),
            projection: None,
            feet: None,
            accel: None,
            envelope: None,
            penalty: vec![0.0; batch],
            outside: vec![0.0; batch],
            rigid: None,
            local: Vec::new(),
            g_rigid: Vec::new(),
        }
    }

    /// From now on move each motion `i` by `rigid[i]` in its person's own frame before the
    /// placement (None: no such move), as [`Decoder::joints`] does with a relaxation.
    pub fn set_rigid(&mut self, rigid: Option<Vec<Placement>>) {
        self.rigid = rigid;
    }

    /// `∂E/∂(yaw, x, z)` of the rigid transforms at the last [`Self::eval`],
    /// `[yaw × M, x × M, z × M]` (empty without [`Self::set_rigid`]).
    pub fn rigid_gradient(&self) -> &[f32] {
        &self.g_rigid
    }

    /// From now on add [`FootLock`]'s penalty (weight `weight`) on the feet that are planted
    /// in these normalised heads (after the skeleton projection, if one is set up) to what
    /// [`eval`](Self::eval) differentiates; returns how many toe-frame pairs are planted.
    pub fn lock_feet(&mut self, head: &[f32], weight: f32) -> usize {
        let people = self.placements.len();
        let joints = self.world_joints(head).to_vec();
        let lock = FootLock::new(&joints, self.frames, people, weight);
        let planted = lock.planted();
        self.feet = Some(lock);
        planted
    }

    /// From now on add [`AccelHold`]'s penalty (weight `weight`) on the joint acceleration
    /// added to these normalised heads to what [`eval`](Self::eval) differentiates.
    ///
    /// With the skeleton projection set up, the reference is the heads' joints *before*
    /// it, except the ankles and toes, which keep the projection's: it rebuilds the body
    /// bone by bone, and the wrists take the elbows' wobble (it alone raised the keyframe
    /// family's peak acceleration from 0.093 to 0.108), which the hold then holds back
    /// too; the feet keep the floor contact it plants.
    pub fn hold_accel(&mut self, head: &[f32], weight: f32) {
        let people = self.placements.len();
        let projection = self.projection.take();
        let raw = projection
            .is_some()
            .then(|| self.world_joints(head).to_vec());
        self.projection = projection;
        // Last, so the objective's joints stay the projection's.
        let mut reference = self.world_joints(head).to_vec();
        if let Some(raw) = raw {
            for (kept, raw) in reference.chunks_exact_mut(J3).zip(raw.chunks_exact(J3)) {
                for j in
                    (0..NUM_JOINTS).filter(|j| !FOOT_LEFT.contains(j) && !FOOT_RIGHT.contains(j))
                {
                    kept[3 * j..3 * j + 3].copy_from_slice(&raw[3 * j..3 * j + 3]);
                }
            }
        }
        self.accel = Some(AccelHold::new(&reference, self.frames, people, weight));
    }

    /// From now on add [`EnvelopeGuard`]'s penalty (weight `weight`; 0 removes it) on
    /// joints below the floor and accelerations beyond the training data's to what
    /// [`eval`](Self::eval) differentiates.
    pub fn keep_in_envelope(&mut self, weight: f32) {
        let people = self.placements.len();
        self.envelope = (weight > 0.0).then(|| EnvelopeGuard::new(self.frames, people, weight));
    }

    /// Stop adding the acceleration hold's penalty.
    pub fn release_accel(&mut self) {
        self.accel = None;
        if !self.penalized() {
            self.penalty.fill(0.0);
        }
    }

    /// Stop adding the foot, acceleration and envelope penalties.
    pub fn unlock_feet(&mut self) {
        self.feet = None;
        self.accel = None;
        self.envelope = None;
        self.penalty.fill(0.0);
        self.outside.fill(0.0);
    }

    /// The foot and acceleration penalties per sample at the last [`eval`](Self::eval):
    /// their gradient is in that evaluation's gradient, their value is not in the returned
    /// errors.
    pub fn penalty(&self) -> &[f32] {
        &self.penalty
    }

    /// The envelope guard's part of [`Self::penalty`] per sample at the last evaluation:
    /// above 0 where the motion leaves the real envelope.
    pub fn outside(&self) -> &[f32] {
        &self.outside
    }

    /// Whether a penalty is set.
    fn penalized(&self) -> bool {
        self.feet.is_some() || self.accel.is_some() || self.envelope.is_some()
    }

    /// The penalties of the current joints per sample; their gradient added to `g`.
    fn eval_penalties(&mut self, g: &mut [f32]) -> Vec<f32> {
        let mut penalty = vec![0.0; self.batch];
        let outside = self
            .envelope
            .as_ref()
            .map(|guard| guard.eval(&self.joints, g));
        self.outside = outside.clone().unwrap_or_else(|| vec![0.0; self.batch]);
        for p in [
            self.feet.as_ref().map(|lock| lock.eval(&self.joints, g)),
            self.accel.as_ref().map(|hold| hold.eval(&self.joints, g)),
            outside,
        ]
        .into_iter()
        .flatten()
        {
            penalty.iter_mut().zip(p).for_each(|(a, b)| *a += b);
        }
        penalty
    }

    /// From now on evaluate the error of `P(head)`, the skeleton projection set up on these
    /// normalised heads (see [`super::bones`]); returns how many frames have a planted foot.
    pub fn project_skeleton(&mut self, head: &[f32]) -> usize {
        let map = SkeletonProjection::new(&self.denormalize(head), self.frames);
        let anchored = map.anchored();
        self.projection = Some(map);
        anchored
    }

    /// Evaluate the error of the heads as they are again.
    pub fn stop_projecting(&mut self) {
        self.projection = None;
    }

    /// Replaces normalised heads by their projection (no-op when not projecting).
    pub fn apply_projection(&mut self, head: &mut [f32]) {
        if self.projection.is_none() {
            return;
        }
        let input = self.denormalize(head);
        let mut out = vec![0.0; input.len()];
        if let Some(p) = &mut self.projection {
            p.forward(&input, &mut out);
        }
        for (row, o) in head.chunks_exact_mut(HEAD).zip(out.chunks_exact(HEAD)) {
            for (((x, o), s), m) in row.iter_mut().zip(o).zip(&self.std).zip(&self.mean) {
                *x = (o - m) / s;
            }
        }
    }

    fn denormalize(&self, head: &[f32]) -> Vec<f32> {
        head.chunks_exact(HEAD)
            .flat_map(|row| {
                row.iter()
                    .zip(&self.std)
                    .zip(&self.mean)
                    .map(|((x, s), m)| x * s + m)
            })
            .collect()
    }

    /// World joints `[B, P, N, 22, 3]` (flat) of normalised heads.
    pub fn world_joints(&mut self, head: &[f32]) -> &[f32] {
        let plain = self.denormalize(head);
        self.head = match &mut self.projection {
            Some(p) => {
                let mut out = vec![0.0; plain.len()];
                p.forward(&plain, &mut out);
                out
            }
            None => plain,
        };
        self.joints.resize(head.len() / HEAD * J3, 0.0);
        self.fk.forward(&self.head, self.frames, &mut self.joints);
        let per = self.frames * NUM_JOINTS;
        if let Some(rigid) = &self.rigid {
            self.local.clone_from(&self.joints);
            for (chunk, r) in self.joints.chunks_exact_mut(per * 3).zip(rigid) {
                move_xz(chunk, r);
            }
        }
        for (i, chunk) in self.joints.chunks_exact_mut(per * 3).enumerate() {
            let q = self.placements[i % self.placements.len()];
            if q != Placement::IDENTITY {
                move_xz(chunk, &q);
            }
        }
        &self.joints
    }

    /// Errors per sample `[B]`; writes `∂(Σ_b error_b + penalty_b)/∂head` (normalised) into
    /// `grad`, where the penalty is the foot lock's and the acceleration hold's, if set
    /// ([`Self::penalty`]). Values are
    /// returned as computed (the caller checks them for NaN/Inf).
    pub fn eval(&mut self, head: &[f32], grad: &mut [f32]) -> Result<Vec<f32>, SolveError> {
        let people = self.placements.len();
        self.world_joints(head);
        let dims = [self.batch, people, self.frames, NUM_JOINTS, 3];
        let j = Tensor::<5>::from_data(TensorData::new(self.joints.clone(), dims), &self.device)
            .require_grad();
        let e = self.error.error(j.clone());
        check_shape(&e, self.batch)?;
        let values = host(e.clone());
        let g_world = if e.is_tracked() {
            let grads = e.sum().backward();
            j.grad(&grads)
                .map(|g| g.into_data().try_to_vec::<f32>().expect("f32 gradient"))
        } else {
            None
        };
        let mut g = match (g_world, self.penalized()) {
            (Some(g), _) => g,
            (None, true) => vec![0.0; self.joints.len()],
            (None, false) => {
                grad.fill(0.0);
                self.g_rigid = vec![0.0; 3 * self.rigid.as_ref().map_or(0, Vec::len)];
                return Ok(values);
            }
        };
        if self.penalized() {
            self.penalty = self.eval_penalties(&mut g);
        }
        self.g_rigid = self.to_head_gradient(&mut g, grad);
        Ok(values)
    }

    /// Errors per sample `[B]` and each term's value and gradient (normalised heads), into
    /// `out`: the error's [`terms`](MotionError::terms), then the foot lock's and the
    /// acceleration hold's penalty if set. A term with no error in any sample gets no gradient pass (its gradient is left
    /// zero), so satisfied hinges cost nothing.
    pub fn eval_terms(&mut self, head: &[f32], out: &mut TermGradients) -> Result<(), SolveError> {
        let people = self.placements.len();
        self.world_joints(head);
        let dims = [self.batch, people, self.frames, NUM_JOINTS, 3];
        let joints =
            || Tensor::<5>::from_data(TensorData::new(self.joints.clone(), dims), &self.device);
        let first = joints().require_grad();
        let terms = self.error.terms(first.clone());
        let [b, count] = terms.dims();
        check_shape(&terms.clone().sum_dim(1).reshape([b]), self.batch)?;
        let flat = terms
            .clone()
            .into_data()
            .try_to_vec::<f32>()
            .expect("f32 terms");
        // A program of prompts alone (a timeline) has no term: every sample's error is 0.
        out.total = match count {
            0 => vec![0.0; b],
            _ => flat
                .chunks_exact(count)
                .map(|row| row.iter().sum())
                .collect(),
        };
        out.statements = count;
        let with_feet = count + usize::from(self.penalized());
        out.values.resize(with_feet, Vec::new());
        out.grads.resize(with_feet, Vec::new());
        for (t, v) in out.values.iter_mut().take(count).enumerate() {
            *v = flat.iter().skip(t).step_by(count).copied().collect();
        }
        let mut pending = Some((first, terms));
        for t in 0..count {
            let grad = &mut out.grads[t];
            grad.clear();
            grad.resize(head.len(), 0.0);
            if !out.values[t].iter().any(|&e| e > 0.0) {
                continue;
            }
            // A backward pass consumes its graph: later terms evaluate again.
            let (j, terms) = pending.take().unwrap_or_else(|| {
                let j = joints().require_grad();
                (j.clone(), self.error.terms(j))
            });
            if !terms.is_tracked() {
                continue;
            }
            let chosen = terms.narrow(1, t, 1).sum();
            let Some(g) = j.grad(&chosen.backward()) else {
                continue;
            };
            let mut g = g.into_data().try_to_vec::<f32>().expect("f32 gradient");
            self.to_head_gradient(&mut g, grad);
        }
        if self.penalized() {
            let mut g = vec![0.0; self.joints.len()];
            self.penalty = self.eval_penalties(&mut g);
            out.values[count] = self.penalty.clone();
            let grad = &mut out.grads[count];
            grad.resize(head.len(), 0.0);
            self.to_head_gradient(&mut g, grad);
        }
        Ok(())
    }

    /// Gradient with respect to world joints → gradient with respect to the normalised
    /// heads (overwrites `grad`): undo the placement (Rᵀ), the rigid transform if set
    /// (whose own gradient is returned, `[yaw × M, x × M, z × M]`; empty without one), the
    /// FK, the projection and the de-normalisation.
    fn to_head_gradient(&self, g: &mut [f32], grad: &mut [f32]) -> Vec<f32> {
        let people = self.placements.len();
        let per = self.frames * NUM_JOINTS * 3;
        for (i, chunk) in g.chunks_exact_mut(per).enumerate() {
            let q = self.placements[i % people];
            if q == Placement::IDENTITY {
                continue;
            }
            rotate_back(chunk, q);
        }
        let mut g_rigid = Vec::new();
        if let Some(rigid) = &self.rigid {
            let m = rigid.len();
            g_rigid = vec![0.0; 3 * m];
            let chunks = g.chunks_exact_mut(per).zip(self.local.chunks_exact(per));
            for (i, ((gm, local), r)) in chunks.zip(rigid).enumerate() {
                // x' = c·x + s·z + tx, z' = −s·x + c·z + tz.
                let (c, s) = r.cos_sin();
                let (mut gyaw, mut gx, mut gz) = (0.0f64, 0.0f64, 0.0f64);
                for (gp, p) in gm.chunks_exact(3).zip(local.chunks_exact(3)) {
                    let (x, z) = (p[0], p[2]);
                    gyaw += (gp[0] * (-s * x + c * z) + gp[2] * (-c * x - s * z)) as f64;
                    gx += gp[0] as f64;
                    gz += gp[2] as f64;
                }
                (g_rigid[i], g_rigid[m + i], g_rigid[2 * m + i]) =
                    (gyaw as f32, gx as f32, gz as f32);
                rotate_back(gm, *r);
            }
        }
        self.fk.backward(&self.head, g, grad);
        if let Some(p) = &self.projection {
            let g_projected = grad.to_vec();
            p.backward(&g_projected, grad);
        }
        for row in grad.chunks_exact_mut(HEAD) {
            for (v, s) in row.iter_mut().zip(&self.std) {
                *v *= s;
            }
        }
        g_rigid
    }
}

/// Moves points `[.., 3]` by `r` in the XZ plane (as [`Placement::apply`]).
fn move_xz(points: &mut [f32], r: &Placement) {
    let (c, s) = r.cos_sin();
    for p in points.chunks_exact_mut(3) {
        let (x, z) = (p[0], p[2]);
        p[0] = c * x + s * z + r.x;
        p[2] = -s * x + c * z + r.z;
    }
}

/// Rotates gradients `[.., 3]` back through `q`'s yaw (Rᵀ; the translation has none).
fn rotate_back(g: &mut [f32], q: Placement) {
    let (c, s) = q.cos_sin();
    for p in g.chunks_exact_mut(3) {
        let (gx, gz) = (p[0], p[2]);
        p[0] = c * gx - s * gz;
        p[2] = s * gx + c * gz;
    }
}

/// What [`HostObjective::eval_terms`] fills in; reused across iterations.
#[derive(Clone, Debug, Default)]
pub struct TermGradients {
    /// The error per sample `[B]` (the sum of the error's terms; no foot penalty).
    pub total: Vec<f32>,
    /// Per term, its value per sample `[T][B]`; the foot penalty last when it is set.
    pub values: Vec<Vec<f32>>,
    /// Per term, its gradient with respect to the normalised heads `[T][B·P·N·67]`.
    pub grads: Vec<Vec<f32>>,
    /// Terms that are the error's (the rest is the foot penalty).
    pub statements: usize,
}

impl TermGradients {
    /// Shares the foot penalty out among the error's terms in proportion to their values,
    /// per sample, and drops it as a term of its own. Where the error is 0 it is dropped
    /// too: the penalty is there so the program's pull is met with the legs, and with
    /// nothing pulling it has nothing to shape. Stepping on it alone, hundreds of
    /// iterations with no denoiser between them, folded the legs: a person told only to
    /// wave, with one statement met from the start, sank to a 0.15 m pelvis with crossed
    /// knees (0.91 m unguided). Where the error is above 0 the sum of the terms and of
    /// their gradients is unchanged: each statement weighs against the held feet as the
    /// whole error did. As a term of its own, with its own step, the penalty held the feet
    /// so firmly that two people could not close the gap between their hands (handshake
    /// contact 0.52 m against 0.01 m without it).
    ///
    /// Samples marked in `alone` (where the error is 0 but the motion is outside the real
    /// envelope, [`HostObjective::outside`]) keep the penalty as a term of its own: it has
    /// a snap or a joint under the floor to remove there, not just feet to hold.
    pub fn share_penalty(&mut self, alone: &[bool]) {
        if self.values.len() <= self.statements {
            return;
        }
        let (mut penalty, mut g_pen) = (
            self.values.pop().unwrap_or_default(),
            self.grads.pop().unwrap_or_default(),
        );
        let samples = self.total.len();
        let per = g_pen.len() / samples.max(1);
        // Samples met whose penalty stays a term of its own.
        let own: Vec<bool> = (0..samples)
            .map(|b| self.total[b] <= 0.0 && alone.get(b) == Some(&true))
            .collect();
        for b in 0..samples {
            let total = self.total[b];
            if total <= 0.0 {
                continue;
            }
            for (v, g) in self.values.iter_mut().zip(self.grads.iter_mut()) {
                let w = v[b].max(0.0) / total;
                if w == 0.0 {
                    continue;
                }
                v[b] += w * penalty[b];
                for (g, p) in g[b * per..(b + 1) * per]
                    .iter_mut()
                    .zip(&g_pen[b * per..(b + 1) * per])
                {
                    *g += w * p;
                }
            }
        }
        if own.contains(&true) {
            for b in (0..samples).filter(|&b| !own[b]) {
                penalty[b] = 0.0;
                g_pen[b * per..(b + 1) * per].fill(0.0);
            }
            self.values.push(penalty);
            self.grads.push(g_pen);
        }
    }
}

/// Checks that an error tensor is `[batch]`.
pub(crate) fn check_shape(e: &Tensor<1>, batch: usize) -> Result<(), SolveError> {
    let d = e.dims();
    if d[0] != batch {
        return Err(SolveError::BadErrorShape {
            got: d.to_vec(),
            batch,
        });
    }
    Ok(())
}

/// Copies the head columns of `[M, N, 263]` rows into `[M, N, 67]`.
pub fn extract_head(full: &[f32], width: usize) -> Vec<f32> {
    full.chunks_exact(width)
        .flat_map(|row| row[..HEAD].iter().copied())
        .collect()
}

/// Writes `[M, N, 67]` heads back into `[M, N, 263]` rows.
pub fn insert_head(full: &mut [f32], width: usize, head: &[f32]) {
    for (row, h) in full.chunks_exact_mut(width).zip(head.chunks_exact(HEAD)) {
        row[..HEAD].copy_from_slice(h);
    }
}
