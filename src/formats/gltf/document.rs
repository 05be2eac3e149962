//! The few glTF 2.0 structures mprog writes, as serde types: a scene of nodes, one buffer,
//! its views, accessors and one animation. Field names follow the specification
//! (<https://registry.khronos.org/glTF/specs/2.0/glTF-2.0.html>); empty fields are left out.

use serde::{Deserialize, Serialize};

/// `componentType` of 32-bit floats.
pub const FLOAT: u32 = 5126;

/// The JSON chunk of a `.glb`.
#[derive(Debug, Default, Serialize, Deserialize)]
pub struct Document {
    pub asset: Asset,
    pub scene: usize,
    pub scenes: Vec<Scene>,
    pub nodes: Vec<Node>,
    pub buffers: Vec<Buffer>,
    #[serde(rename = "bufferViews")]
    pub buffer_views: Vec<BufferView>,
    pub accessors: Vec<Accessor>,
    pub animations: Vec<Animation>,
}

/// Who wrote the file, and the format version ("2.0").
#[derive(Debug, Default, Serialize, Deserialize)]
pub struct Asset {
    pub version: String,
    pub generator: String,
}

/// The root nodes shown together.
#[derive(Debug, Default, Serialize, Deserialize)]
pub struct Scene {
    pub name: String,
    pub nodes: Vec<usize>,
}

/// A node: its rest transform relative to its parent, and its children.
#[derive(Debug, Default, Serialize, Deserialize)]
pub struct Node {
    pub name: String,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub children: Vec<usize>,
    /// Quaternion `[x, y, z, w]`.
    pub rotation: [f32; 4],
    pub translation: [f32; 3],
}

/// The binary chunk (a `.glb` has one buffer with no `uri`).
#[derive(Debug, Default, Serialize, Deserialize)]
pub struct Buffer {
    #[serde(rename = "byteLength")]
    pub byte_length: usize,
}

/// A byte range of the buffer.
#[derive(Debug, Default, Serialize, Deserialize)]
pub struct BufferView {
    pub buffer: usize,
    #[serde(rename = "byteOffset")]
    pub byte_offset: usize,
    #[serde(rename = "byteLength")]
    pub byte_length: usize,
}

/// Typed elements of a buffer view: `count` × `type` (`SCALAR`, `VEC3`, `VEC4`) floats.
#[derive(Debug, Default, Serialize, Deserialize)]
pub struct Accessor {
    #[serde(rename = "bufferView")]
    pub buffer_view: usize,
    #[serde(rename = "componentType")]
    pub component_type: u32,
    pub count: usize,
    #[serde(rename = "type")]
    pub kind: String,
    /// Required for animation inputs (the key times).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<Vec<f32>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<Vec<f32>>,
}

/// Keyframe tracks driving node properties.
#[derive(Debug, Default, Serialize, Deserialize)]
pub struct Animation {
    pub name: String,
    pub channels: Vec<Channel>,
    pub samplers: Vec<Sampler>,
}

/// Which sampler drives which property of which node.
#[derive(Debug, Default, Serialize, Deserialize)]
pub struct Channel {
    pub sampler: usize,
    pub target: Target,
}

/// A node and its property: `rotation` or `translation`.
#[derive(Debug, Default, Serialize, Deserialize)]
pub struct Target {
    pub node: usize,
    pub path: String,
}

/// Key times (input accessor) and values (output accessor).
#[derive(Debug, Default, Serialize, Deserialize)]
pub struct Sampler {
    pub input: usize,
    pub output: usize,
    pub interpolation: String,
}
