//! glTF 2.0 binary export (`.glb`), the open format of the web, three.js and the game
//! engines: in, the motions of the people; out, one file where each person is a skin-less
//! skeleton of nodes animated at the motion's frame rate.
//!
//! * Nodes: the export rig ([`super::rig`]): the 22 HumanML3D joints, named after them
//!   (`p2_pelvis`, … for the second person when there are several), each translated by its
//!   rest offset (rest direction × the motion's mean bone length) from its parent, with the
//!   zero-offset connectors where bones branch. The rest rotations are those of frame 0.
//! * Animation: one, `mprog`: every node's rotation (LINEAR, so slerp; consecutive
//!   quaternions are kept in one hemisphere) and the pelvis's translation, one key per
//!   frame at `frame / fps` seconds.
//! * Axes and units are glTF's own: metres, Y up, right-handed, as mprog.
//! * The file is the 12-byte header, the JSON chunk ([`document`]) padded with spaces, and
//!   the binary chunk of little-endian float32 data.

pub mod document;
#[cfg(test)]
mod tests;

use super::outputs::OutputJob;
use super::rig;
use crate::features::FeatureError;
use crate::features::kinematics;
use crate::motion::Motion;
use document::{
    Accessor, Animation, Asset, Buffer, BufferView, Channel, Document, FLOAT, Node, Sampler, Scene,
    Target,
};
use glam::{DQuat, DVec3};

/// `glTF`: the first four bytes of a `.glb`.
pub const GLB_MAGIC: u32 = 0x4654_6C67;
/// Type of the JSON chunk.
pub const CHUNK_JSON: u32 = 0x4E4F_534A;
/// Type of the binary chunk.
pub const CHUNK_BIN: u32 = 0x004E_4942;

/// Writer of the output table: the `.glb` of every person of the job.
pub fn encode(origin: &str, job: &OutputJob) -> Result<Vec<u8>, String> {
    glb_bytes(job.people).map_err(|e| format!("{origin}: cannot export as glTF: {e}"))
}

/// The `.glb` file of `people` (one skeleton each).
pub fn glb_bytes(people: &[Motion]) -> Result<Vec<u8>, FeatureError> {
    let mut b = Builder::default();
    b.doc.asset = Asset {
        version: "2.0".into(),
        generator: concat!("mprog ", env!("CARGO_PKG_VERSION")).into(),
    };
    let mut animation = Animation {
        name: "mprog".into(),
        ..Animation::default()
    };
    let mut roots = Vec::new();
    for (i, m) in people.iter().enumerate() {
        let prefix = if people.len() == 1 {
            String::new()
        } else {
            format!("p{}_", i + 1)
        };
        roots.push(b.person(m, &prefix, &mut animation)?);
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
    /// Adds one person's nodes and animation tracks; returns its root node.
    fn person(
        &mut self,
        m: &Motion,
        prefix: &str,
        animation: &mut Animation,
    ) -> Result<usize, FeatureError> {
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
        keep_hemisphere(&mut rotations);
        let base = self.doc.nodes.len();
        for (id, node) in nodes.iter().enumerate() {
            let translation = if id == 0 {
                poses[0][0]
            } else {
                rig::rest_offset(node, &lengths)
            };
            self.doc.nodes.push(Node {
                name: format!("{prefix}{}", node.name),
                children: node.children.iter().map(|c| c + base).collect(),
                rotation: quat(rotations[0][id]),
                translation: vec3(translation),
            });
        }
        let times: Vec<f32> = (0..poses.len()).map(|f| f as f32 / m.fps).collect();
        let last = times[times.len() - 1];
        let input = self.accessor("SCALAR", &times, Some((vec![0.0], vec![last])));
        for id in 0..nodes.len() {
            let values: Vec<f32> = rotations.iter().flat_map(|r| quat(r[id])).collect();
            let output = self.accessor("VEC4", &values, None);
            track(animation, input, output, base + id, "rotation");
        }
        let root: Vec<f32> = poses.iter().flat_map(|p| vec3(p[0])).collect();
        let output = self.accessor("VEC3", &root, None);
        track(animation, input, output, base, "translation");
        Ok(base)
    }

    /// Appends float32 `values` to the binary chunk as an accessor of `kind`.
    fn accessor(
        &mut self,
        kind: &str,
        values: &[f32],
        min_max: Option<(Vec<f32>, Vec<f32>)>,
    ) -> usize {
        let width = match kind {
            "VEC3" => 3,
            "VEC4" => 4,
            _ => 1,
        };
        let byte_offset = self.bin.len();
        self.bin.extend(values.iter().flat_map(|v| v.to_le_bytes()));
        self.doc.buffer_views.push(BufferView {
            buffer: 0,
            byte_offset,
            byte_length: values.len() * 4,
        });
        let (min, max) = min_max.unzip();
        self.doc.accessors.push(Accessor {
            buffer_view: self.doc.buffer_views.len() - 1,
            component_type: FLOAT,
            count: values.len() / width,
            kind: kind.into(),
            min,
            max,
        });
        self.doc.accessors.len() - 1
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

/// Flips quaternions that point away from the previous frame's: q and −q are the same
/// rotation, but slerp between opposite signs takes the long way round.
fn keep_hemisphere(rotations: &mut [Vec<DQuat>]) {
    for f in 1..rotations.len() {
        for id in 0..rotations[f].len() {
            if rotations[f][id].dot(rotations[f - 1][id]) < 0.0 {
                rotations[f][id] = -rotations[f][id];
            }
        }
    }
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
