//! Inverse and forward kinematics on the HumanML3D hierarchy, as HumanML3D's
//! `Skeleton.inverse_kinematics_np` / `forward_kinematics_np` do it.
//!
//! In: global joint positions (one [`Pose64`] per frame). Out: rotations.
//! * [`bone_rotations`]: for every bone (index = child joint) the minimal rotation taking
//!   its rest direction ([`RAW_OFFSETS`]) to its current direction. This is the global
//!   rotation of the bone; everything else is built from it (the 6-D feature block here,
//!   the BVH exporter's joint rotations in `formats::bvh_export`).
//! * [`local_rotations`]: HumanML3D's local rotations: `q[0]` is the root rotation, and along
//!   each kinematic chain `q[child] = G_prev⁻¹ · G_child`, where `G_prev` is the previous
//!   bone's global rotation, or the root rotation at the start of a chain. Note that the
//!   two arm chains start at spine3 (9) but, as in HumanML3D, their first rotation is taken
//!   relative to the **root**, not to spine3.
//! * [`root_rotations`]: HumanML3D's per-frame root rotation, the rotation taking the facing
//!   direction to +Z, with the hip-sign quirk and optional smoothing (see the function).
//! * [`forward_kinematics`]: the inverse: positions from local rotations, a root track and
//!   bone offsets.
//!
//! Quaternions are Hamilton (glam), positions metres, Y up; computation is in f64.

use super::FeatureError;
use super::smooth::gaussian_nearest;
use crate::motion::Motion;
use crate::skeleton::{
    FACE_JOINTS, JOINT_NAMES, KINEMATIC_CHAINS, NUM_JOINTS, PARENTS, RAW_OFFSETS,
};
use glam::{DQuat, DVec3};

/// One pose in f64: 22 global joint positions.
pub type Pose64 = [DVec3; NUM_JOINTS];

/// Standard deviation (frames) of the smoothing of the facing direction in HumanML3D.
pub const FACING_SMOOTH_SIGMA: f64 = 20.0;

/// Lengths below this (metres) count as zero: no direction can be taken from them.
const MIN_LENGTH: f64 = 1e-9;

/// Converts a motion to f64 poses, rejecting non-finite coordinates.
pub fn poses_f64(m: &Motion) -> Result<Vec<Pose64>, FeatureError> {
    m.frames
        .iter()
        .enumerate()
        .map(|(frame, pose)| {
            let mut out = [DVec3::ZERO; NUM_JOINTS];
            for (joint, p) in pose.iter().enumerate() {
                if !p.is_finite() {
                    return Err(FeatureError::NonFinite {
                        frame,
                        joint,
                        name: JOINT_NAMES[joint],
                    });
                }
                out[joint] = p.as_dvec3();
            }
            Ok(out)
        })
        .collect()
}

/// Converts f64 poses back to a motion at `fps`.
pub fn motion_from_f64(poses: &[Pose64], fps: f32) -> Motion {
    let frames = poses.iter().map(|p| p.map(|v| v.as_vec3())).collect();
    Motion { frames, fps }
}

/// The minimal rotation taking direction `from` to direction `to` (HumanML3D's `qbetween`).
/// Opposite directions, where the minimal rotation is not unique, get a half turn about an
/// axis perpendicular to `from`. Zero vectors give the identity.
pub fn rotation_between(from: DVec3, to: DVec3) -> DQuat {
    let (Some(a), Some(b)) = (from.try_normalize(), to.try_normalize()) else {
        return DQuat::IDENTITY;
    };
    let w = 1.0 + a.dot(b);
    if w < 1e-12 {
        return DQuat::from_axis_angle(a.any_orthonormal_vector(), std::f64::consts::PI);
    }
    let c = a.cross(b);
    DQuat::from_xyzw(c.x, c.y, c.z, w).normalize()
}

/// The yaw (rotation about +Y) taking the horizontal direction `forward` to +Z. For a
/// horizontal vector this is HumanML3D's `qbetween(forward, +Z)`; written as a yaw it stays a
/// yaw even when `forward` is exactly −Z.
pub fn yaw_to_face_z(forward: DVec3) -> DQuat {
    DQuat::from_rotation_y(-forward.x.atan2(forward.z))
}

/// The body's facing in one pose by the canonical rule: across = (r_hip − l_hip) +
/// (r_sh − l_sh), forward = normalise(up × across). Returns the yaw taking +Z to forward.
///
/// `frame` is only used for the error message of a degenerate facing.
pub fn body_facing(pose: &Pose64, frame: usize) -> Result<DQuat, FeatureError> {
    let [r_hip, l_hip, r_sh, l_sh] = FACE_JOINTS;
    let across = (pose[r_hip] - pose[l_hip]) + (pose[r_sh] - pose[l_sh]);
    let forward = DVec3::Y.cross(across.try_normalize().unwrap_or(DVec3::ZERO));
    // Nearly vertical across vectors leave no reliable horizontal facing.
    if forward.length() < 1e-6 {
        return Err(FeatureError::DegenerateFacing { frame });
    }
    Ok(yaw_to_face_z(forward).inverse())
}

/// The bone from joint `j`'s parent to `j`, or an error naming it when it has no length.
fn bone_vector(pose: &Pose64, j: usize, frame: usize) -> Result<DVec3, FeatureError> {
    let bone = pose[j] - pose[PARENTS[j]];
    if bone.length() < MIN_LENGTH {
        return Err(FeatureError::ZeroBone {
            frame,
            joint: j,
            name: JOINT_NAMES[j],
        });
    }
    Ok(bone)
}

/// Global rotation of every bone of one pose (index = child joint; `[0]` is the identity):
/// the minimal rotation from the rest direction to the current direction.
///
/// `frame` is only used for the error message of a zero-length bone.
pub fn bone_rotations(pose: &Pose64, frame: usize) -> Result<[DQuat; NUM_JOINTS], FeatureError> {
    let mut g = [DQuat::IDENTITY; NUM_JOINTS];
    for j in 1..NUM_JOINTS {
        let bone = bone_vector(pose, j, frame)?;
        g[j] = rotation_between(DVec3::from(RAW_OFFSETS[j].map(f64::from)), bone);
    }
    Ok(g)
}

/// Global bone rotations with no twist relative to the parent bone (for export formats
/// with one rotation per joint, e.g. BVH): each bone's rotation is its parent bone's rotation
/// followed by the minimal swing taking the so-turned rest direction to the current one;
/// `root` (e.g. [`body_facing`]) orients the bones leaving the root. Every entry still takes
/// its bone's rest direction to its current direction, like [`bone_rotations`], but the
/// rotations follow the body (a turned rest pose gets the turn on every bone) instead of
/// being minimal arcs from the unturned rest pose. `[0]` is `root`.
pub fn chained_bone_rotations(
    pose: &Pose64,
    frame: usize,
    root: DQuat,
) -> Result<[DQuat; NUM_JOINTS], FeatureError> {
    let mut g = [DQuat::IDENTITY; NUM_JOINTS];
    g[0] = root;
    // Parents come before their children in HumanML3D's joint order.
    for j in 1..NUM_JOINTS {
        let bone = bone_vector(pose, j, frame)?;
        let base = g[PARENTS[j]];
        let rest = base * DVec3::from(RAW_OFFSETS[j].map(f64::from));
        g[j] = rotation_between(rest, bone) * base;
    }
    Ok(g)
}

/// HumanML3D's local rotations from a root rotation and the bones' global rotations.
pub fn local_rotations(root: DQuat, bones: &[DQuat; NUM_JOINTS]) -> [DQuat; NUM_JOINTS] {
    let mut q = [DQuat::IDENTITY; NUM_JOINTS];
    q[0] = root;
    for chain in KINEMATIC_CHAINS {
        // Every chain, the arm chains included, starts from the root rotation.
        let mut prev = root;
        for &child in &chain[1..] {
            q[child] = prev.inverse() * bones[child];
            prev = bones[child];
        }
    }
    q
}

/// HumanML3D's per-frame root rotation: the yaw taking the facing direction to +Z.
///
/// As in `inverse_kinematics_np`, the across vector is `(l_hip − r_hip) + (r_sh − l_sh)`
/// (the hip term has the opposite sign of the canonicalisation's rule: HumanML3D unpacks
/// its face-joint list in a different order there), normalised; forward = up × across. With
/// `smooth`, forward is Gaussian-smoothed over time (σ = 20 frames, 'nearest' edges) before
/// it is normalised. The rotation of frame 0 is forced to the identity.
pub fn root_rotations(poses: &[Pose64], smooth: bool) -> Result<Vec<DQuat>, FeatureError> {
    let [r_hip, l_hip, r_sh, l_sh] = FACE_JOINTS;
    let mut forward = Vec::with_capacity(poses.len());
    for (frame, p) in poses.iter().enumerate() {
        let across = (p[l_hip] - p[r_hip]) + (p[r_sh] - p[l_sh]);
        let across = across
            .try_normalize()
            .ok_or(FeatureError::DegenerateFacing { frame })?;
        forward.push(DVec3::Y.cross(across));
    }
    if smooth {
        forward = gaussian_nearest(&forward, FACING_SMOOTH_SIGMA);
    }
    forward
        .iter()
        .enumerate()
        .map(|(frame, f)| {
            if frame == 0 {
                return Ok(DQuat::IDENTITY);
            }
            if f.length() < 1e-9 {
                return Err(FeatureError::DegenerateFacing { frame });
            }
            Ok(yaw_to_face_z(*f))
        })
        .collect()
}

/// Local rotations of every frame ([`local_rotations`] of [`bone_rotations`]), given the
/// root rotation of each frame.
pub fn inverse_kinematics(
    poses: &[Pose64],
    roots: &[DQuat],
) -> Result<Vec<[DQuat; NUM_JOINTS]>, FeatureError> {
    poses
        .iter()
        .zip(roots)
        .enumerate()
        .map(|(frame, (p, &root))| Ok(local_rotations(root, &bone_rotations(p, frame)?)))
        .collect()
}

/// Positions from HumanML3D local rotations, a root position per frame and bone offsets
/// (index = child joint, in the rest frame; e.g. raw direction × bone length).
pub fn forward_kinematics(
    locals: &[[DQuat; NUM_JOINTS]],
    root_positions: &[DVec3],
    offsets: &[DVec3; NUM_JOINTS],
) -> Vec<Pose64> {
    locals
        .iter()
        .zip(root_positions)
        .map(|(q, &root)| {
            let mut p = [DVec3::ZERO; NUM_JOINTS];
            p[0] = root;
            for chain in KINEMATIC_CHAINS {
                let mut r = q[0];
                for w in chain.windows(2) {
                    r *= q[w[1]];
                    p[w[1]] = p[w[0]] + r * offsets[w[1]];
                }
            }
            p
        })
        .collect()
}

/// The continuous 6-D form of a rotation: its matrix's first column, then its second.
pub fn rotation_6d(q: DQuat) -> [f64; 6] {
    let m = glam::DMat3::from_quat(q);
    [
        m.x_axis.x, m.x_axis.y, m.x_axis.z, m.y_axis.x, m.y_axis.y, m.y_axis.z,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::{BONE_LENGTHS, rest_pose};

    fn pose64(p: &[glam::Vec3; NUM_JOINTS]) -> Pose64 {
        p.map(|v| v.as_dvec3())
    }

    fn offsets() -> [DVec3; NUM_JOINTS] {
        std::array::from_fn(|j| DVec3::from(RAW_OFFSETS[j].map(f64::from)) * BONE_LENGTHS[j] as f64)
    }

    /// A bent pose: the rest pose with every bone turned by a different rotation.
    fn bent_pose() -> Pose64 {
        let rest = pose64(&rest_pose());
        let mut p = rest;
        for j in 1..NUM_JOINTS {
            let axis = DVec3::new(1.0, (j as f64).sin(), (j as f64 * 0.7).cos()).normalize();
            let turn = DQuat::from_axis_angle(axis, 0.15 * j as f64);
            p[j] = p[PARENTS[j]] + turn * (rest[j] - rest[PARENTS[j]]);
        }
        p
    }

    #[test]
    fn rotation_between_handles_general_and_opposite_directions() {
        let a = DVec3::new(0.3, -1.0, 0.2);
        let b = DVec3::new(-0.5, 0.1, 0.9);
        let q = rotation_between(a, b);
        assert!((q * a.normalize() - b.normalize()).length() < 1e-12);
        let q = rotation_between(DVec3::Y, -DVec3::Y);
        assert!((q * DVec3::Y + DVec3::Y).length() < 1e-12);
        assert_eq!(rotation_between(DVec3::ZERO, DVec3::X), DQuat::IDENTITY);
    }

    #[test]
    fn ik_then_fk_reproduces_the_pose_for_any_root_rotation() {
        let p = bent_pose();
        for root in [
            DQuat::IDENTITY,
            DQuat::from_rotation_y(1.1),
            DQuat::from_rotation_x(0.4),
        ] {
            let q = inverse_kinematics(&[p], &[root]).unwrap();
            let back = forward_kinematics(&q, &[p[0]], &offsets());
            for j in 0..NUM_JOINTS {
                assert!((back[0][j] - p[j]).length() < 1e-6, "joint {j}");
            }
        }
    }

    #[test]
    fn rest_pose_has_identity_rotations() {
        let q = inverse_kinematics(&[pose64(&rest_pose())], &[DQuat::IDENTITY]).unwrap();
        for r in q[0] {
            assert!(r.abs_diff_eq(DQuat::IDENTITY, 1e-12));
            assert_eq!(rotation_6d(r), [1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
        }
    }

    #[test]
    fn root_rotation_uses_the_flipped_hip_term() {
        // A body facing +X (its left is -Z): the hips' across vector is rotated too.
        let turn = DQuat::from_rotation_y(std::f64::consts::FRAC_PI_2);
        let rest = pose64(&rest_pose());
        let turned = rest.map(|v| turn * v);
        // Frame 0 is forced to the identity, frame 1 is the interesting one.
        let r = root_rotations(&[rest, turned], false).unwrap();
        assert_eq!(r[0], DQuat::IDENTITY);
        // Shoulders are wider than hips, so the quirky rule still sees the body's facing.
        assert!((r[1] * (turn * DVec3::Z) - DVec3::Z).length() < 1e-9);
        // Hips wider than shoulders: the flipped hip term wins and the facing flips.
        let mut wide = turned;
        for (j, s) in [(1, 4.0), (2, 4.0)] {
            wide[j] = wide[0] + (wide[j] - wide[0]) * s;
        }
        let r = root_rotations(&[rest, wide], false).unwrap();
        assert!((r[1] * (turn * DVec3::Z) + DVec3::Z).length() < 1e-9);
    }

    #[test]
    fn chained_rotations_follow_the_body() {
        // A rest pose turned by 3 rad (nearly facing -Z, where minimal arcs degenerate).
        let turn = DQuat::from_rotation_y(3.0);
        let turned = pose64(&rest_pose()).map(|v| turn * v);
        let facing = body_facing(&turned, 0).unwrap();
        assert!(facing.abs_diff_eq(turn, 1e-9));
        for g in chained_bone_rotations(&turned, 0, facing).unwrap() {
            assert!(g.abs_diff_eq(turn, 1e-9) || g.abs_diff_eq(-turn, 1e-9));
        }
        let p = bent_pose();
        let g = chained_bone_rotations(&p, 0, DQuat::from_rotation_y(0.3)).unwrap();
        for j in 1..NUM_JOINTS {
            let dir = (p[j] - p[PARENTS[j]]).normalize();
            let rest = DVec3::from(RAW_OFFSETS[j].map(f64::from));
            assert!((g[j] * rest - dir).length() < 1e-9, "joint {j}");
        }
    }

    #[test]
    fn zero_bones_and_degenerate_facing_are_errors() {
        let mut p = bent_pose();
        p[4] = p[1];
        assert!(matches!(
            bone_rotations(&p, 3),
            Err(FeatureError::ZeroBone {
                frame: 3,
                joint: 4,
                ..
            })
        ));
        let mut q = bent_pose();
        for j in FACE_JOINTS {
            q[j] = DVec3::ZERO;
        }
        assert!(matches!(
            root_rotations(&[q], false),
            Err(FeatureError::DegenerateFacing { frame: 0 })
        ));
    }
}
