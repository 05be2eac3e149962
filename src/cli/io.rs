//! Reading and writing motions for the subcommands: any motion file in, any list of
//! outputs out (`.npy` with its `.meta.json` sidecar, `.json`, `.bvh` data; `.gif`, `.png`
//! pictures; `.html` viewer pages).

use super::export::ExportArgs;
use miette::{IntoDiagnostic, Result, WrapErr, miette};
use mprog::features::recover_from_ric;
use mprog::formats::{LoadedMotion, Meta, read_motion, write_motion_with, write_sidecar_meta};
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

/// Writes every requested output with default export settings; pictures get `title`.
pub fn write_outputs(
    outputs: &[PathBuf],
    people: &[Motion],
    meta: &Meta,
    title: &str,
) -> Result<()> {
    write_outputs_with(outputs, people, meta, title, &ExportArgs::default())
}

/// Writes every requested output; pictures and pages get `title`, BVH files `export`'s
/// settings, and every `.npy` a `<name>.meta.json` sidecar holding `meta` (plus `fps`).
pub fn write_outputs_with(
    outputs: &[PathBuf],
    people: &[Motion],
    meta: &Meta,
    title: &str,
    export: &ExportArgs,
) -> Result<()> {
    export.check_against(outputs)?;
    check_outputs(outputs)?;
    let mut bvh_files = bvh_texts(outputs, people, export)?;
    for out in outputs {
        let ext = out
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        match ext.as_str() {
            "gif" | "png" => {
                let mut opts = RenderOptions::titled(title);
                opts.overlays = mprog::view::overlays_from_meta(meta).into_diagnostic()?;
                render_to_path(people, &opts, out)
                    .into_diagnostic()
                    .wrap_err_with(|| format!("rendering {}", out.display()))?
            }
            "html" | "htm" => mprog::view::write_html(people, meta, title, out)
                .into_diagnostic()
                .wrap_err_with(|| format!("writing the viewer {}", out.display()))?,
            "npy" => {
                write_motion_with(out, people, meta, &export.bvh_options()).into_diagnostic()?;
                let mut side = meta.clone();
                if let Some(m) = people.first() {
                    side.entry("fps").or_insert(m.fps.into());
                }
                let path = write_sidecar_meta(out, &side).into_diagnostic()?;
                eprintln!("wrote {} (+ {})", out.display(), path.display());
                continue;
            }
            "bvh" => {
                for (path, text) in bvh_files.remove(0) {
                    mprog::fsutil::write_bytes_atomic(&path, text.as_bytes())
                        .into_diagnostic()
                        .wrap_err_with(|| format!("writing {}", path.display()))?;
                    eprintln!("wrote {}", path.display());
                }
                continue;
            }
            "json" => {
                write_motion_with(out, people, meta, &export.bvh_options()).into_diagnostic()?
            }
            _ => {
                return Err(miette!(
                    help = "use .bvh, .npy, .json, .gif, .png or .html",
                    "cannot write {}: unknown extension",
                    out.display()
                ));
            }
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

/// Whether every output is of a kind mprog writes, judged by its extension (before any
/// work is done, so a typo does not cost a generation).
pub fn check_outputs(outputs: &[PathBuf]) -> Result<()> {
    outputs.iter().try_for_each(|out| check_output(out))
}

/// The text of every BVH file the outputs ask for, in output order (one list per `.bvh`
/// output: one file per person). Made before anything is written, because BVH export can
/// refuse a motion (a pose with no facing direction) and no output should then exist.
fn bvh_texts(
    outputs: &[PathBuf],
    people: &[Motion],
    export: &ExportArgs,
) -> Result<Vec<Vec<(PathBuf, String)>>> {
    let opts = export.bvh_options();
    let mut all = Vec::new();
    for out in outputs.iter().filter(|o| extension(o) == "bvh") {
        let mut files = Vec::new();
        for (i, person) in people.iter().enumerate() {
            // bvh_string refuses non-finite positions itself (naming frame and joint).
            let path = if people.len() == 1 {
                out.clone()
            } else {
                per_person(out, i)
            };
            let text = mprog::formats::bvh_export::bvh_string(person, &opts)
                .map_err(|e| miette!("{}: {e}; nothing was written", path.display()))?;
            files.push((path, text));
        }
        all.push(files);
    }
    Ok(all)
}

/// `out.bvh` → `out_p{i+1}.bvh`: person `i`'s file when a motion has several people.
pub fn per_person(out: &Path, i: usize) -> PathBuf {
    let stem = out.file_stem().unwrap_or_default().to_string_lossy();
    let ext = out.extension().unwrap_or_default().to_string_lossy();
    out.with_file_name(format!("{stem}_p{}.{ext}", i + 1))
}

fn check_output(out: &Path) -> Result<()> {
    match extension(out).as_str() {
        "gif" | "png" | "npy" | "json" | "html" | "htm" | "bvh" => Ok(()),
        _ => Err(miette!(
            help = "use .bvh, .npy, .json, .gif, .png or .html",
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
