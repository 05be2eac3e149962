//! Synthetic motions for the render tests: a stick figure built from the rest skeleton's
//! bone offsets by forward kinematics, walking along +Z (or standing) with swinging legs
//! and arms, bobbing pelvis and bending knees. Frames in, `Motion` out.

use crate::motion::{Motion, Pose};
use crate::skeleton::{NUM_JOINTS, PARENTS, REST_PELVIS_HEIGHT, rest_offsets};
use glam::{Quat, Vec3};
use std::f32::consts::TAU;

/// A walk of `frames` frames at 20 fps along `dir` (horizontal, normalised here) at
/// `speed` m/s starting at `start`, one stride cycle per second.
pub(crate) fn walk(frames: usize, speed: f32, start: Vec3, dir: Vec3) -> Motion {
    let dir = Vec3::new(dir.x, 0.0, dir.z).normalize_or(Vec3::Z);
    let heading = Quat::from_rotation_y(dir.x.atan2(dir.z));
    let swing = if speed > 0.0 { 1.0 } else { 0.0 };
    Motion::new(
        (0..frames)
            .map(|i| {
                let t = i as f32 / crate::skeleton::FPS;
                let phase = TAU * t;
                let root = start
                    + dir * speed * t
                    + Vec3::Y * (REST_PELVIS_HEIGHT + 0.02 * (2.0 * phase).cos() * swing);
                pose(root, heading, phase, swing)
            })
            .collect(),
    )
}

/// One pose of the walk cycle at `phase`, `swing` scaling the limb motion.
fn pose(root: Vec3, heading: Quat, phase: f32, swing: f32) -> Pose {
    let mut offsets = rest_offsets();
    // Real HumanML3D heads sit above the neck; the raw rest table points the head forward.
    offsets[15] = Vec3::new(0.0, 0.1, 0.03);
    let s = phase.sin() * swing;
    let mut local = [Quat::IDENTITY; NUM_JOINTS];
    local[0] = heading;
    // Negative X rotation swings a hanging limb forward (+Z).
    local[1] = Quat::from_rotation_x(-0.45 * s); // left thigh
    local[2] = Quat::from_rotation_x(0.45 * s); // right thigh
    local[4] = Quat::from_rotation_x(0.7 * swing * (-phase.cos()).max(0.0)); // left knee
    local[5] = Quat::from_rotation_x(0.7 * swing * phase.cos().max(0.0)); // right knee
    local[16] = Quat::from_rotation_x(0.35 * s); // left upper arm, opposite the left leg
    local[17] = Quat::from_rotation_x(-0.35 * s);
    local[18] = Quat::from_rotation_x(-0.3); // elbows slightly bent
    local[19] = Quat::from_rotation_x(-0.3);
    let mut global = [Quat::IDENTITY; NUM_JOINTS];
    let mut out = [Vec3::ZERO; NUM_JOINTS];
    global[0] = local[0];
    out[0] = root;
    for j in 1..NUM_JOINTS {
        let p = PARENTS[j];
        out[j] = out[p] + global[p] * offsets[j];
        global[j] = global[p] * local[j];
    }
    out
}

/// The standard test walk: 2 s along +Z from the origin at 1.2 m/s.
pub(crate) fn test_walk() -> Motion {
    walk(40, 1.2, Vec3::ZERO, Vec3::Z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::BONE_LENGTHS;

    #[test]
    fn walk_keeps_bone_lengths_and_moves_forward_upright() {
        let m = test_walk();
        assert_eq!(m.len(), 40);
        for pose in &m.frames {
            for j in 1..NUM_JOINTS {
                if j != 15 {
                    let len = (pose[j] - pose[PARENTS[j]]).length();
                    assert!((len - BONE_LENGTHS[j]).abs() < 1e-4, "joint {j}: {len}");
                }
            }
            assert!(pose[15].y > pose[0].y && pose[0].y > pose[7].y);
            assert!(
                pose[1].x > pose[2].x,
                "left hip must be at +X when facing +Z"
            );
        }
        assert!(m.frames[39][0].z - m.frames[0][0].z > 2.0);
        // The legs swing: the left ankle is ahead of the right at a quarter cycle.
        assert!(m.frames[5][7].z > m.frames[5][8].z);
        assert!(m.frames[15][7].z < m.frames[15][8].z);
    }
}
