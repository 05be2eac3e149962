//! Skeleton projection for the late guidance steps: puts every bone back to the skeleton's
//! length and keeps a foot that is on the floor on the floor.
//!
//! The 263-dim features hold each joint's position independently (the ric block), so an
//! error gradient on those positions moves one joint alone: "head below 0.8 m" pulls the
//! head into the chest. Early in the chain the denoiser repairs such moves; in the last
//! T_s steps (500 iterations each, nothing after them) it cannot. There the guide
//! optimises `E(P(μ))` instead of `E(μ)`, where `P`:
//! 1. rebuilds the body from the pelvis outwards, each bone keeping its direction and
//!    taking its length from [`BONE_LENGTHS`](crate::skeleton::BONE_LENGTHS);
//! 2. on frames where a foot joint touched the floor (below [`CONTACT_HEIGHT`]) when the
//!    projection was set up, shifts the body vertically so that its lowest foot joint is
//!    at that height: the body stands on its lowest foot, whichever that is now.
//!
//! The gradient through `P` moves bone *directions*: to lower the head the spine bends or
//! both knees flex, because lowering the pelvis alone lowers the feet and step 2 takes
//! that back. Everything is in the person's own frame (pelvis at
//! `(0, h₃, 0)`, the ric block), where rotation and translation cannot change a length.

use super::host::HEAD;
use crate::features::layout::RIC;
use crate::skeleton::{BONE_LENGTHS, FOOT_LEFT, FOOT_RIGHT, NUM_JOINTS, PARENTS};

/// A foot joint lower than this (metres) is on the floor.
pub const CONTACT_HEIGHT: f32 = 0.05;

/// Column of the root height in a head row.
const ROOT_Y: usize = 3;

/// `P` and its backward on de-normalised heads `[M, N, 67]`.
#[derive(Clone, Debug)]
pub struct SkeletonProjection {
    /// Per row (motion, frame): the height of the lowest foot joint, if it was planted.
    anchors: Vec<Option<f32>>,
    /// Per row: the lowest foot joint of the last forward (the one the shift used).
    lowest: Vec<usize>,
    /// Bone vectors of the last forward, `[rows, 22, 3]` (index = child joint).
    bones: Vec<f32>,
}

/// Position of joint `j` in a head row (the pelvis is `(0, h₃, 0)`).
fn joint(row: &[f32], j: usize) -> [f32; 3] {
    if j == 0 {
        [0.0, row[ROOT_Y], 0.0]
    } else {
        let b = RIC.start + 3 * (j - 1);
        [row[b], row[b + 1], row[b + 2]]
    }
}

impl SkeletonProjection {
    /// Set up on de-normalised heads: records, per frame, the height of the lowest foot
    /// joint if it is on the floor.
    pub fn new(head: &[f32]) -> Self {
        let anchors: Vec<Option<f32>> = head
            .chunks_exact(HEAD)
            .map(|row| {
                let (_, y) = lowest_foot(|j| joint(row, j)[1]);
                (y < CONTACT_HEIGHT).then_some(y)
            })
            .collect();
        SkeletonProjection {
            lowest: vec![0; anchors.len()],
            anchors,
            bones: Vec::new(),
        }
    }

    /// Frames (rows) with a planted foot.
    pub fn anchored(&self) -> usize {
        self.anchors.iter().filter(|a| a.is_some()).count()
    }

    /// `out ← P(head)`; both `[rows, 67]`, rows as at [`new`](Self::new).
    pub fn forward(&mut self, head: &[f32], out: &mut [f32]) {
        assert_eq!(head.len(), self.anchors.len() * HEAD, "head rows");
        assert_eq!(out.len(), head.len(), "output length");
        self.bones.resize(self.anchors.len() * NUM_JOINTS * 3, 0.0);
        let rows = head.chunks_exact(HEAD).zip(out.chunks_exact_mut(HEAD));
        for (r, (h, o)) in rows.enumerate() {
            let u = &mut self.bones[r * NUM_JOINTS * 3..(r + 1) * NUM_JOINTS * 3];
            let mut q = [[0.0f32; 3]; NUM_JOINTS];
            q[0] = joint(h, 0);
            for j in 1..NUM_JOINTS {
                let (p, pp) = (joint(h, j), joint(h, PARENTS[j]));
                let b = [p[0] - pp[0], p[1] - pp[1], p[2] - pp[2]];
                u[3 * j..3 * j + 3].copy_from_slice(&b);
                let s = BONE_LENGTHS[j] / norm(b);
                q[j] = std::array::from_fn(|a| q[PARENTS[j]][a] + s * b[a]);
            }
            if let Some(y) = self.anchors[r] {
                let (k, lowest) = lowest_foot(|j| q[j][1]);
                self.lowest[r] = k;
                q.iter_mut().for_each(|p| p[1] += y - lowest);
            }
            o[..ROOT_Y].copy_from_slice(&h[..ROOT_Y]);
            o[ROOT_Y] = q[0][1];
            for (j, qj) in q.iter().enumerate().skip(1) {
                let b = RIC.start + 3 * (j - 1);
                o[b..b + 3].copy_from_slice(qj);
            }
        }
    }

    /// `g_head ← (∂P/∂head)ᵀ g_out` at the last [`forward`](Self::forward).
    pub fn backward(&self, g_out: &[f32], g_head: &mut [f32]) {
        assert_eq!(g_out.len(), self.anchors.len() * HEAD, "gradient rows");
        assert_eq!(g_head.len(), g_out.len(), "gradient length");
        let rows = g_out.chunks_exact(HEAD).zip(g_head.chunks_exact_mut(HEAD));
        for (r, (go, gh)) in rows.enumerate() {
            let u = &self.bones[r * NUM_JOINTS * 3..(r + 1) * NUM_JOINTS * 3];
            // Gradient with respect to q (the projected joints), then the vertical shift.
            let mut gq: [[f32; 3]; NUM_JOINTS] = std::array::from_fn(|j| joint(go, j));
            gq[0] = [0.0, go[ROOT_Y], 0.0];
            if self.anchors[r].is_some() {
                let total: f32 = gq.iter().map(|g| g[1]).sum();
                gq[self.lowest[r]][1] -= total;
            }
            // Children before parents: q_j = q_parent + L·b/|b|, b = p_j − p_parent.
            let mut gp = [[0.0f32; 3]; NUM_JOINTS];
            for j in (1..NUM_JOINTS).rev() {
                let par = PARENTS[j];
                let g = gq[j];
                for a in 0..3 {
                    gq[par][a] += g[a];
                }
                let b = [u[3 * j], u[3 * j + 1], u[3 * j + 2]];
                let n = norm(b);
                let dot = (b[0] * g[0] + b[1] * g[1] + b[2] * g[2]) / (n * n);
                let s = BONE_LENGTHS[j] / n;
                for a in 0..3 {
                    let gb = s * (g[a] - b[a] * dot);
                    gp[j][a] += gb;
                    gp[par][a] -= gb;
                }
            }
            gh[..ROOT_Y].copy_from_slice(&go[..ROOT_Y]);
            // Only the pelvis height is a feature; its x and z are the root's (fixed at 0).
            gh[ROOT_Y] = gp[0][1] + gq[0][1];
            for (j, g) in gp.iter().enumerate().skip(1) {
                let b = RIC.start + 3 * (j - 1);
                gh[b..b + 3].copy_from_slice(g);
            }
        }
    }
}

/// The lowest foot joint (ankles and toes) and its height, given each joint's height.
fn lowest_foot(height: impl Fn(usize) -> f32) -> (usize, f32) {
    [FOOT_LEFT, FOOT_RIGHT]
        .concat()
        .into_iter()
        .map(|j| (j, height(j)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("four foot joints")
}

/// Length of a bone vector, kept away from 0 (a collapsed bone keeps its zero direction).
fn norm(b: [f32; 3]) -> f32 {
    (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt().max(1e-6)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::rest_pose;

    /// A head row of a pose (yaw and root velocity columns set to something non-zero).
    fn row_of(pose: &[[f32; 3]; NUM_JOINTS]) -> Vec<f32> {
        let mut row = vec![0.1, 0.02, 0.03, pose[0][1]];
        for p in &pose[1..] {
            row.extend_from_slice(p);
        }
        assert_eq!(row.len(), HEAD);
        row
    }

    fn rest() -> [[f32; 3]; NUM_JOINTS] {
        rest_pose().map(|p| p.to_array())
    }

    fn bone_length(row: &[f32], j: usize) -> f32 {
        let (p, q) = (joint(row, j), joint(row, PARENTS[j]));
        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
    }

    #[test]
    fn the_rest_pose_is_a_fixed_point() {
        let row = row_of(&rest());
        let mut p = SkeletonProjection::new(&row);
        let mut out = vec![0.0; HEAD];
        p.forward(&row, &mut out);
        for (a, b) in row.iter().zip(&out) {
            assert!((a - b).abs() < 1e-5, "{a} vs {b}");
        }
    }

    #[test]
    fn a_head_pulled_into_the_chest_gets_its_neck_back_and_a_planted_foot_stays() {
        let mut pose = rest();
        pose[15][1] -= 0.3; // head below the neck's length
        pose[0][1] -= 0.2; // pelvis sunk: the legs would push the feet through the floor
        let row = row_of(&pose);
        let mut p = SkeletonProjection::new(&row_of(&rest()));
        assert_eq!(p.anchored(), 1, "the rest pose stands on the floor");
        let mut out = vec![0.0; HEAD];
        p.forward(&row, &mut out);
        for (j, length) in BONE_LENGTHS.iter().enumerate().skip(1) {
            assert!((bone_length(&out, j) - length).abs() < 1e-5, "bone {j}");
        }
        let foot_y = |r: &[f32]| [7, 8, 10, 11].map(|j| joint(r, j)[1]);
        let lowest = foot_y(&out).into_iter().fold(f32::INFINITY, f32::min);
        let rest_lowest = foot_y(&row_of(&rest()))
            .into_iter()
            .fold(f32::INFINITY, f32::min);
        assert!(
            (lowest - rest_lowest).abs() < 1e-5,
            "{lowest} vs {rest_lowest}"
        );
    }

    #[test]
    fn backward_matches_finite_differences() {
        let mut pose = rest();
        // A bent, uneven pose so no bone is axis-aligned and lengths are off.
        for (j, p) in pose.iter_mut().enumerate() {
            let f = j as f32;
            p[0] += 0.03 * (1.7 * f).sin();
            p[1] += 0.04 * (0.9 * f).cos();
            p[2] += 0.05 * (1.3 * f).sin();
        }
        let row = row_of(&pose);
        for anchored in [false, true] {
            let setup = if anchored {
                row_of(&rest())
            } else {
                let mut air = rest();
                air.iter_mut().for_each(|p| p[1] += 0.5);
                row_of(&air)
            };
            let mut p = SkeletonProjection::new(&setup);
            assert_eq!(p.anchored(), anchored as usize);
            // Loss = Σ w·P(h) with fixed pseudo-random weights.
            let w: Vec<f32> = (0..HEAD).map(|i| (0.37 * i as f32).sin()).collect();
            let mut out = vec![0.0; HEAD];
            let mut loss = |h: &[f32], p: &mut SkeletonProjection| -> f64 {
                p.forward(h, &mut out);
                out.iter().zip(&w).map(|(o, w)| (o * w) as f64).sum()
            };
            loss(&row, &mut p);
            let mut g = vec![0.0; HEAD];
            p.backward(&w, &mut g);
            let eps = 1e-3;
            for i in 0..HEAD {
                let (mut a, mut b) = (row.clone(), row.clone());
                a[i] += eps;
                b[i] -= eps;
                let fd = (loss(&a, &mut p) - loss(&b, &mut p)) / (2.0 * eps as f64);
                assert!(
                    (fd - g[i] as f64).abs() < 2e-2 * (1.0 + fd.abs()),
                    "column {i} (anchored {anchored}): analytic {} vs numeric {fd}",
                    g[i]
                );
            }
        }
    }
}
