//! Canonical placement of a clip (HumanML3D `process_file`, steps "put on floor", "XZ at
//! origin", "all initially face Z+"): in, global joint positions; out, the same motion
//! moved and turned so that
//! * the lowest joint over all frames touches the floor (min y = 0),
//! * the root of frame 0 is above the origin (x = z = 0),
//! * frame 0 faces +Z, the facing being forward = normalise(up × across) with
//!   across = (r_hip − l_hip) + (r_sh − l_sh) (the correct rule, not the per-frame quirk).

use super::FeatureError;
use super::kinematics::{self, Pose64, motion_from_f64, poses_f64};
use crate::motion::Motion;
use glam::DVec3;

/// Puts a clip on the floor, its frame-0 root above the origin, facing +Z at frame 0.
///
/// An empty motion comes back empty. Errors: non-finite coordinates, or a frame 0 whose
/// hips and shoulders give no horizontal facing direction.
pub fn canonicalize(m: &Motion) -> Result<Motion, FeatureError> {
    let poses = canonicalize_f64(poses_f64(m)?)?;
    Ok(motion_from_f64(&poses, m.fps))
}

/// [`canonicalize`] on f64 poses.
pub(crate) fn canonicalize_f64(mut poses: Vec<Pose64>) -> Result<Vec<Pose64>, FeatureError> {
    let Some(first) = poses.first() else {
        return Ok(poses);
    };
    let floor = poses
        .iter()
        .flatten()
        .map(|p| p.y)
        .fold(f64::INFINITY, f64::min);
    let shift = DVec3::new(first[0].x, floor, first[0].z);
    let turn = kinematics::body_facing(first, 0)?.inverse();
    for pose in &mut poses {
        for p in pose.iter_mut() {
            *p = turn * (*p - shift);
        }
    }
    Ok(poses)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::{NUM_JOINTS, rest_pose};
    use glam::{Quat, Vec3};

    #[test]
    fn moves_a_turned_lifted_clip_back_to_the_canonical_place() {
        let rest = rest_pose();
        let turn = Quat::from_rotation_y(2.0);
        let offset = Vec3::new(3.0, 0.5, -2.0);
        let moved: Vec<_> = (0..3)
            .map(|t| rest.map(|p| turn * (p + Vec3::new(0.0, 0.0, 0.1 * t as f32)) + offset))
            .collect();
        let c = canonicalize(&Motion::new(moved)).unwrap();
        let rest_floor = rest.iter().map(|p| p.y).fold(f32::INFINITY, f32::min);
        for t in 0..3 {
            for (j, r) in rest.iter().enumerate() {
                let want = *r + Vec3::new(0.0, -rest_floor, 0.1 * t as f32);
                assert!(
                    (c.frames[t][j] - want).length() < 1e-5,
                    "frame {t} joint {j}"
                );
            }
        }
        let (lo, _) = c.bounds();
        assert!(lo.y.abs() < 1e-6);
    }

    #[test]
    fn bad_input_is_an_error() {
        let mut p = rest_pose();
        p[3].x = f32::NAN;
        assert!(matches!(
            canonicalize(&Motion::new(vec![p])),
            Err(FeatureError::NonFinite {
                frame: 0,
                joint: 3,
                ..
            })
        ));
        let flat = [Vec3::ONE; NUM_JOINTS];
        assert!(matches!(
            canonicalize(&Motion::new(vec![flat])),
            Err(FeatureError::DegenerateFacing { frame: 0 })
        ));
        assert!(canonicalize(&Motion::new(vec![])).unwrap().is_empty());
    }
}
