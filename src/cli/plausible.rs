//! The plausibility report on the command line's outputs (`run`, `gen`, edits): the
//! envelope of the model bundle, the statements active at each problem's frames, and the
//! error table's plausibility column.

use burn::prelude::*;
use miette::{IntoDiagnostic, Result, miette};
use mprog::dataset::envelope::Envelope;
use mprog::lang::Program;
use mprog::metrics::plausibility::{Kind, Report};
use mprog::motion::Motion;
use std::path::Path;

/// A statement's mean error at or below this (in its unit) counts as met.
pub const MET_TOLERANCE: f32 = 1e-3;

/// The envelope of the bundle in `dir` (the built-in one when it has none).
pub fn envelope(dir: &Path) -> Result<Envelope> {
    mprog::model::weights::envelope_or_builtin(dir).into_diagnostic()
}

/// `line N `source``, how a problem names a statement.
pub fn statement_name(label: &str, line: usize) -> String {
    let text = label.split_once(": ").map_or(label, |(_, t)| t).trim();
    format!("line {line} `{text}`")
}

/// Per statement, the frames where it pulled on `people`: the frames where it applies;
/// for a statement that applies on every frame (`always`), only those where its error on
/// the result or on the unguided sample is above zero.
pub fn active_frames(
    program: &Program,
    people: &[Motion],
    baseline: Option<&[Motion]>,
    device: &Device,
) -> Result<Vec<Vec<bool>>> {
    let total = people.iter().map(Motion::len).min().unwrap_or(0);
    if total == 0 || people.iter().any(|m| !m.is_finite()) {
        return Ok(vec![Vec::new(); program.statements().len()]);
    }
    let eval = |ms: &[Motion]| {
        program
            .evaluate_frames(mprog::view::program::people_tensor(ms, device))
            .into_diagnostic()
    };
    let guided = eval(people)?;
    let base = match baseline {
        Some(b) if b.iter().map(Motion::len).min() == Some(total) => Some(eval(b)?),
        _ => None,
    };
    Ok(guided
        .iter()
        .enumerate()
        .map(|(s, f)| {
            let mut active = vec![false; total];
            let applies = |k: usize| f.applies[0].get(k).copied().unwrap_or(false);
            let count = (0..f.frames.len())
                .filter(|&k| applies(k) && f.frames[k] < total)
                .count();
            let everywhere = count == total && total > 1;
            for (k, &t) in f.frames.iter().enumerate() {
                if t >= total || !applies(k) {
                    continue;
                }
                let above = |e: &Vec<f32>| e.get(k).is_some_and(|e| *e > 0.0);
                let pulls = !everywhere
                    || above(&f.errors[0])
                    || base.as_ref().is_some_and(|b| above(&b[s].errors[0]));
                active[t] |= pulls;
            }
            active
        })
        .collect())
}

/// Fills each problem's `statements` with those active at its frames.
pub fn attach_statements(report: &mut Report, program: &Program, active: &[Vec<bool>]) {
    let names: Vec<String> = program
        .statements()
        .iter()
        .map(|s| statement_name(&s.label, s.line))
        .collect();
    for p in &mut report.problems {
        p.statements = active
            .iter()
            .zip(&names)
            .filter(|(a, _)| {
                a.iter()
                    .enumerate()
                    .any(|(t, &on)| on && t >= p.frames[0] && t <= p.frames[1])
            })
            .map(|(_, n)| n.clone())
            .collect();
    }
}

/// The plausibility column of statement `i`: "met", "met by a snap at 5.85–5.95 s",
/// "not met", or "—" for an objective (minimize/maximize).
pub fn column(program: &Program, i: usize, error: f32, report: &Report) -> String {
    let statements = program.statements();
    let s = &statements[i];
    if program.ir().statements.get(i).is_some_and(|s| s.objective) {
        return "—".into();
    }
    let name = statement_name(&s.label, s.line);
    let met = error.is_finite() && error <= MET_TOLERANCE;
    // Per kind, in order of first appearance: its first stretch and how many more.
    let mut kinds: Vec<(Kind, String, usize)> = Vec::new();
    for p in report
        .problems
        .iter()
        .filter(|p| p.statements.contains(&name) && p.kind != Kind::Invalid)
    {
        match kinds.iter_mut().find(|k| k.0 == p.kind) {
            Some(k) => k.2 += 1,
            None => {
                let who = if report_people(report) > 1 {
                    format!(" (person {})", p.person)
                } else {
                    String::new()
                };
                kinds.push((p.kind, format!("{} at {}{who}", p.kind.noun(), p.when()), 0));
            }
        }
    }
    let how: Vec<String> = kinds
        .into_iter()
        .map(|(_, first, more)| match more {
            0 => first,
            n => format!("{first} and {n} more time{}", if n == 1 { "" } else { "s" }),
        })
        .collect();
    match (met, how.is_empty()) {
        (true, true) => "met".into(),
        (true, false) => format!("met by {}", how.join("; ")),
        (false, true) => "not met".into(),
        (false, false) => format!("not met; {}", how.join("; ")),
    }
}

fn report_people(report: &Report) -> usize {
    report.skating.len()
}

/// One line: "WHO: plausible" or "WHO: 3 problems (acceleration, foot skating)".
pub fn summary(who: &str, report: &Report) -> String {
    if report.ok {
        return format!("{who}: plausible");
    }
    let mut kinds: Vec<&str> = Vec::new();
    for p in &report.problems {
        if !kinds.contains(&p.kind.name()) {
            kinds.push(p.kind.name());
        }
    }
    format!(
        "{who}: {} problem{} ({})",
        report.problems.len(),
        if report.problems.len() == 1 { "" } else { "s" },
        kinds.join(", ")
    )
}

/// Prints the report (stdout, after the table).
pub fn print(report: &Report) {
    for line in report.lines() {
        println!("{line}");
    }
}

/// `--strict`: an error (non-zero exit) when the report has problems; the outputs are
/// already written.
pub fn strict(report: &Report, strict: bool) -> Result<()> {
    if strict && !report.ok {
        return Err(miette!(
            help =
                "the outputs were written; the problems are listed above and in meta.plausibility",
            "implausible result (--strict): {} problem(s)",
            report.problems.len()
        ));
    }
    Ok(())
}
