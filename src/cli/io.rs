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

/// Writes every requested output; pictures get `title`. Every output is checked before
/// the first is written, so a bad one leaves none behind.
pub fn write_outputs(
    outputs: &[PathBuf],
    people: &[Motion],
    meta: &Meta,
    title: &str,
) -> Result<()> {
    check_outputs(outputs, people.len())?;
    for out in outputs {
        match extension(out).as_str() {
            "gif" | "png" => render_to_path(people, &RenderOptions::titled(title), out)
                .into_diagnostic()
                .wrap_err_with(|| format!("rendering {}", out.display()))?,
            _ => write_motion(out, people, meta).into_diagnostic()?,
        }
        eprintln!("wrote {}", out.display());
    }
    Ok(())
}

fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// Whether every output can hold `people` motions, judged by its extension.
pub fn check_outputs(outputs: &[PathBuf], people: usize) -> Result<()> {
    outputs.iter().try_for_each(|out| check_output(out, people))
}

fn check_output(out: &Path, people: usize) -> Result<()> {
    match extension(out).as_str() {
        "gif" | "png" | "npy" | "json" => Ok(()),
        "bvh" if people == 1 => Ok(()),
        "bvh" => Err(miette!(
            help = "write one .bvh per person, or use .json / .npy",
            "cannot write {}: a BVH file holds one skeleton but there are {people} people",
            out.display()
        )),
        _ => Err(miette!(
            help = "use .bvh, .npy, .json, .gif or .png",
            "cannot write {}: unknown extension",
            out.display()
        )),
    }
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
