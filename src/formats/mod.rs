//! Motion file formats: BVH import ([`bvh`]) and export ([`bvh_export`]), `.npy` joint and
//! feature arrays ([`npy`]) with their `.meta.json` sidecars ([`sidecar`]), `.json`
//! documents with reproduction metadata ([`json`]), and one entry point for all of them
//! ([`read_motion`], [`write_motion`]).

pub mod asf;
pub mod bvh;
pub mod bvh_export;
mod file;
pub mod json;
pub mod npy;
pub mod sidecar;

#[cfg(test)]
mod tests;

pub use bvh::{BvhError, BvhImport, BvhImportOptions, import_bvh, import_bvh_str};
pub use file::{FormatError, LoadedMotion, read_motion, write_motion, write_motion_with};
pub use json::{Meta, Person};
pub use npy::{MotionFile, NpyArray};
pub use sidecar::{read_sidecar_meta, sidecar_path, write_sidecar_meta};
