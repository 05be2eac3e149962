//! `mprog view`: one motion file in, one self-contained HTML viewer page out.

use super::io::load_people;
use miette::{IntoDiagnostic, Result, WrapErr, miette};
use mprog::formats::json::read_json;
use std::path::PathBuf;

/// Arguments of `mprog view`.
#[derive(clap::Args)]
pub struct ViewArgs {
    /// Input motion: .json (with `meta.overlays`, `meta.contacts`, `meta.statement_errors`),
    /// .npy (its .meta.json sidecar is read) or .bvh.
    input: PathBuf,
    /// The page to write (.html).
    #[arg(short, long)]
    out: PathBuf,
    /// Title shown on the page (default: the input's file name).
    #[arg(long)]
    title: Option<String>,
}

/// Runs `mprog view`.
pub fn run(args: ViewArgs) -> Result<()> {
    let ext = args
        .out
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    if !matches!(ext.as_deref(), Some("html" | "htm")) {
        return Err(miette!(
            help = "name the page something.html",
            "`mprog view` writes an HTML page, not {}",
            args.out.display()
        ));
    }
    let title = args.title.unwrap_or_else(|| {
        args.input.file_name().map_or_else(
            || args.input.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        )
    });
    let is_json = args
        .input
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    // JSON keeps its own frame rate and people's names, so per-frame meta lines up.
    let (people, names, meta) = if is_json {
        let (people, meta) = read_json(&args.input).into_diagnostic()?;
        let names: Vec<String> = people.iter().map(|p| p.name.clone()).collect();
        (
            people.into_iter().map(|p| p.motion).collect::<Vec<_>>(),
            names,
            meta,
        )
    } else {
        let (people, meta) = load_people(&args.input)?;
        let names: Vec<String> = (1..=people.len()).map(|i| format!("person {i}")).collect();
        (people, names, meta)
    };
    let html = mprog::view::html_string_named(&people, &names, &meta, &title)
        .into_diagnostic()
        .wrap_err_with(|| format!("viewing {}", args.input.display()))?;
    mprog::fsutil::write_bytes_atomic(&args.out, html.as_bytes())
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot write {}", args.out.display()))?;
    let frames = people.iter().map(|m| m.len()).max().unwrap_or(0);
    eprintln!(
        "wrote {} ({} {}, {frames} frames, {:.1} kB); open it in a browser",
        args.out.display(),
        people.len(),
        if people.len() == 1 {
            "person"
        } else {
            "people"
        },
        html.len() as f64 / 1000.0
    );
    Ok(())
}
