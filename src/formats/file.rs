//! One door for motion files: [`read_motion`] and [`write_motion`] pick the format from
//! the extension.
//!
//! | extension | read |
//! | --- | --- |
//! | `.bvh` | [`super::bvh::import_bvh`], retargeted to 22 joints, 20 fps |
//! | `.npy` | `[N,22,3]`, `[P,N,22,3]` joints or `[N,263]` features; `meta` from the [`super::sidecar`] |
//! | `.json` | `mprog-motion` documents |
//!
//! Writing goes through the table of output kinds ([`super::outputs`]).
//!
//! Motions come back at mprog's 20 fps: BVH is resampled on import, JSON at other
//! rates is resampled here, `.npy` has no rate and is taken as 20 fps.

use super::bvh::{BvhError, BvhImportOptions, import_bvh};
use super::bvh_export::BvhExportOptions;
use super::json::{JsonError, Meta, Person, read_json};
use super::npy::{MotionFile, NpyArray, NpyError, read_motion_npy};
use super::outputs::{OutputJob, extension_list, output_kind};
use crate::motion::Motion;
use crate::skeleton::FPS;
use std::path::Path;

/// Any motion-file error.
#[derive(Debug, thiserror::Error)]
pub enum FormatError {
    #[error(transparent)]
    Bvh(#[from] BvhError),
    #[error(transparent)]
    Npy(#[from] NpyError),
    #[error(transparent)]
    Json(#[from] JsonError),
    #[error("{path}: {what}")]
    Unsupported { path: String, what: String },
    /// A writer of the output table refused the motion (the message names the file).
    #[error("{0}")]
    Refused(String),
}

/// What [`read_motion`] found.
#[derive(Clone, Debug, PartialEq)]
pub enum LoadedMotion {
    /// Joint positions of one or more people at 20 fps.
    Joints {
        people: Vec<Person>,
        /// The file's `meta` (JSON) or import facts (BVH: source fps, units, joint map).
        meta: Meta,
    },
    /// HumanML3D features, to be turned into joints by `recover_from_ric`.
    Features(NpyArray),
}

/// Reads a `.bvh`, `.npy` or `.json` motion file.
pub fn read_motion(path: &Path) -> Result<LoadedMotion, FormatError> {
    match extension(path).as_str() {
        "bvh" => {
            let out = import_bvh(path, &BvhImportOptions::default())?;
            let mut meta = Meta::new();
            meta.insert("source_fps".into(), out.source_fps.into());
            meta.insert("source_frames".into(), out.source_frames.into());
            meta.insert("unit_scale".into(), out.unit_scale.into());
            meta.insert("rig".into(), out.joint_map.rig.into());
            meta.insert("joint_map".into(), out.joint_map_lines.clone().into());
            meta.insert("warnings".into(), out.warnings.clone().into());
            let name = path
                .file_stem()
                .map_or("person 1".into(), |s| s.to_string_lossy().to_string());
            Ok(LoadedMotion::Joints {
                people: vec![Person {
                    name,
                    motion: out.motion,
                }],
                meta,
            })
        }
        "npy" => Ok(match read_motion_npy(path)? {
            MotionFile::Joints(motions) => LoadedMotion::Joints {
                people: default_names(motions),
                meta: super::sidecar::read_sidecar_meta(path)?.unwrap_or_default(),
            },
            MotionFile::Features(array) => LoadedMotion::Features(array),
        }),
        "json" => {
            let (people, meta) = read_json(path)?;
            let people = people
                .into_iter()
                .map(|p| Person {
                    motion: p.motion.resample(FPS),
                    ..p
                })
                .collect();
            Ok(LoadedMotion::Joints { people, meta })
        }
        other => Err(unsupported(
            path,
            format!("cannot read `.{other}` files: expected .bvh, .npy or .json"),
        )),
    }
}

/// Writes motions (one per person) as one file of any kind in the output table
/// ([`super::outputs`]): `.npy`, `.json`, `.bvh` (one person, Y up, metres, the motion's
/// frame rate), pictures or pages. Unlike [`super::outputs::write_outputs`] it writes no
/// sidecar and never splits people into files.
pub fn write_motion(path: &Path, motions: &[Motion], meta: &Meta) -> Result<(), FormatError> {
    write_motion_with(path, motions, meta, &BvhExportOptions::default())
}

/// [`write_motion`] with the units, axes and frame rate of a BVH output.
pub fn write_motion_with(
    path: &Path,
    motions: &[Motion],
    meta: &Meta,
    bvh: &BvhExportOptions,
) -> Result<(), FormatError> {
    let kind = output_kind(path).map_err(|_| {
        unsupported(
            path,
            format!(
                "cannot write `.{}` files: expected {}",
                extension(path),
                extension_list()
            ),
        )
    })?;
    let origin = path.display().to_string();
    let title = path
        .file_stem()
        .map_or(String::new(), |s| s.to_string_lossy().into_owned());
    let job = OutputJob {
        people: motions,
        meta,
        title: &title,
        bvh,
        rig: None,
    };
    let bytes = (kind.encode)(&origin, &job).map_err(FormatError::Refused)?;
    crate::fsutil::write_bytes_atomic(path, &bytes)
        .map_err(|e| unsupported(path, format!("cannot write: {e}")))
}

/// People named `person 1`, `person 2`, … in order.
pub(super) fn default_names(motions: Vec<Motion>) -> Vec<Person> {
    motions
        .into_iter()
        .enumerate()
        .map(|(i, motion)| Person {
            name: format!("person {}", i + 1),
            motion,
        })
        .collect()
}

fn extension(path: &Path) -> String {
    path.extension()
        .map_or(String::new(), |e| e.to_string_lossy().to_ascii_lowercase())
}

fn unsupported(path: &Path, what: String) -> FormatError {
    FormatError::Unsupported {
        path: path.display().to_string(),
        what,
    }
}
