//! What the motion prior does with the actions the wider training set added (issue 28's
//! "done when"), measured on the shipped model (or `$MPROG_MODEL`) with seeds 1 and 2,
//! 6 s, DDIM 50, guidance 2.5, no cleanup:
//!
//! ```text
//! cargo test --release --test prior_actions -- --ignored --nocapture
//! ```
//!
//! Heights are above the motion's own floor (its lowest ankle or toe), so a model that
//! floats or sinks a little is not rewarded or punished for it.

use burn::prelude::*;
use mprog::model::ModelBundle;
use mprog::model::generate::{GenerateRequest, generate};
use mprog::model::sampler::SamplerKind;
use mprog::model::weights::default_model_dir;
use mprog::motion::Motion;

const PELVIS: usize = 0;
const L_ANKLE: usize = 7;
const R_ANKLE: usize = 8;
const L_TOE: usize = 10;
const R_TOE: usize = 11;
const HEAD: usize = 15;
const L_WRIST: usize = 20;
const R_WRIST: usize = 21;

/// Per-frame joint heights above the motion's floor, and ground positions of the pelvis.
struct Track {
    y: Vec<[f32; 22]>,
    pelvis_xz: Vec<[f32; 2]>,
}

fn track(m: &Motion) -> Track {
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

struct Case {
    prompt: &'static str,
    what: &'static str,
    value: fn(&Track) -> f32,
    pass: fn(f32) -> bool,
}

const CASES: &[Case] = &[
    Case {
        prompt: "a person jumps up and down in place",
        what: "both feet off the ground at once (m, ≥ 0.15)",
        value: Track::both_feet_up,
        pass: |v| v >= 0.15,
    },
    Case {
        prompt: "a man kicks forward with his right leg",
        what: "highest ankle (m, ≥ 0.6)",
        value: |t| t.max_of(&[L_ANKLE, R_ANKLE]),
        pass: |v| v >= 0.6,
    },
    Case {
        prompt: "a person crouches down low and stands back up",
        what: "lowest head (m, ≤ 1.15)",
        value: |t| t.min_of(&[HEAD]),
        pass: |v| v <= 1.15,
    },
    Case {
        prompt: "a person picks something up from the floor",
        what: "lowest wrist (m, ≤ 0.25)",
        value: |t| t.min_of(&[L_WRIST, R_WRIST]),
        pass: |v| v <= 0.25,
    },
    Case {
        prompt: "a person lies down on the floor",
        what: "pelvis at the end (m, ≤ 0.3)",
        value: |t| t.y[t.y.len() - 1][PELVIS],
        pass: |v| v <= 0.3,
    },
    Case {
        prompt: "a person runs forward",
        what: "speed (m/s, ≥ 2.2)",
        value: Track::speed,
        pass: |v| v >= 2.2,
    },
    Case {
        prompt: "a person walks forward",
        what: "speed (m/s, ≥ 0.34: 2 m in 6 s)",
        value: Track::speed,
        pass: |v| v >= 2.0 / 6.0,
    },
    Case {
        prompt: "a person strolls",
        what: "speed (m/s, ≥ 0.34, like a walk)",
        value: Track::speed,
        pass: |v| v >= 2.0 / 6.0,
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
    },
];

#[test]
#[ignore = "slow: 40 generations with the shipped model"]
fn the_prior_performs_the_wider_actions() {
    let dir = default_model_dir();
    let device = Device::flex();
    let bundle = match ModelBundle::load(&dir, &device) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("skipping: no model bundle at {} ({e})", dir.display());
            return;
        }
    };
    println!(
        "model {} ({})\n\n| prompt | measure | seed 1 | seed 2 |\n| --- | --- | ---: | ---: |",
        bundle.manifest.weights_id,
        dir.display()
    );
    let mut failed = Vec::new();
    for case in CASES {
        let mut cells = Vec::new();
        for seed in [1, 2] {
            let req = GenerateRequest {
                prompts: vec![case.prompt.to_string()],
                frames: 120,
                seed,
                sampler: SamplerKind::Ddim(50),
                guidance_scale: 2.5,
                mirror_average: false,
            };
            let out = generate(&bundle, &req, &device, |_, _| {}).unwrap();
            let v = (case.value)(&track(&out.motions[0]));
            let ok = (case.pass)(v);
            if !ok {
                failed.push(format!(
                    "{} (seed {seed}): {} = {v:.2}",
                    case.prompt, case.what
                ));
            }
            cells.push(format!("{v:.2}{}", if ok { "" } else { " ✗" }));
        }
        println!(
            "| {} | {} | {} | {} |",
            case.prompt, case.what, cells[0], cells[1]
        );
    }
    assert!(failed.is_empty(), "not met:\n{}", failed.join("\n"));
}
