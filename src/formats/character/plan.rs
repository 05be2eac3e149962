//! What drives each rig joint, decided once per rig.
//!
//! In: the rig's joints, their rest positions (metres, Y up) and the correspondence. Out: a
//! [`Plan`]:
//! * each mapped joint's *targets*: the nearest mapped joints below it (one for a limb
//!   joint, several where the body branches: the pelvis, the chest). A joint with targets
//!   is turned so its rest vectors to them point along the motion's; every other joint
//!   (fingers, twist bones, end joints, joints between two mapped ones) keeps its rest pose
//!   relative to its parent;
//! * the legs (hip, knee, ankle and bone lengths), which are solved by two-bone IK so the
//!   ankles land where the motion's do;
//! * the joint whose position channels move the body: the pelvis, or the nearest joint
//!   above it with three position channels.
//!
//! Checked here: every joint that must turn has three rotation channels; the limb bones
//! have a length; something can move the body.

use super::error::{RigError, RigErrorKind};
use crate::formats::bvh::{BvhJoint, parse::Axis, parse::Channel};
use crate::skeleton::{JOINT_NAMES, NUM_JOINTS};
use glam::{DVec3, EulerRot};

/// A leg: rig joints of hip, knee and ankle, and the two bone lengths (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Leg {
    pub hip: usize,
    pub knee: usize,
    pub ankle: usize,
    pub thigh: f64,
    pub shin: f64,
}

/// What drives each rig joint.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The rig joint at the pelvis.
    pub pelvis: usize,
    /// The joint whose position channels move the body.
    pub mover: usize,
    /// HumanML3D joint of each rig joint.
    pub joint_of: Vec<Option<usize>>,
    /// Per rig joint: (rig joint, HumanML3D joint) of the nearest mapped joints below it.
    pub targets: Vec<Vec<(usize, usize)>>,
    /// Left and right leg.
    pub legs: [Leg; 2],
    /// Euler order of each joint's rotation channels (None: it never turns).
    pub euler: Vec<Option<EulerRot>>,
}

/// Rest length (m) below which a bone has no direction.
const MIN_BONE: f64 = 1e-6;

/// Builds the plan; `origin` names the rig in errors.
pub fn plan(
    origin: &str,
    joints: &[BvhJoint],
    rest: &[DVec3],
    map: &[Option<usize>; NUM_JOINTS],
) -> Result<Plan, RigError> {
    let n = joints.len();
    let mut joint_of = vec![None; n];
    for (j, m) in map.iter().enumerate() {
        if let Some(i) = *m {
            joint_of[i] = Some(j);
        }
    }
    let pelvis = map[0].expect("required joint");
    let mut targets: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n];
    for (d, k) in joint_of.iter().enumerate() {
        let Some(k) = *k else { continue };
        if d == pelvis {
            continue;
        }
        let mut a = joints[d].parent;
        while let Some(i) = a {
            if joint_of[i].is_some() {
                // A target at the joint's own place gives no direction.
                if rest[d].distance(rest[i]) > MIN_BONE {
                    targets[i].push((d, k));
                }
                break;
            }
            a = joints[i].parent;
        }
    }
    let bone = |a: usize, b: usize| -> Result<f64, RigError> {
        let (ra, rb) = (map[a].expect("required"), map[b].expect("required"));
        let len = rest[ra].distance(rest[rb]);
        if len > MIN_BONE {
            Ok(len)
        } else {
            Err(RigError::at(
                origin,
                joints[rb].line,
                RigErrorKind::ZeroBone {
                    from: joints[ra].name.clone(),
                    to: joints[rb].name.clone(),
                },
            ))
        }
    };
    for (a, b) in [(16, 18), (18, 20), (17, 19), (19, 21)] {
        bone(a, b)?;
    }
    let leg = |hip: usize, knee: usize, ankle: usize| -> Result<Leg, RigError> {
        Ok(Leg {
            hip: map[hip].expect("required"),
            knee: map[knee].expect("required"),
            ankle: map[ankle].expect("required"),
            thigh: bone(hip, knee)?,
            shin: bone(knee, ankle)?,
        })
    };
    let legs = [leg(1, 4, 7)?, leg(2, 5, 8)?];
    let mut euler = vec![None; n];
    for i in 0..n {
        let turns = i == pelvis || !targets[i].is_empty();
        if !turns || joints[i].end_site {
            continue;
        }
        euler[i] = Some(euler_order(&joints[i].channels).ok_or_else(|| {
            RigError::at(
                origin,
                joints[i].line,
                RigErrorKind::Channels {
                    joint: joints[i].name.clone(),
                    as_joint: joint_of[i].map_or("a mapped joint", |j| JOINT_NAMES[j]),
                    channels: channel_names(&joints[i].channels),
                },
            )
        })?);
    }
    let mover = mover(joints, pelvis).ok_or_else(|| {
        RigError::at(
            origin,
            joints[pelvis].line,
            RigErrorKind::NoTranslation {
                pelvis: joints[pelvis].name.clone(),
            },
        )
    })?;
    Ok(Plan {
        pelvis,
        mover,
        joint_of,
        targets,
        legs,
        euler,
    })
}

/// The pelvis, or the nearest joint above it, with three position channels.
fn mover(joints: &[BvhJoint], pelvis: usize) -> Option<usize> {
    let mut at = Some(pelvis);
    while let Some(i) = at {
        let positions = joints[i]
            .channels
            .iter()
            .filter(|c| matches!(c, Channel::Position(_)))
            .count();
        if positions == 3 {
            return Some(i);
        }
        at = joints[i].parent;
    }
    None
}

/// The intrinsic Euler order of a joint's three rotation channels (as BVH composes them:
/// first · second · third), if they are three and can express any rotation.
pub fn euler_order(channels: &[Channel]) -> Option<EulerRot> {
    let axes: Vec<Axis> = channels
        .iter()
        .filter_map(|c| match c {
            Channel::Rotation(a) => Some(*a),
            Channel::Position(_) => None,
        })
        .collect();
    use Axis::{X, Y, Z};
    Some(match axes.as_slice() {
        [X, Y, Z] => EulerRot::XYZ,
        [X, Z, Y] => EulerRot::XZY,
        [Y, X, Z] => EulerRot::YXZ,
        [Y, Z, X] => EulerRot::YZX,
        [Z, X, Y] => EulerRot::ZXY,
        [Z, Y, X] => EulerRot::ZYX,
        [X, Y, X] => EulerRot::XYX,
        [X, Z, X] => EulerRot::XZX,
        [Y, X, Y] => EulerRot::YXY,
        [Y, Z, Y] => EulerRot::YZY,
        [Z, X, Z] => EulerRot::ZXZ,
        [Z, Y, Z] => EulerRot::ZYZ,
        _ => return None,
    })
}

/// `Zrotation Xrotation Yrotation`, as written in a CHANNELS line.
pub fn channel_names(channels: &[Channel]) -> String {
    channels
        .iter()
        .map(|c| {
            let (axis, kind) = match c {
                Channel::Position(a) => (a, "position"),
                Channel::Rotation(a) => (a, "rotation"),
            };
            let axis = match axis {
                Axis::X => "X",
                Axis::Y => "Y",
                Axis::Z => "Z",
            };
            format!("{axis}{kind}")
        })
        .collect::<Vec<_>>()
        .join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formats::bvh::fk::local_transform;
    use glam::{DQuat, Vec3};

    #[test]
    fn euler_orders_compose_as_the_bvh_reader_reads_them() {
        let q = DQuat::from_euler(EulerRot::ZYX, 0.3, -0.7, 1.1);
        let names = ["Xrotation", "Yrotation", "Zrotation"];
        for a in names {
            for b in names {
                for c in names {
                    let channels: Vec<Channel> = [a, b, c]
                        .iter()
                        .map(|n| Channel::from_name(n).unwrap())
                        .collect();
                    let Some(order) = euler_order(&channels) else {
                        assert!(a == b || b == c, "{a} {b} {c}");
                        continue;
                    };
                    let (x, y, z) = q.to_euler(order);
                    let values = [x, y, z].map(|v| v.to_degrees() as f32);
                    let (_, r) = local_transform(Vec3::ZERO, &channels, &values);
                    let back = r.as_dquat();
                    assert!(back.dot(q).abs() > 1.0 - 1e-6, "{a} {b} {c}");
                }
            }
        }
    }
}
