//! Rig families read by an exact name table: one table per family, each naming where
//! every HumanML3D joint comes from.
//!
//! | family | source | joints |
//! | --- | --- | --- |
//! | `bandai-namco` | Bandai Namco Research Motiondataset 1–2 | 21 (`Hips`, `UpperLeg_L`, …) |
//! | `cmu-cgspeed-31` | CMU, cgspeed MotionBuilder-friendly BVH | 31 (`Hips`, `LHipJoint`, `LeftUpLeg`, …) |
//! | `cmu-asf` | CMU / HDM05 ASF names (also `.asf`+`.amc`) | 31 (`root`, `lhipjoint`, `lfemur`, …) |
//! | `deepmimic` | DeepMimic humanoid3d (13 and 15 joints) | `root`, `chest`, `neck`, `left_hip`, … |
//!
//! A table is used when every name it uses is in the file (case-insensitive). Joints a
//! rig lacks are placed between two of its joints ([`Pick::Between`]) at fractions
//! measured on HumanML3D's golden clip 012314 (heights above the pelvis: spine1 0.12 m,
//! spine2 0.23, spine3 0.26, collars 0.37–0.39 and 40 % of the way out to the shoulder,
//! neck 0.46, head 0.10 above the neck). The book's data chapter lists the measured error
//! of the DeepMimic fill.

use super::parse::Bvh;
use crate::skeleton::NUM_JOINTS;

/// Where one HumanML3D joint comes from, by source joint name.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pick {
    /// A source joint.
    Joint(&'static str),
    /// The first of these source joints the file has (one rig, several exporters).
    OneOf(&'static [&'static str]),
    /// `t` of the way from source joint `a` to source joint `b`.
    Between(&'static str, &'static str, f32),
    /// `t` of the way from a source joint to its (first) End Site.
    End(&'static str, f32),
}

/// One rig family.
#[derive(Clone, Copy, Debug)]
pub struct RigTable {
    /// Family name, reported in the joint map and by `mprog data build`.
    pub name: &'static str,
    /// Index = HumanML3D joint.
    pub picks: [Pick; NUM_JOINTS],
    /// End Sites the family's model defines but some exporters write as `OFFSET 0 0 0`
    /// (joint, offset in the joint's frame, file units): filled in before FK.
    pub end_sites: &'static [(&'static str, [f32; 3])],
}

use Pick::{Between, End, Joint, OneOf};

/// Bandai-Namco (verified on walk files: `_L` joints lie on the person's left). spine2 has
/// no joint: placed between Spine and Chest at HumanML3D's rest proportions.
pub const BANDAI: RigTable = RigTable {
    name: "bandai-namco",
    picks: [
        Joint("Hips"),
        Joint("UpperLeg_L"),
        Joint("UpperLeg_R"),
        Joint("Spine"),
        Joint("LowerLeg_L"),
        Joint("LowerLeg_R"),
        Between("Spine", "Chest", 0.714),
        Joint("Foot_L"),
        Joint("Foot_R"),
        Joint("Chest"),
        Joint("Toes_L"),
        Joint("Toes_R"),
        Joint("Neck"),
        Joint("Shoulder_L"),
        Joint("Shoulder_R"),
        Joint("Head"),
        Joint("UpperArm_L"),
        Joint("UpperArm_R"),
        Joint("LowerArm_L"),
        Joint("LowerArm_R"),
        Joint("Hand_L"),
        Joint("Hand_R"),
    ],
    end_sites: &[],
};

/// cgspeed's MotionBuilder-friendly CMU conversion. `LeftShoulder` sits on the spine
/// (zero offset), so the collar is placed 40 % of the way out to `LeftArm`; the spine
/// runs Spine (0.12 m above the hips) – Spine1 (0.23) – Neck1 (0.33, at shoulder level).
pub const CGSPEED_MB: RigTable = RigTable {
    name: "cmu-cgspeed-31",
    picks: [
        Joint("Hips"),
        Joint("LeftUpLeg"),
        Joint("RightUpLeg"),
        Joint("Spine"),
        Joint("LeftLeg"),
        Joint("RightLeg"),
        Joint("Spine1"),
        Joint("LeftFoot"),
        Joint("RightFoot"),
        Between("Spine1", "Neck1", 0.3),
        Joint("LeftToeBase"),
        Joint("RightToeBase"),
        Joint("Neck1"),
        Between("LeftShoulder", "LeftArm", 0.4),
        Between("RightShoulder", "RightArm", 0.4),
        Joint("Head"),
        Joint("LeftArm"),
        Joint("RightArm"),
        Joint("LeftForeArm"),
        Joint("RightForeArm"),
        Joint("LeftHand"),
        Joint("RightHand"),
    ],
    end_sites: &[],
};

/// The CMU ASF names (CMU's own `.asf`, HDM05). A joint named after a bone sits where the
/// bone starts: `lfemur` is the hip, `ltibia` the knee, `lfoot` the ankle, `lhumerus` the
/// shoulder. Spine: upperback 0.12 m, thorax 0.25, lowerneck 0.37, upperneck 0.47; spine3
/// is taken between thorax and upperneck, because cgspeed's ASF-named files (CMU 16_01,
/// 16_02, whose root is `hip`) put lowerneck on the thorax as their MotionBuilder rig does.
pub const CMU_ASF: RigTable = RigTable {
    name: "cmu-asf",
    picks: [
        OneOf(&["root", "hip"]),
        Joint("lfemur"),
        Joint("rfemur"),
        Joint("upperback"),
        Joint("ltibia"),
        Joint("rtibia"),
        Joint("thorax"),
        Joint("lfoot"),
        Joint("rfoot"),
        Between("thorax", "upperneck", 0.2),
        Joint("ltoes"),
        Joint("rtoes"),
        Joint("upperneck"),
        Between("lclavicle", "lhumerus", 0.4),
        Between("rclavicle", "rhumerus", 0.4),
        Joint("head"),
        Joint("lhumerus"),
        Joint("rhumerus"),
        Joint("lradius"),
        Joint("rradius"),
        Joint("lwrist"),
        Joint("rwrist"),
    ],
    end_sites: &[],
};

/// DeepMimic's humanoid3d (13 joints in the CMU conversions, 15 in DeepMimic's own files,
/// whose wrists are End Sites either way). Its root sits on the line between the hips
/// (HumanML3D's pelvis is 6–10 cm above it), and it has no spine joints, collars or toes:
/// pelvis 25 % and spine1 60 % of the way root→chest, spine2 = chest, spine3 20 % of the way
/// chest→neck, collars halfway neck→shoulder (the fractions of least error on the golden
/// clip, `tests/rig_fill.rs`), toes and head from the End Sites of
/// the ankles and the neck (the humanoid's foot box and head sphere; the 15-joint files
/// write those End Sites as zero and get the 13-joint offsets).
pub const DEEPMIMIC: RigTable = RigTable {
    name: "deepmimic",
    picks: [
        Between("root", "chest", 0.25),
        Joint("left_hip"),
        Joint("right_hip"),
        Between("root", "chest", 0.6),
        Joint("left_knee"),
        Joint("right_knee"),
        Joint("chest"),
        Joint("left_ankle"),
        Joint("right_ankle"),
        Between("chest", "neck", 0.2),
        End("left_ankle", 1.0),
        End("right_ankle", 1.0),
        Joint("neck"),
        Between("neck", "left_shoulder", 0.5),
        Between("neck", "right_shoulder", 0.5),
        End("neck", 0.36),
        Joint("left_shoulder"),
        Joint("right_shoulder"),
        Joint("left_elbow"),
        Joint("right_elbow"),
        End("left_elbow", 1.0),
        End("right_elbow", 1.0),
    ],
    end_sites: &[
        ("left_ankle", [0.1335, -0.0225, 0.0]),
        ("right_ankle", [0.1335, -0.0225, 0.0]),
        ("neck", [0.0, 0.2775, 0.0]),
    ],
};

/// Every table, tried in order.
pub const TABLES: [&RigTable; 4] = [&BANDAI, &CGSPEED_MB, &CMU_ASF, &DEEPMIMIC];

/// Index of the (non-End-Site) joint called `name`, ignoring case.
pub fn find_joint(bvh: &Bvh, name: &str) -> Option<usize> {
    bvh.joint_index(name).or_else(|| {
        bvh.joints
            .iter()
            .position(|j| !j.end_site && j.name.eq_ignore_ascii_case(name))
    })
}

/// Index of the first End Site under joint `j`.
pub fn end_site_of(bvh: &Bvh, j: usize) -> Option<usize> {
    bvh.joints
        .iter()
        .position(|e| e.end_site && e.parent == Some(j))
}

impl RigTable {
    /// True when every joint the table names is in the file.
    pub fn fits(&self, bvh: &Bvh) -> bool {
        self.picks.iter().all(|p| match *p {
            Joint(a) => find_joint(bvh, a).is_some(),
            OneOf(names) => names.iter().any(|a| find_joint(bvh, a).is_some()),
            Between(a, b, _) => find_joint(bvh, a).is_some() && find_joint(bvh, b).is_some(),
            End(a, _) => find_joint(bvh, a).is_some_and(|j| end_site_of(bvh, j).is_some()),
        })
    }
}

/// The first table that fits the file.
pub fn detect(bvh: &Bvh) -> Option<&'static RigTable> {
    TABLES.into_iter().find(|t| t.fits(bvh))
}

/// Gives zero-length End Sites the offsets of the table's model (see
/// [`RigTable::end_sites`]); returns one warning per End Site filled.
pub fn complete_end_sites(bvh: &mut Bvh) -> Vec<String> {
    let Some(table) = detect(bvh) else {
        return Vec::new();
    };
    let mut warnings = Vec::new();
    for (name, offset) in table.end_sites {
        if let Some(j) = find_joint(bvh, name)
            && let Some(e) = end_site_of(bvh, j)
            && bvh.joints[e].offset.length() < 1e-6
        {
            bvh.joints[e].offset = glam::Vec3::from(*offset);
            warnings.push(format!(
                "End Site of `{name}` was zero: given the {} model's offset {offset:?}",
                table.name
            ));
        }
    }
    warnings
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::JOINT_NAMES;

    #[test]
    fn tables_are_left_right_consistent() {
        // Every left_ joint picks a name with an l/left marker, every right_ joint an r/right one.
        for table in TABLES {
            for (j, pick) in table.picks.iter().enumerate() {
                let name = match pick {
                    Joint(a) | End(a, _) => *a,
                    OneOf(names) => names[0],
                    Between(_, b, _) => *b,
                };
                let lower = name.to_ascii_lowercase();
                let left = lower.starts_with('l') && !lower.starts_with("lower")
                    || lower.ends_with("_l")
                    || lower.starts_with("left");
                let right = lower.starts_with('r') && !lower.starts_with("root")
                    || lower.ends_with("_r")
                    || lower.starts_with("right");
                if JOINT_NAMES[j].starts_with("left_") {
                    assert!(left, "{}: {} ← {name}", table.name, JOINT_NAMES[j]);
                }
                if JOINT_NAMES[j].starts_with("right_") {
                    assert!(right, "{}: {} ← {name}", table.name, JOINT_NAMES[j]);
                }
            }
        }
    }
}
