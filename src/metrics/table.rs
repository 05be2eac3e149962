//! Markdown tables of an [`EvalReport`]: the set comparison and the per-label table in
//! the columns of `notes/training-baseline.md`.

use super::report::{EvalReport, LabelStats};
use crate::model::sampler::SamplerKind;
use std::fmt::Write;

/// A chain as the tables name it ("DDIM 50").
pub fn sampler_name(s: SamplerKind) -> String {
    match s {
        SamplerKind::Ddim(n) => format!("DDIM {n}"),
        SamplerKind::Ddpm(n) => format!("DDPM {n}"),
        SamplerKind::Consistency { steps, grid } => format!("consistency {steps} (grid {grid})"),
    }
}

/// The whole report as markdown.
pub fn report_markdown(r: &EvalReport) -> String {
    let mut out = String::new();
    let s = &r.settings;
    let _ = writeln!(
        out,
        "# mprog eval\n\nModel `{}` ({} training steps); {} test captions (clips ≥ {} frames, \
         seed {}), {}, guidance {}; evaluator trained {} steps{}; FID against {} held-out \
         test clips; {:.0} s generating.\n",
        r.model.0,
        r.model.1,
        r.rows.first().map_or(0, |x| x.count),
        s.min_frames,
        s.seed,
        sampler_name(s.sampler),
        s.guidance_scale,
        r.evaluator.0,
        match r.evaluator.1 {
            Some([a, _, c]) => format!(" (real validation R-precision top-1 {a:.2}, top-3 {c:.2})"),
            None => String::new(),
        },
        r.reference_clips,
        r.generate_seconds,
    );
    out.push_str(&sets_markdown(r));
    if !r.labels.is_empty() {
        out.push('\n');
        out.push_str(&labels_markdown(r));
    }
    out
}

/// The set comparison table.
pub fn sets_markdown(r: &EvalReport) -> String {
    let mut out = String::from(
        "| set | motions | foot skating | max accel (m/frame²) | bone-length variation | \
         floor penetration (cm, % frames) | FID ↓ | diversity | R-precision top-1 | top-3 |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for row in &r.rows {
        let m = &row.metrics;
        let _ = writeln!(
            out,
            "| {} | {} | {:.3} | {:.3} | {:.4} | {:.2}, {:.1} % | {:.3} | {:.3} | {:.3} | {:.3} |",
            row.name,
            row.count,
            m.skating,
            m.max_accel,
            m.bone_variation,
            100.0 * m.penetration.mean_depth,
            100.0 * m.penetration.frame_fraction,
            row.fid,
            row.diversity,
            row.r_precision[0],
            row.r_precision[2],
        );
    }
    out.push_str(
        "\nFoot skating: fraction of frames where foot 10 or 11 is below 5 cm and slides \
         faster than 0.5 m/s (5-frame average too). Bone-length variation: std/mean of each \
         bone's length over time, averaged over bones. Floor penetration: mean depth of the \
         lowest joint below y = 0, and frames more than 1 cm below. Embedding scores use \
         unit vectors (diversity ≤ 2).\n",
    );
    out
}

fn pair(real: f32, generated: Option<f32>, digits: usize) -> String {
    match generated {
        Some(g) => format!("{real:.digits$} / {g:.digits$}"),
        None => format!("{real:.digits$} / –"),
    }
}

fn side(s: &LabelStats) -> Option<&LabelStats> {
    (s.count > 0).then_some(s)
}

/// The per-label table (real / generated).
pub fn labels_markdown(r: &EvalReport) -> String {
    let mut out = String::from(
        "| label | clips real / gen | speed m/s real / gen | total turn (deg) real / gen (gen range) | \
         wrists above head (m) real / gen | right − left wrist (m) real / gen | \
         foot skating real / gen |\n\
         | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for row in &r.labels {
        let Some(real) = side(&row.real) else {
            let _ = writeln!(out, "| {} | 0 / 0 | – | – | – | – | – |", row.label);
            continue;
        };
        let generated = row.generated.as_ref().and_then(side);
        let turn = match generated {
            Some(g) => format!(
                "{:+.0} / {:+.0} ({:+.0}…{:+.0})",
                real.turn, g.turn, g.turn_range.0, g.turn_range.1
            ),
            None => format!("{:+.0} / –", real.turn),
        };
        let _ = writeln!(
            out,
            "| {} | {} / {} | {} | {} | {} | {} | {} |",
            row.label,
            real.count,
            generated.map_or(0, |g| g.count),
            pair(real.speed, generated.map(|g| g.speed), 2),
            turn,
            pair(real.wrists, generated.map(|g| g.wrists), 2),
            pair(real.wrist_side, generated.map(|g| g.wrist_side), 2),
            pair(real.skating, generated.map(|g| g.skating), 2),
        );
    }
    out.push_str(
        "\nTotal turn: net heading change of the pelvis path where it moves faster than \
         0.1 m/s, + = left (Y up). Wrists above head: max over frames of the higher wrist's \
         height minus the head's. Right − left wrist: peak height of the right wrist minus \
         the left's (+ = the right hand went higher).\n",
    );
    out
}

/// One row per motion of what `mprog gen` made (speed, turn, hands, feet, acceleration),
/// and a mean ± standard deviation row when there are several: enough to see at a glance
/// whether a batch walks, turns or raises its hands as asked.
pub fn motions_markdown(metrics: &[super::per_motion::MotionMetrics]) -> String {
    let mut out = String::from(
        "| motion | speed m/s | total turn (deg) | wrists above head (m) | foot skating | \
         max accel (m/frame²) |\n| --- | --- | --- | --- | --- | --- |\n",
    );
    let columns = |m: &super::per_motion::MotionMetrics| {
        [
            m.speed,
            m.turn_deg,
            m.wrists_above_head,
            m.skating,
            m.max_accel,
        ]
    };
    let fmt = |v: [f32; 5]| {
        format!(
            "{:.2} | {:+.0} | {:+.2} | {:.3} | {:.3}",
            v[0], v[1], v[2], v[3], v[4]
        )
    };
    for (i, m) in metrics.iter().enumerate() {
        let _ = writeln!(out, "| {i} | {} |", fmt(columns(m)));
    }
    if metrics.len() > 1 {
        let n = metrics.len() as f32;
        let rows: Vec<[f32; 5]> = metrics.iter().map(columns).collect();
        let mean: [f32; 5] = std::array::from_fn(|c| rows.iter().map(|r| r[c]).sum::<f32>() / n);
        let sd: [f32; 5] = std::array::from_fn(|c| {
            (rows.iter().map(|r| (r[c] - mean[c]).powi(2)).sum::<f32>() / (n - 1.0)).sqrt()
        });
        let _ = writeln!(
            out,
            "| mean ± sd | {:.2} ± {:.2} | {:+.0} ± {:.0} | {:+.2} ± {:.2} | {:.3} ± {:.3} | {:.3} ± {:.3} |",
            mean[0], sd[0], mean[1], sd[1], mean[2], sd[2], mean[3], sd[3], mean[4], sd[4]
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::per_motion::MotionMetrics;

    fn turning(turn_deg: f32) -> MotionMetrics {
        MotionMetrics {
            speed: 1.0,
            turn_deg,
            ..Default::default()
        }
    }

    #[test]
    fn one_motion_has_no_summary_row() {
        let table = motions_markdown(&[turning(90.0)]);
        assert!(table.contains("| 0 | 1.00 | +90 |"), "{table}");
        assert!(!table.contains("mean"), "{table}");
    }

    #[test]
    fn several_motions_get_mean_and_sample_sd() {
        let table = motions_markdown(&[turning(80.0), turning(100.0), turning(-60.0)]);
        // mean +40, sample sd sqrt((1600 + 3600 + 10000) / 2) = 87.2
        assert!(
            table.contains("| mean ± sd | 1.00 ± 0.00 | +40 ± 87 |"),
            "{table}"
        );
        assert_eq!(table.lines().count(), 2 + 3 + 1, "{table}");
    }
}
