//! `mprog convert` and `mprog render`: motion files between formats, and pictures of them.

use super::export::ExportArgs;
use super::io::{load_people, write_outputs, write_outputs_with};
use miette::{IntoDiagnostic, Result};
use mprog::formats::Meta;
use mprog::formats::asf::{import_amc_beside_asf, import_asf_amc};
use mprog::formats::bvh::BvhImportOptions;
use mprog::motion::Motion;
use std::path::{Path, PathBuf};

/// Arguments of `mprog convert`.
#[derive(clap::Args)]
pub struct ConvertArgs {
    /// Input motion: .bvh, .amc (with its .asf), .npy (N×22×3 joints or N×263 HumanML3D
    /// features) or .json.
    input: PathBuf,
    /// Outputs; each one's extension picks its kind (`--help` lists them).
    #[arg(short, long, num_args = 1.., required = true, long_help = super::io::outputs_help())]
    out: Vec<PathBuf>,
    /// Skeleton of an .amc input (default: the .asf beside it, in `_asf/`, or
    /// `<subject>.asf`).
    #[arg(long)]
    asf: Option<PathBuf>,
    #[command(flatten)]
    export: ExportArgs,
}

/// Arguments of `mprog render`.
#[derive(clap::Args)]
pub struct RenderArgs {
    /// Input motion: .bvh, .npy or .json.
    input: PathBuf,
    /// Outputs; each one's extension picks its kind (`--help` lists them).
    #[arg(short, long, num_args = 1.., required = true, long_help = super::io::outputs_help())]
    out: Vec<PathBuf>,
    /// Title drawn above the picture (default: the file name).
    #[arg(long)]
    title: Option<String>,
}

/// Runs `mprog convert`.
pub fn convert(mut args: ConvertArgs) -> Result<()> {
    args.export.prepare(&args.out)?;
    let (people, meta) = load_input(&args.input, args.asf.as_deref())?;
    let title = args.input.display().to_string();
    write_outputs_with(&args.out, &people, &meta, &title, &args.export).map(|_| ())
}

/// Runs `mprog render`.
pub fn render(args: RenderArgs) -> Result<()> {
    let (people, meta) = load_people(&args.input)?;
    let title = args
        .title
        .unwrap_or_else(|| args.input.display().to_string());
    write_outputs(&args.out, &people, &meta, &title)
}

/// Reads `.amc` (+ `.asf`) here, everything else through [`load_people`].
fn load_input(input: &Path, asf: Option<&Path>) -> Result<(Vec<Motion>, Meta)> {
    let amc = input
        .extension()
        .is_some_and(|x| x.eq_ignore_ascii_case("amc"));
    if !amc {
        return load_people(input);
    }
    let opts = BvhImportOptions::default();
    let out = match asf {
        Some(asf) => import_asf_amc(asf, input, &opts),
        None => import_amc_beside_asf(input, &opts),
    }
    .into_diagnostic()?;
    let mut meta = Meta::new();
    meta.insert("source_fps".into(), out.source_fps.into());
    meta.insert("source_frames".into(), out.source_frames.into());
    meta.insert("unit_scale".into(), out.unit_scale.into());
    meta.insert("rig".into(), out.joint_map.rig.into());
    meta.insert("warnings".into(), out.warnings.clone().into());
    Ok((vec![out.motion], meta))
}
