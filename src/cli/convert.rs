//! `mprog convert` and `mprog render`: motion files between formats, and pictures of them.

use super::export::ExportArgs;
use super::io::{load_people, write_outputs, write_outputs_with};
use miette::Result;
use std::path::PathBuf;

/// Arguments of `mprog convert`.
#[derive(clap::Args)]
pub struct ConvertArgs {
    /// Input motion: .bvh, .npy (N×22×3 joints or N×263 HumanML3D features) or .json.
    input: PathBuf,
    /// Outputs; each one's extension picks its kind (`--help` lists them).
    #[arg(short, long, num_args = 1.., required = true, long_help = super::io::outputs_help())]
    out: Vec<PathBuf>,
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
pub fn convert(args: ConvertArgs) -> Result<()> {
    let (people, meta) = load_people(&args.input)?;
    let title = args.input.display().to_string();
    write_outputs_with(&args.out, &people, &meta, &title, &args.export)
}

/// Runs `mprog render`.
pub fn render(args: RenderArgs) -> Result<()> {
    let (people, meta) = load_people(&args.input)?;
    let title = args
        .title
        .unwrap_or_else(|| args.input.display().to_string());
    write_outputs(&args.out, &people, &meta, &title)
}
