//! The one table of output kinds: every file mprog writes from a motion (`-o` of
//! `convert`, `render`, `gen`, `run`, `data`, and the REPL's `:save`) is picked here by
//! extension, and nowhere else.
//!
//! In: output paths + an [`OutputJob`] (people, meta, title, BVH settings).
//! Out: the files, written atomically, plus the `.meta.json` sidecars the kinds ask for.
//! Every output is encoded before the first is written, so a motion one kind refuses (a
//! BVH pose with no facing direction, a non-finite joint) leaves no file behind.
//!
//! A new kind is one writer function (in [`super::writers`] or its own module) and one row
//! of [`OUTPUT_KINDS`].

use super::bvh_export::BvhExportOptions;
use super::writers;
use crate::motion::{Meta, Motion};
use std::path::{Path, PathBuf};

/// Everything a writer may draw on.
pub struct OutputJob<'a> {
    /// The motions, one per person (one person when the kind writes a file per person).
    pub people: &'a [Motion],
    /// Reproduction metadata and scene geometry (overlays, contacts, timelines).
    pub meta: &'a Meta,
    /// Title of pictures and pages.
    pub title: &'a str,
    /// Units, axes and frame rate of BVH files.
    pub bvh: &'a BvhExportOptions,
    /// The user's rig (`--rig`): BVH and glTF outputs take its skeleton.
    pub rig: Option<&'a super::Character>,
}

/// A writer: the bytes of one file, or a message saying why the job cannot be written.
/// `origin` names the file in messages.
pub type Encode = fn(origin: &str, job: &OutputJob) -> Result<Vec<u8>, String>;

/// The file written next to an output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sidecar {
    /// None.
    None,
    /// `<name>.meta.json` holding the job's meta plus `fps` ([`super::sidecar`]).
    MetaJson,
}

/// One kind of output file.
#[derive(Debug)]
pub struct OutputKind {
    /// Extensions, lower case, without the dot; the first is the one help text shows.
    pub extensions: &'static [&'static str],
    /// What the file holds, for help text.
    pub what: &'static str,
    /// Whether several people go to several files (`out_p1.bvh`, `out_p2.bvh`, …).
    pub file_per_person: bool,
    /// The file written next to it.
    pub sidecar: Sidecar,
    /// The writer.
    pub encode: Encode,
}

/// Every output kind, in help order.
pub const OUTPUT_KINDS: &[OutputKind] = &[
    OutputKind {
        extensions: &["bvh"],
        what: "a skeleton with rotations per joint (ZYX Euler angles), root translation, frame rate and axes in the header comments; for Blender, MotionBuilder, Maya; with --rig, the rig's own joints, offsets, channels and units",
        file_per_person: true,
        sidecar: Sidecar::None,
        encode: writers::bvh,
    },
    OutputKind {
        extensions: &["npy"],
        what: "joint positions `[frames, 22, 3]` (one person) or `[people, frames, 22, 3]`, float32, metres, Y up, 20 fps; for research code (HumanML3D order)",
        file_per_person: false,
        sidecar: Sidecar::MetaJson,
        encode: writers::npy,
    },
    OutputKind {
        extensions: &["json"],
        what: "joint positions per person and frame, joint names, units, axes, fps and the meta; `mprog view` and the REPL read it back",
        file_per_person: false,
        sidecar: Sidecar::None,
        encode: writers::json,
    },
    OutputKind {
        extensions: &["glb"],
        what: "glTF 2.0 binary: each person a skinned skeleton (joint nodes at their rest offsets, a skin with inverse bind matrices) with a simple body mesh, animated by rotations and root translation; for three.js, game engines, Blender; with --rig, the rig's skeleton; with a .glb rig, that file (its mesh and skin) animated",
        file_per_person: false,
        sidecar: Sidecar::None,
        encode: super::gltf::encode,
    },
    OutputKind {
        extensions: &["gif"],
        what: "an animated stick figure: side view and a top view of the path, with the program's geometry",
        file_per_person: false,
        sidecar: Sidecar::None,
        encode: writers::gif,
    },
    OutputKind {
        extensions: &["png"],
        what: "a strip of frames of the same drawing",
        file_per_person: false,
        sidecar: Sidecar::None,
        encode: writers::png,
    },
    OutputKind {
        extensions: &["html", "htm"],
        what: "the 3-D viewer page, with the program's geometry and error timeline",
        file_per_person: false,
        sidecar: Sidecar::None,
        encode: writers::html,
    },
];

/// Why outputs were not written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// No kind has the path's extension.
    #[error("cannot write {path}: unknown extension; use {known}")]
    UnknownKind {
        /// The output.
        path: String,
        /// The extensions mprog writes.
        known: String,
    },
    /// A writer refused the job; nothing was written.
    #[error("{message}; nothing was written")]
    Encode {
        /// The writer's message, naming the file.
        message: String,
    },
    /// A sidecar could not be written (the message names it).
    #[error("{0}")]
    Sidecar(String),
    /// The file system refused a file.
    #[error("cannot write {path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        message: String,
    },
}

/// The kind of `path`, by its extension (case-insensitive).
pub fn output_kind(path: &Path) -> Result<&'static OutputKind, OutputError> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    OUTPUT_KINDS
        .iter()
        .find(|k| k.extensions.contains(&ext.as_str()))
        .ok_or_else(|| OutputError::UnknownKind {
            path: path.display().to_string(),
            known: extension_list(),
        })
}

/// Whether every output is of a kind mprog writes (before any work is done, so a typo
/// does not cost a generation).
pub fn check_outputs(outputs: &[PathBuf]) -> Result<(), OutputError> {
    outputs.iter().try_for_each(|o| output_kind(o).map(|_| ()))
}

/// `.bvh, .npy, … or .html`: the extensions help text and errors offer.
pub fn extension_list() -> String {
    let names: Vec<String> = OUTPUT_KINDS
        .iter()
        .map(|k| format!(".{}", k.extensions[0]))
        .collect();
    match names.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        _ => names.concat(),
    }
}

/// One line per kind (`.bvh  BVH skeleton animation, …`), for long help.
pub fn kinds_help() -> String {
    OUTPUT_KINDS
        .iter()
        .map(|k| format!(".{:<5} {}", k.extensions[0], k.what))
        .collect::<Vec<_>>()
        .join("\n")
}

/// `out.bvh` → `out_p{i+1}.bvh`: person `i`'s file when a kind writes one per person.
pub fn per_person(out: &Path, i: usize) -> PathBuf {
    let stem = out.file_stem().unwrap_or_default().to_string_lossy();
    let ext = out.extension().unwrap_or_default().to_string_lossy();
    out.with_file_name(format!("{stem}_p{}.{ext}", i + 1))
}

/// Writes every output of `job`; returns the files written, sidecars included, in order.
pub fn write_outputs(outputs: &[PathBuf], job: &OutputJob) -> Result<Vec<PathBuf>, OutputError> {
    check_outputs(outputs)?;
    let mut files = Vec::new();
    for out in outputs {
        let kind = output_kind(out)?;
        for (path, people) in split_people(out, kind, job.people) {
            let origin = path.display().to_string();
            let part = OutputJob { people, ..*job };
            let bytes =
                (kind.encode)(&origin, &part).map_err(|message| OutputError::Encode { message })?;
            files.push((path, bytes, kind.sidecar, people));
        }
    }
    let mut written = Vec::new();
    for (path, bytes, sidecar, people) in files {
        crate::fsutil::write_bytes_atomic(&path, &bytes).map_err(|e| io_error(&path, e))?;
        written.push(path.clone());
        if sidecar == Sidecar::MetaJson {
            let mut meta = job.meta.clone();
            if let Some(m) = people.first() {
                meta.entry("fps").or_insert(m.fps.into());
            }
            let side = super::write_sidecar_meta(&path, &meta)
                .map_err(|e| OutputError::Sidecar(e.to_string()))?;
            written.push(side);
        }
    }
    Ok(written)
}

/// The files of one output and the people each holds.
fn split_people<'a>(
    out: &Path,
    kind: &OutputKind,
    people: &'a [Motion],
) -> Vec<(PathBuf, &'a [Motion])> {
    if kind.file_per_person && people.len() > 1 {
        (0..people.len())
            .map(|i| (per_person(out, i), &people[i..=i]))
            .collect()
    } else {
        vec![(out.to_path_buf(), people)]
    }
}

fn io_error(path: &Path, e: impl std::fmt::Display) -> OutputError {
    OutputError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::test_motion::walk;
    use glam::Vec3;

    #[test]
    fn every_extension_names_one_kind() {
        let mut seen = std::collections::HashSet::new();
        for k in OUTPUT_KINDS {
            for e in k.extensions {
                assert!(seen.insert(*e), ".{e} is in two rows");
                assert_eq!(*e, e.to_ascii_lowercase());
            }
        }
        assert!(output_kind(Path::new("A.BVH")).is_ok());
        let e = output_kind(Path::new("x.txt")).unwrap_err().to_string();
        assert!(
            e.contains("x.txt") && e.contains(".bvh") && e.contains(" or "),
            "{e}"
        );
    }

    #[test]
    fn people_split_by_kind_sidecars_follow_and_a_refusal_writes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let people = [
            walk(6, 1.0, Vec3::ZERO, Vec3::Z),
            walk(6, 1.0, Vec3::X, Vec3::Z),
        ];
        let meta = Meta::new();
        let job = OutputJob {
            people: &people,
            meta: &meta,
            title: "two",
            bvh: &BvhExportOptions::default(),
            rig: None,
        };
        let outs = [dir.path().join("a.npy"), dir.path().join("a.bvh")];
        let written = write_outputs(&outs, &job).unwrap();
        let names: Vec<String> = written
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["a.npy", "a.meta.json", "a_p1.bvh", "a_p2.bvh"]);

        // A pose with no facing direction: BVH refuses it, so the .npy before it is not
        // written either.
        let mut flat = people[0].clone();
        for pose in &mut flat.frames {
            *pose = [Vec3::new(0.0, 1.0, 0.0); crate::skeleton::NUM_JOINTS];
        }
        let broken = OutputJob {
            people: std::slice::from_ref(&flat),
            ..job
        };
        let outs = [dir.path().join("b.npy"), dir.path().join("b.bvh")];
        let e = write_outputs(&outs, &broken).unwrap_err().to_string();
        assert!(
            e.contains("b.bvh") && e.contains("nothing was written"),
            "{e}"
        );
        assert!(!dir.path().join("b.npy").exists());
    }
}
