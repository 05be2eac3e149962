//! Motion file formats: BVH import ([`bvh`]) and export ([`bvh_export`]), `.npy` joint and
//! feature arrays ([`npy`]) with their `.meta.json` sidecars ([`sidecar`]), `.json`
//! documents with reproduction metadata ([`json`]), and one entry point for reading them
//! ([`read_motion`]).
//!
//! Motions go onto a user's own rig through [`character`] (`--rig`): the BVH and glTF
//! writers take the rig's skeleton animated by rotations ([`posed::Posed`]).
//!
//! Every output, motion data, pictures and pages alike, is one row of the table of output
//! kinds ([`outputs::OUTPUT_KINDS`]); [`write_outputs`] is the export stage's entry point.

pub mod asf;
pub mod bvh;
pub mod bvh_export;
pub mod character;
mod file;
pub mod gltf;
pub mod json;
pub mod npy;
pub mod outputs;
pub mod posed;
pub mod rig;
pub mod sidecar;
pub mod writers;

#[cfg(test)]
mod tests;

pub use bvh::{BvhError, BvhImport, BvhImportOptions, import_bvh, import_bvh_str};
pub use character::{Character, RigError};
pub use file::{FormatError, LoadedMotion, read_motion, write_motion, write_motion_with};
pub use json::{Meta, Person};
pub use npy::{MotionFile, NpyArray};
pub use outputs::{
    OUTPUT_KINDS, OutputError, OutputJob, OutputKind, check_outputs, output_kind, write_outputs,
};
pub use sidecar::{read_sidecar_meta, sidecar_path, write_sidecar_meta};
