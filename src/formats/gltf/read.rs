//! Reading `.glb` files. [`chunks`] splits any `.glb` (untrusted: every length checked;
//! a rig is read through it). The rest is for tests and checks: the files mprog writes,
//! their accessors' data and the forward kinematics of the node tree at an animation key,
//! with or without skinning the body mesh ([`parse_glb`] knows the layout
//! [`super::posed_glb`] writes: one buffer, float or unsigned data, LINEAR keys per frame),
//! and [`node_positions_at`] for any file mprog animated.

use super::document::{Document, FLOAT, UNSIGNED_INT, UNSIGNED_SHORT};
use super::{CHUNK_BIN, CHUNK_JSON, GLB_MAGIC};
use glam::{Mat4, Quat, Vec3};

/// A parsed `.glb`: its document and binary chunk.
pub struct Glb {
    pub doc: Document,
    pub bin: Vec<u8>,
}

/// The JSON chunk and the binary chunk, if any.
pub fn chunks(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), String> {
    let word = |at: usize| -> Result<u32, String> {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .ok_or_else(|| format!("the file ends at byte {} inside a header", bytes.len()))
    };
    if word(0)? != GLB_MAGIC {
        return Err(
            "not a glTF binary (.glb): the file does not start with `glTF`; a .gltf with separate files cannot be a rig, export as glTF Binary".into(),
        );
    }
    if word(4)? != 2 {
        return Err(format!("glTF binary version {}, not 2", word(4)?));
    }
    if word(8)? as usize != bytes.len() {
        return Err(format!(
            "the header gives a length of {} bytes but the file has {}",
            word(8)?,
            bytes.len()
        ));
    }
    let mut at = 12;
    let mut found: Vec<(u32, &[u8])> = Vec::new();
    while at < bytes.len() {
        let len = word(at)? as usize;
        let kind = word(at + 4)?;
        let data = bytes
            .get(at + 8..at + 8 + len)
            .ok_or_else(|| format!("the chunk at byte {at} runs past the end of the file"))?;
        found.push((kind, data));
        at += 8 + len;
    }
    match found.as_slice() {
        [(CHUNK_JSON, json), rest @ ..] => {
            let bin = rest.first().filter(|(k, _)| *k == CHUNK_BIN).map(|c| c.1);
            Ok((json, bin))
        }
        _ => Err("the first chunk is not the JSON chunk".into()),
    }
}

/// Parses a `.glb` written by mprog.
pub fn parse_glb(bytes: &[u8]) -> Result<Glb, String> {
    let (json, bin) = chunks(bytes)?;
    let doc: Document = serde_json::from_slice(json).map_err(|e| e.to_string())?;
    Ok(Glb {
        doc,
        bin: bin.ok_or("no binary chunk")?.to_vec(),
    })
}

impl Glb {
    /// The bytes of accessor `a`, checked against its component type `want`.
    fn bytes(&self, a: usize, want: u32) -> Result<&[u8], String> {
        let acc = self.doc.accessors.get(a).ok_or("no such accessor")?;
        if acc.component_type != want {
            return Err(format!(
                "accessor {a} has component type {}, not {want}",
                acc.component_type
            ));
        }
        let view = &self.doc.buffer_views[acc.buffer_view];
        self.bin
            .get(view.byte_offset..view.byte_offset + view.byte_length)
            .ok_or_else(|| format!("accessor {a} lies outside the buffer"))
    }

    /// The floats of accessor `a`.
    pub fn floats(&self, a: usize) -> Result<Vec<f32>, String> {
        Ok(self
            .bytes(a, FLOAT)?
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
            .collect())
    }

    /// The unsigned integers of accessor `a` (16- or 32-bit).
    pub fn uints(&self, a: usize) -> Result<Vec<u32>, String> {
        let kind = self.doc.accessors.get(a).ok_or("no such accessor")?;
        if kind.component_type == UNSIGNED_SHORT {
            Ok(self
                .bytes(a, UNSIGNED_SHORT)?
                .chunks_exact(2)
                .map(|c| u32::from(u16::from_le_bytes([c[0], c[1]])))
                .collect())
        } else {
            Ok(self
                .bytes(a, UNSIGNED_INT)?
                .chunks_exact(4)
                .map(|c| u32::from_le_bytes(c.try_into().expect("4 bytes")))
                .collect())
        }
    }

    /// World transform of every node at animation key `frame` (nodes no scene reaches:
    /// identity).
    pub fn world(&self, frame: usize) -> Result<Vec<Mat4>, String> {
        let doc = &self.doc;
        let mut rot: Vec<Quat> = doc
            .nodes
            .iter()
            .map(|n| Quat::from_array(n.rotation))
            .collect();
        let mut pos: Vec<Vec3> = doc
            .nodes
            .iter()
            .map(|n| Vec3::from(n.translation))
            .collect();
        if let Some(anim) = doc.animations.first() {
            for ch in &anim.channels {
                let s = &anim.samplers[ch.sampler];
                let out = self.floats(s.output)?;
                let node = ch.target.node;
                match ch.target.path.as_str() {
                    "rotation" => {
                        let v = out.get(frame * 4..frame * 4 + 4).ok_or("no such key")?;
                        rot[node] = Quat::from_slice(v);
                    }
                    "translation" => {
                        let v = out.get(frame * 3..frame * 3 + 3).ok_or("no such key")?;
                        pos[node] = Vec3::from_slice(v);
                    }
                    other => return Err(format!("unexpected animated path {other}")),
                }
            }
        }
        let mut world = vec![Mat4::IDENTITY; doc.nodes.len()];
        let scene = doc.scenes.get(doc.scene).ok_or("no scene")?;
        let mut stack: Vec<(usize, Mat4)> =
            scene.nodes.iter().map(|&r| (r, Mat4::IDENTITY)).collect();
        let mut seen = 0;
        while let Some((n, parent)) = stack.pop() {
            seen += 1;
            if seen > doc.nodes.len() {
                return Err("the node tree has a cycle".into());
            }
            let w = parent * Mat4::from_rotation_translation(rot[n], pos[n]);
            world[n] = w;
            stack.extend(doc.nodes[n].children.iter().map(|&c| (c, w)));
        }
        Ok(world)
    }

    /// World position of the node called `name` at key `frame`.
    pub fn node_position(&self, name: &str, frame: usize) -> Result<Vec3, String> {
        let id = self
            .doc
            .nodes
            .iter()
            .position(|n| n.name == name)
            .ok_or_else(|| format!("no node `{name}`"))?;
        Ok(self.world(frame)?[id].w_axis.truncate())
    }

    /// The skinned body mesh of skin `s` at key `frame`: every vertex moved by its joint's
    /// world transform × inverse bind matrix (weights are 1 on the first joint).
    pub fn skinned_vertices(&self, mesh_node: usize, frame: usize) -> Result<Vec<Vec3>, String> {
        let doc = &self.doc;
        let node = &doc.nodes[mesh_node];
        let (Some(m), Some(s)) = (node.mesh, node.skin) else {
            return Err(format!("node {mesh_node} has no skinned mesh"));
        };
        let skin = &doc.skins[s];
        let ibm = self.floats(skin.inverse_bind_matrices)?;
        let world = self.world(frame)?;
        let prim = &doc.meshes[m].primitives[0];
        let positions = self.floats(prim.attributes["POSITION"])?;
        let joints = self.uints(prim.attributes["JOINTS_0"])?;
        let mats: Vec<Mat4> = skin
            .joints
            .iter()
            .enumerate()
            .map(|(k, &n)| world[n] * Mat4::from_cols_slice(&ibm[k * 16..k * 16 + 16]))
            .collect();
        Ok(positions
            .chunks_exact(3)
            .zip(joints.chunks_exact(4))
            .map(|(p, j)| mats[j[0] as usize].transform_point3(Vec3::from_slice(p)))
            .collect())
    }
}

/// Name and world position of every node of any `.glb` (a user's character animated by
/// mprog, say) at key `key` of its first animation (one key per frame, float data, packed
/// views); nodes a cycle hides are an error.
pub fn node_positions_at(bytes: &[u8], key: usize) -> Result<Vec<(String, glam::DVec3)>, String> {
    use crate::formats::character::glb;
    use serde_json::Value;
    let (json, bin) = chunks(bytes)?;
    let json: Value = serde_json::from_slice(json).map_err(|e| e.to_string())?;
    let bin = bin.unwrap_or_default();
    let list = |v: &Value, k: &str| -> Vec<Value> {
        v.get(k)
            .and_then(Value::as_array)
            .cloned()
            .unwrap_or_default()
    };
    let nodes = list(&json, "nodes");
    let mut local = nodes
        .iter()
        .map(glb::local)
        .collect::<Result<Vec<_>, String>>()?;
    let (views, accessors) = (list(&json, "bufferViews"), list(&json, "accessors"));
    let num = |v: &Value, k: &str| v.get(k).and_then(Value::as_u64).unwrap_or(0) as usize;
    let floats = |a: usize, width: usize| -> Result<Vec<f64>, String> {
        let acc = accessors.get(a).ok_or("no such accessor")?;
        let view = views.get(num(acc, "bufferView")).ok_or("no such view")?;
        let start = num(view, "byteOffset") + num(acc, "byteOffset") + key * width * 4;
        let b = bin
            .get(start..start + width * 4)
            .ok_or_else(|| format!("accessor {a} has no key {key}"))?;
        Ok(b.chunks_exact(4)
            .map(|c| f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]])))
            .collect())
    };
    if let Some(anim) = list(&json, "animations").first() {
        let samplers = list(anim, "samplers");
        for ch in list(anim, "channels") {
            let sampler = samplers.get(num(&ch, "sampler")).ok_or("no such sampler")?;
            let target = ch.get("target").ok_or("a channel without a target")?;
            let node = local.get_mut(num(target, "node")).ok_or("no such node")?;
            let output = num(sampler, "output");
            match target.get("path").and_then(Value::as_str) {
                Some("rotation") => {
                    let q = floats(output, 4)?;
                    node.rotation = glam::DQuat::from_xyzw(q[0], q[1], q[2], q[3]).normalize();
                }
                Some("translation") => {
                    node.translation = glam::DVec3::from_slice(&floats(output, 3)?);
                }
                Some("scale") => node.scale = glam::DVec3::from_slice(&floats(output, 3)?),
                other => return Err(format!("unexpected animated path {other:?}")),
            }
        }
    }
    let parent = glb::parents(&json, nodes.len())?;
    let order = glb::preorder(&json, &parent)?;
    let world = glb::worlds(&local, &parent, &order);
    Ok(nodes
        .iter()
        .enumerate()
        .map(|(i, n)| {
            let name = n.get("name").and_then(Value::as_str).unwrap_or("");
            (name.to_string(), world[i].position)
        })
        .collect())
}
