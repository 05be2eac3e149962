//! `mprog train-control`: train a realism ControlNet on a frozen base bundle, resumable.

use indicatif::{ProgressBar, ProgressStyle};
use miette::{IntoDiagnostic, Result, WrapErr, miette};
use mprog::dataset::Dataset;
use mprog::interrupt::Interrupt;
use mprog::model::train::control::{ControlTrainConfig, ControlTrainRun};
use std::path::PathBuf;

/// Arguments of `mprog train-control`.
#[derive(clap::Args)]
pub struct TrainControlArgs {
    /// The base's training set (`mprog data build`): its statistics must be the base's.
    #[arg(long)]
    data: PathBuf,
    /// The frozen base bundle.
    #[arg(long, default_value = "models/default")]
    base: PathBuf,
    /// Settings (TOML, `ControlTrainConfig`); a run folder's own copy wins when resuming.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Run folder: checkpoints, loss log and the bundle with its ControlNet.
    #[arg(long)]
    out: PathBuf,
    /// Start a new run from this bundle's `control.safetensors` rather than from zero: refit
    /// a shipped ControlNet to a retrained base (ignored when `out` has a checkpoint).
    #[arg(long)]
    init_from: Option<PathBuf>,
    /// Stop after this many steps now (the run resumes later from `out`).
    #[arg(long)]
    steps: Option<usize>,
}

/// Runs `mprog train-control`.
pub fn run(args: TrainControlArgs) -> Result<()> {
    let own = args.out.join("config.toml");
    let config: ControlTrainConfig = if own.exists() {
        read_config(&own)?
    } else if let Some(path) = &args.config {
        read_config(path)?
    } else {
        ControlTrainConfig::default()
    };
    let data = Dataset::load(&args.data)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot load the training set {}", args.data.display()))?;
    if !own.exists() {
        std::fs::create_dir_all(&args.out).into_diagnostic()?;
        let text = toml::to_string(&config).into_diagnostic()?;
        mprog::fsutil::write_bytes_atomic(&own, text.as_bytes()).into_diagnostic()?;
    }
    let interrupt = Interrupt::on_signals()
        .into_diagnostic()
        .wrap_err("cannot install the Ctrl-C handler")?;
    let bar = ProgressBar::new(config.steps as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {pos}/{len} steps  {msg}  [{elapsed_precise}]")
            .expect("valid template"),
    );
    let run = ControlTrainRun {
        data: &data,
        base: args.base.clone(),
        config,
        out: args.out.clone(),
        init_from: args.init_from.clone(),
        max_steps_now: args.steps,
        interrupt: interrupt.clone(),
        device: super::device()?,
        after_checkpoint: Some(plot_hint_errors),
    };
    let state = run
        .run(&|state, loss, lr| {
            bar.set_position(state.step as u64);
            bar.set_message(format!("loss {loss:.4}  lr {lr:.1e}"));
            if state.step % 25 == 0 && !std::io::IsTerminal::is_terminal(&std::io::stderr()) {
                eprintln!("step {} loss {loss:.4} lr {lr:.1e}", state.step);
            }
        })
        .into_diagnostic()?;
    bar.finish();
    eprintln!(
        "{} at step {} ({:.0} s in total, last mean loss {:.4}); the bundle with its ControlNet: {}",
        if interrupt.is_requested() {
            "interrupted"
        } else {
            "stopped"
        },
        state.step,
        state.seconds,
        state.recent_loss,
        args.out.join("bundle").display()
    );
    Ok(())
}

/// `<out>/hint.png`: how far the hinted joints of x̂0 lie from their targets on the
/// validation crops, with the ControlNet and with the base alone (`val.csv`).
fn plot_hint_errors(out: &std::path::Path) -> Result<(), String> {
    let val = out.join("val.csv");
    let series = vec![
        mprog::render::Series {
            name: "with the ControlNet".into(),
            points: mprog::model::train::read_curve(&val, 1),
        },
        mprog::render::Series {
            name: "base alone".into(),
            points: mprog::model::train::read_curve(&val, 2),
        },
    ];
    mprog::render::plot_lines(
        &out.join("hint.png"),
        "hinted joints of x̂0: distance to their targets (validation)",
        "step",
        "mean distance (m)",
        &series,
        &mprog::render::PlotOptions::default(),
    )
    .map_err(|e| e.to_string())
}

fn read_config(path: &std::path::Path) -> Result<ControlTrainConfig> {
    let text = std::fs::read_to_string(path)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot read {}", path.display()))?;
    toml::from_str(&text).map_err(|e| miette!("bad ControlNet config {}: {e}", path.display()))
}
