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
use crate::motion::{Motion, Pose};
use crate::skeleton::FACE_JOINTS;
use burn::prelude::*;
use glam::{Vec2, Vec3};

const PELVIS: usize = 0;
const L_KNEE: usize = 4;
const R_KNEE: usize = 5;
const L_ANKLE: usize = 7;
const R_ANKLE: usize = 8;
const L_TOE: usize = 10;
const R_TOE: usize = 11;
const NECK: usize = 12;
const HEAD: usize = 15;
const L_SHOULDER: usize = 16;
const R_SHOULDER: usize = 17;
const L_ELBOW: usize = 18;
const R_ELBOW: usize = 19;
const L_WRIST: usize = 20;
const R_WRIST: usize = 21;

/// Per-frame joint heights above the motion's floor, and ground positions of the pelvis.
pub struct Track {
    y: Vec<[f32; 22]>,
    pelvis_xz: Vec<[f32; 2]>,
    /// Net turn of the pelvis path (degrees, + = left; [`total_turn`]).
    turn: f32,
    /// Every joint, with heights above the motion's floor (x and z as they were).
    pos: Vec<Pose>,
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
        pos: m
            .frames
            .iter()
            .map(|p| p.map(|v| Vec3::new(v.x, v.y - floor, v.z)))
            .collect(),
    }
}

impl Track {
    fn foot(&self, f: usize, ankle: usize, toe: usize) -> f32 {
        self.y[f][ankle].min(self.y[f][toe])
    }
    /// Highest moment both feet are off the ground together.
    pub fn both_feet_up(&self) -> f32 {
        (0..self.y.len())
            .map(|f| {
                self.foot(f, L_ANKLE, L_TOE)
                    .min(self.foot(f, R_ANKLE, R_TOE))
            })
            .fold(0.0, f32::max)
    }
    /// Highest height of any of `joints` over the frames.
    pub fn max_of(&self, joints: &[usize]) -> f32 {
        self.y
            .iter()
            .flat_map(|h| joints.iter().map(|&j| h[j]))
            .fold(f32::NEG_INFINITY, f32::max)
    }
    /// Lowest height of any of `joints` over the frames.
    pub fn min_of(&self, joints: &[usize]) -> f32 {
        self.y
            .iter()
            .flat_map(|h| joints.iter().map(|&j| h[j]))
            .fold(f32::INFINITY, f32::min)
    }
    /// Horizontal path length of the pelvis over time (m/s).
    pub fn speed(&self) -> f32 {
        let path: f32 = self
            .pelvis_xz
            .windows(2)
            .map(|w| ((w[1][0] - w[0][0]).powi(2) + (w[1][1] - w[0][1]).powi(2)).sqrt())
            .sum();
        path / self.seconds()
    }

    /// Length in seconds (20 fps), as [`Track::speed`] counts it.
    fn seconds(&self) -> f32 {
        self.y.len() as f32 / 20.0
    }

    /// Largest (`max`) or smallest value of `f` over the frames; NaN for an empty motion,
    /// so that no threshold holds.
    fn extreme(&self, max: bool, f: impl Fn(usize) -> f32) -> f32 {
        let values = (0..self.pos.len()).map(f);
        let best = if max {
            values.reduce(f32::max)
        } else {
            values.reduce(f32::min)
        };
        best.unwrap_or(f32::NAN)
    }

    /// The body's facing in frame `f` on the ground (unit x, z), by the rule the features
    /// use: across = (r_hip − l_hip) + (r_shoulder − l_shoulder), forward = up × across.
    /// +Z when the hips and shoulders give no horizontal direction.
    pub fn facing(&self, f: usize) -> Vec2 {
        let p = &self.pos[f];
        let [r_hip, l_hip, r_sh, l_sh] = FACE_JOINTS;
        let across = (p[r_hip] - p[l_hip]) + (p[r_sh] - p[l_sh]);
        Vec2::new(across.z, -across.x)
            .try_normalize()
            .unwrap_or(Vec2::Y)
    }

    /// Pelvis displacement on the ground from the first frame to the last.
    fn displacement(&self) -> Vec2 {
        match (self.pos.first(), self.pos.last()) {
            (Some(a), Some(b)) => ground(b[PELVIS] - a[PELVIS]),
            _ => Vec2::splat(f32::NAN),
        }
    }

    /// Metres the pelvis ends up ahead of where it started, along the body's facing at the
    /// first frame (negative: behind).
    pub fn forward(&self) -> f32 {
        if self.pos.is_empty() {
            return f32::NAN;
        }
        self.displacement().dot(self.facing(0))
    }

    /// Metres the pelvis ends up to the left of where it started, along the body's left at
    /// the first frame (negative: to the right).
    pub fn left(&self) -> f32 {
        if self.pos.is_empty() {
            return f32::NAN;
        }
        self.displacement().dot(left_of(self.facing(0)))
    }

    /// [`Track::forward`] per second (m/s).
    pub fn forward_speed(&self) -> f32 {
        self.forward() / self.seconds()
    }

    /// [`Track::left`] per second (m/s).
    pub fn left_speed(&self) -> f32 {
        self.left() / self.seconds()
    }

    /// Net turn of the pelvis path (degrees, + = left; [`total_turn`]).
    pub fn turn(&self) -> f32 {
        self.turn
    }

    /// Height of joint `j` above the floor in frame `f`.
    fn h(&self, f: usize, j: usize) -> f32 {
        self.pos[f][j].y
    }

    /// Highest value over frames of the wrist's height minus the head's.
    pub fn wrist_over_head(&self, wrist: usize) -> f32 {
        self.extreme(true, |f| self.h(f, wrist) - self.h(f, HEAD))
    }

    /// Highest value over frames of the lower wrist's height minus the head's: both hands
    /// above the head in one frame when positive.
    pub fn both_wrists_over_head(&self) -> f32 {
        self.extreme(true, |f| {
            self.h(f, L_WRIST).min(self.h(f, R_WRIST)) - self.h(f, HEAD)
        })
    }

    /// Highest value over frames of the wrist's height minus its own shoulder's.
    pub fn wrist_over_shoulder(&self, wrist: usize) -> f32 {
        let shoulder = if wrist == L_WRIST {
            L_SHOULDER
        } else {
            R_SHOULDER
        };
        self.extreme(true, |f| self.h(f, wrist) - self.h(f, shoulder))
    }

    /// Highest value over frames of the lower of the two wrist-over-shoulder heights.
    pub fn both_wrists_over_shoulder(&self) -> f32 {
        self.extreme(true, |f| {
            (self.h(f, L_WRIST) - self.h(f, L_SHOULDER))
                .min(self.h(f, R_WRIST) - self.h(f, R_SHOULDER))
        })
    }

    /// Peak height of the right wrist minus the peak height of the left (m): positive when
    /// the right hand went higher.
    pub fn right_minus_left_wrist(&self) -> f32 {
        self.max_of(&[R_WRIST]) - self.max_of(&[L_WRIST])
    }

    /// Lowest height of the right wrist minus the lowest of the left (m): negative when the
    /// right hand went lower.
    pub fn right_minus_left_wrist_low(&self) -> f32 {
        self.min_of(&[R_WRIST]) - self.min_of(&[L_WRIST])
    }

    /// Peak height of the right ankle minus that of the left (m).
    pub fn right_minus_left_ankle(&self) -> f32 {
        self.max_of(&[R_ANKLE]) - self.max_of(&[L_ANKLE])
    }

    /// Farthest the ankle gets in front of the pelvis, along the body's facing in that
    /// frame (m).
    pub fn ankle_ahead(&self, ankle: usize) -> f32 {
        self.extreme(true, |f| {
            ground(self.pos[f][ankle] - self.pos[f][PELVIS]).dot(self.facing(f))
        })
    }

    /// Farthest either wrist gets in front of its own shoulder, along the body's facing in
    /// that frame (m): a straight-armed punch reaches about an arm's length (0.5 m).
    pub fn punch_reach(&self) -> f32 {
        self.extreme(true, |f| {
            [(L_WRIST, L_SHOULDER), (R_WRIST, R_SHOULDER)]
                .map(|(w, s)| ground(self.pos[f][w] - self.pos[f][s]).dot(self.facing(f)))
                .into_iter()
                .fold(f32::NEG_INFINITY, f32::max)
        })
    }

    /// Fastest either wrist moves relative to the pelvis (m/s, central differences over
    /// two frames, so one-frame jitter counts half); 0 for motions under three frames.
    pub fn wrist_speed(&self) -> f32 {
        let n = self.pos.len();
        if n < 3 {
            return 0.0;
        }
        (1..n - 1)
            .flat_map(|f| {
                [L_WRIST, R_WRIST].map(|w| {
                    let rel = |g: usize| self.pos[g][w] - self.pos[g][PELVIS];
                    (rel(f + 1) - rel(f - 1)).length() * 20.0 / 2.0
                })
            })
            .fold(0.0, f32::max)
    }

    /// Pelvis height in the first frame.
    pub fn pelvis_start(&self) -> f32 {
        self.y.first().map_or(f32::NAN, |h| h[PELVIS])
    }

    /// Pelvis height in the last frame.
    pub fn pelvis_end(&self) -> f32 {
        self.y.last().map_or(f32::NAN, |h| h[PELVIS])
    }

    /// Head height in the last frame.
    pub fn head_end(&self) -> f32 {
        self.y.last().map_or(f32::NAN, |h| h[HEAD])
    }

    /// Median head height over the frames.
    pub fn head_median(&self) -> f32 {
        let mut h: Vec<f32> = self.y.iter().map(|h| h[HEAD]).collect();
        if h.is_empty() {
            return f32::NAN;
        }
        h.sort_by(f32::total_cmp);
        h[h.len() / 2]
    }

    /// How far the pelvis drops below its starting height at its lowest (m).
    pub fn pelvis_drop(&self) -> f32 {
        self.pelvis_start() - self.min_of(&[PELVIS])
    }

    /// Greatest height of the pelvis above the head (m): upside down when positive.
    pub fn head_below_pelvis(&self) -> f32 {
        self.extreme(true, |f| self.h(f, PELVIS) - self.h(f, HEAD))
    }

    /// Greatest forward lean of the trunk (pelvis → neck) from vertical, along the body's
    /// facing in that frame (degrees; negative leans back).
    pub fn torso_lean(&self) -> f32 {
        self.extreme(true, |f| {
            let trunk = self.pos[f][NECK] - self.pos[f][PELVIS];
            ground(trunk)
                .dot(self.facing(f))
                .atan2(trunk.y)
                .to_degrees()
        })
    }

    /// The farther of the two elbow-to-opposite-knee closest approaches (m): small when
    /// each elbow touches the opposite knee at some moment.
    pub fn elbow_to_opposite_knee(&self) -> f32 {
        let closest = |a: usize, b: usize| {
            self.extreme(false, |f| (self.pos[f][a] - self.pos[f][b]).length())
        };
        closest(L_ELBOW, R_KNEE).max(closest(R_ELBOW, L_KNEE))
    }

    /// Side-to-side reversals of a raised wrist: the wrist's position along the body's
    /// left (relative to the neck), over the frames where it is above its shoulder,
    /// counting each change of direction by at least [`WAVE_SWING`] (5 cm): a hand moved
    /// out, back and out again counts 2.
    pub fn wave_swings(&self, wrist: usize) -> f32 {
        let shoulder = if wrist == L_WRIST {
            L_SHOULDER
        } else {
            R_SHOULDER
        };
        let lateral = (0..self.pos.len())
            .filter(|&f| self.h(f, wrist) > self.h(f, shoulder))
            .map(|f| ground(self.pos[f][wrist] - self.pos[f][NECK]).dot(left_of(self.facing(f))));
        count_reversals(lateral, WAVE_SWING) as f32
    }
}

/// Smallest side-to-side movement of a wrist that counts as a swing of a wave (m).
pub const WAVE_SWING: f32 = 0.05;

/// Changes of direction in `values`, each at least `hysteresis` from the extreme before it.
pub(crate) fn count_reversals(values: impl Iterator<Item = f32>, hysteresis: f32) -> usize {
    let mut values = values;
    let Some(first) = values.next() else {
        return 0;
    };
    // Direction unknown (0) until the values move `hysteresis` from the start.
    let (mut dir, mut extreme, mut count) = (0i8, first, 0);
    let mut low = first;
    let mut high = first;
    for v in values {
        match dir {
            0 => {
                low = low.min(v);
                high = high.max(v);
                if v - low >= hysteresis {
                    (dir, extreme) = (1, v);
                } else if high - v >= hysteresis {
                    (dir, extreme) = (-1, v);
                }
            }
            1 if v > extreme => extreme = v,
            1 if extreme - v >= hysteresis => (dir, extreme, count) = (-1, v, count + 1),
            -1 if v < extreme => extreme = v,
            -1 if v - extreme >= hysteresis => (dir, extreme, count) = (1, v, count + 1),
            _ => {}
        }
    }
    count
}

/// The body's left for a facing on the ground (x, z): facing +Z, the left is +X.
fn left_of(facing: Vec2) -> Vec2 {
    Vec2::new(facing.y, -facing.x)
}

/// The ground (x, z) part of a vector.
fn ground(v: Vec3) -> Vec2 {
    Vec2::new(v.x, v.z)
}

/// A number read off a motion by name: what `bench paraphrases` judges are built from.
pub struct Measure {
    /// Its name in a paraphrase set.
    pub name: &'static str,
    /// What it is, with its unit.
    pub what: &'static str,
    /// The measurement.
    pub value: fn(&Track) -> f32,
}

/// Every [`Measure`], by name (`mprog bench paraphrases --measures` lists them).
pub const MEASURES: &[Measure] = &[
    Measure {
        name: "forward",
        what: "m the pelvis ends up ahead of its start, along the body's first facing (− = behind)",
        value: Track::forward,
    },
    Measure {
        name: "forward_speed",
        what: "`forward` per second (m/s)",
        value: Track::forward_speed,
    },
    Measure {
        name: "left",
        what: "m the pelvis ends up left of its start, along the body's first left (− = right)",
        value: Track::left,
    },
    Measure {
        name: "left_speed",
        what: "`left` per second (m/s)",
        value: Track::left_speed,
    },
    Measure {
        name: "speed",
        what: "length of the pelvis's ground path per second (m/s)",
        value: Track::speed,
    },
    Measure {
        name: "turn",
        what: "net turn of the pelvis's path (degrees, + = left)",
        value: Track::turn,
    },
    Measure {
        name: "both_feet_up",
        what: "highest both feet are off the floor at once (m)",
        value: Track::both_feet_up,
    },
    Measure {
        name: "left_wrist_over_head",
        what: "highest the left wrist gets above the head (m)",
        value: |t| t.wrist_over_head(L_WRIST),
    },
    Measure {
        name: "right_wrist_over_head",
        what: "highest the right wrist gets above the head (m)",
        value: |t| t.wrist_over_head(R_WRIST),
    },
    Measure {
        name: "wrist_over_head",
        what: "highest either wrist gets above the head (m)",
        value: |t| t.wrist_over_head(L_WRIST).max(t.wrist_over_head(R_WRIST)),
    },
    Measure {
        name: "both_wrists_over_head",
        what: "highest the lower wrist gets above the head in one frame (m)",
        value: Track::both_wrists_over_head,
    },
    Measure {
        name: "left_wrist_over_shoulder",
        what: "highest the left wrist gets above the left shoulder (m)",
        value: |t| t.wrist_over_shoulder(L_WRIST),
    },
    Measure {
        name: "right_wrist_over_shoulder",
        what: "highest the right wrist gets above the right shoulder (m)",
        value: |t| t.wrist_over_shoulder(R_WRIST),
    },
    Measure {
        name: "wrist_over_shoulder",
        what: "highest either wrist gets above its shoulder (m)",
        value: |t| {
            t.wrist_over_shoulder(L_WRIST)
                .max(t.wrist_over_shoulder(R_WRIST))
        },
    },
    Measure {
        name: "both_wrists_over_shoulder",
        what: "highest the lower of the two wrists gets above its shoulder in one frame (m)",
        value: Track::both_wrists_over_shoulder,
    },
    Measure {
        name: "right_minus_left_wrist",
        what: "peak height of the right wrist minus the left's (m; + = the right went higher)",
        value: Track::right_minus_left_wrist,
    },
    Measure {
        name: "left_wave_swings",
        what: "side-to-side reversals of the left wrist while above its shoulder (count)",
        value: |t| t.wave_swings(L_WRIST),
    },
    Measure {
        name: "right_wave_swings",
        what: "side-to-side reversals of the right wrist while above its shoulder (count)",
        value: |t| t.wave_swings(R_WRIST),
    },
    Measure {
        name: "wave_swings",
        what: "the larger of the two wrists' wave swings (count)",
        value: |t| t.wave_swings(L_WRIST).max(t.wave_swings(R_WRIST)),
    },
    Measure {
        name: "both_wave_swings",
        what: "the smaller of the two wrists' wave swings (count)",
        value: |t| t.wave_swings(L_WRIST).min(t.wave_swings(R_WRIST)),
    },
    Measure {
        name: "wrist_min",
        what: "lowest either wrist gets (m)",
        value: |t| t.min_of(&[L_WRIST, R_WRIST]),
    },
    Measure {
        name: "left_wrist_min",
        what: "lowest the left wrist gets (m)",
        value: |t| t.min_of(&[L_WRIST]),
    },
    Measure {
        name: "right_wrist_min",
        what: "lowest the right wrist gets (m)",
        value: |t| t.min_of(&[R_WRIST]),
    },
    Measure {
        name: "right_minus_left_wrist_low",
        what: "lowest height of the right wrist minus the left's (m; − = the right went lower)",
        value: Track::right_minus_left_wrist_low,
    },
    Measure {
        name: "wrist_speed",
        what: "fastest either wrist moves relative to the pelvis (m/s)",
        value: Track::wrist_speed,
    },
    Measure {
        name: "punch_reach",
        what: "farthest either wrist gets in front of its shoulder, along the facing (m)",
        value: Track::punch_reach,
    },
    Measure {
        name: "left_ankle_max",
        what: "highest the left ankle gets (m)",
        value: |t| t.max_of(&[L_ANKLE]),
    },
    Measure {
        name: "right_ankle_max",
        what: "highest the right ankle gets (m)",
        value: |t| t.max_of(&[R_ANKLE]),
    },
    Measure {
        name: "ankle_max",
        what: "highest either ankle gets (m)",
        value: |t| t.max_of(&[L_ANKLE, R_ANKLE]),
    },
    Measure {
        name: "right_minus_left_ankle",
        what: "peak height of the right ankle minus the left's (m; + = the right went higher)",
        value: Track::right_minus_left_ankle,
    },
    Measure {
        name: "left_ankle_ahead",
        what: "farthest the left ankle gets in front of the pelvis, along the facing (m)",
        value: |t| t.ankle_ahead(L_ANKLE),
    },
    Measure {
        name: "right_ankle_ahead",
        what: "farthest the right ankle gets in front of the pelvis, along the facing (m)",
        value: |t| t.ankle_ahead(R_ANKLE),
    },
    Measure {
        name: "pelvis_start",
        what: "pelvis height in the first frame (m)",
        value: Track::pelvis_start,
    },
    Measure {
        name: "pelvis_end",
        what: "pelvis height in the last frame (m)",
        value: Track::pelvis_end,
    },
    Measure {
        name: "pelvis_min",
        what: "lowest the pelvis gets (m)",
        value: |t| t.min_of(&[PELVIS]),
    },
    Measure {
        name: "pelvis_drop",
        what: "how far the pelvis drops below its starting height (m)",
        value: Track::pelvis_drop,
    },
    Measure {
        name: "pelvis_end_minus_start",
        what: "pelvis height at the end minus at the start (m)",
        value: |t| t.pelvis_end() - t.pelvis_start(),
    },
    Measure {
        name: "head_min",
        what: "lowest the head gets (m)",
        value: |t| t.min_of(&[HEAD]),
    },
    Measure {
        name: "head_end",
        what: "head height in the last frame (m)",
        value: Track::head_end,
    },
    Measure {
        name: "head_median",
        what: "median head height over the motion (m)",
        value: Track::head_median,
    },
    Measure {
        name: "head_below_pelvis",
        what: "greatest height of the pelvis above the head (m; + = upside down)",
        value: Track::head_below_pelvis,
    },
    Measure {
        name: "torso_lean",
        what: "greatest forward lean of the trunk (pelvis → neck) from vertical (degrees)",
        value: Track::torso_lean,
    },
    Measure {
        name: "elbow_to_opposite_knee",
        what: "the farther of the two elbow-to-opposite-knee closest approaches (m)",
        value: Track::elbow_to_opposite_knee,
    },
];

/// The [`Measure`] called `name`.
pub fn measure(name: &str) -> Option<&'static Measure> {
    MEASURES.iter().find(|m| m.name == name)
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

/// Generates every case with seeds 1 and 2 on the chain `sampler` at classifier-free
/// guidance `guidance` and measures it; `seconds` pins every case's length (else each has
/// its own, see the module's notes).
pub fn measure_actions(
    bundle: &ModelBundle,
    device: &Device,
    seconds: Option<f32>,
    sampler: SamplerKind,
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
                    sampler,
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
