//! Reading and writing motions for the subcommands: any motion file in, any list of
//! outputs out (`.npy`, `.json`, `.bvh` data; `.gif`, `.png` pictures).

use miette::{IntoDiagnostic, Result, WrapErr, miette};
use mprog::features::recover_from_ric;
use mprog::formats::{LoadedMotion, Meta, read_motion, write_motion};
use mprog::motion::Motion;
use mprog::render::{RenderOptions, render_to_path};
use std::path::{Path, PathBuf};

/// People of a motion file (HumanML3D feature arrays are recovered to joints).
pub fn load_people(path: &Path) -> Result<(Vec<Motion>, Meta)> {
    let loaded = read_motion(path).into_diagnostic()?;
    Ok(match loaded {
        LoadedMotion::Joints { people, meta } => {
            (people.into_iter().map(|p| p.motion).collect(), meta)
        }
        LoadedMotion::Features(array) => {
            let motion = recover_from_ric(&array.data)
                .into_diagnostic()
                .wrap_err_with(|| {
                    format!(
                        "{}: recovering joints from HumanML3D features",
                        path.display()
                    )
                })?;
            (vec![motion], Meta::new())
        }
    })
}

/// Writes every requested output; pictures get `title`.
pub fn write_outputs(
    outputs: &[PathBuf],
    people: &[Motion],
    meta: &Meta,
    title: &str,
) -> Result<()> {
    for out in outputs {
        let ext = out
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        match ext.as_str() {
            "gif" | "png" => render_to_path(people, &RenderOptions::titled(title), out)
                .into_diagnostic()
                .wrap_err_with(|| format!("rendering {}", out.display()))?,
            "npy" | "json" | "bvh" => write_motion(out, people, meta).into_diagnostic()?,
            _ => {
                return Err(miette!(
                    help = "use .bvh, .npy, .json, .gif or .png",
                    "cannot write {}: unknown extension",
                    out.display()
                ));
            }
        }
        eprintln!("wrote {}", out.display());
    }
    Ok(())
}

/// Output paths with `_i` inserted before the extension, for sample `i` of `count`.
pub fn numbered(outputs: &[PathBuf], i: usize, count: usize) -> Vec<PathBuf> {
    if count == 1 {
        return outputs.to_vec();
    }
    outputs
        .iter()
        .map(|p| {
            let stem = p
                .file_stem()
                .map(|s| s.to_string_lossy().to_string())
                .unwrap_or_default();
            let ext = p
                .extension()
                .map(|e| format!(".{}", e.to_string_lossy()))
                .unwrap_or_default();
            p.with_file_name(format!("{stem}_{i}{ext}"))
        })
        .collect()
}
