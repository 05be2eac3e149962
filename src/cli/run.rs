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
use mprog::model::weights::{default_model_dir, fast_model_dir};
use mprog::motion::Motion;
use mprog::solve::long::{LongProgress, LongRequest, LongTake, PromptSpan, solve_long, timelines};
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
    /// Leave the feet as the solver made them: no foot cleanup of the result (planted feet
    /// held in place, as `gen` cleans its samples; the error table is of the cleaned motion).
    #[arg(long)]
    raw: bool,
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
    /// Motions longer than the model makes, and prompt timelines, are made in windows:
    /// seconds each window keeps from the one before.
    #[arg(long, default_value_t = mprog::solve::long::DEFAULT_CONTEXT as f32 / 20.0)]
    seam_context: f32,
    /// RePaint resampling rounds of each window after the first (each round costs about
    /// one more chain).
    #[arg(long, default_value_t = mprog::solve::long::DEFAULT_WINDOW_RESAMPLE)]
    seam_resample: usize,
    /// Exit non-zero when the plausibility report finds a problem (a snap, the floor,
    /// foot skating, people overlapping, a deformed body, walking backwards); the outputs
    /// are written all the same, with the report in their meta.
    #[arg(long)]
    strict: bool,
    /// Leave facing and posture to the program and the model: by default a person who
    /// travels is steered to face along the path (unless the prompt asks for walking
    /// backwards or sideways), and a person told to walk or run (and nothing low) is kept
    /// from dipping the pelvis, since a program that pulls the pelvis round a path says
    /// nothing of where the body faces or how upright it stays.
    #[arg(long)]
    free_facing: bool,
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

/// Each person's timeline (see [`timelines`]).
fn timelines_of(program: &Program, prompts: &[String], frames: usize) -> Vec<Vec<PromptSpan>> {
    let spans = program
        .timelines()
        .into_iter()
        .map(|line| line.into_iter().map(|t| (t.from, t.to, t.text)).collect())
        .collect();
    timelines(spans, prompts, frames, program.length())
}

/// Per person: whether the solver steers them to face along their path and keeps them
/// upright ([`mprog::metrics::crouch::prompt_steering`]).
fn facing_people(program: &Program, prompts: &[String], free: bool) -> Vec<(bool, bool)> {
    let lines = program.timelines();
    let texts: Vec<Vec<&str>> = prompts
        .iter()
        .enumerate()
        .map(|(i, prompt)| {
            let spans = lines.get(i).map(Vec::as_slice).unwrap_or(&[]);
            std::iter::once(prompt.as_str())
                .chain(spans.iter().map(|t| t.text.as_str()))
                .collect()
        })
        .collect();
    mprog::metrics::crouch::prompt_steering(&texts, free)
}

/// Solves `req` with a progress bar; with `timelines`, window by window
/// ([`mprog::solve::long`]), the request giving the length, seed, solver and placements.
/// How a motion made in windows is made: the timelines, the context kept, resampling
/// rounds, and the take edited, if any.
#[derive(Clone, Copy)]
struct Windowed<'a> {
    timelines: &'a [Vec<PromptSpan>],
    context: usize,
    resample: usize,
    take: Option<&'a LongTake>,
    /// The prompts' action lengths the windows are cut to.
    actions: &'a [(String, usize)],
}

/// The actions' own lengths the windows are cut to ([`mprog::solve::long::action_frames`]);
/// none when a take is edited (its windows follow the take).
fn window_actions(
    bundle: &ModelBundle,
    timelines: &[Vec<PromptSpan>],
    editing: bool,
) -> Vec<(String, usize)> {
    if editing {
        return Vec::new();
    }
    mprog::solve::long::action_frames(&bundle.text, timelines, bundle.config.max_frames)
}

fn solve_with_bar(
    bundle: &ModelBundle,
    control: Option<&ControlNet>,
    req: &SolveRequest,
    timelines: Option<Windowed>,
    error: &dyn mprog::solve::MotionError,
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
    let prior = Prior::from_bundle(bundle).with_control(control);
    let out = match timelines {
        None => solve(&prior, req, error, device, |p: Progress| {
            bar.set_length(p.total as u64);
            bar.set_position(p.done as u64);
            if let Some(e) = p.error {
                bar.set_message(format!("error {e:.4}"));
            }
        }),
        Some(Windowed {
            timelines: lines,
            context,
            resample,
            take,
            actions,
        }) => {
            let long = LongRequest {
                timelines: lines.to_vec(),
                context,
                resample,
                take: take.cloned(),
                placements: req.placements.clone(),
                guidance_scale: req.guidance_scale,
                // Each window's feet are cleaned as `gen` cleans them (`--raw`: not); `guide`
                // polishes the window's statements after its cleanup, which a cleanup
                // without a polish left 2 cm short (a timeline's `at 11s`).
                clean_feet: req.clean_feet,
                action_frames: actions.to_vec(),
                ..LongRequest::new(Vec::new(), req.frames, req.seed, req.solver.clone())
            };
            solve_long(&prior, &long, error, device, |p: LongProgress| {
                let (done, total) = p.overall();
                bar.set_length(total as u64);
                bar.set_position(done as u64);
                let e = p
                    .step
                    .error
                    .map_or(String::new(), |e| format!(", error {e:.4}"));
                bar.set_message(format!("window {}/{}{e}", p.window + 1, p.windows));
            })
        }
    }
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
pub fn run(mut args: RunArgs) -> Result<()> {
    let program = compile_file(&args.program, &args.set)?;
    let solver = solver_with_knobs(&args.solver, &args.knobs)?;
    let prompts = prompts_of(&program, &args.text)?;
    check_outputs(&args.out)?;
    args.export.prepare(&args.out)?;
    let device = super::device()?;
    // `latent-fast` needs the few-step model: the shipped one unless --model names another.
    let dir = args.model.clone().unwrap_or_else(|| {
        if solver.name() == "latent-fast" {
            fast_model_dir()
        } else {
            default_model_dir()
        }
    });
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
    // Poses no training clip comes near, said before solving (as `check` says them).
    let coverage = super::check::print_unseen(&program, &dir);
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
    // Longer than the model makes, or prompts on a timeline: made in windows.
    let timelines = timelines_of(&program, &prompts, frames);
    let windowed = frames > bundle.config.max_frames || timelines.iter().any(|t| t.len() > 1);
    // A take longer than the model makes, or edited under a timeline: each window edits
    // its stretch of it (an in-between's gap is no take to stretch).
    let long_take = match (&edit, &plan) {
        (Some(_), Some(p)) if windowed && p.after.is_some() => {
            return Err(miette!(
                help = format!(
                    "in-between takes whose gap and ends fit in {:.1} s, with a single prompt",
                    bundle.config.max_frames as f32 / 20.0
                ),
                "an in-between in windows (longer than the model makes, or a prompt timeline) is not supported"
            ));
        }
        (Some(e), Some(p)) if windowed => Some(LongTake::of(e, p.people.clone())),
        _ => None,
    };
    let context = super::generate::seam_context_frames(args.seam_context)?;
    let actions = match windowed {
        true => window_actions(&bundle, &timelines, long_take.is_some()),
        false => Vec::new(),
    };
    let windows = windowed.then_some(Windowed {
        timelines: &timelines,
        context,
        resample: args.seam_resample,
        take: long_take.as_ref(),
        actions: &actions,
    });
    let window_plan = if windowed {
        let w = mprog::solve::long::plan_windows(
            &timelines,
            frames,
            bundle.config.max_frames,
            context,
            &actions,
        )
        .into_diagnostic()?;
        eprintln!(
            "{:.1} s in {} windows of at most {:.1} s, each keeping {:.1} s of the one before",
            frames as f32 / 20.0,
            w.len(),
            bundle.config.max_frames as f32 / 20.0,
            context as f32 / 20.0
        );
        w
    } else {
        Vec::new()
    };
    let request = |solver: Solver| {
        let req = SolveRequest::new(prompts.clone(), frames, args.seed, solver)
            .placed(program.placements())
            .cleaned(!args.raw);
        match &edit {
            Some(e) => req.editing(e.clone()),
            None => req,
        }
    };
    let req = request(solver.clone());
    // The program's error, and what a walking prompt implies (`solve::facing`).
    let steering = facing_people(&program, &prompts, args.free_facing);
    let along = mprog::solve::facing::FacingAlongPath::steered(&program, &steering);
    let result = solve_with_bar(
        &bundle,
        control.as_ref(),
        &req,
        windows,
        &along,
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
            windows,
            &along,
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
    if windowed {
        let lines: Vec<Vec<serde_json::Value>> = timelines
            .iter()
            .map(|line| {
                line.iter()
                    .map(|s| serde_json::json!({"from": s.from, "to": s.to, "prompt": s.prompt}))
                    .collect()
            })
            .collect();
        meta.insert("timeline".into(), serde_json::json!(lines));
        meta.insert(
            "windows".into(),
            super::generate::windows_meta(&window_plan),
        );
        meta.insert("seam_resample".into(), args.seam_resample.into());
    }
    if let Some(plan) = &plan {
        meta.insert("edit".into(), plan.meta.clone().into());
    }
    meta.extend(mprog::view::program::program_meta(&program, people, &device).into_diagnostic()?);
    meta.insert("plausibility".into(), plausibility.to_json());
    meta.insert("coverage".into(), coverage.clone());
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
            "coverage": coverage,
            "outputs": written,
        });
        let text = serde_json::to_string_pretty(&report).into_diagnostic()?;
        mprog::fsutil::write_bytes_atomic(path, text.as_bytes())
            .into_diagnostic()
            .wrap_err_with(|| format!("writing {}", path.display()))?;
    }
    super::plausible::strict(&plausibility, args.strict)
}
