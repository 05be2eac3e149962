//! `mprog train`: train the denoiser on a built dataset, resumable.

use indicatif::{ProgressBar, ProgressStyle};
use miette::{IntoDiagnostic, Result, WrapErr, miette};
use mprog::dataset::Dataset;
use mprog::interrupt::Interrupt;
use mprog::model::TrainConfig;
use mprog::model::train::TrainRun;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

/// Arguments of `mprog train`.
#[derive(clap::Args)]
pub struct TrainArgs {
    /// Training set written by `mprog data build`.
    #[arg(long)]
    data: PathBuf,
    /// Training settings (TOML); ignored when resuming (the run's own copy is used).
    #[arg(long, default_value = "models/train-default.toml")]
    config: PathBuf,
    /// Run folder: checkpoints, loss curves and the exported bundle go here.
    #[arg(long)]
    out: PathBuf,
    /// Continue the run in `--out` from its last checkpoint.
    #[arg(long)]
    resume: bool,
    /// Start a new run from a model bundle's weights (e.g. `models/default`) instead of
    /// random ones; its config and vocabulary must match the training config.
    #[arg(long, conflicts_with = "resume")]
    init_from: Option<PathBuf>,
    /// Stop after this many steps in this session (the run can be resumed later).
    #[arg(long)]
    steps: Option<usize>,
}

/// Runs `mprog train`.
pub fn run(args: TrainArgs) -> Result<()> {
    let run_config = args.out.join("config.toml");
    // Everything is read and checked before the run folder is created, so a bad
    // argument leaves nothing behind.
    let config: TrainConfig = if args.resume {
        let text = std::fs::read_to_string(&run_config)
            .into_diagnostic()
            .wrap_err_with(|| format!("--resume needs {}", run_config.display()))?;
        toml::from_str(&text)
            .into_diagnostic()
            .wrap_err_with(|| format!("bad run config {}", run_config.display()))?
    } else {
        if run_config.exists() {
            return Err(miette!(
                help = "pass --resume to continue it, or choose another --out",
                "{} already holds a training run",
                args.out.display()
            ));
        }
        let text = std::fs::read_to_string(&args.config)
            .into_diagnostic()
            .wrap_err_with(|| format!("cannot read {}", args.config.display()))?;
        toml::from_str(&text)
            .into_diagnostic()
            .wrap_err_with(|| format!("bad training config {}", args.config.display()))?
    };
    let config_file = if args.resume {
        &run_config
    } else {
        &args.config
    };
    config
        .check()
        .map_err(|e| miette!("bad training config {}: {e}", config_file.display()))?;
    let data = Dataset::load(&args.data)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot load the training set {}", args.data.display()))?;
    if !args.resume {
        std::fs::create_dir_all(&args.out).into_diagnostic()?;
        mprog::fsutil::write_bytes_atomic(
            &run_config,
            toml::to_string(&config).into_diagnostic()?.as_bytes(),
        )
        .into_diagnostic()?;
    }
    eprintln!(
        "training on {} clips ({} train), d_model {}, {} layers, batch {}, crops of {} frames",
        data.index.clips.len(),
        data.index.stats[0].clips,
        config.model.d_model,
        config.model.layers,
        config.batch_size,
        config.crop_frames
    );
    let interrupt = Interrupt::on_signals()
        .into_diagnostic()
        .wrap_err("cannot install the Ctrl-C handler")?;
    let bar = ProgressBar::new(config.steps as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:30} {pos}/{len} steps  {msg}  [{elapsed_precise}, eta {eta}]",
        )
        .expect("valid template"),
    );
    let run = TrainRun {
        data: &data,
        config: config.clone(),
        out: args.out.clone(),
        max_steps_now: args.steps,
        interrupt: interrupt.clone(),
        init_from: args.init_from.clone(),
        device: super::device()?,
        after_checkpoint: Some(plot_loss_curves),
        text_encoder: None,
    };
    // The log's s/step is wall time over the last logged steps (checkpoints included), not
    // the run's lifetime mean, which carries every earlier session's speed.
    let last_log = std::cell::Cell::new(None::<(usize, std::time::Instant)>);
    let state = run
        .run(&|state, loss, lr| {
            bar.set_position(state.step as u64);
            bar.set_message(format!("loss {loss:.4}  lr {lr:.1e}"));
            // Without a terminal (a background run) the bar is hidden: log a line instead.
            if !std::io::stderr().is_terminal() && state.step % 25 == 0 {
                let now = std::time::Instant::now();
                let rate = match last_log.replace(Some((state.step, now))) {
                    Some((step, at)) if state.step > step => format!(
                        "{:.2} s/step",
                        (now - at).as_secs_f64() / (state.step - step) as f64
                    ),
                    _ => "first logged step".to_string(),
                };
                eprintln!("step {} loss {loss:.4} lr {lr:.1e} {rate}", state.step);
            }
        })
        .into_diagnostic()?;
    bar.finish();
    if interrupt.is_requested() {
        eprintln!(
            "interrupted at step {}: checkpoint saved in {}; continue with --resume",
            state.step,
            args.out.join("ckpt").display()
        );
        std::process::exit(130);
    }
    eprintln!(
        "stopped at step {} after {:.0} s of training in total; last mean loss {:.4}, val {:?}",
        state.step, state.seconds, state.recent_loss, state.val_loss
    );
    Ok(())
}

/// `<out>/loss.png`: training loss (mean over 50-step windows) and validation loss, log y.
fn plot_loss_curves(out: &Path) -> Result<(), String> {
    let raw = mprog::model::train::read_curve(&out.join("loss.csv"), 1);
    let train: Vec<(f32, f32)> = raw
        .chunks(50)
        .map(|c| {
            let n = c.len() as f32;
            (c[c.len() - 1].0, c.iter().map(|p| p.1).sum::<f32>() / n)
        })
        .collect();
    let series = vec![
        mprog::render::Series {
            name: "train (50-step mean)".into(),
            points: train,
        },
        mprog::render::Series {
            name: "validation (EMA)".into(),
            points: mprog::model::train::read_curve(&out.join("val.csv"), 1),
        },
    ];
    let opts = mprog::render::PlotOptions {
        log_y: true,
        ..Default::default()
    };
    mprog::render::plot_lines(
        &out.join("loss.png"),
        "training loss",
        "step",
        "x0 MSE (normalised)",
        &series,
        &opts,
    )
    .map_err(|e| e.to_string())
}
