//! Reading back the `.glb` files mprog writes, for tests and checks: the chunks, the
//! accessors' data, and forward kinematics of the node tree at an animation key, with or
//! without skinning the body mesh. Not a general glTF reader: it knows the layout
//! [`super::posed_glb`] writes (one buffer, float or unsigned data, LINEAR keys per frame).

use super::document::{Document, FLOAT, UNSIGNED_INT, UNSIGNED_SHORT};
use super::{CHUNK_BIN, CHUNK_JSON, GLB_MAGIC};
use glam::{Mat4, Quat, Vec3};

/// A parsed `.glb`: its document and binary chunk.
pub struct Glb {
    pub doc: Document,
    pub bin: Vec<u8>,
}

/// Parses a `.glb` written by mprog.
pub fn parse_glb(bytes: &[u8]) -> Result<Glb, String> {
    let word = |at: usize| -> Result<u32, String> {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes(b.try_into().expect("4 bytes")))
            .ok_or_else(|| format!("truncated at byte {at}"))
    };
    if (word(0)?, word(4)?) != (GLB_MAGIC, 2) {
        return Err("not a glTF 2 binary".into());
    }
    if word(8)? as usize != bytes.len() {
        return Err("the header's length is not the file's".into());
    }
    let json_len = word(12)? as usize;
    if word(16)? != CHUNK_JSON {
        return Err("the first chunk is not JSON".into());
    }
    let json = bytes.get(20..20 + json_len).ok_or("truncated JSON chunk")?;
    let bin_at = 20 + json_len;
    let bin_len = word(bin_at)? as usize;
    if word(bin_at + 4)? != CHUNK_BIN || bin_at + 8 + bin_len != bytes.len() {
        return Err("the binary chunk does not end the file".into());
    }
    let doc: Document = serde_json::from_slice(json).map_err(|e| e.to_string())?;
    Ok(Glb {
        doc,
        bin: bytes[bin_at + 8..].to_vec(),
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
