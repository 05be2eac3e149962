//! PMG's output regulariser (`reg(idx)` in its task configs, reference-algorithms §1.5):
//! λ · mean over frames and chosen feature columns of (x̂ − x̂_ref)², in normalised feature
//! space, where x̂_ref is the chain's output at iteration 0 (the unguided DDIM sample).
//! While z moves to meet a program, it keeps what the program does not ask about (the
//! path, the legs' stepping) as the model first made it. PMG pulls the root columns for
//! HSI-4 and HOI-2 and the pelvis and legs for PBG-1; here the two groups have a weight each.

use crate::features::FEATURE_DIM;
use crate::features::layout::{CONTACT, LOCAL_VEL, RIC, ROOT_Y, ROOT_YAW_VEL, ROT};

/// Hips, knees, ankles and toes (HumanML3D indices).
pub const LEG_JOINTS: [usize; 8] = [1, 2, 4, 5, 7, 8, 10, 11];

/// The root columns: yaw velocity, XZ velocity, height.
pub fn root_columns() -> Vec<usize> {
    (ROOT_YAW_VEL.start..ROOT_Y.end).collect()
}

/// Every column that describes the legs: their root-relative positions, 6-D rotations and
/// local velocities, and the four foot contacts.
pub fn leg_columns() -> Vec<usize> {
    let mut cols = Vec::new();
    for &j in &LEG_JOINTS {
        cols.extend(RIC.start + 3 * (j - 1)..RIC.start + 3 * j);
        cols.extend(ROT.start + 6 * (j - 1)..ROT.start + 6 * j);
        cols.extend(LOCAL_VEL.start + 3 * j..LOCAL_VEL.start + 3 * (j + 1));
    }
    cols.extend(CONTACT);
    cols
}

/// The pull, as a weight per feature column.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferencePull {
    /// `[263]`: λ of the column's group divided by the group's width.
    column_weights: Vec<f32>,
}

impl ReferencePull {
    /// The pull with weight `root` on the root columns and `legs` on the leg columns
    /// (each group's term is a mean over its columns); `None` when both are zero.
    pub fn new(root: f32, legs: f32) -> Option<Self> {
        if root == 0.0 && legs == 0.0 {
            return None;
        }
        let mut column_weights = vec![0.0f32; FEATURE_DIM];
        for (lambda, cols) in [(root, root_columns()), (legs, leg_columns())] {
            let w = lambda / cols.len() as f32;
            for c in cols {
                column_weights[c] += w;
            }
        }
        Some(ReferencePull { column_weights })
    }

    /// Adds the pull's gradient with respect to `x` to `grad` and returns its value per
    /// motion. `x`, `reference` and `grad` are `[motions, frames, 263]`.
    pub fn add(&self, x: &[f32], reference: &[f32], frames: usize, grad: &mut [f32]) -> Vec<f32> {
        let per = frames * FEATURE_DIM;
        let inv_frames = 1.0 / frames.max(1) as f32;
        x.chunks_exact(per)
            .zip(reference.chunks_exact(per))
            .zip(grad.chunks_exact_mut(per))
            .map(|((xm, rm), gm)| {
                let mut value = 0.0f64;
                for ((xr, rr), gr) in xm
                    .chunks_exact(FEATURE_DIM)
                    .zip(rm.chunks_exact(FEATURE_DIM))
                    .zip(gm.chunks_exact_mut(FEATURE_DIM))
                {
                    for (c, &w) in self.column_weights.iter().enumerate() {
                        if w != 0.0 {
                            let d = xr[c] - rr[c];
                            value += f64::from(w * d * d);
                            gr[c] += 2.0 * w * d * inv_frames;
                        }
                    }
                }
                (value * f64::from(inv_frames)) as f32
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_cover_the_right_columns() {
        assert_eq!(root_columns(), vec![0, 1, 2, 3]);
        let legs = leg_columns();
        assert_eq!(legs.len(), 8 * (3 + 6 + 3) + 4);
        // Left hip's ric block, the right toe's velocity, no arm column.
        assert!(legs.contains(&4) && legs.contains(&(193 + 3 * 11 + 2)));
        assert!(!legs.contains(&(4 + 3 * 19)));
        assert!(ReferencePull::new(0.0, 0.0).is_none());
    }

    #[test]
    fn value_and_gradient_match_finite_differences() {
        let frames = 3;
        let n = 2 * frames * FEATURE_DIM;
        let x: Vec<f32> = (0..n)
            .map(|i| ((i * 37 % 101) as f32 / 50.0) - 1.0)
            .collect();
        let r: Vec<f32> = (0..n)
            .map(|i| ((i * 53 % 97) as f32 / 48.0) - 1.0)
            .collect();
        let pull = ReferencePull::new(0.3, 2.0).unwrap();
        let mut g = vec![0.0; n];
        let v = pull.add(&x, &r, frames, &mut g);
        assert_eq!(v.len(), 2);
        // The root term alone, by hand, for the first motion.
        let root: f32 = (0..frames)
            .flat_map(|t| (0..4).map(move |c| t * FEATURE_DIM + c))
            .map(|i| (x[i] - r[i]).powi(2))
            .sum::<f32>()
            * 0.3
            / 4.0
            / frames as f32;
        assert!(v[0] > root);
        let eps = 1e-3f32;
        for &i in &[0usize, 5, 4 + 3 * 10, 263 + 259, n - 1, 100] {
            let mut xp = x.clone();
            xp[i] += eps;
            let mut xm = x.clone();
            xm[i] -= eps;
            let total = |x: &[f32]| {
                pull.add(x, &r, frames, &mut vec![0.0; n])
                    .iter()
                    .sum::<f32>()
            };
            let fd = (total(&xp) - total(&xm)) / (2.0 * eps);
            assert!((fd - g[i]).abs() < 1e-3, "column {i}: fd {fd} vs {}", g[i]);
        }
        // Equal to the reference: no value, no gradient.
        let mut g0 = vec![0.0; n];
        assert_eq!(pull.add(&r, &r, frames, &mut g0), vec![0.0, 0.0]);
        assert!(g0.iter().all(|&v| v == 0.0));
    }
}
