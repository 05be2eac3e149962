//! The benchmark's markdown: a header saying when, where and with what, then one section
//! per family.

use super::RunRow;
use super::keyframe::{CONTROLLED, ControlErrors};
use super::suite::Family;
use std::collections::BTreeMap;
use std::fmt::Write;

/// Where and how the run was made.
#[derive(Clone, Debug, Default)]
pub struct RunInfo {
    /// UTC date and time.
    pub date: String,
    /// Machine: CPU model and cores, or the GPU.
    pub machine: String,
    /// burn backend.
    pub backend: String,
    /// Weights id and training steps.
    pub weights: String,
    /// The command that made the table.
    pub command: String,
    /// Each solver's settings.
    pub solvers: Vec<String>,
    /// Seconds the whole run took.
    pub seconds: f64,
}

/// Realism score of each (family, solver): FID against held-out test clips and the
/// number of motions it was computed on.
pub type Realism = BTreeMap<(Family, String), (f64, usize)>;

fn solvers_in_order(rows: &[&RunRow]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for r in rows {
        if !names.contains(&r.solver) {
            names.push(r.solver.clone());
        }
    }
    names
}

fn avg(rows: &[&RunRow], f: impl Fn(&RunRow) -> f32) -> f32 {
    let ok: Vec<f32> = rows
        .iter()
        .filter(|r| r.failure.is_none())
        .map(|r| f(r))
        .collect();
    ok.iter().sum::<f32>() / ok.len().max(1) as f32
}

fn realism_cell(realism: &Realism, family: Family, solver: &str) -> String {
    realism
        .get(&(family, solver.to_string()))
        .map_or("—".into(), |(fid, n)| format!("{fid:.3} ({n})"))
}

/// The whole report.
pub fn markdown(info: &RunInfo, rows: &[RunRow], realism: &Realism) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# Task benchmark\n");
    let _ = writeln!(
        md,
        "- date: {}\n- machine: {}\n- backend: {}\n- weights: {}\n- command: `{}`\n- wall time: {:.0} s",
        info.date, info.machine, info.backend, info.weights, info.command, info.seconds
    );
    let _ = writeln!(md, "- solver settings:");
    for s in &info.solvers {
        let _ = writeln!(md, "  - `{s}`");
    }
    let _ = writeln!(
        md,
        "\nC.err: the program's total error (keyframes: mean distance, m). Unsuccess: share of \
         samples with any statement or keyframe error above 5 cm. Skating: PMG's foot-skating \
         ratio. Accel: max joint acceleration (m/frame²). Bones: largest bone-length error against \
         the skeleton (m; a solver that stretches limbs to meet a constraint shows here). Realism: FID of the solver's motions \
         against held-out test clips (the evaluator of `mprog eval`; motions in brackets; few \
         motions make it noisy). Lower is better everywhere."
    );
    for family in [
        Family::Pmg,
        Family::HeadHeight,
        Family::Keyframe,
        Family::Contact,
    ] {
        let fam: Vec<&RunRow> = rows.iter().filter(|r| r.family == family).collect();
        if fam.is_empty() {
            continue;
        }
        let _ = writeln!(md, "\n## {}\n", family.title());
        summary(&mut md, family, &fam, realism);
        match family {
            Family::Keyframe => keyframe_details(&mut md, &fam),
            _ => per_task(&mut md, &fam),
        }
    }
    let failures: Vec<&RunRow> = rows.iter().filter(|r| r.failure.is_some()).collect();
    if !failures.is_empty() {
        let _ = writeln!(md, "\n## Failed runs\n");
        for r in failures {
            let _ = writeln!(
                md,
                "- {} / {}: {}",
                r.task,
                r.solver,
                r.failure.as_deref().unwrap_or("")
            );
        }
    }
    md
}

fn summary(md: &mut String, family: Family, rows: &[&RunRow], realism: &Realism) {
    let keyframe = family == Family::Keyframe;
    let _ = writeln!(md, "Mean over the family's tasks:\n");
    if keyframe {
        let _ = writeln!(
            md,
            "| solver | avg err (m) | traj err | loc err | unsuccess | skating | accel | bones (m) | realism (FID) | s/sample |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
        );
    } else {
        let _ = writeln!(
            md,
            "| solver | C.err | unsuccess | skating | accel | bones (m) | realism (FID) | s/sample |\n| --- | --- | --- | --- | --- | --- | --- | --- |"
        );
    }
    for solver in solvers_in_order(rows) {
        let rs: Vec<&RunRow> = rows
            .iter()
            .copied()
            .filter(|r| r.solver == solver)
            .collect();
        let control =
            |f: fn(&ControlErrors) -> f32| avg(&rs, |r| r.control.as_ref().map_or(0.0, f));
        let secs = rs
            .iter()
            .filter(|r| r.failure.is_none())
            .map(|r| r.seconds_per_sample)
            .sum::<f64>()
            / rs.iter().filter(|r| r.failure.is_none()).count().max(1) as f64;
        let tail = format!(
            "{:.3} | {:.3} | {:.3} | {} | {secs:.1} |",
            avg(&rs, |r| r.skating),
            avg(&rs, |r| r.max_accel),
            avg(&rs, |r| r.bone_error),
            realism_cell(realism, family, &solver)
        );
        if keyframe {
            let _ = writeln!(
                md,
                "| {solver} | {:.3} | {:.3} | {:.3} | {:.3} | {tail}",
                control(|c| c.avg),
                control(|c| c.traj),
                control(|c| c.loc),
                avg(&rs, |r| r.unsuccess)
            );
        } else {
            let _ = writeln!(
                md,
                "| {solver} | {:.4} | {:.3} | {tail}",
                avg(&rs, |r| r.error),
                avg(&rs, |r| r.unsuccess)
            );
        }
    }
}

fn per_task(md: &mut String, rows: &[&RunRow]) {
    let solvers = solvers_in_order(rows);
    let mut tasks: Vec<&str> = Vec::new();
    for r in rows {
        if !tasks.contains(&r.task.as_str()) {
            tasks.push(&r.task);
        }
    }
    let _ = writeln!(
        md,
        "\nPer task, C.err / skating / accel:\n\n| task | {} |\n| --- |{}",
        solvers.join(" | "),
        " --- |".repeat(solvers.len())
    );
    for task in tasks {
        let cells: Vec<String> = solvers
            .iter()
            .map(|s| {
                rows.iter()
                    .find(|r| r.task == task && &r.solver == s)
                    .map_or("—".into(), |r| match &r.failure {
                        Some(_) => "failed".into(),
                        None => format!("{:.4} / {:.2} / {:.3}", r.error, r.skating, r.max_accel),
                    })
            })
            .collect();
        let _ = writeln!(md, "| {task} | {} |", cells.join(" | "));
    }
}

fn keyframe_details(md: &mut String, rows: &[&RunRow]) {
    let solvers = solvers_in_order(rows);
    // (joint or density label) → solver → distances.
    let mut by_joint: BTreeMap<usize, BTreeMap<String, Vec<f32>>> = BTreeMap::new();
    let mut by_density: Vec<(String, BTreeMap<String, Vec<f32>>)> = Vec::new();
    // joint → solver → each sample's foot-skating ratio.
    let mut skating: BTreeMap<usize, BTreeMap<String, Vec<f32>>> = BTreeMap::new();
    for r in rows.iter().filter(|r| r.failure.is_none()) {
        for cell in &r.cells {
            let (joint, density, d) = (&cell.joint, &cell.density, &cell.distances);
            by_joint
                .entry(*joint)
                .or_default()
                .entry(r.solver.clone())
                .or_default()
                .extend(d);
            skating
                .entry(*joint)
                .or_default()
                .entry(r.solver.clone())
                .or_default()
                .push(cell.skating);
            let slot = match by_density.iter().position(|(l, _)| l == density) {
                Some(i) => i,
                None => {
                    by_density.push((density.clone(), BTreeMap::new()));
                    by_density.len() - 1
                }
            };
            by_density[slot]
                .1
                .entry(r.solver.clone())
                .or_default()
                .extend(d);
        }
    }
    let mean = |v: Option<&Vec<f32>>| {
        v.filter(|v| !v.is_empty()).map_or("—".into(), |v| {
            format!("{:.3}", v.iter().sum::<f32>() / v.len() as f32)
        })
    };
    let header = format!(
        "| {} |\n| --- |{}",
        solvers.join(" | "),
        " --- |".repeat(solvers.len())
    );
    let joint_rows =
        |md: &mut String, title: &str, map: &BTreeMap<usize, BTreeMap<String, Vec<f32>>>| {
            let _ = writeln!(md, "\n{title}:\n\n| joint {header}");
            for (joint, per) in map {
                let name = CONTROLLED
                    .iter()
                    .find(|c| c.0 == *joint)
                    .map_or("?", |c| c.1);
                let cells: Vec<String> = solvers.iter().map(|s| mean(per.get(s))).collect();
                let _ = writeln!(md, "| {name} | {} |", cells.join(" | "));
            }
        };
    joint_rows(
        md,
        "Average keyframe error (m) by controlled joint",
        &by_joint,
    );
    joint_rows(
        md,
        "Foot skating by controlled joint (PMG's ratio, mean over the samples that control it)",
        &skating,
    );
    let _ = writeln!(
        md,
        "\nAverage keyframe error (m) by density:\n\n| density {header}"
    );
    for (label, per) in &by_density {
        let cells: Vec<String> = solvers.iter().map(|s| mean(per.get(s))).collect();
        let _ = writeln!(md, "| {label} | {} |", cells.join(" | "));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tasks::CellOutcome;

    fn row(solver: &str, cells: Vec<CellOutcome>) -> RunRow {
        RunRow {
            motions: cells.len(),
            cells,
            ..RunRow::unmeasured(Family::Keyframe, "clip", solver)
        }
    }

    fn cell(joint: usize, distance: f32, skating: f32) -> CellOutcome {
        CellOutcome {
            joint,
            density: "1 frame".into(),
            distances: vec![distance],
            skating,
        }
    }

    #[test]
    fn keyframe_details_give_each_controlled_joints_error_and_skating_per_solver() {
        let (pelvis, left_foot) = (CONTROLLED[0].0, CONTROLLED[1].0);
        let a = row(
            "guide",
            vec![
                cell(pelvis, 0.01, 0.1),
                cell(pelvis, 0.03, 0.3),
                cell(left_foot, 0.02, 0.5),
            ],
        );
        let b = row("plain", vec![cell(pelvis, 0.4, 0.0)]);
        let mut md = String::new();
        keyframe_details(&mut md, &[&a, &b]);
        let table = |title: &str| {
            let at = md
                .find(title)
                .unwrap_or_else(|| panic!("no {title} in\n{md}"));
            md[at..]
                .lines()
                .skip(4)
                .take(2)
                .collect::<Vec<_>>()
                .join("\n")
        };
        let errors = table("Average keyframe error (m) by controlled joint");
        let skating = table("Foot skating by controlled joint");
        let (p, f) = (CONTROLLED[0].1, CONTROLLED[1].1);
        assert_eq!(
            errors,
            format!("| {p} | 0.020 | 0.400 |\n| {f} | 0.020 | — |")
        );
        assert_eq!(
            skating,
            format!("| {p} | 0.200 | 0.000 |\n| {f} | 0.500 | — |")
        );
    }
}
