//! `mprog doc`: generated documentation (`book` pages, the library reference).

use miette::{IntoDiagnostic, Result, WrapErr, miette};
use mprog::docgen::book::{pages, read_programs, summary_with_cookbook};
use std::path::PathBuf;

/// `mprog doc …` subcommands.
#[derive(clap::Subcommand, Debug)]
pub enum DocCommand {
    /// Print the library reference (markdown) to stdout.
    Stdlib,
    /// Write the book's generated pages (library reference, prompt card, cookbook).
    Book {
        /// The book's source folder.
        #[arg(long, default_value = "book/src")]
        dir: PathBuf,
        /// The programs shown in the cookbook.
        #[arg(long, default_value = "programs")]
        programs: PathBuf,
        /// Only report stale pages (exit status 1 when any is).
        #[arg(long)]
        check: bool,
    },
}

/// Runs `mprog doc`.
pub fn run(cmd: DocCommand) -> Result<()> {
    match cmd {
        DocCommand::Stdlib => {
            print!("{}", mprog::docgen::library::stdlib_reference());
            Ok(())
        }
        DocCommand::Book {
            dir,
            programs,
            check,
        } => book(&dir, &programs, check),
    }
}

fn book(dir: &std::path::Path, programs: &std::path::Path, check: bool) -> Result<()> {
    let progs = read_programs(programs)
        .into_diagnostic()
        .wrap_err_with(|| format!("reading {}", programs.display()))?;
    let summary_path = dir.join("SUMMARY.md");
    let summary = std::fs::read_to_string(&summary_path)
        .into_diagnostic()
        .wrap_err_with(|| format!("reading {}", summary_path.display()))?;
    let new_summary = summary_with_cookbook(&summary, &progs)
        .ok_or_else(|| miette!("{} has no cookbook markers", summary_path.display()))?;
    let mut files = pages(&progs, dir, &mprog::model::weights::shipped_actions());
    files.push((PathBuf::from("SUMMARY.md"), new_summary));
    let mut stale = 0;
    for (rel, text) in files {
        let path = dir.join(&rel);
        if std::fs::read_to_string(&path).ok().as_deref() == Some(text.as_str()) {
            continue;
        }
        stale += 1;
        if check {
            println!("stale: {}", path.display());
            continue;
        }
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).into_diagnostic()?;
        }
        mprog::fsutil::write_atomic(&path, |w| w.write_all(text.as_bytes()))
            .into_diagnostic()
            .wrap_err_with(|| format!("writing {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    if check && stale > 0 {
        return Err(miette!(
            help = "run `cargo run -- doc book`",
            "{stale} generated page(s) are stale"
        ));
    }
    if stale == 0 {
        println!("book pages up to date");
    }
    Ok(())
}
