//! `mprog bench solvers`: what steering costs. Each solver at its defaults (the papers'
//! settings) on one program, next to the unguided sampler it is compared with, as a
//! markdown table: guide/unguided time ratio (OmniControl reports 3.1×, InterControl 2×),
//! the inner loop on the fused host FK vs burn's autodiff tape, and latent's seconds per
//! motion.

use super::score::compile_file;
use indicatif::{ProgressBar, ProgressStyle};
use miette::{IntoDiagnostic, Result, WrapErr, miette};
use mprog::lang::Program;
use mprog::model::ModelBundle;
use mprog::model::control::ControlNet;
use mprog::model::weights::default_model_dir;
use mprog::solve::{GuideConfig, LatentConfig, Prior, Progress, SolveRequest, Solver, solve};
use std::fmt::Write as _;
use std::path::PathBuf;

/// Arguments of `mprog bench solvers`.
#[derive(clap::Args)]
pub struct SolverBenchArgs {
    /// The program every solver runs (its prompt and length).
    #[arg(long, default_value = "programs/fig1_hand_on_head.mprog")]
    program: PathBuf,
    /// Latent iterations actually run at the default chain (DDIM-100); fewer than the
    /// default 100 measures seconds per iteration and extrapolates the total, saying so.
    #[arg(long, default_value_t = 100)]
    latent_iterations: usize,
    /// Leave out the burn-tape inner loop (`guide` with `fused: None`), the slowest row.
    #[arg(long)]
    skip_tape: bool,
    /// Seed of every run.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Model bundle (default: the shipped model).
    #[arg(long)]
    model: Option<PathBuf>,
    /// Only the plain DDPM chain and `guide`'s rows (with a ControlNet: with realism, without
    /// it, and with OmniControl's ControlNet pass per step and guidance half).
    #[arg(long)]
    guide_only: bool,
    /// Time realism guidance with a zero-initialised ControlNet when the bundle has none:
    /// what it costs does not depend on its training.
    #[arg(long)]
    fresh_control: bool,
    /// Write the markdown here (atomically) as well as to stdout.
    #[arg(short, long)]
    out: Option<PathBuf>,
}

struct Timed {
    label: String,
    seconds: f64,
    error: f32,
}

#[allow(clippy::too_many_arguments)]
fn timed(
    bundle: &ModelBundle,
    control: Option<&ControlNet>,
    program: &Program,
    prompts: &[String],
    seed: u64,
    solver: Solver,
    label: &str,
    device: &burn::prelude::Device,
) -> Result<Timed> {
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{label:>28} {{bar:30}} {{pos}}/{{len}} [{{elapsed}}]"
        ))
        .expect("template"),
    );
    let req = SolveRequest::new(prompts.to_vec(), program.length(), seed, solver)
        .placed(program.placements());
    let error: &dyn mprog::solve::MotionError = program;
    let out = solve(
        &Prior::from_bundle(bundle).with_control(control),
        &req,
        error,
        device,
        |p: Progress| {
            bar.set_length(p.total as u64);
            bar.set_position(p.done as u64);
        },
    )
    .into_diagnostic()
    .wrap_err_with(|| format!("{label} failed"))?;
    bar.finish_and_clear();
    eprintln!("{label:>28} {:8.1} s", out.seconds);
    Ok(Timed {
        label: label.to_string(),
        seconds: out.seconds,
        error: out.error.iter().sum::<f32>() / out.error.len().max(1) as f32,
    })
}

/// Runs `mprog bench solvers`.
pub fn run(args: SolverBenchArgs) -> Result<()> {
    let device = super::device()?;
    let program = compile_file(&args.program, &[])?;
    let prompts: Vec<String> = program
        .prompts()
        .into_iter()
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| miette!("{}: every person needs a prompt", args.program.display()))?;
    let dir = args.model.clone().unwrap_or_else(default_model_dir);
    let bundle = ModelBundle::load(&dir, &device)
        .into_diagnostic()
        .wrap_err("cannot load the model")?;
    let control =
        match ControlNet::load(&dir, &bundle.model, bundle.manifest.half_precision, &device)
            .into_diagnostic()?
        {
            Some(c) => Some(c),
            None => args
                .fresh_control
                .then(|| ControlNet::from_base(&bundle.model, &device)),
        };
    let run = |solver: Solver, label: &str| {
        timed(
            &bundle,
            control.as_ref(),
            &program,
            &prompts,
            args.seed,
            solver,
            label,
            &device,
        )
    };

    let guide = GuideConfig::default();
    let plain_ddpm = run(
        Solver::new(guide.clone()).unguided(),
        &format!("plain DDPM-{}", guide.steps),
    )?;
    let guided = run(
        Solver::new(guide.clone()),
        if control.is_some() {
            "guide (fused inner loop, realism: one ControlNet pass per 2 steps)"
        } else {
            "guide (fused inner loop)"
        },
    )?;
    let no_realism = match &control {
        Some(_) => Some(run(
            Solver::new(GuideConfig {
                realism: false,
                ..guide.clone()
            }),
            "guide (realism=0)",
        )?),
        None => None,
    };
    let shared = match &control {
        Some(_) => Some(run(
            Solver::new(GuideConfig {
                realism_shared: false,
                realism_every: 1,
                ..guide.clone()
            }),
            "guide (realism as OmniControl: a ControlNet pass per step and guidance half)",
        )?),
        None => None,
    };
    let mut md = String::new();
    let _ = writeln!(md, "### Solver cost\n");
    let frames = program.length();
    let _ = writeln!(
        md,
        "- program: `{}` ({} frames = {:.1} s, {} person{}), seed {}",
        args.program.display(),
        frames,
        frames as f32 / 20.0,
        prompts.len(),
        if prompts.len() == 1 { "" } else { "s" },
        args.seed
    );
    let _ = writeln!(
        md,
        "- machine: {}; backend: {}",
        mprog::backend::machine_description(),
        mprog::backend::backend_name()
    );
    let _ = writeln!(md, "- weights: {}\n", bundle.manifest.weights_id);
    let _ = writeln!(md, "| run | seconds | × its unguided sampler | error |");
    let _ = writeln!(md, "| --- | --- | --- | --- |");
    let row = |md: &mut String, t: &Timed, base: Option<&Timed>| {
        let ratio = base.map_or("—".to_string(), |b| {
            format!("{:.2}×", t.seconds / b.seconds)
        });
        let _ = writeln!(
            md,
            "| {} | {:.1} | {ratio} | {:.4} |",
            t.label, t.seconds, t.error
        );
    };
    row(&mut md, &plain_ddpm, None);
    row(&mut md, &guided, Some(&plain_ddpm));
    for t in no_realism.iter().chain(&shared) {
        row(&mut md, t, Some(&plain_ddpm));
    }
    if args.guide_only {
        return finish(md, args.out.as_deref());
    }
    let tape = if args.skip_tape {
        None
    } else {
        Some(run(
            Solver::new(GuideConfig {
                fused: None,
                ..guide.clone()
            }),
            "guide (burn autodiff tape, skeleton=0)",
        )?)
    };
    let lbfgs_solver = Solver::by_name("lbfgs").expect("known solver");
    let lbfgs = run(lbfgs_solver, "lbfgs")?;

    let latent = LatentConfig::default();
    let iterations = args.latent_iterations.clamp(1, latent.iterations);
    let plain_ddim = run(
        Solver::new(latent.clone()).unguided(),
        &format!("plain DDIM-{}", latent.ddim_steps),
    )?;
    let latent_run = run(
        Solver::new(LatentConfig {
            iterations,
            ..latent.clone()
        }),
        &format!("latent ({iterations} iterations)"),
    )?;
    let fast = LatentConfig {
        ddim_steps: 10,
        iterations: 30,
        lr: 0.02,
        ..latent.clone()
    };
    let latent_fast = run(Solver::new(fast.clone()), "latent (10 × 30, lr 0.02)")?;

    if let Some(t) = &tape {
        row(&mut md, t, Some(&plain_ddpm));
    }
    row(&mut md, &lbfgs, Some(&plain_ddpm));
    row(&mut md, &plain_ddim, None);
    row(&mut md, &latent_run, Some(&plain_ddim));
    row(&mut md, &latent_fast, Some(&plain_ddim));
    let per_iteration = (latent_run.seconds - plain_ddim.seconds).max(0.0) / iterations as f64;
    let total = plain_ddim.seconds + per_iteration * latent.iterations as f64;
    let _ = writeln!(
        md,
        "\n`latent` at the defaults (DDIM-{}, {} iterations, lr {}): {:.1} s per iteration, \
         {:.0} s per motion{}.",
        latent.ddim_steps,
        latent.iterations,
        latent.lr,
        per_iteration,
        total,
        if iterations < latent.iterations {
            format!(" (extrapolated from {iterations} iterations)")
        } else {
            " (measured)".to_string()
        }
    );
    finish(md, args.out.as_deref())
}

/// Prints the table and writes it to `out` (atomically) when asked.
fn finish(md: String, out: Option<&std::path::Path>) -> Result<()> {
    print!("{md}");
    if let Some(path) = out {
        mprog::fsutil::write_bytes_atomic(path, md.as_bytes())
            .into_diagnostic()
            .wrap_err_with(|| format!("cannot write {}", path.display()))?;
    }
    Ok(())
}
