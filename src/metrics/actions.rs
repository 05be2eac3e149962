//! What the motion prior does with named actions (issue 28's "done when"): each prompt is
//! generated with seeds 1 and 2 (DDIM 50, guidance 2.5 unless told, no cleanup) and one
//! number is read off the motion against a threshold. `mprog bench actions` prints the table.
//!
//! Each prompt is as long as `mprog gen` makes it by default: the model's length prior
//! ([`crate::model::lengths`]; 6 s for a model without one), except the walk, which the
//! issue measures in 6 s. `--seconds` pins every prompt to one length.
//!
//! Heights are above the motion's own floor (its lowest ankle or toe), so a model that
//! floats or sinks a little is not rewarded or punished for it.

use crate::metrics::per_motion::total_turn;
use crate::model::ModelBundle;
use crate::model::generate::{GenerateError, GenerateRequest, generate};
use crate::model::sampler::SamplerKind;
use crate::motion::Motion;
use burn::prelude::*;

const PELVIS: usize = 0;
const L_ANKLE: usize = 7;
const R_ANKLE: usize = 8;
const L_TOE: usize = 10;
const R_TOE: usize = 11;
const HEAD: usize = 15;
const L_WRIST: usize = 20;
const R_WRIST: usize = 21;

/// Per-frame joint heights above the motion's floor, and ground positions of the pelvis.
pub struct Track {
    y: Vec<[f32; 22]>,
    pelvis_xz: Vec<[f32; 2]>,
    /// Net turn of the pelvis path (degrees, + = left; [`total_turn`]).
    turn: f32,
}

/// Heights and ground path of a motion.
pub fn track(m: &Motion) -> Track {
    let floor = m
        .frames
        .iter()
        .flat_map(|p| [L_ANKLE, R_ANKLE, L_TOE, R_TOE].map(|j| p[j].y))
        .fold(f32::INFINITY, f32::min);
    Track {
        y: m.frames
            .iter()
            .map(|p| std::array::from_fn(|j| p[j].y - floor))
            .collect(),
        pelvis_xz: m
            .frames
            .iter()
            .map(|p| [p[PELVIS].x, p[PELVIS].z])
            .collect(),
        turn: total_turn(m),
    }
}

impl Track {
    fn foot(&self, f: usize, ankle: usize, toe: usize) -> f32 {
        self.y[f][ankle].min(self.y[f][toe])
    }
    /// Highest moment both feet are off the ground together.
    fn both_feet_up(&self) -> f32 {
        (0..self.y.len())
            .map(|f| {
                self.foot(f, L_ANKLE, L_TOE)
                    .min(self.foot(f, R_ANKLE, R_TOE))
            })
            .fold(0.0, f32::max)
    }
    fn max_of(&self, joints: &[usize]) -> f32 {
        self.y
            .iter()
            .flat_map(|h| joints.iter().map(|&j| h[j]))
            .fold(f32::NEG_INFINITY, f32::max)
    }
    fn min_of(&self, joints: &[usize]) -> f32 {
        self.y
            .iter()
            .flat_map(|h| joints.iter().map(|&j| h[j]))
            .fold(f32::INFINITY, f32::min)
    }
    /// Horizontal path length of the pelvis over time (m/s).
    fn speed(&self) -> f32 {
        let path: f32 = self
            .pelvis_xz
            .windows(2)
            .map(|w| ((w[1][0] - w[0][0]).powi(2) + (w[1][1] - w[0][1]).powi(2)).sqrt())
            .sum();
        path / (self.y.len() as f32 / 20.0)
    }
}

pub struct Case {
    /// The prompt.
    pub prompt: &'static str,
    /// What is measured, with its threshold.
    pub what: &'static str,
    /// The measurement.
    pub value: fn(&Track) -> f32,
    /// Whether a value meets the threshold.
    pub pass: fn(f32) -> bool,
    /// A fixed length in seconds (None: the model's length prior).
    pub seconds: Option<f32>,
}

/// The prompts and what each must do.
pub const CASES: &[Case] = &[
    Case {
        prompt: "a person jumps up and down in place",
        what: "both feet off the ground at once (m, ≥ 0.15)",
        value: Track::both_feet_up,
        pass: |v| v >= 0.15,
        seconds: None,
    },
    Case {
        prompt: "a man kicks forward with his right leg",
        what: "highest ankle (m, ≥ 0.6)",
        value: |t| t.max_of(&[L_ANKLE, R_ANKLE]),
        pass: |v| v >= 0.6,
        seconds: None,
    },
    Case {
        prompt: "a person crouches down low and stands back up",
        what: "lowest head (m, ≤ 1.15)",
        value: |t| t.min_of(&[HEAD]),
        pass: |v| v <= 1.15,
        seconds: None,
    },
    Case {
        prompt: "a person picks something up from the floor",
        what: "lowest wrist (m, ≤ 0.25)",
        value: |t| t.min_of(&[L_WRIST, R_WRIST]),
        pass: |v| v <= 0.25,
        seconds: None,
    },
    Case {
        prompt: "a person lies down on the floor",
        what: "pelvis at the end (m, ≤ 0.3)",
        value: |t| t.y[t.y.len() - 1][PELVIS],
        pass: |v| v <= 0.3,
        seconds: None,
    },
    Case {
        prompt: "a person runs forward",
        what: "speed (m/s, ≥ 2.2)",
        value: Track::speed,
        pass: |v| v >= 2.2,
        seconds: None,
    },
    Case {
        prompt: "a person walks forward",
        what: "speed (m/s, ≥ 0.34: 2 m in 6 s)",
        value: Track::speed,
        pass: |v| v >= 2.0 / 6.0,
        seconds: Some(6.0),
    },
    Case {
        prompt: "a person walks and turns left",
        what: "net turn of the path (deg, + = left, ≥ 45)",
        value: |t| t.turn,
        pass: |v| v >= 45.0,
        seconds: None,
    },
    Case {
        prompt: "a person walks and turns right",
        what: "net turn of the path (deg, + = left, ≤ −45)",
        value: |t| t.turn,
        pass: |v| v <= -45.0,
        seconds: None,
    },
    Case {
        prompt: "a person strolls",
        what: "speed (m/s, ≥ 0.34, like a walk)",
        value: Track::speed,
        pass: |v| v >= 2.0 / 6.0,
        seconds: None,
    },
    Case {
        prompt: "a person hurries",
        what: "speed (m/s, ≥ 0.34, like its neighbours: walks)",
        value: Track::speed,
        pass: |v| v >= 2.0 / 6.0,
        seconds: None,
    },
    Case {
        prompt: "a person raises both hands",
        what: "wrists over the head (m above the head's lowest, > 0)",
        value: |t| {
            t.y.iter()
                .map(|h| h[L_WRIST].min(h[R_WRIST]) - h[HEAD])
                .fold(f32::NEG_INFINITY, f32::max)
        },
        pass: |v| v > 0.0,
        seconds: None,
    },
    Case {
        prompt: "a person elevates both arms",
        what: "wrists over the head (paraphrase, > 0)",
        value: |t| {
            t.y.iter()
                .map(|h| h[L_WRIST].min(h[R_WRIST]) - h[HEAD])
                .fold(f32::NEG_INFINITY, f32::max)
        },
        pass: |v| v > 0.0,
        seconds: None,
    },
];

/// One prompt's measurements, seed 1 then seed 2.
pub struct ActionRow {
    /// The case.
    pub case: &'static Case,
    /// Value per seed.
    pub values: [f32; 2],
    /// Length generated, in frames.
    pub frames: usize,
}

impl ActionRow {
    /// Whether both seeds meet the threshold.
    pub fn passed(&self) -> bool {
        self.values.iter().all(|&v| (self.case.pass)(v))
    }
}

/// Generates every case with seeds 1 and 2 at classifier-free guidance `guidance` and
/// measures it; `seconds` pins every case's length (else each has its own, see the
/// module's notes).
pub fn measure_actions(
    bundle: &ModelBundle,
    device: &Device,
    seconds: Option<f32>,
    guidance: f32,
) -> Result<Vec<ActionRow>, GenerateError> {
    CASES
        .iter()
        .map(|case| {
            let frames = match seconds.or(case.seconds) {
                Some(s) => (s * 20.0).round().max(1.0) as usize,
                None => bundle
                    .text
                    .natural_frames(case.prompt, bundle.config.max_frames)
                    .map_or(120, |(frames, _)| frames),
            };
            let mut values = [0.0; 2];
            for (i, seed) in [1u64, 2].into_iter().enumerate() {
                let req = GenerateRequest {
                    prompts: vec![case.prompt.to_string()],
                    frames,
                    seed,
                    sampler: SamplerKind::Ddim(50),
                    guidance_scale: guidance,
                    mirror_average: false,
                };
                let out = generate(bundle, &req, device, |_, _| {})?;
                values[i] = (case.value)(&track(&out.motions[0]));
            }
            Ok(ActionRow {
                case,
                values,
                frames,
            })
        })
        .collect()
}

/// The rows as a Markdown table (✗ marks a value that misses its threshold).
pub fn actions_table(rows: &[ActionRow]) -> String {
    let mut s = String::from(
        "| prompt | length (s) | measure | seed 1 | seed 2 |\n| --- | ---: | --- | ---: | ---: |\n",
    );
    for row in rows {
        let cell = |v: f32| format!("{v:.2}{}", if (row.case.pass)(v) { "" } else { " ✗" });
        s.push_str(&format!(
            "| {} | {:.1} | {} | {} | {} |\n",
            row.case.prompt,
            row.frames as f32 / 20.0,
            row.case.what,
            cell(row.values[0]),
            cell(row.values[1])
        ));
    }
    s
}
