//! The HumanML3D 22-joint skeleton: joint order, names, parents, kinematic chains, rest
//! offsets, the aliases used by PMG-style programs, and the body-segment masses used for
//! the centre of mass.
//!
//! Conventions (the whole crate follows them): metres, Y up, the person's forward is +Z
//! at frame 0 of a canonicalised clip, their left is +X, 20 frames per second.

pub mod capsules;

use glam::Vec3;

/// Number of joints in the HumanML3D skeleton.
pub const NUM_JOINTS: usize = 22;

/// Frames per second of every motion inside mprog.
pub const FPS: f32 = 20.0;

/// Canonical joint names, index = HumanML3D joint index.
pub const JOINT_NAMES: [&str; NUM_JOINTS] = [
    "pelvis",
    "left_hip",
    "right_hip",
    "spine1",
    "left_knee",
    "right_knee",
    "spine2",
    "left_ankle",
    "right_ankle",
    "spine3",
    "left_foot",
    "right_foot",
    "neck",
    "left_collar",
    "right_collar",
    "head",
    "left_shoulder",
    "right_shoulder",
    "left_elbow",
    "right_elbow",
    "left_wrist",
    "right_wrist",
];

/// Parent of each joint; the root (pelvis) is its own parent, as in HumanML3D's tables.
pub const PARENTS: [usize; NUM_JOINTS] = [
    0, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9, 12, 13, 14, 16, 17, 18, 19,
];

/// `t2m_kinematic_chain`: right leg, left leg, spine to head, right arm, left arm.
pub const KINEMATIC_CHAINS: [&[usize]; 5] = [
    &[0, 2, 5, 8, 11],
    &[0, 1, 4, 7, 10],
    &[0, 3, 6, 9, 12, 15],
    &[9, 14, 17, 19, 21],
    &[9, 13, 16, 18, 20],
];

/// `t2m_raw_offsets`: unit direction of each bone in the rest pose.
pub const RAW_OFFSETS: [[f32; 3]; NUM_JOINTS] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [-1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.0, 0.0, 1.0],
    [0.0, 1.0, 0.0],
    [1.0, 0.0, 0.0],
    [-1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.0, -1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, -1.0, 0.0],
];

/// Bone lengths (metres) of HumanML3D's uniform target skeleton, index = child joint.
/// Every HumanML3D clip is retargeted to these lengths; measured on the golden clip 012314
/// (constant over its frames to 3e-7 m).
pub const BONE_LENGTHS: [f32; NUM_JOINTS] = [
    0.0, 0.10307, 0.10988, 0.13157, 0.39362, 0.39019, 0.14319, 0.43243, 0.42564, 0.05736, 0.14338,
    0.14942, 0.21936, 0.13749, 0.14338, 0.10304, 0.13161, 0.12298, 0.25684, 0.26309, 0.26601,
    0.26988,
];

/// The body's parts, each with its joints: what an edit holds or frees as a whole and what
/// the plausibility report groups joints by.
pub const BODY_PARTS: [(&str, &[usize]); 6] = [
    ("torso", &[0, 3, 6, 9]),
    ("head", &[12, 15]),
    ("left arm", &[13, 16, 18, 20]),
    ("right arm", &[14, 17, 19, 21]),
    ("left leg", &[1, 4, 7, 10]),
    ("right leg", &[2, 5, 8, 11]),
];

/// Height of the pelvis above the floor in HumanML3D's rest pose (metres).
pub const REST_PELVIS_HEIGHT: f32 = 0.837;

/// Foot joints used for contacts: (left ankle, left foot), (right ankle, right foot).
pub const FOOT_LEFT: [usize; 2] = [7, 10];
/// The foot joints (`left_foot`, `right_foot`, the toes): what foot skating measures and
/// the foot lock holds.
pub const FEET: [usize; 2] = [10, 11];
/// See [`FOOT_LEFT`].
pub const FOOT_RIGHT: [usize; 2] = [8, 11];
/// Joints whose positions define the facing direction: r_hip, l_hip, r_shoulder, l_shoulder.
pub const FACE_JOINTS: [usize; 4] = [2, 1, 17, 16];

/// Rest offset of every joint from its parent (raw direction times bone length).
pub fn rest_offsets() -> [Vec3; NUM_JOINTS] {
    std::array::from_fn(|j| Vec3::from(RAW_OFFSETS[j]) * BONE_LENGTHS[j])
}

/// Joint positions of the rest pose (T-pose, feet on the floor, facing +Z).
pub fn rest_pose() -> [Vec3; NUM_JOINTS] {
    let offsets = rest_offsets();
    let mut pose = [Vec3::ZERO; NUM_JOINTS];
    pose[0] = Vec3::new(0.0, REST_PELVIS_HEIGHT, 0.0);
    for j in 1..NUM_JOINTS {
        pose[j] = pose[PARENTS[j]] + offsets[j];
    }
    pose
}

/// Aliases accepted wherever a joint name is: PMG's program names (`l_hand`, `chest`, …),
/// SMPL-style short names and a few common words.
pub const ALIASES: &[(&str, usize)] = &[
    ("root", 0),
    ("hips", 0),
    ("hip", 0),
    ("l_hip", 1),
    ("r_hip", 2),
    ("spine", 3),
    ("l_knee", 4),
    ("r_knee", 5),
    ("chest", 9),
    ("l_ankle", 7),
    ("r_ankle", 8),
    ("l_foot", 10),
    ("r_foot", 11),
    ("left_toe", 10),
    ("right_toe", 11),
    ("l_toe", 10),
    ("r_toe", 11),
    ("l_collar", 13),
    ("r_collar", 14),
    ("l_shoulder", 16),
    ("r_shoulder", 17),
    ("l_elbow", 18),
    ("r_elbow", 19),
    ("l_wrist", 20),
    ("r_wrist", 21),
    ("l_hand", 20),
    ("r_hand", 21),
    ("left_hand", 20),
    ("right_hand", 21),
];

/// Resolves a joint name or alias (case-insensitive) to its index.
pub fn joint_index(name: &str) -> Option<usize> {
    let lower = name.to_ascii_lowercase();
    JOINT_NAMES
        .iter()
        .position(|n| *n == lower)
        .or_else(|| ALIASES.iter().find(|(a, _)| *a == lower).map(|(_, j)| *j))
}

/// Every accepted name: canonical names first, then aliases.
pub fn all_joint_names() -> impl Iterator<Item = &'static str> {
    JOINT_NAMES
        .iter()
        .copied()
        .chain(ALIASES.iter().map(|(a, _)| *a))
}

/// Body-segment mass: a bone between two joints whose mass sits at its midpoint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// Proximal joint.
    pub a: usize,
    /// Distal joint.
    pub b: usize,
    /// Relative weight (the table sums to 100.26; normalise before use).
    pub weight: f32,
}

/// PMG's bone weights for the centre of mass (ProgMoGen `get_center_of_mass`; see
/// `reference-algorithms.md` §1.4). The head segment (12–15) is the one `fixhead` zeroes.
pub const SEGMENTS: [Segment; 21] = [
    Segment {
        a: 0,
        b: 1,
        weight: 7.5,
    },
    Segment {
        a: 0,
        b: 2,
        weight: 7.5,
    },
    Segment {
        a: 1,
        b: 4,
        weight: 11.255,
    },
    Segment {
        a: 2,
        b: 5,
        weight: 11.255,
    },
    Segment {
        a: 4,
        b: 7,
        weight: 5.05,
    },
    Segment {
        a: 5,
        b: 8,
        weight: 5.05,
    },
    Segment {
        a: 7,
        b: 10,
        weight: 1.38,
    },
    Segment {
        a: 8,
        b: 11,
        weight: 1.38,
    },
    Segment {
        a: 0,
        b: 3,
        weight: 6.0,
    },
    Segment {
        a: 3,
        b: 6,
        weight: 6.65,
    },
    Segment {
        a: 6,
        b: 9,
        weight: 6.5,
    },
    Segment {
        a: 9,
        b: 12,
        weight: 3.0,
    },
    Segment {
        a: 12,
        b: 15,
        weight: 5.0,
    },
    Segment {
        a: 9,
        b: 13,
        weight: 3.0,
    },
    Segment {
        a: 9,
        b: 14,
        weight: 3.0,
    },
    Segment {
        a: 13,
        b: 16,
        weight: 3.0,
    },
    Segment {
        a: 14,
        b: 17,
        weight: 3.0,
    },
    Segment {
        a: 16,
        b: 18,
        weight: 3.075,
    },
    Segment {
        a: 17,
        b: 19,
        weight: 3.075,
    },
    Segment {
        a: 18,
        b: 20,
        weight: 2.295,
    },
    Segment {
        a: 19,
        b: 21,
        weight: 2.295,
    },
];

/// Per-joint weights equivalent to [`SEGMENTS`]: the centre of mass is
/// `Σ_j w_j p_j` (each bone's weight split half to each end), normalised to sum 1.
/// This turns `massCtr` into one weighted sum over the joint axis.
pub fn joint_mass_weights(include_head: bool) -> [f32; NUM_JOINTS] {
    let mut w = [0.0f32; NUM_JOINTS];
    for s in SEGMENTS {
        let m = if !include_head && s.a == 12 && s.b == 15 {
            0.0
        } else {
            s.weight
        };
        w[s.a] += 0.5 * m;
        w[s.b] += 0.5 * m;
    }
    let total: f32 = w.iter().sum();
    w.map(|x| x / total)
}

/// Index of the joint mirrored left/right (pelvis and spine map to themselves).
pub fn mirror_joint(j: usize) -> usize {
    const MIRROR: [usize; NUM_JOINTS] = [
        0, 2, 1, 3, 5, 4, 6, 8, 7, 9, 11, 10, 12, 14, 13, 15, 17, 16, 19, 18, 21, 20,
    ];
    MIRROR[j]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chains_agree_with_parents() {
        for chain in KINEMATIC_CHAINS {
            for w in chain.windows(2) {
                assert_eq!(PARENTS[w[1]], w[0], "chain {chain:?}");
            }
        }
    }

    #[test]
    fn aliases_resolve() {
        assert_eq!(joint_index("l_hand"), Some(20));
        assert_eq!(joint_index("R_HAND"), Some(21));
        assert_eq!(joint_index("chest"), Some(9));
        assert_eq!(joint_index("head"), Some(15));
        assert_eq!(joint_index("pelvis"), Some(0));
        assert_eq!(joint_index("tail"), None);
    }

    #[test]
    fn mass_weights_sum_to_one_and_match_segment_table() {
        let w = joint_mass_weights(true);
        assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        let total: f32 = SEGMENTS.iter().map(|s| s.weight).sum();
        assert!((total - 100.26).abs() < 1e-3);
        // A pose with every joint at distinct points: joint weights == bone midpoints.
        let pose = rest_pose();
        let by_bone: Vec3 = SEGMENTS
            .iter()
            .map(|s| (pose[s.a] + pose[s.b]) * 0.5 * s.weight / total)
            .sum();
        let by_joint: Vec3 = (0..NUM_JOINTS).map(|j| pose[j] * w[j]).sum();
        assert!((by_bone - by_joint).length() < 1e-5);
        assert_eq!(joint_mass_weights(false)[15], 0.0);
    }

    #[test]
    fn mirror_is_an_involution() {
        for j in 0..NUM_JOINTS {
            assert_eq!(mirror_joint(mirror_joint(j)), j);
        }
    }
}
