//! `mprog eval`: score a model against real test clips and a trivial baseline;
//! `mprog eval train-encoder`: train the learned evaluator behind FID and R-precision.

use clap::Subcommand;
use indicatif::{ProgressBar, ProgressStyle};
use miette::{IntoDiagnostic, Result, WrapErr, miette};
use mprog::dataset::Dataset;
use mprog::metrics::report::Sample;
use mprog::metrics::{
    EncoderTrainConfig, EvalSettings, Evaluator, default_evaluator_dir, report_markdown, run_eval,
    train_evaluator,
};
use mprog::model::ModelBundle;
use mprog::model::weights::default_model_dir;
use mprog::render::{RenderOptions, render_to_path};
use mprog::solve::cleanup::FootCleanup;
use std::path::{Path, PathBuf};

/// Arguments of `mprog eval`.
#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct EvalArgs {
    #[command(subcommand)]
    command: Option<EvalCommand>,
    #[command(flatten)]
    run: RunArgs,
}

/// Subcommands of `mprog eval`.
#[derive(Subcommand)]
enum EvalCommand {
    /// Train the text–motion evaluator (FID, diversity, R-precision) on the train split.
    TrainEncoder(TrainEncoderArgs),
}

/// Options of an evaluation run.
#[derive(clap::Args)]
struct RunArgs {
    /// Dataset written by `mprog data build` (its test split is used).
    #[arg(long, required = true)]
    data: Option<PathBuf>,
    /// Model bundle (default: the shipped model, `$MPROG_MODEL` or models/default).
    #[arg(long)]
    model: Option<PathBuf>,
    /// Evaluator folder (default: `$MPROG_EVALUATOR` or models/evaluator).
    #[arg(long)]
    evaluator: Option<PathBuf>,
    /// Test captions to generate from.
    #[arg(long, default_value_t = 32)]
    count: usize,
    /// Seed of the clip choice, captions and noise.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Sampler: `ddim` (deterministic), `ddpm` (stochastic, seeded), or `lcm` (a
    /// consistency-distilled model's few-step chain; such a model's default).
    #[arg(long)]
    sampler: Option<String>,
    /// Denoising steps (DDIM default 50, DDPM default 1000, lcm 4; fewer are respaced).
    #[arg(long, alias = "ddim-steps")]
    steps: Option<usize>,
    /// Classifier-free guidance scale (default 2.5; 1 for a consistency-distilled model).
    #[arg(long, value_parser = super::parse_guidance, allow_hyphen_values = true)]
    guidance: Option<f32>,
    /// Motions generated per call.
    #[arg(long, default_value_t = 16)]
    batch: usize,
    /// Ignore test clips shorter than this many frames.
    #[arg(long, default_value_t = 40)]
    min_frames: usize,
    /// Also print the per-label table (speed, turn, wrists, skating; real vs generated).
    #[arg(long)]
    per_label: bool,
    /// Motions generated per label for `--per-label`.
    #[arg(long, default_value_t = 3)]
    per_label_count: usize,
    /// Also write the tables to this markdown file.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Write a PNG strip of every generated motion into this folder.
    #[arg(long)]
    render_dir: Option<PathBuf>,
    /// Clean the feet of the generated motions as `mprog gen` does (default: score the
    /// model's raw samples).
    #[arg(long)]
    foot_cleanup: bool,
    /// Average the denoiser with its left/right mirror, as `mprog gen --mirror-average`.
    #[arg(long)]
    mirror_average: bool,
}

/// Options of `mprog eval train-encoder`.
#[derive(clap::Args)]
struct TrainEncoderArgs {
    /// Dataset written by `mprog data build` (its train split is used).
    #[arg(long)]
    data: PathBuf,
    /// Output folder for the evaluator.
    #[arg(long, default_value = "models/evaluator")]
    out: PathBuf,
    /// Optimisation steps.
    #[arg(long)]
    steps: Option<usize>,
    /// Clips per batch.
    #[arg(long)]
    batch: Option<usize>,
    /// Seed of weights and batches.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

/// Runs `mprog eval`.
pub fn run(args: EvalArgs) -> Result<()> {
    match args.command {
        Some(EvalCommand::TrainEncoder(t)) => train_encoder(t),
        None => evaluate(args.run),
    }
}

fn train_encoder(args: TrainEncoderArgs) -> Result<()> {
    let data = Dataset::load(&args.data).into_diagnostic()?;
    let defaults = EncoderTrainConfig::default();
    let cfg = EncoderTrainConfig {
        steps: args.steps.unwrap_or(defaults.steps),
        batch_size: args.batch.unwrap_or(defaults.batch_size),
        seed: args.seed,
        ..defaults
    };
    let bar = ProgressBar::new(cfg.steps as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:30} {pos}/{len} steps  {msg}  [{elapsed_precise}, eta {eta}]",
        )
        .expect("valid template"),
    );
    let mut recent = Vec::new();
    let (evaluator, losses) = train_evaluator(&data, &cfg, &mut |step, loss| {
        recent.push(loss);
        let tail = &recent[recent.len().saturating_sub(20)..];
        bar.set_position(step as u64);
        bar.set_message(format!(
            "loss {:.3}",
            tail.iter().sum::<f32>() / tail.len() as f32
        ));
    })
    .into_diagnostic()?;
    bar.finish();
    evaluator.save(&args.out).into_diagnostic()?;
    let m = &evaluator.manifest;
    eprintln!(
        "trained {} steps in {:.0} s: loss {:.3} → {:.3}; validation R-precision {:?}; wrote {}",
        m.steps,
        m.train_seconds,
        losses.first().copied().unwrap_or(f32::NAN),
        m.final_loss,
        m.val_r_precision,
        args.out.display()
    );
    Ok(())
}

fn evaluate(args: RunArgs) -> Result<()> {
    // Settings first: a typo fails before minutes of loading.
    if args.count < 2 || args.batch == 0 || args.steps == Some(0) {
        return Err(miette!("--count must be ≥ 2, --batch and --steps ≥ 1"));
    }
    super::generate::check_sampler_name(args.sampler.as_deref())?;
    let data_dir = args.data.ok_or_else(|| miette!("--data is required"))?;
    let device = super::device()?;
    let data = Dataset::load(&data_dir).into_diagnostic()?;
    let model_dir = args.model.unwrap_or_else(default_model_dir);
    let bundle = ModelBundle::load(&model_dir, &device)
        .into_diagnostic()
        .wrap_err_with(|| format!("loading the model {}", model_dir.display()))?;
    let eval_dir = args.evaluator.unwrap_or_else(default_evaluator_dir);
    let evaluator = Evaluator::load(&eval_dir, &device)
        .into_diagnostic()
        .wrap_err_with(|| {
            format!(
                "loading the evaluator {} (train one with `mprog eval train-encoder`)",
                eval_dir.display()
            )
        })?;
    let (sampler, guidance_scale) = super::generate::sampling_for(
        &bundle.manifest,
        args.sampler.as_deref(),
        args.steps,
        args.guidance,
    )?;
    let settings = EvalSettings {
        count: args.count,
        seed: args.seed,
        sampler,
        guidance_scale,
        batch_size: args.batch,
        min_frames: args.min_frames,
        per_label: args.per_label.then_some(args.per_label_count),
        foot_cleanup: args.foot_cleanup.then(FootCleanup::default),
        mirror_average: args.mirror_average,
    };
    let (report, samples) = run_eval(
        &data,
        &bundle,
        &evaluator,
        &settings,
        &device,
        &mut |line| eprintln!("{line}"),
    )
    .into_diagnostic()?;
    let text = report_markdown(&report);
    println!("{text}");
    if let Some(out) = &args.out {
        mprog::fsutil::write_bytes_atomic(out, text.as_bytes())
            .into_diagnostic()
            .wrap_err_with(|| format!("writing {}", out.display()))?;
        eprintln!("wrote {}", out.display());
    }
    if let Some(dir) = &args.render_dir {
        render_samples(dir, &samples)?;
    }
    Ok(())
}

fn render_samples(dir: &Path, samples: &[Sample]) -> Result<()> {
    for (i, s) in samples.iter().enumerate() {
        let path = dir.join(format!("{i:03}_{}.png", s.label));
        render_to_path(
            std::slice::from_ref(&s.motion),
            &RenderOptions::titled(&s.caption),
            &path,
        )
        .into_diagnostic()
        .wrap_err_with(|| format!("rendering {}", path.display()))?;
    }
    eprintln!("wrote {} pictures to {}", samples.len(), dir.display());
    Ok(())
}
