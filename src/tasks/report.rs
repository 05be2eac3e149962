//! The benchmark's markdown: a header saying when, where and with what, then one section
//! per family.

use super::RunRow;
use super::keyframe::{CONTROLLED, ControlErrors};
use super::suite::Family;
use crate::skeleton::{FOOT_LEFT, FOOT_RIGHT};
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
         the skeleton (m; a solver that stretches limbs to meet a constraint shows here). Plausible: share of \
         samples whose plausibility report (snaps, floor, skating, overlap, rigid parts, facing against \
         the shipped envelope of real clips) is clean; higher is better. Realism: FID of the solver's motions \
         against held-out test clips (the evaluator of `mprog eval`; motions in brackets; few \
         motions make it noisy). Lower is better everywhere else."
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
            "| solver | avg err (m) | traj err | loc err | unsuccess | skating | accel | bones (m) | plausible | realism (FID) | s/sample |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
        );
    } else {
        let _ = writeln!(
            md,
            "| solver | C.err | unsuccess | skating | accel | bones (m) | plausible | realism (FID) | s/sample |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
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
            "{:.3} | {:.3} | {:.3} | {:.2} | {} | {secs:.1} |",
            avg(&rs, |r| r.skating),
            avg(&rs, |r| r.max_accel),
            avg(&rs, |r| r.bone_error),
            avg(&rs, |r| r.plausible),
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

/// Samples of one solver, grouped under a key (a controlled joint, a density, a place).
type Grouped<K> = BTreeMap<K, BTreeMap<String, Vec<f32>>>;

fn push<K: Ord>(map: &mut Grouped<K>, key: K, solver: &str, values: impl IntoIterator<Item = f32>) {
    map.entry(key)
        .or_default()
        .entry(solver.to_string())
        .or_default()
        .extend(values);
}

/// Where a sample's peak acceleration is, as the rows of the report's table.
const PEAK_PLACES: [&str; 4] = [
    "at the controlled joint",
    "at an ankle or toe",
    "within 2 frames of a keyframe",
    "in the first or last 2 frames",
];

fn keyframe_details(md: &mut String, rows: &[&RunRow]) {
    let solvers = solvers_in_order(rows);
    let mut by_joint: Grouped<usize> = BTreeMap::new();
    // Density labels in the order the cells bring them, for the rows' order.
    let mut densities: Vec<String> = Vec::new();
    let mut by_density: Grouped<usize> = BTreeMap::new();
    // Each sample's foot-skating ratio and peak acceleration, by controlled joint.
    let mut skating: Grouped<usize> = BTreeMap::new();
    let mut accel: Grouped<usize> = BTreeMap::new();
    let mut accel_by_density: Grouped<usize> = BTreeMap::new();
    // 1 where the sample's peak is at that place, else 0: the mean is a share.
    let mut places: Grouped<usize> = BTreeMap::new();
    for r in rows.iter().filter(|r| r.failure.is_none()) {
        let s = r.solver.as_str();
        for cell in &r.cells {
            let density = match densities.iter().position(|l| *l == cell.density) {
                Some(i) => i,
                None => {
                    densities.push(cell.density.clone());
                    densities.len() - 1
                }
            };
            push(&mut by_joint, cell.joint, s, cell.distances.iter().copied());
            push(&mut by_density, density, s, cell.distances.iter().copied());
            push(&mut skating, cell.joint, s, [cell.skating]);
            push(&mut accel, cell.joint, s, [cell.accel.value]);
            push(&mut accel_by_density, density, s, [cell.accel.value]);
            let at = cell.accel.frame;
            let flags = [
                cell.accel.joint == cell.joint,
                FOOT_LEFT.contains(&cell.accel.joint) || FOOT_RIGHT.contains(&cell.accel.joint),
                cell.accel_to_keyframe <= 2,
                at < 2 || at + 2 >= cell.frames,
            ];
            for (place, flag) in flags.into_iter().enumerate() {
                push(&mut places, place, s, [f32::from(u8::from(flag))]);
            }
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
    let table = |md: &mut String,
                 title: &str,
                 first: &str,
                 map: &Grouped<usize>,
                 name: &dyn Fn(usize) -> String| {
        let _ = writeln!(md, "\n{title}:\n\n| {first} {header}");
        for (key, per) in map {
            let cells: Vec<String> = solvers.iter().map(|s| mean(per.get(s))).collect();
            let _ = writeln!(md, "| {} | {} |", name(*key), cells.join(" | "));
        }
    };
    let joint = |j: usize| {
        CONTROLLED
            .iter()
            .find(|c| c.0 == j)
            .map_or("?", |c| c.1)
            .to_string()
    };
    let density = |i: usize| densities[i].clone();
    table(
        md,
        "Average keyframe error (m) by controlled joint",
        "joint",
        &by_joint,
        &joint,
    );
    table(
        md,
        "Foot skating by controlled joint (PMG's ratio, mean over the samples that control it)",
        "joint",
        &skating,
        &joint,
    );
    table(
        md,
        "Average keyframe error (m) by density",
        "density",
        &by_density,
        &density,
    );
    table(
        md,
        "Peak acceleration (m/frame²) by controlled joint",
        "joint",
        &accel,
        &joint,
    );
    table(
        md,
        "Peak acceleration (m/frame²) by density",
        "density",
        &accel_by_density,
        &density,
    );
    table(
        md,
        "Where each sample's peak acceleration is (share of the samples)",
        "peak",
        &places,
        &|i| PEAK_PLACES[i].to_string(),
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::per_motion::PeakAcceleration;
    use crate::tasks::CellOutcome;

    fn row(solver: &str, cells: Vec<CellOutcome>) -> RunRow {
        RunRow {
            motions: cells.len(),
            cells,
            ..RunRow::unmeasured(Family::Keyframe, "clip", solver)
        }
    }

    /// A 60-frame sample keyed at frame 10, its peak acceleration `accel` at (joint, frame).
    fn cell(joint: usize, distance: f32, skating: f32, accel: (f32, usize, usize)) -> CellOutcome {
        CellOutcome {
            joint,
            density: "1 frame".into(),
            distances: vec![distance],
            skating,
            accel: PeakAcceleration {
                value: accel.0,
                joint: accel.1,
                frame: accel.2,
            },
            accel_to_keyframe: accel.2.abs_diff(10),
            frames: 60,
        }
    }

    #[test]
    fn keyframe_details_give_each_controlled_joints_error_skating_and_acceleration_per_solver() {
        let (pelvis, left_foot) = (CONTROLLED[0].0, CONTROLLED[1].0);
        let a = row(
            "guide",
            vec![
                // Peak at the pelvis, on the keyframe.
                cell(pelvis, 0.01, 0.1, (0.2, pelvis, 10)),
                // Peak at the right toe (11), in the last frame but one.
                cell(pelvis, 0.03, 0.3, (0.1, 11, 58)),
                // Peak at the left ankle (7), 2 frames from the keyframe.
                cell(left_foot, 0.02, 0.5, (0.3, 7, 12)),
            ],
        );
        let b = row("plain", vec![cell(pelvis, 0.4, 0.0, (0.05, 15, 30))]);
        let mut md = String::new();
        keyframe_details(&mut md, &[&a, &b]);
        let table = |title: &str, rows: usize| {
            let at = md
                .find(title)
                .unwrap_or_else(|| panic!("no {title} in\n{md}"));
            md[at..]
                .lines()
                .skip(4)
                .take(rows)
                .collect::<Vec<_>>()
                .join("\n")
        };
        let (p, f) = (CONTROLLED[0].1, CONTROLLED[1].1);
        assert_eq!(
            table("Average keyframe error (m) by controlled joint", 2),
            format!("| {p} | 0.020 | 0.400 |\n| {f} | 0.020 | — |")
        );
        assert_eq!(
            table("Foot skating by controlled joint", 2),
            format!("| {p} | 0.200 | 0.000 |\n| {f} | 0.500 | — |")
        );
        assert_eq!(
            table("Peak acceleration (m/frame²) by controlled joint", 2),
            format!("| {p} | 0.150 | 0.050 |\n| {f} | 0.300 | — |")
        );
        assert_eq!(
            table("Peak acceleration (m/frame²) by density", 1),
            "| 1 frame | 0.200 | 0.050 |"
        );
        assert_eq!(
            table("Where each sample's peak acceleration is", 4),
            "| at the controlled joint | 0.333 | 0.000 |\n\
             | at an ankle or toe | 0.667 | 0.000 |\n\
             | within 2 frames of a keyframe | 0.667 | 0.000 |\n\
             | in the first or last 2 frames | 0.333 | 0.000 |"
        );
    }
}
