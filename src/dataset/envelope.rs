//! The plausibility envelope: how real motion moves, measured once on a training set and
//! shipped in the model bundle (`<bundle>/envelope.json`), so every output can be held
//! against it (`metrics::plausibility`).
//!
//! ```text
//! version      ENVELOPE_VERSION
//! source       what it was measured on ("data/combined: 3,702 clips, 1,092,812 frames")
//! speed        per joint (HumanML3D order), over frames: ‖p[t+1] − p[t]‖·fps in m/s
//! accel        per joint, over frames: ‖p[t+1] − 2p[t] + p[t−1]‖ in m/frame² (no fps
//!              scaling)
//! speed_peak,  per joint, over clips: each clip's largest speed / acceleration (the
//! accel_peak   limits use their 99th percentile: a few real clips are acrobatics, and
//!              a few have capture glitches of metres per frame, so the plain maximum
//!              says nothing)
//! floor        per frame: the lowest joint's height (m)
//! skating      per clip: metrics::per_motion::foot_skating_ratio
//! skating_moving  the same over the clips whose pelvis moves faster than 0.5 m/s on
//!              average (walks and runs: what a moving output is compared with)
//! rigid        per frame: distances the skeleton's bones do not hold (hip width,
//!              shoulder width, pelvis → spine3 …) as a ratio to the rest pose's
//! ```
//!
//! Every distribution is a [`Spread`]: min, the 0.1st, 1st, 5th, 50th, 95th, 99th and
//! 99.9th percentiles, max and mean.
//! `mprog data envelope` measures it; [`Envelope::builtin`] is the one the binary was
//! built with (the shipped `models/default/envelope.json`), the fallback for a bundle
//! without its own.

use serde::{Deserialize, Serialize};
use std::path::Path;

/// Version of the file layout; bumped when a field changes meaning.
pub const ENVELOPE_VERSION: u32 = 1;

/// Mean horizontal pelvis speed (m/s) above which a clip (or an output) counts as moving
/// for the foot skating comparison.
pub const MOVING_SPEED: f32 = 0.5;

/// A distribution's summary.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Spread {
    /// Smallest value.
    pub min: f32,
    /// 0.1st percentile.
    #[serde(rename = "p0.1")]
    pub p0_1: f32,
    /// 1st percentile.
    pub p1: f32,
    /// 5th percentile.
    pub p5: f32,
    /// Median.
    pub p50: f32,
    /// 95th percentile.
    pub p95: f32,
    /// 99th percentile.
    pub p99: f32,
    /// 99.9th percentile.
    #[serde(rename = "p99.9")]
    pub p99_9: f32,
    /// Largest value.
    pub max: f32,
    /// Mean.
    pub mean: f32,
}

impl Spread {
    /// The summary of `values` (non-finite ones are dropped; all zero when none is left).
    /// Reorders `values`.
    pub fn of(values: &mut Vec<f32>) -> Spread {
        values.retain(|v| v.is_finite());
        let n = values.len();
        if n == 0 {
            return Spread::default();
        }
        let mean = (values.iter().map(|&v| v as f64).sum::<f64>() / n as f64) as f32;
        let mut at = |q: f64| -> f32 {
            let k = ((q * (n - 1) as f64).round() as usize).min(n - 1);
            *values.select_nth_unstable_by(k, f32::total_cmp).1
        };
        Spread {
            min: at(0.0),
            p0_1: at(0.001),
            p1: at(0.01),
            p5: at(0.05),
            p50: at(0.5),
            p95: at(0.95),
            p99: at(0.99),
            p99_9: at(0.999),
            max: at(1.0),
            mean,
        }
    }
}

/// A distance between two joints that no bone holds but a real body keeps nearly fixed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidPair {
    /// Name in reports ("hip width").
    pub name: &'static str,
    /// The two joints.
    pub joints: [usize; 2],
}

/// The rigid parts checked: the pelvis triangle's free side, the shoulder girdle and the
/// spine as a whole (the pelvis → l_hip and → r_hip sides are bones already).
pub const RIGID_PAIRS: [RigidPair; 7] = [
    RigidPair {
        name: "hip width (left_hip–right_hip)",
        joints: [1, 2],
    },
    RigidPair {
        name: "shoulder width (left_shoulder–right_shoulder)",
        joints: [16, 17],
    },
    RigidPair {
        name: "collar width (left_collar–right_collar)",
        joints: [13, 14],
    },
    RigidPair {
        name: "spine (pelvis–spine3)",
        joints: [0, 9],
    },
    RigidPair {
        name: "spine (pelvis–neck)",
        joints: [0, 12],
    },
    RigidPair {
        name: "left hip–spine3",
        joints: [1, 9],
    },
    RigidPair {
        name: "right hip–spine3",
        joints: [2, 9],
    },
];

/// One rigid distance's real range.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RigidRange {
    /// [`RigidPair::name`].
    pub name: String,
    /// The two joints.
    pub joints: [usize; 2],
    /// Its length in the skeleton's rest pose (m).
    pub rest: f32,
    /// Per frame: the distance ÷ `rest`.
    pub ratio: Spread,
}

/// How real motion moves (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Envelope {
    /// [`ENVELOPE_VERSION`].
    pub version: u32,
    /// What it was measured on.
    pub source: String,
    /// Clips measured.
    pub clips: usize,
    /// Frames measured.
    pub frames: usize,
    /// Frame rate of the clips.
    pub fps: f32,
    /// Per joint: speed in m/s.
    pub speed: Vec<Spread>,
    /// Per joint: acceleration ‖p[t+1] − 2p[t] + p[t−1]‖ in m/frame².
    pub accel: Vec<Spread>,
    /// Per joint, over clips: each clip's largest speed (m/s).
    pub speed_peak: Vec<Spread>,
    /// Per joint, over clips: each clip's largest acceleration (m/frame²).
    pub accel_peak: Vec<Spread>,
    /// Per frame: the lowest joint's height (m).
    pub floor: Spread,
    /// Per clip: foot skating ratio.
    pub skating: Spread,
    /// Per clip, over clips whose mean pelvis speed is above [`MOVING_SPEED`]: foot
    /// skating ratio.
    pub skating_moving: Spread,
    /// The rigid distances.
    pub rigid: Vec<RigidRange>,
}

/// The envelope the binary was built with.
const BUILTIN: &str = include_str!("../../models/default/envelope.json");

/// Errors reading an envelope.
#[derive(Debug, thiserror::Error)]
pub enum EnvelopeError {
    /// Unreadable file.
    #[error("cannot read {path}: {reason}")]
    Read {
        /// The file.
        path: String,
        /// Why.
        reason: String,
    },
    /// Readable but wrong.
    #[error("{path}: {reason}")]
    Invalid {
        /// The file.
        path: String,
        /// What is wrong.
        reason: String,
    },
}

impl Envelope {
    /// Parses and checks an envelope's JSON; `path` names it in errors.
    pub fn from_json(text: &str, path: &str) -> Result<Envelope, EnvelopeError> {
        let invalid = |reason: String| EnvelopeError::Invalid {
            path: path.to_string(),
            reason,
        };
        let env: Envelope =
            serde_json::from_str(text).map_err(|e| invalid(format!("bad envelope: {e}")))?;
        if env.version != ENVELOPE_VERSION {
            return Err(invalid(format!(
                "envelope version {} but this mprog reads {ENVELOPE_VERSION}; measure it again with `mprog data envelope`",
                env.version
            )));
        }
        let joints = crate::skeleton::NUM_JOINTS;
        let lens = [
            env.speed.len(),
            env.accel.len(),
            env.speed_peak.len(),
            env.accel_peak.len(),
        ];
        if lens.iter().any(|&n| n != joints) {
            return Err(invalid(format!(
                "{lens:?} speed, acceleration, peak speed and peak acceleration entries, expected {joints} of each"
            )));
        }
        if env
            .rigid
            .iter()
            .any(|r| r.joints.iter().any(|&j| j >= joints) || r.rest <= 0.0)
        {
            return Err(invalid(
                "a rigid distance names a joint outside 0..22 or has no rest length".into(),
            ));
        }
        Ok(env)
    }

    /// Reads `path`.
    pub fn load(path: &Path) -> Result<Envelope, EnvelopeError> {
        let text = std::fs::read_to_string(path).map_err(|e| EnvelopeError::Read {
            path: path.display().to_string(),
            reason: e.to_string(),
        })?;
        Envelope::from_json(&text, &path.display().to_string())
    }

    /// Writes it as pretty JSON, atomically.
    pub fn save(&self, path: &Path) -> std::io::Result<()> {
        let text = serde_json::to_string_pretty(self).expect("envelope serialises");
        crate::fsutil::write_bytes_atomic(path, format!("{text}\n").as_bytes())
    }

    /// The envelope this binary was built with (`models/default/envelope.json` at build
    /// time): what a bundle without its own `envelope.json` is checked against.
    pub fn builtin() -> Envelope {
        let mut env =
            Envelope::from_json(BUILTIN, "built-in envelope").expect("the shipped envelope parses");
        env.source = format!("built in: {}", env.source);
        env
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_of_a_ramp() {
        let mut v: Vec<f32> = (0..=1000).map(|i| i as f32).collect();
        v.push(f32::NAN);
        let s = Spread::of(&mut v);
        assert_eq!(
            (s.min, s.p0_1, s.p1, s.p5, s.p50),
            (0.0, 1.0, 10.0, 50.0, 500.0)
        );
        assert_eq!(s.p95, 950.0);
        assert_eq!((s.p99, s.p99_9, s.max), (990.0, 999.0, 1000.0));
        assert!((s.mean - 500.0).abs() < 1e-3);
        assert_eq!(Spread::of(&mut Vec::new()), Spread::default());
    }

    #[test]
    fn the_builtin_envelope_parses_and_round_trips() {
        let env = Envelope::builtin();
        assert_eq!(env.speed.len(), 22);
        assert!(env.accel.iter().all(|a| a.max > 0.0));
        assert!(env.accel_peak.iter().all(|a| a.p99 > 0.0 && a.p99 <= a.max));
        let text = serde_json::to_string(&env).unwrap();
        assert_eq!(Envelope::from_json(&text, "x").unwrap(), env);
        let old = text.replace("\"version\":1", "\"version\":0");
        assert!(Envelope::from_json(&old, "x").is_err());
    }
}
