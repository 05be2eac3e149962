//! `mprog bench tasks`: run the task suite ([`mprog::tasks`]) and write its markdown.

use indicatif::{ProgressBar, ProgressStyle};
use miette::{IntoDiagnostic, Result, WrapErr, miette};
use mprog::dataset::{Dataset, FEATURE_DIM, Split};
use mprog::metrics::evaluator::{Evaluator, default_evaluator_dir};
use mprog::metrics::scores::fid;
use mprog::model::ModelBundle;
use mprog::model::control::ControlNet;
use mprog::model::weights::default_model_dir;
use mprog::solve::{Prior, Solver};
use mprog::tasks::head_height;
use mprog::tasks::report::{Realism, RunInfo, markdown};
use mprog::tasks::suite::{
    Family, SolverSettings, SuiteSize, Task, keyframe_suite, program_suite, solvers,
};
use mprog::tasks::{RunRow, run_task};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `mprog bench tasks`.
#[derive(clap::Args)]
pub struct TaskBenchArgs {
    /// A few tasks (minutes on a laptop CPU) instead of the whole suite.
    #[arg(long)]
    quick: bool,
    /// Chain lengths: `fast` (sized for a CPU) or `paper` (the papers' defaults, for a GPU).
    #[arg(long, value_enum, default_value = "fast")]
    settings: SolverSettings,
    /// Built dataset (`mprog data build`): test clips for keyframe control and the
    /// realism reference. Without it those parts are skipped, with a message.
    #[arg(long, default_value = "data/humanml")]
    data: PathBuf,
    /// Folder of the task programs.
    #[arg(long, default_value = "programs")]
    programs: PathBuf,
    /// Samples per program task (full run).
    #[arg(long, default_value_t = 4)]
    samples: usize,
    /// Test clips for keyframe control (full run).
    #[arg(long, default_value_t = 4)]
    clips: usize,
    /// Test clips for the head-height task, PMG's HSI-1 with the clips' own targets (full run).
    #[arg(long, default_value_t = 4)]
    head_clips: usize,
    /// Only these task families (comma separated: pmg, head-height, keyframe, contact).
    #[arg(long, value_delimiter = ',', value_enum)]
    family: Vec<Family>,
    /// Only the tasks with these names, comma separated, as the table's first column
    /// writes them (`--tasks HSI-2,HSI-4`; case does not matter).
    #[arg(long, value_delimiter = ',')]
    tasks: Vec<String>,
    /// Only these solvers, comma separated (default: every registered one; `mprog run --help`
    /// lists them).
    #[arg(long, value_delimiter = ',')]
    solvers: Vec<String>,
    /// Override a solver setting for this run: `--knob latent.iterations=20`.
    #[arg(long = "knob", value_parser = parse_knob)]
    knobs: Vec<(String, String, f64)>,
    /// Seed of every sample and of the keyframe draws.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Model bundle (default: the shipped model).
    #[arg(long)]
    model: Option<PathBuf>,
    /// Write the markdown here (atomically) as well as to stdout.
    #[arg(short, long)]
    out: Option<PathBuf>,
}

fn parse_knob(s: &str) -> Result<(String, String, f64), String> {
    let (key, value) = s
        .split_once('=')
        .ok_or_else(|| format!("`{s}`: expected solver.knob=value"))?;
    let (solver, knob) = key
        .split_once('.')
        .ok_or_else(|| format!("`{key}`: expected solver.knob, e.g. latent.iterations"))?;
    let value: f64 = value
        .trim()
        .parse()
        .map_err(|_| format!("`{value}` is not a number"))?;
    Ok((solver.trim().into(), knob.trim().into(), value))
}

/// Row label of guide run without the ControlNet.
pub const GUIDE_NO_REALISM: &str = "guide, realism 0";

/// `list` with a copy of `guide` at `realism = 0` after it, when the bundle has a
/// ControlNet (without one the two would be the same run).
fn with_no_realism_guide(
    list: Vec<(Solver, String)>,
    has_control: bool,
) -> Result<Vec<(Solver, String)>> {
    let mut out = Vec::with_capacity(list.len() + 1);
    for (solver, label) in list {
        let copy = (has_control && solver.name() == "guide").then(|| solver.clone());
        out.push((solver, label));
        if let Some(mut plain) = copy {
            plain
                .set_knob("realism", 0.0)
                .map_err(|e| miette!("guide's realism knob: {e}"))?;
            out.push((plain, GUIDE_NO_REALISM.to_string()));
        }
    }
    Ok(out)
}

/// The solvers of this run, with `--solvers` and `--knob` applied.
fn chosen_solvers(args: &TaskBenchArgs) -> Result<Vec<Solver>> {
    let mut list = solvers(args.settings);
    if !args.solvers.is_empty() {
        for name in &args.solvers {
            if Solver::by_name(name).is_none() {
                return Err(miette!("unknown solver `{name}` in --solvers"));
            }
        }
        list.retain(|s| args.solvers.iter().any(|n| n == s.name()));
    }
    for (solver, knob, value) in &args.knobs {
        let mut hit = false;
        for s in list.iter_mut().filter(|s| s.name() == solver) {
            s.set_knob(knob, *value)
                .map_err(|e| miette!("--knob {solver}.{knob}: {e}"))?;
            hit = true;
        }
        if !hit {
            return Err(miette!(
                "--knob {solver}.{knob}: `{solver}` is not in this run"
            ));
        }
    }
    Ok(list)
}

/// UTC `YYYY-MM-DD HH:MM` of now (civil-from-days, proleptic Gregorian).
pub(super) fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs() as i64);
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02} {:02}:{:02} UTC",
        rem / 3600,
        rem % 3600 / 60
    )
}

/// FID of each (family, solver)'s motions against test clips, when the data and the
/// evaluator are there.
fn realism(
    rows: &[RunRow],
    data: Option<&Dataset>,
    device: &burn::prelude::Device,
) -> Result<Realism> {
    let mut out = Realism::new();
    let Some(data) = data else { return Ok(out) };
    let evaluator = match Evaluator::load(&default_evaluator_dir(), device) {
        Ok(e) => e,
        Err(e) => {
            eprintln!("realism column skipped: {e}");
            return Ok(out);
        }
    };
    let cap = evaluator.manifest.config.max_frames;
    let reference: Vec<&[f32]> = data
        .clips(Split::Test)
        .filter(|c| c.frames >= 40)
        .take(512)
        .map(|c| &data.clip_features(c)[..c.frames.min(cap) * FEATURE_DIM])
        .collect();
    let reference = evaluator
        .embed_motions(&reference, device)
        .into_diagnostic()?;
    let mut groups: std::collections::BTreeMap<_, Vec<&[f32]>> = Default::default();
    for r in rows.iter().filter(|r| r.failure.is_none()) {
        let g = groups.entry((r.family, r.solver.clone())).or_default();
        g.extend(
            r.features
                .iter()
                .map(|f| &f[..f.len().min(cap * FEATURE_DIM)]),
        );
    }
    for (key, motions) in groups {
        if motions.len() < 2 {
            continue;
        }
        let emb = evaluator
            .embed_motions(&motions, device)
            .into_diagnostic()?;
        if let Ok(score) = fid(&emb, &reference) {
            out.insert(key, (score, motions.len()));
        }
    }
    Ok(out)
}

/// Runs `mprog bench tasks`.
pub fn run(args: TaskBenchArgs) -> Result<()> {
    let started = Instant::now();
    let device = super::device()?;
    let list: Vec<(Solver, String)> = chosen_solvers(&args)?
        .into_iter()
        .map(|s| {
            let label = s.name().to_string();
            (s, label)
        })
        .collect();
    let size = if args.quick {
        SuiteSize::quick()
    } else {
        SuiteSize::full(args.samples.max(1), args.clips.max(1), args.head_clips)
    };
    let dir = args.model.clone().unwrap_or_else(default_model_dir);
    let bundle = ModelBundle::load(&dir, &device)
        .into_diagnostic()
        .wrap_err("cannot load the model")?;
    // A realism ControlNet beside the weights steers `guide` by default; the run then also
    // measures guide without it (`realism = 0`), its own row in every table.
    let control = ControlNet::load(&dir, &bundle.model, bundle.manifest.half_precision, &device)
        .into_diagnostic()?;
    let prior = Prior::from_bundle(&bundle).with_control(control.as_ref());
    // A few-step model runs only the solvers that can use its chain, and `latent-fast`
    // needs one: the others are named and left out.
    let few_step = bundle.manifest.consistency.is_some();
    let (list, skipped): (Vec<_>, Vec<_>) =
        list.into_iter().partition(|(s, _)| s.runs_on(few_step));
    if !skipped.is_empty() {
        let names: Vec<&str> = skipped.iter().map(|(_, l)| l.as_str()).collect();
        eprintln!(
            "skipped on {}: {} ({})",
            bundle.manifest.weights_id,
            names.join(", "),
            if few_step {
                "they need a diffusion model"
            } else {
                "it needs a few-step model: pass --model models/fast"
            }
        );
    }
    if list.is_empty() {
        return Err(miette!(
            "no chosen solver runs on {}",
            bundle.manifest.weights_id
        ));
    }
    let list = with_no_realism_guide(list, control.is_some())?;
    let mut tasks: Vec<Task> = program_suite(&args.programs, &size).map_err(|e| miette!("{e}"))?;
    let data = match Dataset::load(&args.data) {
        Ok(d) => Some(d),
        Err(e) => {
            eprintln!(
                "head heights, keyframe control and realism skipped: no dataset at {} ({e}); build it with `mprog data build`",
                args.data.display()
            );
            None
        }
    };
    if let Some(d) = &data {
        tasks.extend(
            head_height::suite(d, size.head_clips, size.samples).map_err(|e| miette!("{e}"))?,
        );
        tasks.extend(keyframe_suite(d, &size, args.seed).map_err(|e| miette!("{e}"))?);
    }
    if !args.family.is_empty() {
        tasks.retain(|t| args.family.contains(&t.family));
    }
    if !args.tasks.is_empty() {
        let names: Vec<String> = tasks.iter().map(|t| t.name.clone()).collect();
        if let Some(unknown) = args
            .tasks
            .iter()
            .find(|w| !names.iter().any(|n| n.eq_ignore_ascii_case(w)))
        {
            return Err(miette!(
                help = format!("the tasks of this run: {}", names.join(", ")),
                "no task named `{unknown}` in this run"
            ));
        }
        tasks.retain(|t| args.tasks.iter().any(|w| t.name.eq_ignore_ascii_case(w)));
    }
    if tasks.is_empty() {
        return Err(miette!(
            "no tasks to run: --quick has no head-height tasks, and head heights and keyframe \
             control need the dataset ({})",
            args.data.display()
        ));
    }
    let runs = tasks.len() * list.len();
    eprintln!(
        "{} tasks × {} solvers = {runs} runs on {}",
        tasks.len(),
        list.len(),
        mprog::backend::backend_name()
    );
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template("{prefix:>28} {bar:25} {pos}/{len} {msg} [{elapsed}]")
            .expect("template"),
    );
    let mut rows = Vec::with_capacity(runs);
    for task in &tasks {
        for (solver, label) in &list {
            bar.set_prefix(format!("{}/{runs} {} {label}", rows.len() + 1, task.name));
            let mut row = run_task(&prior, task, solver, args.seed, &device, &mut |p| {
                bar.set_length(p.total as u64);
                bar.set_position(p.done as u64);
                if let Some(e) = p.error {
                    bar.set_message(format!("error {e:.4}"));
                }
            });
            row.solver = label.clone();
            let line = if let Some(f) = &row.failure {
                format!("{} / {label}: failed: {f}", task.name)
            } else {
                format!(
                    "{:<28} {:<7} error {:.4}  unsuccess {:.2}  skating {:.3}  accel {:.3}  {:.1} s/sample",
                    task.name,
                    row.solver,
                    row.error,
                    row.unsuccess,
                    row.skating,
                    row.max_accel,
                    row.seconds_per_sample
                )
            };
            // A hidden bar (no terminal) drops its println: log plainly then.
            if bar.is_hidden() {
                eprintln!("{line}");
            } else {
                bar.println(line);
            }
            rows.push(row);
        }
    }
    bar.finish_and_clear();
    let realism = realism(&rows, data.as_ref(), &device)?;
    let info = RunInfo {
        date: utc_now(),
        machine: mprog::backend::machine_description(),
        backend: mprog::backend::backend_name(),
        weights: format!(
            "{} ({} training steps)",
            bundle.manifest.weights_id, bundle.manifest.steps
        ),
        command: std::env::args()
            .skip(1)
            .collect::<Vec<_>>()
            .join(" ")
            .replace("bench tasks", "mprog bench tasks"),
        solvers: list
            .iter()
            .map(|(s, label)| format!("{label}: {s:?}"))
            .collect(),
        seconds: started.elapsed().as_secs_f64(),
    };
    let md = markdown(&info, &rows, &realism);
    print!("{md}");
    if let Some(path) = &args.out {
        mprog::fsutil::write_bytes_atomic(path, md.as_bytes())
            .into_diagnostic()
            .wrap_err_with(|| format!("cannot write {}", path.display()))?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
