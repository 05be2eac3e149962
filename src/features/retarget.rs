//! Retargeting to HumanML3D's uniform skeleton (its `uniform_skeleton`, step 2 of the
//! pipeline): in, joint positions of any body; out, the same motion on a body with
//! HumanML3D's bone lengths ([`BONE_LENGTHS`]), so that every training clip has one body.
//!
//! As HumanML3D does it: the root track is scaled by the ratio of leg lengths
//! (hip→knee + knee→ankle of the right leg, target over source, the source measured on
//! frame 0); joint rotations come from IK ([`super::kinematics`]); FK with the target offsets
//! (raw direction × target length) rebuilds the joints. Because HumanML3D's IK gives every
//! bone its minimal-arc global rotation, the result keeps every bone's direction and sets its
//! length to the target length; the root rotation cancels out, so none is needed here.

use super::FeatureError;
use super::kinematics::{
    Pose64, forward_kinematics, inverse_kinematics, motion_from_f64, poses_f64,
};
use crate::motion::Motion;
use crate::skeleton::{BONE_LENGTHS, NUM_JOINTS, PARENTS, RAW_OFFSETS};
use glam::{DQuat, DVec3};

/// Right hip→knee and knee→ankle: the bones whose lengths give the scale of the root track.
const LEG_BONES: [usize; 2] = [5, 8];

/// Retargets a motion to HumanML3D's bone lengths (see the module docs).
pub fn uniform_skeleton(m: &Motion) -> Result<Motion, FeatureError> {
    let poses = uniform_skeleton_f64(&poses_f64(m)?)?;
    Ok(motion_from_f64(&poses, m.fps))
}

/// [`uniform_skeleton`] on f64 poses.
pub(crate) fn uniform_skeleton_f64(poses: &[Pose64]) -> Result<Vec<Pose64>, FeatureError> {
    let Some(first) = poses.first() else {
        return Ok(Vec::new());
    };
    let length = |j: usize| (first[j] - first[PARENTS[j]]).length();
    let src_leg: f64 = LEG_BONES.iter().map(|&j| length(j)).sum();
    let tgt_leg: f64 = LEG_BONES.iter().map(|&j| BONE_LENGTHS[j] as f64).sum();
    if src_leg < 1e-9 {
        return Err(FeatureError::ZeroBone {
            frame: 0,
            joint: 5,
            name: "right_knee",
        });
    }
    let scale = tgt_leg / src_leg;
    let roots: Vec<DVec3> = poses.iter().map(|p| p[0] * scale).collect();
    let locals = inverse_kinematics(poses, &vec![DQuat::IDENTITY; poses.len()])?;
    let offsets: [DVec3; NUM_JOINTS] = std::array::from_fn(|j| {
        DVec3::from(RAW_OFFSETS[j].map(f64::from)) * BONE_LENGTHS[j] as f64
    });
    Ok(forward_kinematics(&locals, &roots, &offsets))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::rest_pose;
    use glam::Vec3;

    #[test]
    fn scaled_body_gets_the_target_lengths_and_keeps_directions() {
        let rest = rest_pose();
        // A body 1.5× as large, walking along +X, with a bent left elbow.
        let frames: Vec<_> = (0..4)
            .map(|t| {
                let mut p = rest.map(|v| v * 1.5 + Vec3::new(0.2 * t as f32, 0.0, 0.0));
                p[20] = p[18] + Vec3::new(0.0, 0.0, 1.5 * BONE_LENGTHS[20]);
                p
            })
            .collect();
        let out = uniform_skeleton(&Motion::new(frames.clone())).unwrap();
        for (t, pose) in out.frames.iter().enumerate() {
            // Root track scaled by 1/1.5.
            let want_root = frames[t][0] / 1.5;
            assert!((pose[0] - want_root).length() < 1e-5);
            for j in 1..NUM_JOINTS {
                let bone = pose[j] - pose[PARENTS[j]];
                let src = frames[t][j] - frames[t][PARENTS[j]];
                assert!((bone.length() - BONE_LENGTHS[j]).abs() < 1e-5, "joint {j}");
                assert!(
                    bone.normalize().dot(src.normalize()) > 1.0 - 1e-6,
                    "joint {j}"
                );
            }
        }
    }
}
