//! `mprog check`: parse and check `.mprog` files, print their diagnostics (a miette
//! report, or JSON for repair loops), exit with status 1 when any has errors.

use clap::{Args, ValueEnum};
use mprog::model::prompt::PromptEncoder;
use std::path::PathBuf;

/// Output format of `mprog check`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// Human-readable report with source excerpts.
    Human,
    /// One JSON object per file: `{file, ok, diagnostics: [...]}`.
    Json,
}

/// Arguments of `mprog check`.
#[derive(Args, Debug)]
pub struct CheckArgs {
    /// Program files to check.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Output format.
    #[arg(long, value_enum, default_value = "human")]
    pub format: Format,
    /// Override a parameter: `--set diameter=0.5` (in the unit of its default).
    #[arg(long = "set", value_parser = parse_override)]
    pub set: Vec<(String, f64)>,
    /// Plain ASCII output without colours.
    #[arg(long)]
    pub plain: bool,
}

pub fn parse_override(s: &str) -> Result<(String, f64), String> {
    let (k, v) = s
        .split_once('=')
        .ok_or_else(|| format!("expected NAME=VALUE, got `{s}`"))?;
    let v: f64 = v
        .trim()
        .parse()
        .map_err(|_| format!("`{v}` is not a number"))?;
    Ok((k.trim().to_string(), v))
}

/// The shipped model's prompt encoder when it reads sentences (only then is "far from
/// the training captions" measurable); None without a loadable sentence model.
pub fn sentence_reader(dir: &std::path::Path) -> Option<PromptEncoder> {
    let config = std::fs::read_to_string(dir.join("config.toml")).ok()?;
    if !config.contains("text_encoder") {
        return None;
    }
    let device = super::device().ok()?;
    let bundle = mprog::model::ModelBundle::load(dir, &device).ok()?;
    matches!(bundle.text, PromptEncoder::Sentences(_)).then_some(bundle.text)
}

/// What a sentence model says of a prompt (the lines `run` prints), for
/// [`mprog::lang::with_far_prompts`].
pub fn prompt_report_of(text: PromptEncoder) -> Box<mprog::lang::PromptReport> {
    Box::new(move |prompt: &str| text.report(prompt))
}

/// The poses the model in `dir` was trained on (its `coverage.bin`, else the built-in
/// set), for [`mprog::lang::with_unseen_poses`]; None, with a note on stderr, when the
/// bundle's file is unreadable.
pub fn coverage_of(dir: &std::path::Path) -> Option<mprog::coverage::Coverage> {
    mprog::coverage::Coverage::for_bundle(dir)
        .map_err(|e| eprintln!("note: no pose coverage, so no `mprog::unseen_pose` warnings: {e}"))
        .ok()
}

/// Prints on stderr the `mprog::unseen_pose` warnings of `program` against the poses the
/// model in `dir` was trained on (what `mprog check` would say), before a run solves;
/// returns them for the outputs' meta and the run report:
/// `{"source": …, "ok": bool, "unseen": [diagnostic, …]}` (null without a coverage set).
pub fn print_unseen(program: &mprog::lang::Program, dir: &std::path::Path) -> serde_json::Value {
    let Some(coverage) = coverage_of(dir) else {
        return serde_json::Value::Null;
    };
    let found = mprog::lang::unseen_poses(program, &coverage);
    let diags =
        mprog::lang::Diagnostics::new(program.name(), program.warnings().source.clone(), found);
    if !diags.items.is_empty() {
        eprint!(
            "{}",
            diags.render_for(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        );
    }
    serde_json::json!({
        "source": coverage.source,
        "ok": diags.items.is_empty(),
        "unseen": diags.to_json(),
    })
}

/// Runs `mprog check`; returns whether every file is free of errors.
pub fn run(args: &CheckArgs) -> miette::Result<bool> {
    let mut all_ok = true;
    let mut json = Vec::new();
    let model_dir = mprog::model::weights::default_model_dir();
    let reader = sentence_reader(&model_dir).map(prompt_report_of);
    let coverage = coverage_of(&model_dir);
    for path in &args.files {
        let name = path.display().to_string();
        let source = std::fs::read_to_string(path)
            .map_err(|e| miette::miette!("cannot read {name}: {e}"))?;
        let diags = mprog::lang::check_source(&source, &name, &args.set);
        let diags = match &reader {
            Some(report) => mprog::lang::with_far_prompts(diags, &source, report),
            None => diags,
        };
        let diags = match &coverage {
            Some(c) => mprog::lang::with_unseen_poses(diags, &source, &args.set, c),
            None => diags,
        };
        let ok = !diags.has_errors();
        all_ok &= ok;
        match args.format {
            Format::Json => json.push(serde_json::json!({
                "file": name,
                "ok": ok,
                "diagnostics": diags.to_json(),
            })),
            Format::Human => {
                let text = if args.plain {
                    diags.render_plain()
                } else {
                    diags.render_for(std::io::IsTerminal::is_terminal(&std::io::stdout()))
                };
                print!("{text}");
                let warnings = diags.warnings().count();
                if ok {
                    println!(
                        "{name}: ok ({warnings} warning{})",
                        if warnings == 1 { "" } else { "s" }
                    );
                } else {
                    println!(
                        "{name}: {} error(s), {warnings} warning(s)",
                        diags.error_count()
                    );
                }
            }
        }
    }
    if args.format == Format::Json {
        let out = if json.len() == 1 {
            json.remove(0)
        } else {
            serde_json::Value::Array(json)
        };
        println!("{}", serde_json::to_string_pretty(&out).unwrap_or_default());
    }
    Ok(all_ok)
}
