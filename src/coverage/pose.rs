//! One frame's pose as the coverage set keeps it: the 22 joints with the pelvis over the
//! origin and the body facing +Z, heights unchanged (the floor stays at y = 0).

use crate::skeleton::{NUM_JOINTS, mirror_joint};

/// Joint positions of one frame (metres, Y up).
pub type Pose = [[f32; 3]; NUM_JOINTS];

/// The body's facing as a yaw about +Y (0 faces +Z): the hips' and shoulders' left-right
/// line turned a quarter to the front, as the rest of mprog measures it.
pub fn facing_yaw(p: &Pose) -> f32 {
    // left minus right: hips (1, 2) and shoulders (16, 17).
    let ax = (p[1][0] - p[2][0]) + (p[16][0] - p[17][0]);
    let az = (p[1][2] - p[2][2]) + (p[16][2] - p[17][2]);
    // forward = across × up = (−az, 0, ax).
    (-az).atan2(ax)
}

/// `p` moved so the pelvis stands over the origin and turned to face +Z.
pub fn canonical(p: &Pose) -> Pose {
    let yaw = facing_yaw(p);
    let (s, c) = yaw.sin_cos();
    let (x0, z0) = (p[0][0], p[0][2]);
    p.map(|[x, y, z]| {
        let (x, z) = (x - x0, z - z0);
        [x * c - z * s, y, x * s + z * c]
    })
}

/// The left/right mirror image of a canonical pose (still facing +Z).
pub fn mirrored(p: &Pose) -> Pose {
    std::array::from_fn(|j| {
        let [x, y, z] = p[mirror_joint(j)];
        [-x, y, z]
    })
}

/// The largest distance between corresponding joints of two poses (m).
pub fn joint_distance(a: &Pose, b: &Pose) -> f32 {
    let mut worst = 0.0f32;
    for (p, q) in a.iter().zip(b) {
        let d = (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2);
        worst = worst.max(d);
    }
    worst.sqrt()
}

/// The pose of frame `t` of a clip's flat joints (`frames × 22 × 3`).
pub fn frame_pose(joints: &[f32], t: usize) -> Pose {
    let at = t * NUM_JOINTS * 3;
    std::array::from_fn(|j| {
        let k = at + 3 * j;
        [joints[k], joints[k + 1], joints[k + 2]]
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rest() -> Pose {
        crate::skeleton::rest_pose().map(|v| [v.x, v.y, v.z])
    }

    #[test]
    fn a_turned_and_moved_pose_comes_back_to_the_rest_pose() {
        let r = rest();
        assert!(facing_yaw(&r).abs() < 1e-5);
        let (s, c) = 1.1f32.sin_cos();
        let moved = r.map(|[x, y, z]| [x * c + z * s + 2.0, y, -x * s + z * c - 0.5]);
        assert!((facing_yaw(&moved) - 1.1).abs() < 1e-4);
        assert!(joint_distance(&canonical(&moved), &r) < 1e-4);
    }

    #[test]
    fn mirroring_twice_is_the_identity_and_swaps_sides() {
        let mut p = rest();
        p[20][1] = 2.0; // the left wrist up
        let m = mirrored(&p);
        assert_eq!(m[21][1], 2.0);
        assert!(joint_distance(&mirrored(&m), &p) < 1e-6);
        assert!(facing_yaw(&m).abs() < 1e-5);
    }
}
