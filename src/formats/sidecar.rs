//! Sidecar metadata: `.npy` arrays cannot carry the settings that made them, so every
//! `.npy` output gets a `<name>.meta.json` beside it (`walk.npy` → `walk.meta.json`):
//!
//! ```json
//! {"format": "mprog-meta", "version": 1, "describes": "walk.npy",
//!  "layout": "float32 [frames, 22, 3] or [people, frames, 22, 3]; metres, Y up, HumanML3D joint order",
//!  "joint_names": ["pelvis", …],
//!  "meta": {"seed": 7, "program": "…", "solver": {…}, "weights": "…", "fps": 20}}
//! ```
//!
//! [`write_sidecar_meta`] writes it (atomically); [`read_sidecar_meta`] finds and checks
//! it when the `.npy` is read again, so `meta` survives a `.npy` round trip.

use super::json::{JsonError, Meta};
use crate::skeleton::JOINT_NAMES;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Value of the `format` field.
pub const SIDECAR_FORMAT: &str = "mprog-meta";

const LAYOUT: &str =
    "float32 [frames, 22, 3] or [people, frames, 22, 3]; metres, Y up, HumanML3D joint order";

#[derive(Serialize, Deserialize)]
struct SidecarDocument {
    format: String,
    version: u32,
    describes: String,
    #[serde(default)]
    layout: String,
    #[serde(default)]
    joint_names: Vec<String>,
    meta: Meta,
}

/// Where the sidecar of `path` lives: the same name with `.meta.json` for its extension.
pub fn sidecar_path(path: &Path) -> PathBuf {
    path.with_extension("meta.json")
}

/// Writes the sidecar of the data file `path` holding `meta`; returns the sidecar's path.
pub fn write_sidecar_meta(path: &Path, meta: &Meta) -> Result<PathBuf, JsonError> {
    let side = sidecar_path(path);
    let doc = SidecarDocument {
        format: SIDECAR_FORMAT.into(),
        version: 1,
        describes: path
            .file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned()),
        layout: LAYOUT.into(),
        joint_names: JOINT_NAMES.iter().map(|n| n.to_string()).collect(),
        meta: meta.clone(),
    };
    crate::fsutil::write_atomic(&side, |w| {
        serde_json::to_writer_pretty(&mut *w, &doc).map_err(std::io::Error::other)?;
        w.write_all(b"\n")
    })
    .map_err(|source| JsonError::Write {
        path: side.display().to_string(),
        source,
    })?;
    Ok(side)
}

/// The `meta` of the sidecar of `path`, or `None` when there is none.
pub fn read_sidecar_meta(path: &Path) -> Result<Option<Meta>, JsonError> {
    let side = sidecar_path(path);
    let origin = side.display().to_string();
    let text = match std::fs::read_to_string(&side) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(source) => return Err(JsonError::Io { origin, source }),
    };
    let doc: SidecarDocument =
        serde_json::from_str(&text).map_err(|e| JsonError::syntax(&origin, &e))?;
    if doc.format != SIDECAR_FORMAT || doc.version != 1 {
        return Err(JsonError::Invalid {
            origin,
            message: format!(
                "`format` {:?} version {} is not an mprog sidecar ({SIDECAR_FORMAT:?} version 1)",
                doc.format, doc.version
            ),
        });
    }
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
    if name.as_deref() != Some(doc.describes.as_str()) {
        return Err(JsonError::Invalid {
            origin,
            message: format!(
                "describes {:?}, not {:?}; it belongs to another file (rename or delete it)",
                doc.describes,
                name.unwrap_or_default()
            ),
        });
    }
    Ok(Some(doc.meta))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn meta() -> Meta {
        json!({"seed": 7, "program": "keep pelvis.y > 0.5", "solver": {"steps": 50}, "weights": "abc123"})
            .as_object()
            .unwrap()
            .clone()
    }

    #[test]
    fn sidecar_sits_beside_the_file_and_round_trips() {
        assert_eq!(
            sidecar_path(Path::new("out/walk.npy")),
            Path::new("out/walk.meta.json")
        );
        let dir = tempfile::tempdir().unwrap();
        let npy = dir.path().join("walk.npy");
        assert_eq!(read_sidecar_meta(&npy).unwrap(), None);
        let side = write_sidecar_meta(&npy, &meta()).unwrap();
        assert_eq!(side, dir.path().join("walk.meta.json"));
        let doc: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&side).unwrap()).unwrap();
        assert_eq!(doc["format"], "mprog-meta");
        assert_eq!(doc["describes"], "walk.npy");
        assert_eq!(doc["meta"]["seed"], 7);
        assert_eq!(doc["joint_names"][0], "pelvis");
        assert_eq!(read_sidecar_meta(&npy).unwrap(), Some(meta()));
    }

    #[test]
    fn foreign_or_broken_sidecars_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.npy");
        write_sidecar_meta(&a, &meta()).unwrap();
        // The sidecar of a.npy copied next to b.npy does not describe b.npy.
        let b = dir.path().join("b.npy");
        std::fs::copy(sidecar_path(&a), sidecar_path(&b)).unwrap();
        let e = read_sidecar_meta(&b).unwrap_err().to_string();
        assert!(e.contains("describes \"a.npy\", not \"b.npy\""), "{e}");
        std::fs::write(sidecar_path(&b), "{\"format\": \"mprog-meta\",").unwrap();
        let e = read_sidecar_meta(&b).unwrap_err().to_string();
        assert!(e.contains("b.meta.json:1:"), "{e}");
        std::fs::write(
            sidecar_path(&b),
            r#"{"format": "other", "version": 1, "describes": "b.npy", "meta": {}}"#,
        )
        .unwrap();
        let e = read_sidecar_meta(&b).unwrap_err().to_string();
        assert!(e.contains("not an mprog sidecar"), "{e}");
    }
}
