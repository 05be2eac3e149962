//! The output folder of `mprog mcp`: every file a request names is a relative path inside
//! it. A request's text is untrusted, so a path that is absolute, climbs (`..`), is empty,
//! or passes through a symbolic link (which could point anywhere) is refused before any
//! file is touched.

use std::path::{Component, Path, PathBuf};

/// Longest relative path accepted (bytes).
const MAX_PATH: usize = 512;

/// A folder that requests may write and read under.
#[derive(Clone, Debug)]
pub struct OutDir {
    /// Its canonical path (no links, absolute).
    root: PathBuf,
}

impl OutDir {
    /// Creates the folder if needed and resolves it once: the root itself may be a link
    /// (the user chose it); nothing below it may be.
    pub fn new(dir: &Path) -> std::io::Result<OutDir> {
        std::fs::create_dir_all(dir)?;
        Ok(OutDir {
            root: dir.canonicalize()?,
        })
    }

    /// The folder.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// The checked path of `rel`, for writing: its folders are created, and none of them
    /// (nor the file, if it exists) is a link.
    pub fn for_writing(&self, rel: &str) -> Result<PathBuf, String> {
        let path = self.resolve(rel)?;
        let parent = path.parent().unwrap_or(&self.root);
        std::fs::create_dir_all(parent).map_err(|e| format!("`{rel}`: {e}"))?;
        self.no_links(rel, &path)?;
        Ok(path)
    }

    /// The checked path of `rel`, for reading: an existing regular file reached without
    /// links.
    pub fn for_reading(&self, rel: &str) -> Result<PathBuf, String> {
        let path = self.resolve(rel)?;
        self.no_links(rel, &path)?;
        match std::fs::metadata(&path) {
            Ok(m) if m.is_file() => Ok(path),
            Ok(_) => Err(format!("`{rel}` is not a file")),
            Err(e) => Err(format!("cannot read `{rel}` in the output folder: {e}")),
        }
    }

    /// `rel` joined to the root, refusing anything but plain names.
    fn resolve(&self, rel: &str) -> Result<PathBuf, String> {
        let refuse = |why: &str| {
            Err(format!(
                "refused path `{}`: {why}; files are read and written only inside the output \
                 folder, by a relative path like `walk.bvh` or `runs/walk.bvh`",
                rel.escape_debug()
            ))
        };
        if rel.is_empty() {
            return refuse("it is empty");
        }
        if rel.len() > MAX_PATH {
            return refuse("it is too long");
        }
        if rel.contains('\0') || rel.contains('\\') {
            return refuse("it holds a NUL or a backslash");
        }
        let mut out = self.root.clone();
        for c in Path::new(rel).components() {
            match c {
                Component::Normal(name) => out.push(name),
                Component::CurDir => {}
                Component::ParentDir => return refuse("it climbs out with `..`"),
                Component::RootDir | Component::Prefix(_) => return refuse("it is absolute"),
            }
        }
        if out == self.root {
            return refuse("it names no file");
        }
        Ok(out)
    }

    /// Refuses `path` if it, or a folder between the root and it, is a link.
    fn no_links(&self, rel: &str, path: &Path) -> Result<(), String> {
        let mut at = path;
        while at != self.root {
            if std::fs::symlink_metadata(at).is_ok_and(|m| m.file_type().is_symlink()) {
                return Err(format!(
                    "refused path `{}`: `{}` is a symbolic link, which could lead out of the \
                     output folder",
                    rel.escape_debug(),
                    at.strip_prefix(&self.root).unwrap_or(at).display()
                ));
            }
            at = match at.parent() {
                Some(p) => p,
                None => break,
            };
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_relative_paths_stay_inside() {
        let dir = tempfile::tempdir().unwrap();
        let out = OutDir::new(dir.path()).unwrap();
        let p = out.for_writing("runs/a.bvh").unwrap();
        assert_eq!(p, out.root().join("runs/a.bvh"));
        assert!(out.root().join("runs").is_dir());
        assert_eq!(
            out.for_writing("./b.json").unwrap(),
            out.root().join("b.json")
        );
    }

    #[test]
    fn escapes_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let out = OutDir::new(&dir.path().join("out")).unwrap();
        for bad in [
            "../x.bvh",
            "a/../../x.bvh",
            "/etc/x.bvh",
            "",
            ".",
            "a\\..\\x",
            "a\0b",
        ] {
            let e = out.for_writing(bad).unwrap_err();
            assert!(e.starts_with("refused path"), "{bad}: {e}");
        }
        assert!(!dir.path().join("x.bvh").exists());
    }

    #[test]
    fn links_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let outside = dir.path().join("outside");
        std::fs::create_dir(&outside).unwrap();
        std::fs::write(outside.join("m.json"), "{}").unwrap();
        let out = OutDir::new(&dir.path().join("out")).unwrap();
        std::os::unix::fs::symlink(&outside, out.root().join("link")).unwrap();
        std::os::unix::fs::symlink(outside.join("m.json"), out.root().join("m.json")).unwrap();
        for bad in ["link/x.bvh", "link/m.json"] {
            assert!(
                out.for_writing(bad).unwrap_err().contains("symbolic link"),
                "{bad}"
            );
        }
        assert!(
            out.for_reading("m.json")
                .unwrap_err()
                .contains("symbolic link")
        );
        assert!(
            out.for_reading("link/m.json")
                .unwrap_err()
                .contains("symbolic link")
        );
        assert!(out.for_reading("missing.json").is_err());
    }
}
