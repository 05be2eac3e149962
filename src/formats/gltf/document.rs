//! The few glTF 2.0 structures mprog writes, as serde types: a scene of nodes, one buffer,
//! its views, accessors, one animation, and per person a skin and its body mesh. Field names follow the specification
//! (<https://registry.khronos.org/glTF/specs/2.0/glTF-2.0.html>); empty fields are left out.

use serde::{Deserialize, Serialize};

/// `componentType` of 32-bit floats.
pub const FLOAT: u32 = 5126;
/// `componentType` of 16-bit unsigned integers (`JOINTS_0`).
pub const UNSIGNED_SHORT: u32 = 5123;
/// `componentType` of 32-bit unsigned integers (indices).
pub const UNSIGNED_INT: u32 = 5125;
/// `bufferView.target` of vertex attributes.
pub const ARRAY_BUFFER: u32 = 34962;
/// `bufferView.target` of indices.
pub const ELEMENT_ARRAY_BUFFER: u32 = 34963;

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
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub skins: Vec<Skin>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub meshes: Vec<Mesh>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub materials: Vec<Material>,
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
    /// The mesh drawn at this node.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<usize>,
    /// The skin that deforms that mesh.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub skin: Option<usize>,
}

/// A skeleton for skinning: its joint nodes and their inverse bind matrices.
#[derive(Debug, Default, Serialize, Deserialize)]
pub struct Skin {
    pub name: String,
    /// Accessor of one column-major `MAT4` per joint.
    #[serde(rename = "inverseBindMatrices")]
    pub inverse_bind_matrices: usize,
    /// The root of the joint hierarchy.
    pub skeleton: usize,
    pub joints: Vec<usize>,
}

/// A mesh: one triangle list.
#[derive(Debug, Default, Serialize, Deserialize)]
pub struct Mesh {
    pub name: String,
    pub primitives: Vec<Primitive>,
}

/// Vertex attributes (accessors by name: `POSITION`, `NORMAL`, `JOINTS_0`, `WEIGHTS_0`),
/// indices and material of one triangle list.
#[derive(Debug, Default, Serialize, Deserialize)]
pub struct Primitive {
    pub attributes: std::collections::BTreeMap<String, usize>,
    pub indices: usize,
    pub material: usize,
}

/// A plain PBR material.
#[derive(Debug, Default, Serialize, Deserialize)]
pub struct Material {
    pub name: String,
    #[serde(rename = "pbrMetallicRoughness")]
    pub pbr: Pbr,
}

/// Base colour, metalness and roughness.
#[derive(Debug, Default, Serialize, Deserialize)]
pub struct Pbr {
    #[serde(rename = "baseColorFactor")]
    pub base_color_factor: [f32; 4],
    #[serde(rename = "metallicFactor")]
    pub metallic_factor: f32,
    #[serde(rename = "roughnessFactor")]
    pub roughness_factor: f32,
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
    /// What the GPU binds it as (vertex attributes or indices); absent for animation data.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<u32>,
}

/// Typed elements of a buffer view: `count` × `type` (`SCALAR`, `VEC3`, `VEC4`, `MAT4`) of
/// `componentType`.
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
