//! Shared helpers of the feature tests: the HumanML3D golden clip (read with npyz) and a
//! synthetic walking motion built by FK on the HumanML3D skeleton.
#![allow(dead_code)]

use glam::{Quat, Vec3};
use mprog::motion::{Motion, Pose};
use mprog::skeleton::{NUM_JOINTS, PARENTS, rest_pose};
use std::path::PathBuf;

/// Path of a file in `tests/fixtures/humanml3d`.
pub fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/humanml3d")
        .join(name)
}

/// Reads an f32 `.npy` file: (shape, data).
pub fn read_npy(name: &str) -> (Vec<usize>, Vec<f32>) {
    let bytes = std::fs::read(fixture(name)).expect("fixture present");
    let npy = npyz::NpyFile::new(&bytes[..]).expect("valid npy");
    let shape = npy.shape().iter().map(|&d| d as usize).collect();
    (shape, npy.into_vec::<f32>().expect("f32 data"))
}

/// The golden clip 012314: features `[170, 263]` (flat) and joints.
pub fn golden() -> (Vec<f32>, Motion) {
    let (fs, feats) = read_npy("new_joint_vecs_012314.npy");
    assert_eq!(fs, [170, 263]);
    let (js, joints) = read_npy("new_joints_012314.npy");
    assert_eq!(js, [170, 22, 3]);
    (feats, Motion::from_flat(&joints))
}

/// HumanML3D Mean and Std.
pub fn mean_std() -> (Vec<f32>, Vec<f32>) {
    (read_npy("Mean.npy").1, read_npy("Std.npy").1)
}

/// A synthetic walk: the rest pose's bones turned by swinging hips, knees, shoulders and
/// elbows, the root moving forward along a slow left turn with a bobbing height.
pub fn synthetic_walk(frames: usize) -> Motion {
    let rest = rest_pose();
    let poses = (0..frames)
        .map(|t| {
            let phase = t as f32 * 0.35;
            let heading = t as f32 * 0.01;
            let mut local = [Quat::IDENTITY; NUM_JOINTS];
            local[4] = Quat::from_rotation_x(0.5 * phase.sin()); // left knee: thigh swing
            local[5] = Quat::from_rotation_x(-0.5 * phase.sin());
            local[7] = Quat::from_rotation_x(0.4 * (1.0 + phase.cos())); // shins bend
            local[8] = Quat::from_rotation_x(0.4 * (1.0 - phase.cos()));
            local[18] = Quat::from_rotation_x(-0.4 * phase.sin()); // upper arms swing
            local[19] = Quat::from_rotation_x(0.4 * phase.sin());
            local[20] = Quat::from_rotation_x(-0.3); // bent elbows
            local[21] = Quat::from_rotation_x(-0.3);
            local[6] = Quat::from_rotation_y(0.1 * phase.sin()); // torso twist
            let yaw = Quat::from_rotation_y(heading);
            let mut global = [Quat::IDENTITY; NUM_JOINTS];
            let mut pose: Pose = [Vec3::ZERO; NUM_JOINTS];
            pose[0] = Vec3::new(
                0.02 * t as f32 * heading.sin(),
                0.9 + 0.02 * (2.0 * phase).cos(),
                0.04 * t as f32,
            );
            global[0] = yaw;
            for j in 1..NUM_JOINTS {
                let p = PARENTS[j];
                // local[j] turns the bone entering j, on top of the parent's bone.
                global[j] = global[p] * local[j];
                pose[j] = pose[p] + global[j] * (rest[j] - rest[p]);
            }
            pose
        })
        .collect();
    Motion::new(poses)
}

/// Largest distance between corresponding joints of two motions (over the shorter one).
pub fn max_joint_error(a: &Motion, b: &Motion) -> f32 {
    a.frames
        .iter()
        .zip(&b.frames)
        .flat_map(|(p, q)| p.iter().zip(q).map(|(x, y)| (*x - *y).length()))
        .fold(0.0, f32::max)
}
