//! A leading T-pose frame: cgspeed's CMU conversions (and many MotionBuilder exports)
//! put the rig's rest pose before the motion. Left in, it becomes a one-frame jump into a
//! pose nobody takes, which the model would learn as a start.
//!
//! In: the parsed file and its joint map. Out: how many leading frames to drop (0 or 1).
//! Frame 1 is dropped when it is a T-pose (straight legs, both arms straight and
//! horizontal, pointing away from the body) and frame 2 is not: a clip whose arms are
//! held out for real (an "airplane") keeps its first frame.

use super::fk::{SamplePoint, global_positions_at};
use super::parse::Bvh;
use super::retarget::JointMap;
use super::units::UpAxis;
use crate::motion::Pose;

/// Largest |sin| of an arm bone's angle to the horizontal in a T-pose (about 20°).
const ARM_LEVEL: f32 = 0.35;
/// Smallest cosine between consecutive bones of a straight limb (about 25°).
const STRAIGHT: f32 = 0.9;

/// Leading frames to drop: 1 if the first frame is a T-pose and the second is not.
pub fn leading_tpose_frames(bvh: &Bvh, map: &JointMap, up: UpAxis) -> usize {
    if bvh.frame_count < 3 {
        return 0;
    }
    let at = |i| SamplePoint {
        i0: i,
        i1: i,
        t: 0.0,
    };
    let globals = global_positions_at(bvh, &[at(0), at(1)]);
    let mut poses = globals
        .chunks_exact(bvh.joints.len())
        .map(|g| map.pose(g).map(|p| up.to_y_up(p)));
    match (poses.next(), poses.next()) {
        (Some(first), Some(second)) if is_tpose(&first) && !is_tpose(&second) => 1,
        _ => 0,
    }
}

/// Straight legs, and both arms straight, level and pointing away from the body.
pub fn is_tpose(p: &Pose) -> bool {
    let dir = |a: usize, b: usize| (p[b] - p[a]).normalize_or_zero();
    let straight = |a: usize, b: usize, c: usize| dir(a, b).dot(dir(b, c)) > STRAIGHT;
    let level = |a: usize, b: usize| dir(a, b).y.abs() < ARM_LEVEL;
    let across = (p[16] - p[17]).normalize_or_zero();
    let arm = |shoulder: usize, elbow: usize, wrist: usize, outward: f32| {
        straight(shoulder, elbow, wrist)
            && level(shoulder, elbow)
            && level(elbow, wrist)
            && dir(shoulder, wrist).dot(across) * outward > 0.8
    };
    straight(1, 4, 7) && straight(2, 5, 8) && arm(16, 18, 20, 1.0) && arm(17, 19, 21, -1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::rest_pose;
    use glam::Vec3;

    /// HumanML3D's rest pose with the arms hanging down.
    fn standing() -> Pose {
        let mut p = rest_pose();
        for (shoulder, elbow, wrist) in [(16, 18, 20), (17, 19, 21)] {
            p[elbow] = p[shoulder] - Vec3::Y * 0.26;
            p[wrist] = p[elbow] - Vec3::Y * 0.26;
        }
        p
    }

    fn t_pose() -> Pose {
        let mut p = rest_pose();
        for (shoulder, elbow, wrist, side) in [(16, 18, 20, 1.0), (17, 19, 21, -1.0)] {
            p[elbow] = p[shoulder] + Vec3::X * 0.26 * side;
            p[wrist] = p[elbow] + Vec3::X * 0.26 * side;
        }
        p
    }

    #[test]
    fn arms_out_is_a_tpose_and_arms_down_is_not() {
        assert!(is_tpose(&t_pose()));
        assert!(!is_tpose(&standing()));
        // Arms out but one elbow bent forward: not a T-pose.
        let mut bent = t_pose();
        bent[20] = bent[18] + Vec3::Z * 0.26;
        assert!(!is_tpose(&bent));
    }
}
