//! `mprog bench sentences`: the held-out sentence tasks (issue 48, ask 4). Each program runs
//! exactly as a user runs it (`mprog run PROGRAM --seed S --no-baseline`, a child process of
//! this binary), then the task's judge ([`mprog::tasks::sentences`]) reads the motion, the
//! run's `--report` gives met and plausible, and the envelope is measured directly.

use indicatif::{ProgressBar, ProgressStyle};
use miette::{IntoDiagnostic, Result, WrapErr, miette};
use mprog::formats::npy::{MotionFile, read_motion_npy};
use mprog::motion::Motion;
use mprog::tasks::sentences::inside::Inside;
use mprog::tasks::sentences::report::{Outcome, table};
use mprog::tasks::sentences::set::{DEFAULT_SET, SentenceTask, read_set};
use mprog::tasks::sentences::{Verdict, judge};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// Arguments of `mprog bench sentences`.
#[derive(clap::Args)]
pub struct SentenceBenchArgs {
    /// The task file (sentences and their programs; see its header).
    #[arg(long, default_value = DEFAULT_SET)]
    set: PathBuf,
    /// Seeds of every task, comma separated.
    #[arg(long, value_delimiter = ',', default_value = "1")]
    seeds: Vec<u64>,
    /// Only these task ids (repeatable).
    #[arg(long)]
    only: Vec<String>,
    /// Where each run's motion, report and log go. Runs whose motion and report are there
    /// already are judged again, not run again (delete the folder to start over).
    #[arg(long, default_value = "target/bench-sentences")]
    work: PathBuf,
    /// Model bundle (default: the shipped model).
    #[arg(long)]
    model: Option<PathBuf>,
    /// Write the markdown here (atomically) as well as to stdout.
    #[arg(short = 'o', long = "out")]
    out: Option<PathBuf>,
    /// More arguments for every `mprog run` (after `--`), e.g. `-- --free-facing`.
    #[arg(last = true)]
    run_args: Vec<String>,
}

/// Runs `mprog bench sentences`.
pub fn run(args: SentenceBenchArgs) -> Result<()> {
    let tasks = read_set(&args.set).map_err(|e| miette!("{e}"))?;
    let tasks: Vec<SentenceTask> = tasks
        .into_iter()
        .filter(|t| args.only.is_empty() || args.only.contains(&t.id))
        .collect();
    if tasks.is_empty() {
        return Err(miette!(
            help = "the ids are in the task file",
            "no task matches --only"
        ));
    }
    if args.seeds.is_empty() {
        return Err(miette!("--seeds needs at least one seed"));
    }
    std::fs::create_dir_all(&args.work)
        .into_diagnostic()
        .wrap_err_with(|| format!("creating {}", args.work.display()))?;
    let exe = std::env::current_exe().into_diagnostic()?;
    let started = Instant::now();
    let date = super::bench_tasks::utc_now();
    let bar = ProgressBar::new((tasks.len() * args.seeds.len()) as u64);
    bar.set_style(
        ProgressStyle::with_template("{prefix:>6} {bar:25} {pos}/{len} {msg} [{elapsed}]")
            .expect("template"),
    );
    let mut outcomes = Vec::new();
    for task in &tasks {
        for &seed in &args.seeds {
            bar.set_prefix(task.id.clone());
            bar.set_message(format!("seed {seed}"));
            outcomes.push(run_task(&exe, &args, task, seed));
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    let mut text = format!(
        "`mprog bench sentences` on {date}: {} task(s) of {}, seed(s) {:?}, `mprog run --no-baseline{}{}` ({:.0} s)\n\n",
        tasks.len(),
        args.set.display(),
        args.seeds,
        args.model
            .as_ref()
            .map_or(String::new(), |m| format!(" --model {}", m.display())),
        args.run_args
            .iter()
            .map(|a| format!(" {a}"))
            .collect::<String>(),
        started.elapsed().as_secs_f64()
    );
    text.push_str(&table(&outcomes));
    print!("{text}");
    if let Some(path) = &args.out {
        mprog::fsutil::write_bytes_atomic(path, text.as_bytes())
            .into_diagnostic()
            .wrap_err_with(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

/// Runs (or reuses) one task's motion and judges it; a failed run is an outcome, not an error.
fn run_task(exe: &Path, args: &SentenceBenchArgs, task: &SentenceTask, seed: u64) -> Outcome {
    let stem = args.work.join(format!("{}-s{seed}", task.id));
    let npy = stem.with_extension("npy");
    let report = stem.with_extension("report.json");
    let log = stem.with_extension("log");
    let mut outcome = Outcome {
        id: task.id.clone(),
        sentence: task.sentence.clone(),
        seed,
        met: None,
        plausible: None,
        verdict: Verdict::wrong("no motion"),
        inside: None,
        not_met: Vec::new(),
        seconds: 0.0,
        failure: None,
    };
    let started = Instant::now();
    if !(npy.exists() && report.exists()) {
        let mut cmd = Command::new(exe);
        cmd.arg("run")
            .arg(&task.program)
            .args(["--seed", &seed.to_string(), "--no-baseline", "-o"])
            .arg(&npy)
            .arg("--report")
            .arg(&report);
        if let Some(m) = &args.model {
            cmd.arg("--model").arg(m);
        }
        cmd.args(&args.run_args);
        match cmd.output() {
            Ok(out) => {
                let mut text = out.stdout;
                text.extend_from_slice(&out.stderr);
                let _ = mprog::fsutil::write_bytes_atomic(&log, &text);
                if !out.status.success() && !npy.exists() {
                    let tail = String::from_utf8_lossy(&text);
                    let last = tail.lines().rev().find(|l| !l.trim().is_empty());
                    outcome.failure = Some(format!(
                        "`mprog run` exited with {} ({}; log {})",
                        out.status,
                        last.unwrap_or("no output").trim(),
                        log.display()
                    ));
                    return outcome;
                }
            }
            Err(e) => {
                outcome.failure = Some(format!("cannot start {}: {e}", exe.display()));
                return outcome;
            }
        }
        outcome.seconds = started.elapsed().as_secs_f64();
    }
    let people = match read_motion_npy(&npy) {
        Ok(MotionFile::Joints(people)) => people,
        Ok(MotionFile::Features(_)) => {
            outcome.failure = Some(format!("{} holds features, not joints", npy.display()));
            return outcome;
        }
        Err(e) => {
            outcome.failure = Some(e.to_string());
            return outcome;
        }
    };
    match read_report(&report) {
        Ok((met, plausible, not_met, seconds)) => {
            outcome.seconds = seconds.unwrap_or(outcome.seconds);
            outcome.met = Some(met);
            outcome.plausible = Some(plausible);
            outcome.not_met = not_met;
        }
        Err(e) => outcome.failure = Some(e),
    }
    outcome.verdict = judged(task, &people);
    outcome.inside = Some(Inside::measure(&people));
    outcome
}

fn judged(task: &SentenceTask, people: &[Motion]) -> Verdict {
    judge(&task.id, people).unwrap_or_else(|| Verdict::wrong(format!("no judge for {}", task.id)))
}

/// What `mprog run --report` says: met, plausible, the statements not called "met", and the
/// solver's seconds.
type RunReport = (bool, bool, Vec<String>, Option<f64>);

/// Reads `mprog run --report`.
fn read_report(path: &Path) -> std::result::Result<RunReport, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let v: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| format!("{} is not a run report: {e}", path.display()))?;
    let statements = v["statements"]
        .as_array()
        .ok_or_else(|| format!("{} has no statements", path.display()))?;
    let mut not_met = Vec::new();
    for s in statements {
        let column = s["plausibility"].as_str().unwrap_or("");
        // "—" is an objective (minimize/maximize): nothing to meet.
        if column != "—" && !column.starts_with("met") {
            not_met.push(format!(
                "line {}: `{}` {column} ({:.4})",
                s["line"],
                s["statement"].as_str().unwrap_or("?"),
                s["guided"].as_f64().unwrap_or(f64::NAN)
            ));
        }
    }
    let plausible = v["plausibility"]["ok"]
        .as_bool()
        .ok_or_else(|| format!("{} has no plausibility", path.display()))?;
    let seconds = v["seconds"]["guided"].as_f64();
    Ok((not_met.is_empty(), plausible, not_met, seconds))
}
