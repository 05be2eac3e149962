//! `:eval`, `:grad` and `:score`: typed code is compiled as a probe program (the
//! session's program + the input), evaluated on the current motion, and only the input's
//! statements are reported. The checker decides what the input is: a constraint, a
//! scalar (compiled as `minimize (e)`) or a vector (`minimize (e).x`, `.y`, `.z`).

use super::reply::{Item, Reply};
use super::session::{CurrentMotion, NO_MOTION, SOURCE_NAME, Session, real_errors, visible};
use super::summary::{SPARK_WIDTH, bar, num, sparkline, stats};
use crate::lang::{Diagnostics, FrameErrors, Program, compile};
use crate::skeleton::{JOINT_NAMES, NUM_JOINTS};
use burn::tensor::{Device, Tensor, TensorData};
use std::ops::Range;

/// What the input turned out to be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A constraint: its error per frame.
    Statement,
    /// A scalar value.
    Scalar,
    /// A vector value: three statements, x, y and z.
    Vector,
}

/// A compiled probe: the program and which of its statements are the input's.
pub struct Probe {
    /// Session program + input.
    pub program: Program,
    /// Columns of the input's statements.
    pub cols: Range<usize>,
    /// How the input was read.
    pub kind: Kind,
}

/// Compiles `text` against the session's program.
pub fn compile_probe(session: &Session, text: &str) -> Result<Probe, Reply> {
    let base = session.source();
    let text = text.trim();
    let attempt = |code: String, kind: Kind| -> Result<Probe, Diagnostics> {
        let src = format!("{base}{code}\n");
        let program = compile(&src, SOURCE_NAME, &[])?;
        let first = program
            .statements()
            .iter()
            .position(|s| s.span.start >= base.len())
            .unwrap_or(program.statements().len());
        let cols = first..program.statements().len();
        Ok(Probe {
            program,
            cols,
            kind,
        })
    };
    let as_statement = match attempt(text.to_string(), Kind::Statement) {
        Ok(p) if p.cols.is_empty() => {
            return Err(Reply::error(
                "nothing to evaluate: the input has no constraint or value",
            ));
        }
        Ok(p) => return Ok(p),
        Err(d) => d,
    };
    let only_not_constraint = as_statement
        .items
        .iter()
        .filter(|i| i.severity == crate::lang::Severity::Error)
        .all(|i| i.code == crate::lang::codes::NOT_A_CONSTRAINT);
    if !real_errors(&as_statement) {
        return Err(Reply::error(
            "nothing to evaluate: the input has no constraint or value",
        ));
    }
    if !only_not_constraint {
        return Err(Reply::diagnostics(visible(without_not_constraint(
            as_statement,
        ))));
    }
    match attempt(format!("minimize ({text})"), Kind::Scalar) {
        Ok(p) => Ok(p),
        Err(d)
            if d.items.iter().any(|i| {
                i.code == crate::lang::codes::TYPE_MISMATCH && i.message.contains("vector")
            }) =>
        {
            let code = ["x", "y", "z"]
                .map(|c| format!("minimize ({text}).{c}"))
                .join("\n");
            attempt(code, Kind::Vector).map_err(|d| Reply::diagnostics(visible(d)))
        }
        Err(_) => Err(Reply::diagnostics(visible(as_statement))),
    }
}

fn without_not_constraint(d: Diagnostics) -> Diagnostics {
    let others = d.items.iter().any(|i| {
        i.code != crate::lang::codes::NOT_A_CONSTRAINT && i.severity == crate::lang::Severity::Error
    });
    if !others {
        return d;
    }
    let items = d
        .items
        .into_iter()
        .filter(|i| i.code != crate::lang::codes::NOT_A_CONSTRAINT)
        .collect();
    Diagnostics::new(&d.name, d.source, items)
}

/// The motion as `[1, people, frames, 22, 3]` for a program of `people` people.
pub fn joints_tensor(
    m: &CurrentMotion,
    people: usize,
    device: &Device,
) -> Result<Tensor<5>, String> {
    if m.people.len() != people {
        return Err(format!(
            "the program describes {people} person(s) but the motion ({}) has {}; {}",
            m.origin,
            m.people.len(),
            if people == 1 {
                "load a single-person motion, or declare `people a, b, …`"
            } else {
                "load a motion with one track per declared person"
            }
        ));
    }
    let frames = m.frames();
    if frames == 0 {
        return Err(format!("the motion ({}) has no frames", m.origin));
    }
    let data: Vec<f32> = m
        .people
        .iter()
        .flat_map(|p| {
            p.frames[..frames]
                .iter()
                .flat_map(|pose| pose.iter().flat_map(|v| v.to_array()))
        })
        .collect();
    Ok(Tensor::from_data(
        TensorData::new(data, [1, people, frames, NUM_JOINTS, 3]),
        device,
    ))
}

/// `:eval`.
pub fn eval(session: &Session, text: &str) -> Reply {
    let Some(m) = session.motion() else {
        return Reply::error(NO_MOTION);
    };
    let probe = match compile_probe(session, text) {
        Ok(p) => p,
        Err(r) => return r,
    };
    let x = match joints_tensor(m, probe.program.people().len(), session.device()) {
        Ok(x) => x,
        Err(e) => return Reply::error(e),
    };
    let frames = match probe.program.evaluate_frames(x.clone()) {
        Ok(f) => f,
        Err(e) => return Reply::error(e.to_string()),
    };
    let infos = probe.program.statements();
    let unit = infos[probe.cols.start].unit.clone();
    let f = m.frames();
    let shown = text.split_whitespace().collect::<Vec<_>>().join(" ");
    let head = format!("{shown}  [{unit}] on {} ({f} frames)", m.origin);
    let mut out = vec![head];
    match probe.kind {
        Kind::Scalar => out.extend(series_lines("", &frames[probe.cols.start], f)),
        Kind::Vector => {
            for (c, fe) in ["x", "y", "z"].iter().zip(&frames[probe.cols.clone()]) {
                out.extend(series_lines(c, fe, f));
            }
        }
        Kind::Statement => {
            let ev = probe.program.evaluate(x);
            let per = host(ev.per_statement);
            let score: f32 = per[probe.cols.clone()].iter().sum();
            let merged = merge(&frames[probe.cols.clone()], f);
            let applies = merged.iter().flatten().count();
            let zero = merged.iter().flatten().filter(|v| **v <= 0.0).count();
            out.push(format!(
                "  error {} {unit}  (mean over the {applies} frame{} it applies to; zero at {zero})",
                num(score),
                if applies == 1 { "" } else { "s" }
            ));
            out.extend(series_lines("", &as_frame_errors(&merged), f));
        }
    }
    Reply::text(out.join("\n"))
}

/// The statements' per-frame errors summed on a full frame axis (None where none applies).
fn merge(fe: &[FrameErrors], frames: usize) -> Vec<Option<f32>> {
    let mut out = vec![None; frames];
    for s in fe {
        for (i, &t) in s.frames.iter().enumerate() {
            if t < frames && s.applies[0][i] {
                *out[t].get_or_insert(0.0) += s.errors[0][i];
            }
        }
    }
    out
}

fn as_frame_errors(merged: &[Option<f32>]) -> FrameErrors {
    let frames: Vec<usize> = (0..merged.len()).filter(|&t| merged[t].is_some()).collect();
    FrameErrors {
        errors: vec![frames.iter().map(|&t| merged[t].unwrap_or(0.0)).collect()],
        applies: vec![vec![true; frames.len()]],
        frames,
    }
}

/// `min mean max` and a sparkline (or the value at the one frame).
fn series_lines(label: &str, fe: &FrameErrors, frames: usize) -> Vec<String> {
    let pad = if label.is_empty() {
        String::new()
    } else {
        format!("{label}  ")
    };
    let blank = " ".repeat(pad.chars().count());
    let mut full = vec![None; frames];
    for (i, &t) in fe.frames.iter().enumerate() {
        if t < frames && fe.applies[0][i] {
            full[t] = Some(fe.errors[0][i]);
        }
    }
    let present: Vec<(usize, f32)> = full
        .iter()
        .enumerate()
        .filter_map(|(t, v)| v.map(|v| (t, v)))
        .collect();
    match present.as_slice() {
        [] => vec![format!("  {pad}applies at no frame of this motion")],
        [(t, v)] => vec![format!("  {pad}frame {t}: {}", num(*v))],
        _ => {
            let vals: Vec<f32> = present.iter().map(|p| p.1).collect();
            let (lo, mean, hi) = stats(&vals).unwrap_or((f32::NAN, f32::NAN, f32::NAN));
            let first = present[0].0;
            let last = present[present.len() - 1].0;
            let span = &full[first..=last];
            vec![
                format!(
                    "  {pad}min {}  mean {}  max {}",
                    num(lo),
                    num(mean),
                    num(hi)
                ),
                format!(
                    "  {blank}{}  frames {first}–{last}",
                    sparkline(span, SPARK_WIDTH)
                ),
            ]
        }
    }
}

/// `:grad`.
pub fn grad(session: &Session, text: &str) -> Reply {
    let Some(m) = session.motion() else {
        return Reply::error(NO_MOTION);
    };
    let probe = match compile_probe(session, text) {
        Ok(p) if p.kind == Kind::Vector => {
            return Reply::error(
                "`:grad` needs a constraint or a scalar; a vector has no single gradient (try `norm(…)` or `.y`)",
            );
        }
        Ok(p) => p,
        Err(r) => return r,
    };
    let ad = session.device().clone().autodiff();
    let people = probe.program.people().len();
    let x = match joints_tensor(m, people, &ad) {
        Ok(x) => x.require_grad(),
        Err(e) => return Reply::error(e),
    };
    let ev = match probe.program.try_evaluate(x.clone()) {
        Ok(e) => e,
        Err(e) => return Reply::error(e.to_string()),
    };
    let cols = probe.cols.clone();
    let picked = ev.per_statement.narrow(1, cols.start, cols.len());
    let value = host(picked.clone().sum_dim(1))
        .first()
        .copied()
        .unwrap_or(f32::NAN);
    let grads = picked.sum().backward();
    let Some(g) = x.grad(&grads) else {
        return Reply::text(format!(
            "{}: the error does not depend on the motion",
            text.trim()
        ));
    };
    let g = host5(g);
    let unit = probe.program.statements()[cols.start].unit.clone();
    let shown = text.split_whitespace().collect::<Vec<_>>().join(" ");
    Reply::text(grad_table(
        &shown,
        &g,
        people,
        m.frames(),
        value,
        &unit,
        &probe.program,
    ))
}

fn grad_table(
    text: &str,
    g: &[f32],
    people: usize,
    frames: usize,
    value: f32,
    unit: &str,
    p: &Program,
) -> String {
    // [people, frames, 22, 3] → per (person, joint): L2 norm over frames and xyz, peak frame.
    let mut rows: Vec<(usize, usize, f32, usize)> = Vec::new();
    for person in 0..people {
        for j in 0..NUM_JOINTS {
            let mut sq = 0.0f64;
            let mut peak = (0usize, 0.0f32);
            for t in 0..frames {
                let o = ((person * frames + t) * NUM_JOINTS + j) * 3;
                let n2: f32 = g[o..o + 3].iter().map(|v| v * v).sum();
                sq += f64::from(n2);
                if n2 > peak.1 {
                    peak = (t, n2);
                }
            }
            rows.push((person, j, sq.sqrt() as f32, peak.0));
        }
    }
    rows.sort_by(|a, b| b.2.total_cmp(&a.2));
    let total: f32 = rows.iter().map(|r| r.2 * r.2).sum::<f32>().sqrt();
    let mut out = vec![format!(
        "{text}  error {} {unit}; |∂error/∂joints| = {} {unit}/m",
        num(value),
        num(total)
    )];
    if total.is_nan() || total <= 0.0 {
        out.push(
            "  the gradient is zero: this constraint is satisfied (or flat) on this motion".into(),
        );
        return out.join("\n");
    }
    let max = rows[0].2;
    let moving = rows.iter().filter(|r| r.2 > 1e-6 * max).count();
    for &(person, j, mag, peak) in rows.iter().take(8).filter(|r| r.2 > 1e-6 * max) {
        let who = if people > 1 {
            format!("{}.", p.people()[person].name)
        } else {
            String::new()
        };
        out.push(format!(
            "  {:18} {:>10}  {:<16} peak at frame {peak}",
            format!("{who}{}", JOINT_NAMES[j]),
            num(mag),
            bar(mag, max, 16)
        ));
    }
    if moving > 8 {
        out.push(format!(
            "  … {} more joints with a smaller gradient",
            moving - 8
        ));
    }
    out.join("\n")
}

/// `:score`.
pub fn score(session: &Session) -> Reply {
    let Some(m) = session.motion() else {
        return Reply::error(NO_MOTION);
    };
    let program = match session.program() {
        Ok(p) => p,
        Err(d) if !real_errors(&d) => {
            return Reply::error("the program has no constraints yet: type one, or `:load FILE`");
        }
        Err(d) => return Reply::diagnostics(d),
    };
    let cols = 0..program.statements().len();
    match score_lines(&program, cols, m, session.device(), true) {
        Ok(lines) => Reply::text(lines),
        Err(e) => Reply::error(e),
    }
}

/// After code was added with a motion loaded: the new statements' errors.
pub fn score_new(session: &Session, start: usize, reply: &mut Reply) {
    let (Ok(program), Some(m)) = (session.program(), session.motion()) else {
        return;
    };
    let infos = program.statements();
    let first = infos
        .iter()
        .position(|s| s.span.start >= start)
        .unwrap_or(infos.len());
    if first == infos.len() {
        return;
    }
    match score_lines(&program, first..infos.len(), m, session.device(), false) {
        Ok(lines) => reply.push(Item::Text(lines)),
        Err(e) => reply.push(Item::Warning(e)),
    }
}

fn score_lines(
    program: &Program,
    cols: Range<usize>,
    m: &CurrentMotion,
    device: &Device,
    with_total: bool,
) -> Result<String, String> {
    let x = joints_tensor(m, program.people().len(), device)?;
    let ev = program.try_evaluate(x.clone()).map_err(|e| e.to_string())?;
    let frames = program.evaluate_frames(x).map_err(|e| e.to_string())?;
    let per = host(ev.per_statement);
    let infos = program.statements();
    let f = m.frames();
    let width = infos[cols.clone()]
        .iter()
        .map(|s| s.label.chars().count())
        .max()
        .unwrap_or(0)
        .min(48);
    let mut out = Vec::new();
    for i in cols.clone() {
        let s = &infos[i];
        let label: String = s.label.chars().take(48).collect();
        let weight = if s.weight == 1.0 {
            String::new()
        } else {
            format!(" ×{}", s.weight)
        };
        let spark = sparkline(&merge(std::slice::from_ref(&frames[i]), f), 24);
        out.push(format!(
            "  {label:width$}  {:>9} {:<5}{weight}  {spark}",
            num(per[i]),
            s.unit
        ));
    }
    if with_total {
        let total: f32 = per.iter().sum();
        out.push(format!(
            "  total {} on {} ({f} frames)",
            num(total),
            m.origin
        ));
    }
    Ok(out.join("\n"))
}

fn host(t: Tensor<2>) -> Vec<f32> {
    t.into_data().try_into_vec::<f32>().unwrap_or_default()
}

fn host5(t: Tensor<5>) -> Vec<f32> {
    t.into_data().try_into_vec::<f32>().unwrap_or_default()
}
