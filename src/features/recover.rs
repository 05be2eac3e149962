//! `recover_from_ric` on plain floats: in, **de-normalised** features `[frames, 263]`; out,
//! the 22 global joint positions of every frame (reference-algorithms §5.6).
//!
//! 1. a[0] = 0, a[t] = Σ_{k<t} yaw_vel[k] (the root facing, as a half-angle).
//! 2. Un-rotating by the root quaternion (cos a, 0, sin a, 0) is the yaw R_y(−2a):
//!    (x, z) ↦ (x cos 2a − z sin 2a, x sin 2a + z cos 2a).
//! 3. Root XZ = Σ_{1≤k≤t} R_y(−2a[k]) · root_vel[k−1]; root y = the height column.
//! 4. Joints 1..21 = R_y(−2a[t]) · ric[t] + (root x, 0, root z).
//!
//! Only the root and ric blocks are read; the rotation, velocity and contact blocks are not.

use super::FeatureError;
use super::layout::{FEATURE_DIM, RIC, ROOT_VEL, ROOT_Y, ROOT_YAW_VEL};
use crate::motion::{Motion, Pose};
use crate::skeleton::NUM_JOINTS;
use glam::Vec3;

/// Joint positions from de-normalised features (flat `[frames, 263]`).
pub fn recover_from_ric(features: &[f32]) -> Result<Motion, FeatureError> {
    if !features.len().is_multiple_of(FEATURE_DIM) {
        return Err(FeatureError::BadFeatureLength {
            len: features.len(),
            dim: FEATURE_DIM,
        });
    }
    let mut half_angle = 0.0f64;
    let (mut root_x, mut root_z) = (0.0f64, 0.0f64);
    let mut frames = Vec::with_capacity(features.len() / FEATURE_DIM);
    for (t, row) in features.chunks_exact(FEATURE_DIM).enumerate() {
        if t > 0 {
            let prev = &features[(t - 1) * FEATURE_DIM..t * FEATURE_DIM];
            half_angle += prev[ROOT_YAW_VEL.start] as f64;
            let (s, c) = (2.0 * half_angle).sin_cos();
            let (vx, vz) = (prev[ROOT_VEL.start] as f64, prev[ROOT_VEL.start + 1] as f64);
            root_x += vx * c - vz * s;
            root_z += vx * s + vz * c;
        }
        let (s, c) = (2.0 * half_angle).sin_cos();
        let mut pose: Pose = [Vec3::ZERO; NUM_JOINTS];
        pose[0] = Vec3::new(root_x as f32, row[ROOT_Y.start], root_z as f32);
        for (j, ric) in row[RIC].chunks_exact(3).enumerate() {
            let (x, z) = (ric[0] as f64, ric[2] as f64);
            pose[j + 1] = Vec3::new(
                (x * c - z * s + root_x) as f32,
                ric[1],
                (x * s + z * c + root_z) as f32,
            );
        }
        frames.push(pose);
    }
    Ok(Motion::new(frames))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrates_a_turning_walk() {
        // Constant forward speed 0.05 m/frame along the facing, turning π/40 per frame.
        let frames = 21;
        let mut feat = vec![0.0f32; frames * FEATURE_DIM];
        for row in feat.chunks_exact_mut(FEATURE_DIM) {
            row[0] = std::f32::consts::PI / 80.0; // half-angle
            row[2] = 0.05;
            row[3] = 0.9;
            row[RIC.start] = 0.1; // left hip at +x of the root
        }
        let m = recover_from_ric(&feat).unwrap();
        assert_eq!(m.len(), frames);
        assert_eq!(m.frames[0][0], Vec3::new(0.0, 0.9, 0.0));
        // After 20 frames the body has turned by π/2, having taken 20 equal steps at
        // headings kΔ (k = 1..20, Δ = π/40): |Σ e^{ikΔ}| = sin(10Δ)/sin(Δ/2).
        let step = std::f64::consts::PI / 40.0;
        let want = 0.05 * (10.0 * step).sin() / (step / 2.0).sin();
        let end = m.frames[20][0];
        let ground = glam::Vec2::new(end.x, end.z).length() as f64;
        assert!((ground - want).abs() < 1e-5, "{end} vs {want}");
        assert!(end.x < 0.0 && end.z > 0.0, "turns right, towards -x: {end}");
        // The left hip points along the rotated +x.
        let hip = m.frames[20][1] - m.frames[20][0];
        assert!((hip - Vec3::new(0.0, -0.9, 0.1)).length() < 1e-5, "{hip}");
    }

    #[test]
    fn ragged_input_is_an_error() {
        assert!(matches!(
            recover_from_ric(&[0.0; 300]),
            Err(FeatureError::BadFeatureLength { len: 300, dim: 263 })
        ));
    }
}
