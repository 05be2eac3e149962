//! glTF 2.0 binary export (`.glb`), the open format of the web, three.js and the game
//! engines: in, the motions of the people; out, one file where each person is a skinned
//! skeleton with a simple body, animated at the motion's frame rate.
//!
//! * Skeleton: a [`Posed`]: the export rig ([`super::rig`], through
//!   [`posed::from_export_rig`]): the 22 HumanML3D joints, named after them (`p2_pelvis`, …
//!   for the second person when there are several), each translated by its rest offset (rest
//!   direction × the motion's mean bone length) from its parent, with the zero-offset
//!   connectors where bones branch; or, with `--rig`, the user's rig ([`super::character`]):
//!   its joints, names and rest offsets (End Sites are drawn, not nodes). Every joint node's
//!   rest rotation is the identity: the bind pose is the skeleton's rest pose. A rig read
//!   from a skinned `.glb` is written as that file animated instead ([`onto_rig`]).
//! * Skin: one per person: its joint nodes and inverse bind matrices (the inverse of each
//!   joint's rest transform, a translation).
//! * Body: one mesh per person ([`body`]): a capped prism per bone, each vertex bound with
//!   weight 1 to the bone's parent joint, on a node at the scene root that names the skin.
//! * Animation: one, `mprog`: every joint node's rotation (LINEAR, so slerp; consecutive
//!   quaternions are kept in one hemisphere) and the moving joint's translation, one key per
//!   frame at `frame / fps` seconds.
//! * Axes and units are glTF's own: metres, Y up, right-handed, as mprog.
//! * The file is the 12-byte header, the JSON chunk ([`document`]) padded with spaces, and
//!   the binary chunk of little-endian data, each view 4-byte aligned.

pub mod body;
pub mod document;
pub mod onto_rig;
pub mod read;
#[cfg(test)]
mod tests;

use super::outputs::OutputJob;
use super::posed::{self, Posed};
use crate::features::FeatureError;
use crate::motion::Motion;
use document::{
    ARRAY_BUFFER, Accessor, Animation, Asset, Buffer, BufferView, Channel, Document,
    ELEMENT_ARRAY_BUFFER, FLOAT, Material, Mesh, Node, Pbr, Primitive, Sampler, Scene, Skin,
    Target, UNSIGNED_INT, UNSIGNED_SHORT,
};
use glam::{DQuat, DVec3};

/// `glTF`: the first four bytes of a `.glb`.
pub const GLB_MAGIC: u32 = 0x4654_6C67;
/// Type of the JSON chunk.
pub const CHUNK_JSON: u32 = 0x4E4F_534A;
/// Type of the binary chunk.
pub const CHUNK_BIN: u32 = 0x004E_4942;

/// Writer of the output table: the `.glb` of every person of the job (on the job's rig,
/// if it has one).
pub fn encode(origin: &str, job: &OutputJob) -> Result<Vec<u8>, String> {
    let people = job
        .people
        .iter()
        .map(|m| match job.rig {
            Some(rig) => rig.retarget(m).map_err(|e| {
                let kind = super::character::RigErrorKind::Motion(e);
                super::RigError::whole(origin, kind).to_string()
            }),
            None => posed::from_export_rig(m)
                .map_err(|e| format!("{origin}: cannot export as glTF: {e}")),
        })
        .collect::<Result<Vec<Posed>, String>>()?;
    let written = match job.rig.and_then(|r| r.glb.as_deref().map(|g| (r, g))) {
        Some((rig, glb)) => onto_rig::onto_rig_glb(rig, glb, &people),
        None => posed_glb(&people),
    };
    written.map_err(|e| format!("{origin}: cannot export as glTF: {e}"))
}

/// The `.glb` file of `people` (one skeleton each, on the 22-joint export rig).
pub fn glb_bytes(people: &[Motion]) -> Result<Vec<u8>, FeatureError> {
    let posed = people
        .iter()
        .map(posed::from_export_rig)
        .collect::<Result<Vec<_>, _>>()?;
    Ok(posed_glb(&posed).expect("the export rig has 27 joints"))
}

/// The `.glb` file of posed skeletons; an error only for a skeleton over 65,535 joints.
pub fn posed_glb(people: &[Posed]) -> Result<Vec<u8>, String> {
    let mut b = Builder::default();
    b.doc.asset = Asset {
        version: "2.0".into(),
        generator: concat!("mprog ", env!("CARGO_PKG_VERSION")).into(),
    };
    b.doc.materials = vec![Material {
        name: "body".into(),
        pbr: Pbr {
            base_color_factor: [0.78, 0.62, 0.5, 1.0],
            metallic_factor: 0.0,
            roughness_factor: 0.8,
        },
    }];
    let mut animation = Animation {
        name: "mprog".into(),
        ..Animation::default()
    };
    let mut roots = Vec::new();
    for (i, p) in people.iter().enumerate() {
        let prefix = if people.len() == 1 {
            String::new()
        } else {
            format!("p{}_", i + 1)
        };
        roots.extend(b.person(p, &prefix, &mut animation)?);
    }
    b.doc.scenes = vec![Scene {
        name: "mprog".into(),
        nodes: roots,
    }];
    b.doc.animations = vec![animation];
    Ok(b.finish())
}

/// The document and binary chunk being built.
#[derive(Default)]
struct Builder {
    doc: Document,
    bin: Vec<u8>,
}

impl Builder {
    /// Adds one person's joint nodes, skin, body and animation tracks; returns the scene
    /// roots it adds (its skeleton roots and its body node).
    fn person(
        &mut self,
        p: &Posed,
        prefix: &str,
        animation: &mut Animation,
    ) -> Result<Vec<usize>, String> {
        if p.is_empty() {
            return Err("the motion has no frames".into());
        }
        let base = self.doc.nodes.len();
        // Node of each joint (End Sites have none).
        let mut node_of = vec![None; p.joints.len()];
        let mut next = base;
        for (i, j) in p.joints.iter().enumerate() {
            if !j.end_site {
                node_of[i] = Some(next);
                next += 1;
            }
        }
        let count = next - base;
        if count > usize::from(u16::MAX) {
            return Err(format!(
                "{count} joints, over the {} a skin can bind",
                u16::MAX
            ));
        }
        let rest = p.rest_positions();
        let mut roots = Vec::new();
        for (i, j) in p.joints.iter().enumerate() {
            let Some(_) = node_of[i] else { continue };
            let translation = if i == p.mover {
                p.translations[0]
            } else {
                j.offset
            };
            let children = p
                .joints
                .iter()
                .enumerate()
                .filter(|(_, c)| c.parent == Some(i))
                .filter_map(|(c, _)| node_of[c])
                .collect();
            if j.parent.is_none() {
                roots.push(node_of[i].expect("a joint node"));
            }
            self.doc.nodes.push(Node {
                name: format!("{prefix}{}", j.name),
                children,
                rotation: quat(DQuat::IDENTITY),
                translation: vec3(translation),
                ..Node::default()
            });
        }
        let skin_joint: Vec<Option<u16>> = node_of
            .iter()
            .map(|n| n.map(|n| (n - base) as u16))
            .collect();
        // Inverse bind matrices: the rest pose has no rotations, so each is a translation.
        let ibm: Vec<f32> = (0..p.joints.len())
            .filter(|&i| node_of[i].is_some())
            .flat_map(|i| {
                let t = -rest[i].as_vec3();
                [
                    1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, t.x, t.y, t.z, 1.0,
                ]
            })
            .collect();
        let ibm = self.floats("MAT4", &ibm, None, None);
        self.doc.skins.push(Skin {
            name: format!("{prefix}skeleton"),
            inverse_bind_matrices: ibm,
            skeleton: roots[0],
            joints: (base..next).collect(),
        });
        let mesh = body::body_mesh(p, &rest, &skin_joint);
        let body_node = self.body(&mesh, prefix);
        roots.push(body_node);

        let times: Vec<f32> = (0..p.len()).map(|f| f as f32 / p.fps).collect();
        let last = times[times.len() - 1];
        let input = self.floats("SCALAR", &times, Some((vec![0.0], vec![last])), None);
        for (i, n) in node_of.iter().enumerate() {
            let Some(n) = *n else { continue };
            let values: Vec<f32> = p.rotations.iter().flat_map(|r| quat(r[i])).collect();
            let output = self.floats("VEC4", &values, None, None);
            track(animation, input, output, n, "rotation");
        }
        let moved: Vec<f32> = p.translations.iter().flat_map(|t| vec3(*t)).collect();
        let output = self.floats("VEC3", &moved, None, None);
        let mover = node_of[p.mover].expect("the mover is a joint");
        track(animation, input, output, mover, "translation");
        Ok(roots)
    }

    /// Adds the body mesh and the node that draws it with the last skin; returns the node.
    fn body(&mut self, mesh: &body::BodyMesh, prefix: &str) -> usize {
        let flat = |v: &[[f32; 3]]| v.iter().flatten().copied().collect::<Vec<f32>>();
        let positions = flat(&mesh.positions);
        let (mut min, mut max) = ([f32::MAX; 3], [f32::MIN; 3]);
        for p in &mesh.positions {
            for k in 0..3 {
                min[k] = min[k].min(p[k]);
                max[k] = max[k].max(p[k]);
            }
        }
        if mesh.positions.is_empty() {
            (min, max) = ([0.0; 3], [0.0; 3]);
        }
        let mut attributes = std::collections::BTreeMap::new();
        let pos = self.floats(
            "VEC3",
            &positions,
            Some((min.to_vec(), max.to_vec())),
            Some(ARRAY_BUFFER),
        );
        attributes.insert("POSITION".to_string(), pos);
        let normals = self.floats("VEC3", &flat(&mesh.normals), None, Some(ARRAY_BUFFER));
        attributes.insert("NORMAL".to_string(), normals);
        let joints: Vec<u8> = mesh
            .joints
            .iter()
            .flat_map(|&j| [j, 0, 0, 0])
            .flat_map(u16::to_le_bytes)
            .collect();
        let joints = self.raw(
            "VEC4",
            UNSIGNED_SHORT,
            &joints,
            mesh.joints.len(),
            ARRAY_BUFFER,
        );
        attributes.insert("JOINTS_0".to_string(), joints);
        let weights: Vec<f32> = mesh
            .joints
            .iter()
            .flat_map(|_| [1.0, 0.0, 0.0, 0.0])
            .collect();
        let weights = self.floats("VEC4", &weights, None, Some(ARRAY_BUFFER));
        attributes.insert("WEIGHTS_0".to_string(), weights);
        let indices: Vec<u8> = mesh.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let indices = self.raw(
            "SCALAR",
            UNSIGNED_INT,
            &indices,
            mesh.indices.len(),
            ELEMENT_ARRAY_BUFFER,
        );
        self.doc.meshes.push(Mesh {
            name: format!("{prefix}body"),
            primitives: vec![Primitive {
                attributes,
                indices,
                material: 0,
            }],
        });
        self.doc.nodes.push(Node {
            name: format!("{prefix}body"),
            rotation: quat(DQuat::IDENTITY),
            mesh: Some(self.doc.meshes.len() - 1),
            skin: Some(self.doc.skins.len() - 1),
            ..Node::default()
        });
        self.doc.nodes.len() - 1
    }

    /// Appends float32 `values` as an accessor of `kind`.
    fn floats(
        &mut self,
        kind: &str,
        values: &[f32],
        min_max: Option<(Vec<f32>, Vec<f32>)>,
        target: Option<u32>,
    ) -> usize {
        let width = match kind {
            "VEC3" => 3,
            "VEC4" => 4,
            "MAT4" => 16,
            _ => 1,
        };
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let a = self.view(&bytes, target);
        let (min, max) = min_max.unzip();
        self.doc.accessors.push(Accessor {
            buffer_view: a,
            component_type: FLOAT,
            count: values.len() / width,
            kind: kind.into(),
            min,
            max,
        });
        self.doc.accessors.len() - 1
    }

    /// Appends integer data (`count` elements of `kind` of `component`) as an accessor.
    fn raw(
        &mut self,
        kind: &str,
        component: u32,
        bytes: &[u8],
        count: usize,
        target: u32,
    ) -> usize {
        let a = self.view(bytes, Some(target));
        self.doc.accessors.push(Accessor {
            buffer_view: a,
            component_type: component,
            count,
            kind: kind.into(),
            min: None,
            max: None,
        });
        self.doc.accessors.len() - 1
    }

    /// Appends `bytes` as a buffer view starting on a 4-byte boundary; returns the view.
    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        pad(&mut self.bin, 0);
        let byte_offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.doc.buffer_views.push(BufferView {
            buffer: 0,
            byte_offset,
            byte_length: bytes.len(),
            target,
        });
        self.doc.buffer_views.len() - 1
    }

    /// The `.glb`: header, JSON chunk, binary chunk, each chunk padded to 4 bytes.
    fn finish(mut self) -> Vec<u8> {
        self.doc.buffers = vec![Buffer {
            byte_length: self.bin.len(),
        }];
        let mut json = serde_json::to_vec(&self.doc).expect("the document is plain data");
        pad(&mut json, b' ');
        let mut bin = self.bin;
        pad(&mut bin, 0);
        let total = 12 + 8 + json.len() + 8 + bin.len();
        let mut out = Vec::with_capacity(total);
        for word in [GLB_MAGIC, 2, total as u32, json.len() as u32, CHUNK_JSON] {
            out.extend(word.to_le_bytes());
        }
        out.extend(json);
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(CHUNK_BIN.to_le_bytes());
        out.extend(bin);
        out
    }
}

/// Adds a LINEAR track driving `path` of `node`.
fn track(animation: &mut Animation, input: usize, output: usize, node: usize, path: &str) {
    animation.samplers.push(Sampler {
        input,
        output,
        interpolation: "LINEAR".into(),
    });
    animation.channels.push(Channel {
        sampler: animation.samplers.len() - 1,
        target: Target {
            node,
            path: path.into(),
        },
    });
}

fn pad(bytes: &mut Vec<u8>, with: u8) {
    while !bytes.len().is_multiple_of(4) {
        bytes.push(with);
    }
}

fn quat(q: DQuat) -> [f32; 4] {
    [q.x as f32, q.y as f32, q.z as f32, q.w as f32]
}

fn vec3(v: DVec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}
