//! `mprog run`: a program becomes a motion. Generate with the shipped model, steer it with
//! the program's error through a solver, print each statement's error next to the
//! unguided sample's, and write the outputs with everything needed to reproduce them.

use super::io::{check_outputs, write_outputs_with};
use super::score::compile_file;
use burn::prelude::*;
use indicatif::{ProgressBar, ProgressStyle};
use miette::{IntoDiagnostic, Result, WrapErr, miette};
use mprog::formats::Meta;
use mprog::lang::Program;
use mprog::model::ModelBundle;
use mprog::model::control::ControlNet;
use mprog::model::weights::default_model_dir;
use mprog::motion::Motion;
use mprog::solve::{Prior, Progress, SolveRequest, SolveResult, Solver, solve};
use std::path::PathBuf;

/// One line on how physical the result is: a solver that stretched limbs, shook joints or
/// slid the feet to meet the program shows here (the numbers `mprog bench tasks` reports).
/// The skating figure says what it is measured against: the envelope's real clips.
fn body_summary(people: &[Motion], env: &mprog::dataset::envelope::Envelope) -> String {
    use mprog::metrics::per_motion::{foot_skating_ratio, max_acceleration, max_bone_error};
    let worst = |f: fn(&Motion) -> f32| people.iter().map(f).fold(0.0, f32::max);
    format!(
        "body: bone lengths within {:.1} cm of the skeleton's, foot skating {:.3} (real clips: mean {:.3}, p95 {:.3}; moving ones: mean {:.3}, p95 {:.3}), max joint acceleration {:.3} m/frame²{}",
        100.0 * worst(max_bone_error),
        worst(foot_skating_ratio),
        env.skating.mean,
        env.skating.p95,
        env.skating_moving.mean,
        env.skating_moving.p95,
        worst(max_acceleration),
        if people.len() > 1 {
            " (worst person)"
        } else {
            ""
        }
    )
}

/// Arguments of `mprog run`.
#[derive(clap::Args)]
pub struct RunArgs {
    /// The program.
    program: PathBuf,
    /// Solver (`--help` lists them with their knobs and defaults).
    #[arg(long, default_value = "guide", long_help = solvers_long_help())]
    solver: String,
    /// Solver setting, repeatable: `--knob iterations=30 --knob ddim_steps=20` (latent),
    /// `--knob steps=100` (guide, lbfgs, plain); an unknown name lists the valid ones.
    #[arg(long = "knob", value_parser = super::check::parse_override)]
    knobs: Vec<(String, f64)>,
    /// Seed: the same program, seed, settings and weights give the same motion.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Override a parameter: `--set diameter=0.5` (in the unit of its default).
    #[arg(long = "set", value_parser = super::check::parse_override)]
    set: Vec<(String, f64)>,
    /// Prompt for a single-person program without a `prompt` line.
    #[arg(long)]
    text: Option<String>,
    /// Skip the unguided comparison sample.
    #[arg(long)]
    no_baseline: bool,
    /// Give the model the prompt as written, even when it lies far from every training
    /// caption (by default such a prompt is replaced by the mean of its nearest captions).
    #[arg(long)]
    literal_prompt: bool,
    /// Model bundle folder (default: models/default).
    #[arg(long)]
    model: Option<PathBuf>,
    /// Also write the per-statement errors (next to the unguided ones), the times and the
    /// files written as JSON, for tools (`mprog mcp` reads it).
    #[arg(long)]
    report: Option<PathBuf>,
    /// Exit non-zero when the plausibility report finds a problem (a snap, the floor,
    /// foot skating, people overlapping, a deformed body, walking backwards); the outputs
    /// are written all the same, with the report in their meta.
    #[arg(long)]
    strict: bool,
    /// Outputs; each one's extension picks its kind (`--help` lists them).
    #[arg(short, long, num_args = 1.., required = true, long_help = super::io::outputs_help())]
    out: Vec<PathBuf>,
    #[command(flatten)]
    export: super::export::ExportArgs,
    #[command(flatten)]
    take: super::take::TakeArgs,
}

fn prompts_of(program: &Program, text: &Option<String>) -> Result<Vec<String>> {
    let prompts = program.prompts();
    prompts
        .iter()
        .enumerate()
        .map(|(i, p)| {
            p.clone().or_else(|| text.clone()).ok_or_else(|| {
                miette!(
                    help = "add `prompt \"…\"` to the program or pass --text",
                    "person {} of {} has no prompt",
                    i + 1,
                    program.name()
                )
            })
        })
        .collect()
}

fn per_statement(program: &Program, people: &[Motion], device: &Device) -> Result<Vec<f32>> {
    let e = program
        .try_evaluate(mprog::view::program::people_tensor(people, device))
        .into_diagnostic()?;
    e.per_statement
        .into_data()
        .try_into_vec::<f32>()
        .map_err(|e| miette!("{e:?}"))
}

fn solve_with_bar(
    bundle: &ModelBundle,
    control: Option<&ControlNet>,
    req: &SolveRequest,
    program: &Program,
    device: &Device,
    label: &str,
) -> Result<SolveResult> {
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{label:>9} {{bar:30}} {{pos}}/{{len}} {{msg}} [{{elapsed}}]"
        ))
        .expect("template"),
    );
    let error: &dyn mprog::solve::MotionError = program;
    let out = solve(
        &Prior::from_bundle(bundle).with_control(control),
        req,
        error,
        device,
        |p: Progress| {
            bar.set_length(p.total as u64);
            bar.set_position(p.done as u64);
            if let Some(e) = p.error {
                bar.set_message(format!("error {e:.4}"));
            }
        },
    )
    .into_diagnostic()
    .wrap_err_with(|| format!("solver {}", req.solver.name()))?;
    bar.finish_and_clear();
    Ok(out)
}

fn solvers_long_help() -> String {
    format!("Solver, one of:\n{}", mprog::solve::solvers_help())
}

/// The solver named `name` with the `--knob` settings applied.
pub fn solver_with_knobs(name: &str, knobs: &[(String, f64)]) -> Result<Solver> {
    let mut solver = Solver::by_name(name).ok_or_else(|| {
        miette!(
            help = format!("use {}", Solver::names().join(", ")),
            "unknown solver `{name}`"
        )
    })?;
    for (k, v) in knobs {
        solver
            .set_knob(k, *v)
            .map_err(|e| miette!("--knob {k}={v}: {e}"))?;
    }
    Ok(solver)
}

/// Runs `mprog run`.
pub fn run(args: RunArgs) -> Result<()> {
    let program = compile_file(&args.program, &args.set)?;
    let solver = solver_with_knobs(&args.solver, &args.knobs)?;
    let prompts = prompts_of(&program, &args.text)?;
    check_outputs(&args.out)?;
    args.export.check_against(&args.out)?;
    let device = super::device()?;
    let dir = args.model.clone().unwrap_or_else(default_model_dir);
    let mut bundle = ModelBundle::load(&dir, &device)
        .into_diagnostic()
        .wrap_err("cannot load the model (train one with `mprog train`, or pass --model)")?;
    if args.literal_prompt {
        bundle.text.read_literally();
    }
    // A realism ControlNet beside the weights steers `guide` (knob `realism`).
    let control = ControlNet::load(&dir, &bundle.model, bundle.manifest.half_precision, &device)
        .into_diagnostic()?;
    let control_loaded = control.is_some();
    let envelope = super::plausible::envelope(&dir)?;
    let several = prompts.len() > 1;
    for (person, prompt) in program.people().iter().zip(&prompts) {
        for line in bundle.text.report(prompt) {
            if several {
                eprintln!("{}: {line}", person.name);
            } else {
                eprintln!("{line}");
            }
        }
    }
    let mut plan = super::take::plan(&args.take, &program, bundle.config.max_frames)?;
    let edit = plan
        .as_mut()
        .map(|p| p.edit(&bundle.mean, &program))
        .transpose()?;
    let frames = edit.as_ref().map_or(program.length(), |e| e.take.frames);
    let request = |solver: Solver| {
        let req = SolveRequest::new(prompts.clone(), frames, args.seed, solver)
            .placed(program.placements());
        match &edit {
            Some(e) => req.editing(e.clone()),
            None => req,
        }
    };
    let req = request(solver.clone());
    let result = solve_with_bar(
        &bundle,
        control.as_ref(),
        &req,
        &program,
        &device,
        solver.name(),
    )?;
    let people = &result.motions[0];
    let guided = per_statement(&program, people, &device)?;
    let baseline = if args.no_baseline {
        None
    } else {
        let req = request(solver.unguided());
        let r = solve_with_bar(
            &bundle,
            control.as_ref(),
            &req,
            &program,
            &device,
            "unguided",
        )?;
        Some((
            per_statement(&program, &r.motions[0], &device)?,
            r.seconds,
            r.motions[0].clone(),
        ))
    };
    let prompt_list: Vec<Option<String>> = prompts.iter().cloned().map(Some).collect();
    let mut plausibility = mprog::metrics::plausibility::check(people, &prompt_list, &envelope);
    let active = super::plausible::active_frames(
        &program,
        people,
        baseline.as_ref().map(|(_, _, m)| m.as_slice()),
        &device,
    )?;
    super::plausible::attach_statements(&mut plausibility, &program, &active);
    let column = |i: usize| super::plausible::column(&program, i, guided[i], &plausibility);
    println!(
        "| line | statement | unit | unguided | {} | plausibility |",
        solver.name()
    );
    println!("| --- | --- | --- | --- | --- | --- |");
    for (i, s) in program.statements().iter().enumerate() {
        let text = s
            .label
            .split_once(": ")
            .map_or(s.label.as_str(), |(_, t)| t)
            .trim();
        let base = baseline
            .as_ref()
            .map_or("—".into(), |(b, _, _)| format!("{:.4}", b[i]));
        println!(
            "| {} | `{text}` | {} | {base} | {:.4} | {} |",
            s.line,
            s.unit,
            guided[i],
            column(i)
        );
    }
    let total: f32 = guided.iter().sum();
    let base_total = baseline.as_ref().map_or("—".into(), |(b, _, _)| {
        format!("{:.4}", b.iter().sum::<f32>())
    });
    let verdict = if plausibility.ok {
        "plausible"
    } else {
        "implausible"
    };
    println!("| | **total** | | {base_total} | {total:.4} | {verdict} |");
    super::plausible::print(&plausibility);
    // The unguided sample's report tells what the steering added.
    let unguided_plausibility = baseline
        .as_ref()
        .map(|(_, _, m)| mprog::metrics::plausibility::check(m, &prompt_list, &envelope));
    if let Some(u) = &unguided_plausibility {
        println!("{}", super::plausible::summary("the unguided sample", u));
    }
    // After the table, so a terminal does not interleave them with its rows.
    if let Some((base, _, _)) = &baseline {
        for (s, b) in program.statements().iter().zip(base) {
            if *b <= 0.0 && ["<", ">", "<=", ">="].iter().any(|op| s.label.contains(op)) {
                eprintln!(
                    "warning: line {}: already satisfied on every frame by the unguided motion, so it steers nothing (is the inequality the right way round?)",
                    s.line
                );
            }
        }
    }
    match &baseline {
        Some((_, s, _)) => eprintln!(
            "{}: {:.1} s (unguided: {s:.1} s)",
            solver.name(),
            result.seconds
        ),
        None => eprintln!("{}: {:.1} s", solver.name(), result.seconds),
    }
    eprintln!("{}", body_summary(people, &envelope));
    let mut meta = Meta::new();
    meta.insert(
        "program".into(),
        std::fs::read_to_string(&args.program)
            .unwrap_or_default()
            .into(),
    );
    meta.insert(
        "program_file".into(),
        args.program.display().to_string().into(),
    );
    meta.insert("overrides".into(), serde_json::json!(args.set));
    meta.insert("knobs".into(), serde_json::json!(args.knobs));
    meta.insert("seed".into(), args.seed.into());
    meta.insert("solver".into(), format!("{solver:?}").into());
    meta.insert(
        "weights_id".into(),
        bundle.manifest.weights_id.clone().into(),
    );
    if control_loaded {
        let id = bundle.manifest.control_id.clone();
        meta.insert(
            "control_id".into(),
            id.unwrap_or_else(|| "unnamed".into()).into(),
        );
    }
    meta.insert("prompts".into(), serde_json::json!(prompts));
    if let Some(plan) = &plan {
        meta.insert("edit".into(), plan.meta.clone().into());
    }
    meta.extend(mprog::view::program::program_meta(&program, people, &device).into_diagnostic()?);
    meta.insert("plausibility".into(), plausibility.to_json());
    let written = write_outputs_with(
        &args.out,
        people,
        &meta,
        &format!("{} ({})", program.name(), solver.name()),
        &args.export,
    )?;
    if let Some(path) = &args.report {
        let statements: Vec<serde_json::Value> = program
            .statements()
            .iter()
            .enumerate()
            .map(|(i, s)| {
                serde_json::json!({
                    "line": s.line,
                    "statement": s.label.split_once(": ").map_or(s.label.as_str(), |(_, t)| t).trim(),
                    "unit": s.unit,
                    "unguided": baseline.as_ref().map(|(b, _, _)| b[i]),
                    "guided": guided[i],
                    "plausibility": column(i),
                })
            })
            .collect();
        let report = serde_json::json!({
            "solver": solver.name(),
            "seed": args.seed,
            "statements": statements,
            "total": {"guided": total, "unguided": baseline.as_ref().map(|(b, _, _)| b.iter().sum::<f32>())},
            "seconds": {"guided": result.seconds, "unguided": baseline.as_ref().map(|(_, s, _)| *s)},
            "body": body_summary(people, &envelope),
            "plausibility": plausibility.to_json(),
            "plausibility_unguided": unguided_plausibility.as_ref().map(|u| u.to_json()),
            "outputs": written,
        });
        let text = serde_json::to_string_pretty(&report).into_diagnostic()?;
        mprog::fsutil::write_bytes_atomic(path, text.as_bytes())
            .into_diagnostic()
            .wrap_err_with(|| format!("writing {}", path.display()))?;
    }
    super::plausible::strict(&plausibility, args.strict)
}
