//! A skinned glTF character as the rig (`--rig character.glb`): the joints of its skin,
//! read as a rig, and what the output needs to animate the file itself.
//!
//! In: a `.glb` (untrusted: at most [`MAX_GLB_BYTES`], the container, the JSON and every
//! index checked). Out: the skin's joints as rig joints (parents first, offsets from the
//! nodes' rest transforms in the scene's world, which glTF defines as metres, Y up; each
//! with position and rotation channels, since any glTF node can move) and a [`GlbRig`]:
//! the document and binary chunk as read, and per joint the rest rotations and scales the
//! writer ([`crate::formats::gltf::onto_rig`]) turns rig rotations into node rotations with.
//!
//! A glTF node's rest pose carries a rotation, a BVH joint's does not: the rig is the
//! nodes' world rest positions, and a node rotation is `P⁻¹ · q · W` (the parent node's
//! world rest rotation `P`, the rig rotation `q`, the node's own world rest rotation `W`).
//! The skin taken is the one with the most joints; nodes on the way to a joint must have a
//! uniform, positive scale.

use super::error::{RigError, RigErrorKind};
use crate::formats::bvh::BvhJoint;
use crate::formats::bvh::parse::{Axis, Channel};
use crate::formats::gltf::read::chunks;
use glam::{DMat4, DQuat, DVec3};
use serde_json::Value;
use std::io::Read;
use std::path::Path;

/// Largest `.glb` read as a rig (a textured game character is tens of MB).
pub const MAX_GLB_BYTES: u64 = 256 << 20;
/// Most nodes in a rig file.
pub const MAX_NODES: usize = 200_000;
/// Most joints in the skin taken.
pub const MAX_JOINTS: usize = 4096;

/// What the `.glb` writer needs from the rig file.
#[derive(Clone, PartialEq)]
pub struct GlbRig {
    /// The JSON chunk, whole (unknown fields and extensions kept).
    pub json: Value,
    /// The binary chunk (empty when the file has none).
    pub bin: Vec<u8>,
    /// Per rig joint (the rig's joint order).
    pub joints: Vec<GlbJoint>,
}

impl std::fmt::Debug for GlbRig {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GlbRig")
            .field("bin_bytes", &self.bin.len())
            .field("joints", &self.joints)
            .finish_non_exhaustive()
    }
}

/// One joint of the skin: its node and its rest frame.
#[derive(Clone, Debug, PartialEq)]
pub struct GlbJoint {
    /// Its node.
    pub node: usize,
    /// World rest rotation of the node.
    pub rest: DQuat,
    /// World rest rotation of the node's parent (identity for a scene root).
    pub parent_rest: DQuat,
    /// World scale of the node's parent (1 for a scene root).
    pub parent_scale: f64,
    /// World rest position of the node's parent less that of the nearest joint above the
    /// node (of the origin, when none), file units: what a non-joint node between two
    /// joints adds.
    pub parent_shift: DVec3,
}

/// A node's transform relative to its parent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Local {
    pub translation: DVec3,
    pub rotation: DQuat,
    pub scale: DVec3,
}

/// A node's rest transform in the scene (uniform scales only).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct World {
    pub position: DVec3,
    pub rotation: DQuat,
    pub scale: f64,
    /// False when this node or a node above it has a non-uniform or non-positive scale.
    pub uniform: bool,
}

impl World {
    /// The scene's origin: no move, no turn, unit scale.
    pub const ORIGIN: World = World {
        position: DVec3::ZERO,
        rotation: DQuat::IDENTITY,
        scale: 1.0,
        uniform: true,
    };

    /// The world transform of a child at `local` below `self`.
    pub fn child(&self, local: &Local) -> World {
        let s = local.scale;
        let uniform = s.min_element() > 0.0 && s.max_element() <= s.min_element() * (1.0 + 1e-4);
        World {
            position: self.position + self.rotation * (self.scale * local.translation),
            rotation: (self.rotation * local.rotation).normalize(),
            scale: self.scale * (s.x + s.y + s.z) / 3.0,
            uniform: self.uniform && uniform,
        }
    }
}

/// The joints and the [`GlbRig`] of the `.glb` at `path`.
pub fn read_glb_rig_file(path: &Path) -> Result<(Vec<BvhJoint>, GlbRig), RigError> {
    let origin = path.display().to_string();
    let io = |e: std::io::Error| RigError::whole(&origin, RigErrorKind::Io(e.to_string()));
    let file = std::fs::File::open(path).map_err(io)?;
    let mut bytes = Vec::new();
    file.take(MAX_GLB_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_GLB_BYTES {
        return Err(RigError::whole(
            &origin,
            RigErrorKind::Glb(format!(
                "the file is over {MAX_GLB_BYTES} bytes, the most a character may be"
            )),
        ));
    }
    glb_rig(&origin, &bytes)
}

/// The joints and the [`GlbRig`] of `.glb` bytes.
pub fn glb_rig(origin: &str, bytes: &[u8]) -> Result<(Vec<BvhJoint>, GlbRig), RigError> {
    let fail = |m: String| RigError::whole(origin, RigErrorKind::Glb(m));
    let (json, bin) = chunks(bytes).map_err(fail)?;
    let json: Value = serde_json::from_slice(json)
        .map_err(|e| fail(format!("the JSON chunk is not valid JSON: {e}")))?;
    if !json.is_object() {
        return Err(fail("the JSON chunk is not an object".into()));
    }
    check_buffers(&json, bin.is_some()).map_err(fail)?;
    let nodes = nodes(&json).map_err(fail)?;
    let parent = parents(&json, nodes.len()).map_err(fail)?;
    let order = preorder(&json, &parent).map_err(fail)?;
    let skin = skin_joints(&json, nodes.len()).map_err(fail)?;

    let locals: Vec<Local> = nodes.iter().map(|n| n.local).collect();
    let world = worlds(&locals, &parent, &order);
    let mut is_joint = vec![false; nodes.len()];
    for &n in &skin {
        is_joint[n] = true;
    }
    // Rig index of each joint node, and the nearest joint node above each node.
    let mut rig_index = vec![None; nodes.len()];
    let mut joint_above: Vec<Option<usize>> = vec![None; nodes.len()];
    let mut joints = Vec::with_capacity(skin.len());
    let mut glb_joints = Vec::with_capacity(skin.len());
    for &i in &order {
        joint_above[i] = parent[i].and_then(|p| if is_joint[p] { Some(p) } else { joint_above[p] });
        if !is_joint[i] {
            continue;
        }
        let name = &nodes[i].name;
        if !world[i].uniform || !world[i].position.is_finite() {
            return Err(fail(format!(
                "joint node {i} (`{name}`) or a node above it has a non-uniform or non-positive scale; apply the scale to the armature before exporting"
            )));
        }
        let above = joint_above[i];
        let base = above.map_or(DVec3::ZERO, |a| world[a].position);
        let parent_world = parent[i].map_or(World::ORIGIN, |p| world[p]);
        rig_index[i] = Some(joints.len());
        joints.push(BvhJoint {
            name: name.clone(),
            parent: above.map(|a| rig_index[a].expect("parents come first")),
            offset: (world[i].position - base).as_vec3(),
            channels: CHANNELS.to_vec(),
            first_channel: CHANNELS.len() * joints.len(),
            end_site: false,
            line: 0,
        });
        glb_joints.push(GlbJoint {
            node: i,
            rest: world[i].rotation,
            parent_rest: parent_world.rotation,
            parent_scale: parent_world.scale,
            parent_shift: parent_world.position - base,
        });
    }
    Ok((
        joints,
        GlbRig {
            json,
            bin: bin.map(<[u8]>::to_vec).unwrap_or_default(),
            joints: glb_joints,
        },
    ))
}

/// Every joint of a glTF rig can move and turn.
const CHANNELS: [Channel; 6] = [
    Channel::Position(Axis::X),
    Channel::Position(Axis::Y),
    Channel::Position(Axis::Z),
    Channel::Rotation(Axis::Z),
    Channel::Rotation(Axis::X),
    Channel::Rotation(Axis::Y),
];

/// The file's buffers must all be the binary chunk: the output rewrites it.
fn check_buffers(json: &Value, has_bin: bool) -> Result<(), String> {
    for key in ["bufferViews", "accessors", "animations", "scenes"] {
        if json.get(key).is_some_and(|v| !v.is_array()) {
            return Err(format!("`{key}` is not an array"));
        }
    }
    let Some(buffers) = json.get("buffers") else {
        return Ok(());
    };
    let buffers = buffers.as_array().ok_or("`buffers` is not an array")?;
    for (i, b) in buffers.iter().enumerate() {
        if let Some(uri) = b.get("uri") {
            return Err(format!(
                "buffer {i} is the separate file {uri}: a rig must be one self-contained .glb (export as glTF Binary)"
            ));
        }
        if i > 0 {
            return Err("more than one buffer: a .glb has one binary chunk".into());
        }
    }
    if !buffers.is_empty() && !has_bin {
        return Err("buffer 0 has no binary chunk".into());
    }
    Ok(())
}

/// A node as read.
struct NodeRead {
    name: String,
    local: Local,
}

/// Every node's name and rest transform.
fn nodes(json: &Value) -> Result<Vec<NodeRead>, String> {
    let nodes = match json.get("nodes") {
        None => return Err("the file has no nodes, so no skeleton".into()),
        Some(n) => n.as_array().ok_or("`nodes` is not an array")?,
    };
    if nodes.len() > MAX_NODES {
        return Err(format!(
            "{} nodes, over the {MAX_NODES} a rig may have",
            nodes.len()
        ));
    }
    nodes
        .iter()
        .enumerate()
        .map(|(i, n)| {
            let name = node_name(n, i);
            let local = local(n).map_err(|e| format!("node {i} (`{name}`): {e}"))?;
            Ok(NodeRead { name, local })
        })
        .collect()
}

/// A node's name (`node{i}` when it has none).
pub fn node_name(node: &Value, i: usize) -> String {
    node.get("name")
        .and_then(Value::as_str)
        .map_or_else(|| format!("node{i}"), str::to_string)
}

/// Every node's world transform from its `local` one, visiting `order` (parents first).
pub fn worlds(local: &[Local], parent: &[Option<usize>], order: &[usize]) -> Vec<World> {
    let mut world = vec![World::ORIGIN; local.len()];
    for &i in order {
        let above = parent[i].map_or(World::ORIGIN, |p| world[p]);
        world[i] = above.child(&local[i]);
    }
    world
}

/// A node's `matrix`, or its `translation`, `rotation` and `scale`.
pub fn local(node: &Value) -> Result<Local, String> {
    if !node.is_object() {
        return Err("not an object".into());
    }
    if let Some(m) = numbers::<16>(node, "matrix")? {
        let m = DMat4::from_cols_array(&m);
        if m.determinant() <= 0.0 {
            return Err("its matrix mirrors or flattens space".into());
        }
        let (scale, rotation, translation) = m.to_scale_rotation_translation();
        return Ok(Local {
            translation,
            rotation: rotation.normalize(),
            scale,
        });
    }
    let translation = numbers::<3>(node, "translation")?.map_or(DVec3::ZERO, DVec3::from_array);
    let rotation = match numbers::<4>(node, "rotation")? {
        None => DQuat::IDENTITY,
        Some(q) => {
            let q = DQuat::from_array(q);
            if q.length() < 1e-6 {
                return Err("its rotation is the zero quaternion".into());
            }
            q.normalize()
        }
    };
    let scale = numbers::<3>(node, "scale")?.map_or(DVec3::ONE, DVec3::from_array);
    Ok(Local {
        translation,
        rotation,
        scale,
    })
}

/// `node[key]` as `N` finite numbers, if present.
fn numbers<const N: usize>(node: &Value, key: &str) -> Result<Option<[f64; N]>, String> {
    let Some(v) = node.get(key) else {
        return Ok(None);
    };
    let bad = || format!("`{key}` is not {N} finite numbers");
    let a = v.as_array().ok_or_else(bad)?;
    if a.len() != N {
        return Err(bad());
    }
    let mut out = [0.0; N];
    for (o, x) in out.iter_mut().zip(a) {
        *o = x.as_f64().filter(|x| x.is_finite()).ok_or_else(bad)?;
    }
    Ok(Some(out))
}

/// The parent of every node, from the `children` lists (each node has at most one).
pub fn parents(json: &Value, count: usize) -> Result<Vec<Option<usize>>, String> {
    let mut parent = vec![None; count];
    let nodes = json.get("nodes").and_then(Value::as_array);
    for (i, n) in nodes.into_iter().flatten().enumerate() {
        let Some(children) = n.get("children") else {
            continue;
        };
        let children = children
            .as_array()
            .ok_or_else(|| format!("node {i}: `children` is not an array"))?;
        for c in children {
            let c = index(c, count).ok_or_else(|| {
                format!("node {i}: child {c} is not a node (the file has {count})")
            })?;
            if c == i || parent[c].is_some() {
                return Err(format!(
                    "node {c} is the child of two nodes or of itself: the nodes do not form trees"
                ));
            }
            parent[c] = Some(i);
        }
    }
    Ok(parent)
}

/// Every node, parents first (depth first, children in file order); an error for nodes in
/// a cycle, which no root reaches.
pub fn preorder(json: &Value, parent: &[Option<usize>]) -> Result<Vec<usize>, String> {
    let count = parent.len();
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); count];
    let nodes = json.get("nodes").and_then(Value::as_array);
    for (i, n) in nodes.into_iter().flatten().enumerate() {
        for c in n
            .get("children")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
        {
            if let Some(c) = index(c, count) {
                children[i].push(c);
            }
        }
    }
    let mut order = Vec::with_capacity(count);
    let mut stack: Vec<usize> = (0..count).rev().filter(|&i| parent[i].is_none()).collect();
    while let Some(i) = stack.pop() {
        order.push(i);
        stack.extend(children[i].iter().rev());
    }
    if order.len() < count {
        let mut seen = vec![false; count];
        for &i in &order {
            seen[i] = true;
        }
        let stuck = seen
            .iter()
            .position(|s| !s)
            .expect("a node was not reached");
        return Err(format!(
            "node {stuck} is in a cycle of children: the nodes do not form trees"
        ));
    }
    Ok(order)
}

/// The joint nodes of the skin with the most joints.
fn skin_joints(json: &Value, count: usize) -> Result<Vec<usize>, String> {
    const NO_SKIN: &str = "the file has no skin: export the character's armature with its mesh (a skinned glTF), or the armature as .bvh";
    let skins = json
        .get("skins")
        .map(|s| s.as_array().ok_or("`skins` is not an array"))
        .transpose()?
        .filter(|s| !s.is_empty())
        .ok_or(NO_SKIN)?;
    let mut best: Option<Vec<usize>> = None;
    for (s, skin) in skins.iter().enumerate() {
        let list = skin
            .get("joints")
            .and_then(Value::as_array)
            .ok_or_else(|| format!("skin {s} has no `joints` list"))?;
        let mut joints = Vec::with_capacity(list.len());
        let mut seen = std::collections::HashSet::new();
        for j in list {
            let n = index(j, count).ok_or_else(|| {
                format!("skin {s}: joint {j} is not a node (the file has {count})")
            })?;
            if !seen.insert(n) {
                return Err(format!("skin {s} lists node {n} twice"));
            }
            joints.push(n);
        }
        if best.as_ref().is_none_or(|b| joints.len() > b.len()) {
            best = Some(joints);
        }
    }
    let best = best.filter(|b| !b.is_empty()).ok_or(NO_SKIN)?;
    if best.len() > MAX_JOINTS {
        return Err(format!(
            "the skin has {} joints, over the {MAX_JOINTS} a rig may have",
            best.len()
        ));
    }
    Ok(best)
}

/// A JSON number that indexes one of `count` items.
fn index(v: &Value, count: usize) -> Option<usize> {
    v.as_u64()
        .and_then(|i| usize::try_from(i).ok())
        .filter(|&i| i < count)
}
