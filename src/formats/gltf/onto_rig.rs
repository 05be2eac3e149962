//! The `.glb` of motions on a skinned glTF character (`--rig character.glb`): the user's own
//! file, its nodes, mesh, skin, materials and extensions kept, with one animation, `mprog`,
//! that turns the skin's joint nodes and moves the body's.
//!
//! In: the [`Character`] read from the `.glb` and one [`Posed`] per person (made by
//! [`Character::retarget`]). Out: the file's bytes. A node's rotation is `P⁻¹ · q · W` (see
//! [`crate::formats::character::glb`]); the moving node's translation is the rig's,
//! brought into its parent node's frame. The file's own animations are replaced. A second
//! person is a copy of the scene's node trees (names prefixed `p2_`, its own skins; meshes
//! are shared), so one file holds everyone, as the plain `.glb` does. Joint nodes written
//! as a `matrix` are rewritten as translation, rotation and scale, which glTF animates.

use super::{CHUNK_BIN, CHUNK_JSON, GLB_MAGIC, pad};
use crate::formats::character::Character;
use crate::formats::character::glb::{self, GlbRig};
use crate::formats::posed::Posed;
use glam::{DQuat, DVec3};
use serde_json::{Map, Value, json};

/// `componentType` of 32-bit floats.
const FLOAT: u64 = 5126;

/// The `.glb` of `people` on `ch`, read from the `.glb` `rig`.
pub fn onto_rig_glb(ch: &Character, rig: &GlbRig, people: &[Posed]) -> Result<Vec<u8>, String> {
    if people.iter().any(Posed::is_empty) {
        return Err("the motion has no frames".into());
    }
    let mut doc = rig.json.clone();
    let count = |key: &str| doc.get(key).and_then(Value::as_array).map_or(0, Vec::len);
    let mut out = Out {
        bin: rig.bin.clone(),
        views: Vec::new(),
        accessors: Vec::new(),
        base_views: count("bufferViews"),
        base_accessors: count("accessors"),
    };
    let mut nodes = take_array(&mut doc, "nodes");
    let mut skins = take_array(&mut doc, "skins");
    let node_of: Vec<Vec<usize>> = (0..people.len())
        .map(|k| match k {
            0 => Ok((0..nodes.len()).collect()),
            _ => copy_scene(&mut doc, &mut nodes, &mut skins, &format!("p{}_", k + 1)),
        })
        .collect::<Result<_, String>>()?;

    let to_file = ch.axes().inverse();
    let mut channels = Vec::new();
    let mut samplers = Vec::new();
    let mut track = |input: usize, output: usize, node: usize, path: &str| {
        samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
        channels
            .push(json!({"sampler": samplers.len() - 1, "target": {"node": node, "path": path}}));
    };
    for (p, map) in people.iter().zip(&node_of) {
        let times: Vec<f32> = (0..p.len()).map(|f| f as f32 / p.fps).collect();
        let last = times[times.len() - 1];
        let input = out.floats("SCALAR", &times, Some((0.0, last)));
        for (i, joint) in rig.joints.iter().enumerate() {
            let node = map[joint.node];
            as_trs(&mut nodes[node])?;
            let unrest = joint.parent_rest.inverse();
            let mut previous = DQuat::IDENTITY;
            let rotations: Vec<f32> = p
                .rotations
                .iter()
                .flat_map(|r| {
                    let q = (unrest * to_file * r[i] * to_file.inverse() * joint.rest).normalize();
                    // One hemisphere from key to key, so that LINEAR slerps the short way.
                    let q = if q.dot(previous) < 0.0 { -q } else { q };
                    previous = q;
                    [q.x, q.y, q.z, q.w].map(|v| v as f32)
                })
                .collect();
            let output = out.floats("VEC4", &rotations, None);
            track(input, output, node, "rotation");
            if i == p.mover {
                let moves: Vec<f32> = p
                    .translations
                    .iter()
                    .flat_map(|t| {
                        let file = to_file * *t / ch.unit_scale;
                        let local: DVec3 =
                            unrest * (file - joint.parent_shift) / joint.parent_scale;
                        local.to_array().map(|v| v as f32)
                    })
                    .collect();
                let output = out.floats("VEC3", &moves, None);
                track(input, output, node, "translation");
            }
        }
    }

    let obj = doc.as_object_mut().expect("checked when read");
    obj.insert("nodes".into(), Value::Array(nodes));
    if !skins.is_empty() {
        obj.insert("skins".into(), Value::Array(skins));
    }
    append(obj, "bufferViews", out.views);
    append(obj, "accessors", out.accessors);
    obj.insert(
        "animations".into(),
        json!([{"name": "mprog", "channels": channels, "samplers": samplers}]),
    );
    let mut bin = out.bin;
    pad(&mut bin, 0);
    let mut buffer = obj
        .get("buffers")
        .and_then(|b| b.get(0))
        .cloned()
        .unwrap_or_else(|| json!({}));
    buffer["byteLength"] = json!(bin.len());
    obj.insert("buffers".into(), json!([buffer]));

    let mut text = serde_json::to_vec(&doc).map_err(|e| e.to_string())?;
    pad(&mut text, b' ');
    let total = 12 + 8 + text.len() + 8 + bin.len();
    let total32 = u32::try_from(total)
        .map_err(|_| format!("the file would be {total} bytes, over glTF's 4 GiB"))?;
    let mut bytes = Vec::with_capacity(total);
    for word in [GLB_MAGIC, 2, total32, text.len() as u32, CHUNK_JSON] {
        bytes.extend(word.to_le_bytes());
    }
    bytes.extend(text);
    bytes.extend((bin.len() as u32).to_le_bytes());
    bytes.extend(CHUNK_BIN.to_le_bytes());
    bytes.extend(bin);
    Ok(bytes)
}

/// Data appended to the binary chunk, and the views and accessors that describe it,
/// numbered after the file's own.
struct Out {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    /// The file's own counts of views and accessors.
    base_views: usize,
    base_accessors: usize,
}

impl Out {
    /// Appends float32 `values` as an accessor of `kind` (`min_max` of a SCALAR).
    fn floats(&mut self, kind: &str, values: &[f32], min_max: Option<(f32, f32)>) -> usize {
        let width = match kind {
            "VEC3" => 3,
            "VEC4" => 4,
            _ => 1,
        };
        pad(&mut self.bin, 0);
        let offset = self.bin.len();
        self.bin.extend(values.iter().flat_map(|v| v.to_le_bytes()));
        self.views.push(json!({
            "buffer": 0,
            "byteOffset": offset,
            "byteLength": values.len() * 4,
        }));
        let mut accessor = json!({
            "bufferView": self.base_views + self.views.len() - 1,
            "componentType": FLOAT,
            "count": values.len() / width,
            "type": kind,
        });
        if let Some((min, max)) = min_max {
            accessor["min"] = json!([min]);
            accessor["max"] = json!([max]);
        }
        self.accessors.push(accessor);
        self.base_accessors + self.accessors.len() - 1
    }
}

/// Appends `items` to the array `key` of `obj` (made if absent).
fn append(obj: &mut Map<String, Value>, key: &str, items: Vec<Value>) {
    let list = obj.entry(key).or_insert_with(|| Value::Array(Vec::new()));
    if let Some(list) = list.as_array_mut() {
        list.extend(items);
    }
}

/// Removes and returns the array `key` of the document (empty when absent).
fn take_array(doc: &mut Value, key: &str) -> Vec<Value> {
    match doc.as_object_mut().and_then(|o| o.remove(key)) {
        Some(Value::Array(a)) => a,
        _ => Vec::new(),
    }
}

/// Writes a node's `matrix` as `translation`, `rotation` and `scale`.
fn as_trs(node: &mut Value) -> Result<(), String> {
    if node.get("matrix").is_none() {
        return Ok(());
    }
    let l = glb::local(node)?;
    let obj = node.as_object_mut().expect("a node is an object");
    obj.remove("matrix");
    obj.insert("translation".into(), json!(l.translation.to_array()));
    obj.insert("rotation".into(), json!(l.rotation.to_array()));
    obj.insert("scale".into(), json!(l.scale.to_array()));
    Ok(())
}

/// Copies the node trees of the document's scene (names prefixed with `prefix`) and the
/// skins that bind them, adds the copies to the scene; returns the copy of every node
/// (nodes outside the scene map to themselves).
fn copy_scene(
    doc: &mut Value,
    nodes: &mut Vec<Value>,
    skins: &mut Vec<Value>,
    prefix: &str,
) -> Result<Vec<usize>, String> {
    let count = nodes.len();
    let tree = json!({"nodes": nodes.clone()});
    let parent = glb::parents(&tree, count)?;
    let scene = doc.get("scene").and_then(Value::as_u64).unwrap_or(0) as usize;
    let roots: Vec<usize> = match doc
        .get("scenes")
        .and_then(|s| s.get(scene))
        .and_then(|s| s.get("nodes"))
        .and_then(Value::as_array)
    {
        Some(list) => list
            .iter()
            .filter_map(|v| v.as_u64().map(|i| i as usize))
            .filter(|&i| i < count && parent[i].is_none())
            .collect(),
        None => (0..count).filter(|&i| parent[i].is_none()).collect(),
    };
    let order = glb::preorder(&tree, &parent)?;
    let mut in_scene = vec![false; count];
    for &i in &order {
        in_scene[i] = roots.contains(&i) || parent[i].is_some_and(|p| in_scene[p]);
    }
    let mut map: Vec<usize> = (0..count).collect();
    let mut next = count;
    for i in 0..count {
        if in_scene[i] {
            map[i] = next;
            next += 1;
        }
    }
    // Skins whose joints are all copied get a copy of their own.
    let mut skin_map: Vec<usize> = (0..skins.len()).collect();
    for s in 0..skins.len() {
        let joints: Vec<usize> = skins[s]
            .get("joints")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
            .filter_map(|v| v.as_u64().map(|i| i as usize))
            .collect();
        if joints.is_empty() || !joints.iter().all(|&j| j < count && in_scene[j]) {
            continue;
        }
        let mut copy = skins[s].clone();
        copy["joints"] = json!(joints.iter().map(|&j| map[j]).collect::<Vec<_>>());
        if let Some(k) = copy.get("skeleton").and_then(Value::as_u64) {
            copy["skeleton"] = json!(map.get(k as usize).copied().unwrap_or(k as usize));
        }
        if let Some(name) = copy.get("name").and_then(Value::as_str) {
            copy["name"] = json!(format!("{prefix}{name}"));
        }
        skins.push(copy);
        skin_map[s] = skins.len() - 1;
    }
    for i in 0..count {
        if !in_scene[i] {
            continue;
        }
        let mut copy = nodes[i].clone();
        let name = glb::node_name(&copy, i);
        copy["name"] = json!(format!("{prefix}{name}"));
        if let Some(children) = copy.get("children").and_then(Value::as_array) {
            let moved: Vec<usize> = children
                .iter()
                .filter_map(|c| c.as_u64().map(|c| map[c as usize]))
                .collect();
            copy["children"] = json!(moved);
        }
        if let Some(s) = copy.get("skin").and_then(Value::as_u64) {
            copy["skin"] = json!(skin_map.get(s as usize).copied().unwrap_or(s as usize));
        }
        nodes.push(copy);
    }
    if let Some(list) = doc
        .get_mut("scenes")
        .and_then(|s| s.get_mut(scene))
        .and_then(|s| s.get_mut("nodes"))
        .and_then(Value::as_array_mut)
    {
        list.extend(roots.iter().map(|&r| json!(map[r])));
    }
    Ok(map)
}
