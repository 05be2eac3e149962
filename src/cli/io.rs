//! Reading and writing motions for the subcommands: any motion file in, any list of
//! outputs out (the kinds of [`mprog::formats::outputs::OUTPUT_KINDS`]).

use super::export::ExportArgs;
use miette::{IntoDiagnostic, Result, WrapErr, miette};
use mprog::features::recover_from_ric;
use mprog::formats::{self, LoadedMotion, Meta, OutputJob, read_motion};
use mprog::motion::Motion;
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
    write_outputs_with(outputs, people, meta, title, &ExportArgs::default()).map(|_| ())
}

/// Writes every requested output through the table of output kinds; pictures and pages
/// get `title`, BVH files `export`'s settings.
pub fn write_outputs_with(
    outputs: &[PathBuf],
    people: &[Motion],
    meta: &Meta,
    title: &str,
    export: &ExportArgs,
) -> Result<Vec<PathBuf>> {
    export.check_against(outputs)?;
    let rig = export.character()?;
    let job = OutputJob {
        people,
        meta,
        title,
        bvh: &export.bvh_options(),
        rig: rig.as_deref(),
    };
    let written = formats::write_outputs(outputs, &job).into_diagnostic()?;
    for path in &written {
        eprintln!("wrote {}", path.display());
    }
    Ok(written)
}

/// Whether every output is of a kind mprog writes, judged by its extension (before any
/// work is done, so a typo does not cost a generation).
pub fn check_outputs(outputs: &[PathBuf]) -> Result<()> {
    formats::check_outputs(outputs).map_err(|e| miette!("{e}"))
}

/// Help for `-o`: one line per output kind, read from the table.
pub fn outputs_help() -> String {
    format!(
        "Outputs, by extension (several allowed):\n{}",
        formats::outputs::kinds_help()
    )
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
