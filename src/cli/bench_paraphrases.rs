//! `mprog bench paraphrases`: the held-out paraphrase set (issue 49), exact captions against
//! other wordings, with and without `gen`'s nearest-caption conditioning
//! ([`mprog::metrics::paraphrases`]).

use miette::{IntoDiagnostic, Result, WrapErr};
use mprog::metrics::paraphrases::{
    BenchSettings, Conditioning, DEFAULT_SET, measures_table, read_set, run_bench, tables,
};
use mprog::model::ModelBundle;
use std::path::PathBuf;
use std::time::Instant;

/// Which conditionings to run.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum ConditioningArg {
    /// Both, side by side.
    Both,
    /// Far prompts conditioned on the mean of their nearest captions (`gen`'s default).
    Nearest,
    /// Every prompt as written (`gen --literal-prompt`).
    Literal,
}

/// Arguments of `mprog bench paraphrases`.
#[derive(clap::Args)]
pub struct ParaphraseBenchArgs {
    /// The paraphrase set (captions, wordings, judges; see the file's header).
    #[arg(long, default_value = DEFAULT_SET)]
    set: PathBuf,
    /// Seeds of every prompt, comma separated.
    #[arg(long, value_delimiter = ',', default_value = "1,2")]
    seeds: Vec<u64>,
    /// Model bundle (default: the shipped model).
    #[arg(long, alias = "model")]
    bundle: Option<PathBuf>,
    /// The first seed and the first two wordings of each caption only.
    #[arg(long)]
    quick: bool,
    /// Nearest-caption conditioning, literal, or both as columns.
    #[arg(long, value_enum, default_value = "both")]
    conditioning: ConditioningArg,
    /// Only the literal column (the same as `--conditioning literal`).
    #[arg(long, conflicts_with = "conditioning")]
    literal: bool,
    /// Only the entries whose caption contains this text (repeatable).
    #[arg(long)]
    only: Vec<String>,
    /// Generate every wording as long as its caption (default: as long as `gen` makes the
    /// wording itself, from the model's length prior).
    #[arg(long)]
    caption_length: bool,
    /// DDIM steps (`gen`'s and `bench actions`' 50).
    #[arg(long, default_value_t = 50)]
    steps: usize,
    /// Classifier-free guidance scale (`mprog gen`'s default).
    #[arg(long, default_value_t = 2.5, value_parser = super::parse_guidance, allow_hyphen_values = true)]
    guidance: f32,
    /// List the measures a judge can use and exit.
    #[arg(long)]
    measures: bool,
    /// Write the markdown here (atomically) as well as to stdout.
    #[arg(short = 'o', long = "out")]
    out: Option<PathBuf>,
}

/// Runs `mprog bench paraphrases`.
pub fn run(args: ParaphraseBenchArgs) -> Result<()> {
    if args.measures {
        print!("{}", measures_table());
        return Ok(());
    }
    let started = Instant::now();
    let date = super::bench_tasks::utc_now();
    let set = read_set(&args.set).map_err(|e| {
        miette::miette!(
            help = "the file's header describes the format; `mprog bench paraphrases --measures` lists the measures",
            "{e}"
        )
    })?;
    if args.seeds.is_empty() {
        return Err(miette::miette!("--seeds names no seed"));
    }
    if args.steps == 0 {
        return Err(miette::miette!("--steps must be at least 1"));
    }
    let entries: Vec<_> = set
        .entries
        .iter()
        .filter(|e| args.only.is_empty() || args.only.iter().any(|o| e.caption.contains(o)))
        .cloned()
        .collect();
    if entries.is_empty() {
        return Err(miette::miette!(
            "no caption of {} contains {}",
            args.set.display(),
            args.only.join(" or ")
        ));
    }
    let conditioning = match (args.literal, args.conditioning) {
        (true, _) | (false, ConditioningArg::Literal) => vec![Conditioning::Literal],
        (false, ConditioningArg::Nearest) => vec![Conditioning::Nearest],
        (false, ConditioningArg::Both) => vec![Conditioning::Nearest, Conditioning::Literal],
    };
    let settings = BenchSettings {
        seeds: if args.quick {
            args.seeds[..1].to_vec()
        } else {
            args.seeds.clone()
        },
        steps: args.steps,
        guidance: args.guidance,
        conditioning,
        max_wordings: args.quick.then_some(2),
        caption_length: args.caption_length,
    };
    let device = super::device()?;
    let dir = args
        .bundle
        .clone()
        .unwrap_or_else(mprog::model::weights::default_model_dir);
    let mut bundle = ModelBundle::load(&dir, &device)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot load the model {}", dir.display()))?;
    let run = run_bench(&mut bundle, &device, &entries, &settings, |p| {
        eprintln!(
            "[{}/{}] {} seed {} {}: {}",
            p.done,
            p.total,
            p.conditioning.short(),
            p.seed,
            if p.passed { "✓" } else { "✗" },
            p.prompt
        );
    })
    .into_diagnostic()?;
    let wordings: usize = run
        .entries
        .iter()
        .map(|e| e.prompts.len().saturating_sub(1))
        .sum();
    let mut md = String::new();
    md.push_str(&format!(
        "Paraphrase bench: {} captions and {wordings} wordings of `{}` (sha256 {}), seeds {}, DDIM {}, guidance {}, no foot cleanup, {}{}; model {} ({}, {} training steps); {} backend on {}; started {date}, {:.0} s.\n\n",
        run.entries.len(),
        args.set.display(),
        mprog::fsutil::sha256_hex(&args.set)
            .map(|h| h[..12].to_string())
            .unwrap_or_else(|_| "?".into()),
        settings
            .seeds
            .iter()
            .map(u64::to_string)
            .collect::<Vec<_>>()
            .join(", "),
        settings.steps,
        settings.guidance,
        if settings.caption_length {
            "every wording as long as its caption"
        } else {
            "each prompt as long as `gen` makes it"
        },
        if args.quick {
            " (--quick: the first seed and two wordings per caption)"
        } else {
            ""
        },
        bundle.manifest.weights_id,
        dir.display(),
        bundle.manifest.steps,
        mprog::backend::backend_name(),
        mprog::backend::machine_description(),
        started.elapsed().as_secs_f64()
    ));
    md.push_str(&tables(&run));
    print!("{md}");
    if let Some(path) = &args.out {
        mprog::fsutil::write_bytes_atomic(path, md.as_bytes())
            .into_diagnostic()
            .wrap_err_with(|| format!("cannot write {}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
