//! The export rig: the 22 HumanML3D joints as a tree of nodes with one rotation each, for
//! the formats that animate a skeleton by rotations (BVH, glTF).
//!
//! In: global joint positions (one [`Pose64`] per frame). Out: the node tree, its rest
//! offsets, and each node's local rotation per frame, whose forward kinematics gives back
//! the positions (up to the bone lengths, which the rig takes as their mean over frames).
//!
//! * Rotations come from [`kinematics::chained_bone_rotations`]: every bone gets its parent bone's
//!   rotation plus the minimal swing to its current direction; the bones leaving the pelvis
//!   are oriented by the body's facing ([`kinematics::body_facing`]).
//! * A node has one rotation for all its children, while pelvis and spine3 have several
//!   bones leaving them whose relative angles change over time; so each of those bones
//!   hangs from a zero-offset connector node (`pelvis_to_left_hip`, …,
//!   `spine3_to_right_collar`) that carries its rotation. The pelvis itself carries the
//!   facing yaw; spine3 carries the neck bone.

use crate::features::FeatureError;
use crate::features::kinematics::{self, Pose64};
use crate::skeleton::{JOINT_NAMES, NUM_JOINTS, PARENTS, RAW_OFFSETS};
use glam::{DQuat, DVec3};

/// Where a node's global rotation comes from.
#[derive(Clone, Copy, Debug)]
pub enum Carry {
    /// The body's facing yaw (the pelvis).
    Facing,
    /// The rotation of the bone ending at this HumanML3D joint.
    Bone(usize),
    /// The parent's rotation (leaves, which have no bone of their own).
    Inherit,
}

/// One node: where it sits, what it is attached to, what drives its rotation.
#[derive(Clone, Debug)]
pub struct Node {
    /// The joint's name, or `parent_to_child` for a connector.
    pub name: String,
    /// Parent node (None: the root, the pelvis).
    pub parent: Option<usize>,
    /// HumanML3D joint whose rest offset this node's offset is (None: zero offset).
    pub offset_of: Option<usize>,
    /// What drives its rotation.
    pub carry: Carry,
    /// Child nodes, in order.
    pub children: Vec<usize>,
}

/// The rig's nodes in depth-first order (the root first, parents before children).
pub fn hierarchy() -> Vec<Node> {
    let mut nodes = Vec::new();
    add_joint(&mut nodes, 0, None, None);
    nodes
}

fn push(nodes: &mut Vec<Node>, node: Node) -> usize {
    let id = nodes.len();
    if let Some(p) = node.parent {
        nodes[p].children.push(id);
    }
    nodes.push(node);
    id
}

/// Adds HumanML3D joint `j` under node `parent`, then its subtree.
fn add_joint(nodes: &mut Vec<Node>, j: usize, parent: Option<usize>, offset_of: Option<usize>) {
    let children: Vec<usize> = (1..NUM_JOINTS).filter(|&c| PARENTS[c] == j).collect();
    let carry = match (j, children.first()) {
        (0, _) => Carry::Facing,
        (_, Some(&first)) => Carry::Bone(first),
        (_, None) => Carry::Inherit,
    };
    let name = JOINT_NAMES[j].to_string();
    let id = push(
        nodes,
        Node {
            name,
            parent,
            offset_of,
            carry,
            children: Vec::new(),
        },
    );
    for (k, &c) in children.iter().enumerate() {
        // The first child of a non-root joint uses the joint's own rotation; every other
        // bone leaving a branching joint gets a connector carrying its rotation.
        if j != 0 && k == 0 {
            add_joint(nodes, c, Some(id), Some(c));
        } else {
            let name = format!("{}_to_{}", JOINT_NAMES[j], JOINT_NAMES[c]);
            let node = Node {
                name,
                parent: Some(id),
                offset_of: None,
                carry: Carry::Bone(c),
                children: Vec::new(),
            };
            let conn = push(nodes, node);
            add_joint(nodes, c, Some(conn), Some(c));
        }
    }
}

/// Mean length of every bone over the frames (index = child joint).
pub fn mean_bone_lengths(poses: &[Pose64]) -> [f64; NUM_JOINTS] {
    let mut len = [0.0; NUM_JOINTS];
    for p in poses {
        for j in 1..NUM_JOINTS {
            len[j] += (p[j] - p[PARENTS[j]]).length() / poses.len() as f64;
        }
    }
    len
}

/// The rest offset of a node from its parent: the rest direction of its joint × `length`
/// (zero for connectors).
pub fn rest_offset(node: &Node, lengths: &[f64; NUM_JOINTS]) -> DVec3 {
    node.offset_of.map_or(DVec3::ZERO, |j| {
        DVec3::from(RAW_OFFSETS[j].map(f64::from)) * lengths[j]
    })
}

/// Every node's local rotation (relative to its parent node) in one pose, expressed in the
/// axes `axes` rotates into (identity: mprog's Y up).
pub fn local_rotations(
    nodes: &[Node],
    pose: &Pose64,
    frame: usize,
    axes: DQuat,
) -> Result<Vec<DQuat>, FeatureError> {
    let facing = kinematics::body_facing(pose, frame)?;
    let bones = kinematics::chained_bone_rotations(pose, frame, facing)?;
    let to_file = |q: DQuat| axes * q * axes.inverse();
    let mut global = vec![DQuat::IDENTITY; nodes.len()];
    let mut local = Vec::with_capacity(nodes.len());
    for (id, node) in nodes.iter().enumerate() {
        let parent = node.parent.map_or(DQuat::IDENTITY, |p| global[p]);
        global[id] = match node.carry {
            Carry::Facing => to_file(facing),
            Carry::Bone(b) => to_file(bones[b]),
            Carry::Inherit => parent,
        };
        local.push((parent.inverse() * global[id]).normalize());
    }
    Ok(local)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hierarchy_has_the_22_joints_and_5_connectors() {
        let nodes = hierarchy();
        assert_eq!(nodes.len(), NUM_JOINTS + 5);
        for name in JOINT_NAMES {
            assert_eq!(nodes.iter().filter(|n| n.name == name).count(), 1, "{name}");
        }
        // Every joint node hangs (through at most one connector) from its HumanML3D parent.
        for (id, n) in nodes.iter().enumerate().skip(1) {
            let Some(j) = n.offset_of else { continue };
            let mut p = n.parent.unwrap();
            if nodes[p].offset_of.is_none() && p != 0 {
                p = nodes[p].parent.unwrap();
            }
            assert_eq!(nodes[p].name, JOINT_NAMES[PARENTS[j]], "node {id}");
        }
    }
}
