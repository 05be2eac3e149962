//! A skeleton animated by rotations: the common shape of what the rotation-based writers
//! (the skinned glTF, the BVH of a user's rig) write.
//!
//! In: built by [`from_export_rig`] (the 22-joint export rig of [`super::rig`], from joint
//! positions) or by [`super::character`] (a user's rig). Out: joints with rest offsets
//! (metres, mprog's axes: Y up), one local rotation per joint and frame (identity = the
//! rest pose), and the per-frame translation of the one joint that moves the body.

use super::rig;
use crate::features::FeatureError;
use crate::features::kinematics;
use crate::motion::Motion;
use crate::skeleton::JOINT_NAMES;
use glam::{DQuat, DVec3};

/// One joint of a [`Posed`] skeleton.
#[derive(Clone, Debug, PartialEq)]
pub struct PosedJoint {
    /// Its name in the output.
    pub name: String,
    /// Parent joint (None: a root). Parents come before their children.
    pub parent: Option<usize>,
    /// Rest offset from the parent (a root: its rest position), metres, Y up.
    pub offset: DVec3,
    /// An End Site: a point that is drawn but neither animated nor a node.
    pub end_site: bool,
    /// The HumanML3D joint this joint sits at, if any (what the body mesh is sized by).
    pub body: Option<usize>,
}

/// A skeleton and its animation.
#[derive(Clone, Debug, PartialEq)]
pub struct Posed {
    /// Joints, parents first.
    pub joints: Vec<PosedJoint>,
    /// Frames per second.
    pub fps: f32,
    /// `[frame][joint]` rotation relative to the parent (End Sites: identity).
    pub rotations: Vec<Vec<DQuat>>,
    /// The joint whose translation is animated.
    pub mover: usize,
    /// `[frame]` translation of [`Self::mover`] relative to its parent, metres.
    pub translations: Vec<DVec3>,
    /// Metres per unit of the character's own size, for the body mesh (1 for a
    /// HumanML3D-sized body).
    pub size: f64,
}

impl Posed {
    /// Number of frames.
    pub fn len(&self) -> usize {
        self.rotations.len()
    }

    /// True when there are no frames.
    pub fn is_empty(&self) -> bool {
        self.rotations.is_empty()
    }

    /// Rest positions of every joint (the mover at its frame-0 translation).
    pub fn rest_positions(&self) -> Vec<DVec3> {
        let mut out: Vec<DVec3> = Vec::with_capacity(self.joints.len());
        for (i, j) in self.joints.iter().enumerate() {
            let local = if i == self.mover {
                self.translations.first().copied().unwrap_or(j.offset)
            } else {
                j.offset
            };
            out.push(j.parent.map_or(local, |p| out[p] + local));
        }
        out
    }

    /// World positions of every joint at `frame`, by forward kinematics.
    pub fn positions(&self, frame: usize) -> Vec<DVec3> {
        let mut pos: Vec<DVec3> = Vec::with_capacity(self.joints.len());
        let mut rot: Vec<DQuat> = Vec::with_capacity(self.joints.len());
        for (i, j) in self.joints.iter().enumerate() {
            let local = if i == self.mover {
                self.translations[frame]
            } else {
                j.offset
            };
            let (p, r) = match j.parent {
                Some(p) => (pos[p] + rot[p] * local, rot[p] * self.rotations[frame][i]),
                None => (local, self.rotations[frame][i]),
            };
            pos.push(p);
            rot.push(r);
        }
        pos
    }
}

/// The 22-joint export rig of `m` (with its zero-offset connectors) as a [`Posed`]: rest
/// offsets are the rest directions × the motion's mean bone lengths, the pelvis moves.
pub fn from_export_rig(m: &Motion) -> Result<Posed, FeatureError> {
    if m.is_empty() {
        return Err(FeatureError::TooFewFrames {
            frames: 0,
            needed: 1,
        });
    }
    let poses = kinematics::poses_f64(m)?;
    let nodes = rig::hierarchy();
    let lengths = rig::mean_bone_lengths(&poses);
    let mut rotations = Vec::with_capacity(poses.len());
    for (frame, pose) in poses.iter().enumerate() {
        rotations.push(rig::local_rotations(&nodes, pose, frame, DQuat::IDENTITY)?);
    }
    let joints = nodes
        .iter()
        .map(|n| PosedJoint {
            name: n.name.clone(),
            parent: n.parent,
            offset: rig::rest_offset(n, &lengths),
            end_site: false,
            // A connector sits at its parent joint.
            body: n
                .offset_of
                .or_else(|| JOINT_NAMES.iter().position(|j| *j == n.name))
                .or_else(|| n.name.split("_to_").next().and_then(joint_named)),
        })
        .collect();
    keep_hemisphere(&mut rotations);
    Ok(Posed {
        joints,
        fps: m.fps,
        rotations,
        mover: 0,
        translations: poses.iter().map(|p| p[0]).collect(),
        size: 1.0,
    })
}

/// Flips quaternions that point away from the previous frame's: q and −q are the same
/// rotation, but slerp between opposite signs takes the long way round.
pub fn keep_hemisphere(rotations: &mut [Vec<DQuat>]) {
    for f in 1..rotations.len() {
        for i in 0..rotations[f].len() {
            if rotations[f][i].dot(rotations[f - 1][i]) < 0.0 {
                rotations[f][i] = -rotations[f][i];
            }
        }
    }
}

fn joint_named(name: &str) -> Option<usize> {
    JOINT_NAMES.iter().position(|j| *j == name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::test_motion::walk;
    use glam::Vec3;

    #[test]
    fn the_export_rig_gives_back_the_joints() {
        let m = walk(12, 1.1, Vec3::new(0.3, 0.0, 0.2), Vec3::X);
        let posed = from_export_rig(&m).unwrap();
        assert_eq!(posed.len(), 12);
        for (f, pose) in m.frames.iter().enumerate() {
            let got = posed.positions(f);
            for (j, name) in JOINT_NAMES.iter().enumerate() {
                let id = posed.joints.iter().position(|n| n.name == *name).unwrap();
                assert!((got[id].as_vec3() - pose[j]).length() < 0.01, "{name}");
                assert_eq!(posed.joints[id].body, Some(j));
            }
        }
        let conn = posed
            .joints
            .iter()
            .find(|n| n.name == "pelvis_to_left_hip")
            .unwrap();
        assert_eq!(conn.body, Some(0));
    }
}
