//! The bench's markdown: one row per (task, seed) and the counts a reviewer reads.

use super::Verdict;
use super::inside::Inside;

/// What one run of one task gave.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Task id.
    pub id: String,
    /// The sentence.
    pub sentence: String,
    /// Seed of the run.
    pub seed: u64,
    /// Every statement met by the error table (`None`: the run failed).
    pub met: Option<bool>,
    /// The plausibility report found no problem (`None`: the run failed).
    pub plausible: Option<bool>,
    /// The judge's decision (wrong when the run failed).
    pub verdict: Verdict,
    /// Measured envelope figures (`None`: the run failed).
    pub inside: Option<Inside>,
    /// The statements the table did not call "met", with their column.
    pub not_met: Vec<String>,
    /// Wall seconds of the run.
    pub seconds: f64,
    /// Why the run failed.
    pub failure: Option<String>,
}

impl Outcome {
    /// mprog's own word on the result: met and plausible.
    pub fn fine(&self) -> bool {
        self.met == Some(true) && self.plausible == Some(true)
    }

    /// The judge and mprog's report say the same (right and fine, or wrong and flagged).
    pub fn agree(&self) -> bool {
        self.verdict.right == self.fine()
    }
}

/// The counts under the table.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Summary {
    /// Runs.
    pub runs: usize,
    /// Runs that failed (no motion).
    pub failed: usize,
    /// Right by the judge.
    pub right: usize,
    /// Met by the error table.
    pub met: usize,
    /// Plausible by the report.
    pub plausible: usize,
    /// Met and plausible.
    pub fine: usize,
    /// Met and plausible, wrong by the judge (mprog said fine).
    pub fine_but_wrong: usize,
    /// Right by the judge, reported not met or implausible.
    pub right_but_flagged: usize,
    /// Judge and report agree.
    pub agree: usize,
    /// Inside the measured envelope.
    pub inside: usize,
    /// Plausible by the report yet outside the measured envelope (the report missed it).
    pub plausible_outside: usize,
}

/// Counts the outcomes.
pub fn summarise(outcomes: &[Outcome]) -> Summary {
    let mut s = Summary {
        runs: outcomes.len(),
        ..Summary::default()
    };
    for o in outcomes {
        let inside = o.inside.as_ref().is_some_and(Inside::ok);
        s.failed += usize::from(o.failure.is_some());
        s.right += usize::from(o.verdict.right);
        s.met += usize::from(o.met == Some(true));
        s.plausible += usize::from(o.plausible == Some(true));
        s.fine += usize::from(o.fine());
        s.fine_but_wrong += usize::from(o.fine() && !o.verdict.right);
        s.right_but_flagged += usize::from(o.verdict.right && !o.fine());
        s.agree += usize::from(o.agree());
        s.inside += usize::from(inside);
        s.plausible_outside += usize::from(o.plausible == Some(true) && !inside);
    }
    s
}

fn yes_no(v: Option<bool>) -> &'static str {
    match v {
        Some(true) => "yes",
        Some(false) => "**no**",
        None => "—",
    }
}

fn cell(text: &str) -> String {
    text.replace('|', "\\|").replace('\n', " ")
}

/// The per-run table and the counts, as markdown.
pub fn table(outcomes: &[Outcome]) -> String {
    let mut out = String::from(
        "| task | seed | met | plausible | inside the envelope | right by the judge | agree | s | the judge's figures; what the table did not meet; what is outside |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for o in outcomes {
        let inside = o.inside.as_ref().map(Inside::ok);
        let mut notes = vec![cell(&o.verdict.reason)];
        if let Some(f) = &o.failure {
            notes.push(format!("run failed: {}", cell(f)));
        }
        notes.extend(o.not_met.iter().map(|s| cell(s)));
        if let Some(i) = &o.inside {
            notes.extend(i.outside());
        }
        out.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {:.0} | {} |\n",
            o.id,
            o.seed,
            yes_no(o.met),
            yes_no(o.plausible),
            yes_no(inside),
            if o.verdict.right {
                "right"
            } else {
                "**wrong**"
            },
            if o.agree() { "yes" } else { "**no**" },
            o.seconds,
            notes.join("; ")
        ));
    }
    let s = summarise(outcomes);
    out.push_str(&format!(
        "\n- right by the judge: **{} / {}**\n\
         - met by the error table: {}; plausible by the report: {}; both: {}\n\
         - met and plausible but wrong by the judge (mprog said fine): {}\n\
         - right by the judge but reported not met or implausible: {}\n\
         - the judge and the report agree: {} / {}\n\
         - inside the measured envelope (torso acceleration ≤ {} m/frame², floor ≥ {} m, hip width ±{:.0} %, pelvises ≥ {} m apart): {}; plausible by the report yet outside it: {}\n\
         - runs that failed: {}\n",
        s.right,
        s.runs,
        s.met,
        s.plausible,
        s.fine,
        s.fine_but_wrong,
        s.right_but_flagged,
        s.agree,
        s.runs,
        super::inside::TORSO_ACCEL_LIMIT,
        super::inside::FLOOR_LIMIT,
        100.0 * super::inside::HIP_WIDTH_TOLERANCE,
        super::inside::PELVIS_APART,
        s.inside,
        s.plausible_outside,
        s.failed,
    ));
    out
}
