//! The left/right mirror in feature space: the 263-dim features of a motion mirrored in
//! joint space (x negated, left and right joints swapped) are a signed permutation of the
//! motion's own features, so a model can be asked about the mirrored motion without
//! recovering joints.

use super::layout::{CONTACT, FEATURE_DIM, LOCAL_VEL, RIC, ROOT_VEL, ROOT_Y, ROOT_YAW_VEL, ROT};
use crate::skeleton::mirror_joint;

/// Signs of a 6-D rotation (first then second column of R) under R ↦ S R S with
/// S = diag(−1, 1, 1): entry (a, b) changes by s_a · s_b.
const ROT6_SIGNS: [f32; 6] = [1.0, -1.0, -1.0, -1.0, 1.0, 1.0];

/// For each output feature i: mirrored\[i\] = sign\[i\] · features\[source\[i\]\].
#[derive(Clone, Debug, PartialEq)]
pub struct FeatureMirror {
    /// Index of the feature each output feature is read from.
    pub source: Vec<usize>,
    /// Its sign (±1).
    pub sign: Vec<f32>,
}

impl FeatureMirror {
    /// The mirror of HumanML3D's 263-dim layout.
    pub fn humanml3d() -> Self {
        let mut source = vec![0; FEATURE_DIM];
        let mut sign = vec![1.0; FEATURE_DIM];
        // Yaw velocity turns the other way; the facing frame's x (lateral) flips.
        sign[ROOT_YAW_VEL.start] = -1.0;
        source[ROOT_VEL.start] = ROOT_VEL.start;
        sign[ROOT_VEL.start] = -1.0;
        source[ROOT_VEL.start + 1] = ROOT_VEL.start + 1;
        source[ROOT_Y.start] = ROOT_Y.start;
        // Per-joint xyz blocks: joints swap sides, x flips.
        let xyz = |source: &mut [usize], sign: &mut [f32], start: usize, first_joint: usize| {
            let joints = 22 - first_joint;
            for k in 0..joints {
                let from = mirror_joint(k + first_joint) - first_joint;
                for c in 0..3 {
                    source[start + 3 * k + c] = start + 3 * from + c;
                    sign[start + 3 * k + c] = if c == 0 { -1.0 } else { 1.0 };
                }
            }
        };
        xyz(&mut source, &mut sign, RIC.start, 1);
        xyz(&mut source, &mut sign, LOCAL_VEL.start, 0);
        for k in 0..21 {
            let from = mirror_joint(k + 1) - 1;
            for c in 0..6 {
                source[ROT.start + 6 * k + c] = ROT.start + 6 * from + c;
                sign[ROT.start + 6 * k + c] = ROT6_SIGNS[c];
            }
        }
        // Contacts: left ankle, left foot, right ankle, right foot.
        for (k, from) in [2, 3, 0, 1].into_iter().enumerate() {
            source[CONTACT.start + k] = CONTACT.start + from;
        }
        FeatureMirror { source, sign }
    }

    /// Mirrors flat `[frames, 263]` rows.
    pub fn apply(&self, rows: &[f32]) -> Vec<f32> {
        rows.chunks_exact(FEATURE_DIM)
            .flat_map(|row| {
                self.source
                    .iter()
                    .zip(&self.sign)
                    .map(move |(&j, &s)| s * row[j])
            })
            .collect()
    }

    /// The same map on normalised features `(x − mean) / std`: an affine map
    /// x ↦ scale ⊙ x\[source\] + shift, exact whatever the statistics.
    pub fn normalized(&self, mean: &[f32], std: &[f32]) -> (Vec<f32>, Vec<f32>) {
        (0..FEATURE_DIM)
            .map(|i| {
                let (j, s) = (self.source[i], self.sign[i]);
                (s * std[j] / std[i], (s * mean[j] - mean[i]) / std[i])
            })
            .unzip()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mirroring_twice_is_the_identity() {
        let m = FeatureMirror::humanml3d();
        let rows: Vec<f32> = (0..2 * FEATURE_DIM)
            .map(|i| i as f32 * 0.37 - 9.0)
            .collect();
        assert_eq!(m.apply(&m.apply(&rows)), rows);
    }

    #[test]
    fn source_is_a_permutation() {
        let mut seen = FeatureMirror::humanml3d().source;
        seen.sort_unstable();
        assert_eq!(seen, (0..FEATURE_DIM).collect::<Vec<_>>());
    }

    #[test]
    fn normalized_map_agrees_with_the_raw_one() {
        let m = FeatureMirror::humanml3d();
        let mean: Vec<f32> = (0..FEATURE_DIM).map(|i| (i % 7) as f32 * 0.1).collect();
        let std: Vec<f32> = (0..FEATURE_DIM)
            .map(|i| 0.5 + (i % 5) as f32 * 0.2)
            .collect();
        let raw: Vec<f32> = (0..FEATURE_DIM).map(|i| (i as f32).sin()).collect();
        let norm: Vec<f32> = (0..FEATURE_DIM)
            .map(|i| (raw[i] - mean[i]) / std[i])
            .collect();
        let (scale, shift) = m.normalized(&mean, &std);
        let mirrored_raw = m.apply(&raw);
        for i in 0..FEATURE_DIM {
            let via_norm = scale[i] * norm[m.source[i]] + shift[i];
            let expected = (mirrored_raw[i] - mean[i]) / std[i];
            assert!((via_norm - expected).abs() < 1e-5, "feature {i}");
        }
    }
}
