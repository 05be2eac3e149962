//! `.json` motion files: self-describing, with the settings that made them.
//!
//! In/out: [`MotionDocument`], serialised as
//! ```json
//! {"format": "mprog-motion", "version": 1, "fps": 20, "skeleton": "humanml3d-22",
//!  "joint_names": ["pelvis", …], "up": "+y", "units": "m",
//!  "people": [{"name": "person 1", "frames": [[[x, y, z], … 22 joints], …]}],
//!  "meta": {"seed": 7, "program": "…", "solver": {…}, "weights": "…"}}
//! ```
//! `meta` is a free-form object (seed, program text, solver settings, weights id) so a
//! result can be reproduced. Reading validates every field and converts `cm`/`mm` to
//! metres; errors name the file and, for syntax, the line and column.

use crate::motion::Motion;
use crate::skeleton::{JOINT_NAMES, NUM_JOINTS};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Value of the `format` field.
pub const FORMAT_NAME: &str = "mprog-motion";
/// Current format version.
pub const FORMAT_VERSION: u32 = 1;
/// Value of the `skeleton` field.
pub const SKELETON_NAME: &str = "humanml3d-22";

/// Longest motion a document may hold, in seconds (6 hours).
pub const MAX_SECONDS: f64 = 6.0 * 3600.0;

pub use crate::motion::Meta;

/// The whole file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MotionDocument {
    pub format: String,
    pub version: u32,
    pub fps: f32,
    pub skeleton: String,
    pub joint_names: Vec<String>,
    pub up: String,
    pub units: String,
    pub people: Vec<PersonTrack>,
    #[serde(default)]
    pub meta: Meta,
}

/// One person's frames: `[frames][22][3]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PersonTrack {
    pub name: String,
    pub frames: Vec<Vec<[f32; 3]>>,
}

/// A named motion read from or written to a document.
#[derive(Clone, Debug, PartialEq)]
pub struct Person {
    pub name: String,
    pub motion: Motion,
}

/// A `.json` problem; every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum JsonError {
    #[error("{origin}: cannot read: {source}")]
    Io {
        origin: String,
        source: std::io::Error,
    },
    #[error("{origin}:{line}:{column}: {message}")]
    Syntax {
        origin: String,
        line: usize,
        column: usize,
        message: String,
    },
    #[error("{origin}: {message}")]
    Invalid { origin: String, message: String },
    #[error("{path}: cannot write: {source}")]
    Write {
        path: String,
        source: std::io::Error,
    },
}

impl MotionDocument {
    /// A document of `people` (all at the same fps) with `meta`.
    pub fn new(people: &[Person], meta: Meta) -> Self {
        MotionDocument {
            format: FORMAT_NAME.into(),
            version: FORMAT_VERSION,
            fps: people
                .first()
                .map_or(crate::skeleton::FPS, |p| p.motion.fps),
            skeleton: SKELETON_NAME.into(),
            joint_names: JOINT_NAMES.iter().map(|n| n.to_string()).collect(),
            up: "+y".into(),
            units: "m".into(),
            people: people
                .iter()
                .map(|p| PersonTrack {
                    name: p.name.clone(),
                    frames: p
                        .motion
                        .frames
                        .iter()
                        .map(|pose| pose.iter().map(|v| v.to_array()).collect())
                        .collect(),
                })
                .collect(),
            meta,
        }
    }

    /// Checks every field and returns the people in metres.
    pub fn validate(&self, origin: &str) -> Result<Vec<Person>, JsonError> {
        let invalid = |message: String| JsonError::Invalid {
            origin: origin.into(),
            message,
        };
        if self.format != FORMAT_NAME {
            return Err(invalid(format!(
                "`format` is \"{}\", expected \"{FORMAT_NAME}\"",
                self.format
            )));
        }
        if self.version != FORMAT_VERSION {
            return Err(invalid(format!(
                "version {} is not supported (this mprog reads version {FORMAT_VERSION})",
                self.version
            )));
        }
        if self.skeleton != SKELETON_NAME {
            return Err(invalid(format!(
                "`skeleton` is \"{}\", expected \"{SKELETON_NAME}\"",
                self.skeleton
            )));
        }
        if self.joint_names != JOINT_NAMES {
            return Err(invalid(format!(
                "`joint_names` must be the HumanML3D order {JOINT_NAMES:?}, found {:?}",
                self.joint_names
            )));
        }
        if self.up != "+y" {
            return Err(invalid(format!(
                "`up` is \"{}\"; only \"+y\" is supported",
                self.up
            )));
        }
        let scale = match self.units.as_str() {
            "m" => 1.0,
            "cm" => 0.01,
            "mm" => 0.001,
            other => {
                return Err(invalid(format!(
                    "`units` is \"{other}\", expected \"m\", \"cm\" or \"mm\""
                )));
            }
        };
        if !(self.fps.is_finite() && self.fps > 0.0) {
            return Err(invalid(format!(
                "`fps` must be positive, found {}",
                self.fps
            )));
        }
        if self.people.is_empty() {
            return Err(invalid("`people` is empty".into()));
        }
        self.people
            .iter()
            .enumerate()
            .map(|(i, p)| p.to_person(i, self.fps, scale).map_err(invalid))
            .collect()
    }
}

impl PersonTrack {
    fn to_person(&self, index: usize, fps: f32, scale: f32) -> Result<Person, String> {
        let who = format!("person {index} (\"{}\")", self.name);
        if self.frames.is_empty() {
            return Err(format!("{who} has no frames"));
        }
        // Reading resamples to 20 fps: a tiny `fps` would turn two frames into billions.
        let seconds = (self.frames.len() - 1) as f64 / f64::from(fps);
        if seconds > MAX_SECONDS {
            return Err(format!(
                "{who} is too long: {} frames at {fps} fps last {seconds:.3e} s; the limit is {MAX_SECONDS} s (check `fps`)",
                self.frames.len()
            ));
        }
        let mut frames = Vec::with_capacity(self.frames.len());
        for (f, joints) in self.frames.iter().enumerate() {
            if joints.len() != NUM_JOINTS {
                return Err(format!(
                    "{who} frame {f} has {} joints, expected {NUM_JOINTS}",
                    joints.len()
                ));
            }
            if let Some(j) = joints.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
                return Err(format!(
                    "{who} frame {f} joint {} is not finite",
                    JOINT_NAMES[j]
                ));
            }
            frames.push(std::array::from_fn(|j| glam::Vec3::from(joints[j]) * scale));
        }
        Ok(Person {
            name: self.name.clone(),
            motion: Motion { frames, fps },
        })
    }
}

impl JsonError {
    /// A serde_json parse error as `origin:line:column: message`.
    pub fn syntax(origin: &str, e: &serde_json::Error) -> Self {
        let text = e.to_string();
        JsonError::Syntax {
            origin: origin.into(),
            line: e.line(),
            column: e.column(),
            message: text
                .split(" at line ")
                .next()
                .unwrap_or_default()
                .to_string(),
        }
    }
}

/// Parses and validates a document.
pub fn read_json_str(origin: &str, text: &str) -> Result<(Vec<Person>, Meta), JsonError> {
    let doc: MotionDocument =
        serde_json::from_str(text).map_err(|e| JsonError::syntax(origin, &e))?;
    let people = doc.validate(origin)?;
    Ok((people, doc.meta))
}

/// Reads a `.json` motion file.
pub fn read_json(path: &Path) -> Result<(Vec<Person>, Meta), JsonError> {
    let origin = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| JsonError::Io {
        origin: origin.clone(),
        source,
    })?;
    read_json_str(&origin, &text)
}

/// Writes people and metadata as a `.json` motion file (atomically).
pub fn write_json(path: &Path, people: &[Person], meta: &Meta) -> Result<(), JsonError> {
    let name = path.display().to_string();
    let bytes = json_bytes(&name, people, meta)?;
    crate::fsutil::write_bytes_atomic(path, &bytes)
        .map_err(|source| JsonError::Write { path: name, source })
}

/// The bytes of the `.json` file [`write_json`] writes; `origin` names it in errors.
pub fn json_bytes(origin: &str, people: &[Person], meta: &Meta) -> Result<Vec<u8>, JsonError> {
    let fps: Vec<f32> = people.iter().map(|p| p.motion.fps).collect();
    if people.is_empty() || fps.iter().any(|&f| f != fps[0]) {
        let message = format!(
            "cannot write {} people with frame rates {fps:?}: need at least one, all at the same rate",
            people.len()
        );
        return Err(JsonError::Invalid {
            origin: origin.to_string(),
            message,
        });
    }
    let doc = MotionDocument::new(people, meta.clone());
    let mut bytes = serde_json::to_vec(&doc).map_err(|e| JsonError::Write {
        path: origin.to_string(),
        source: std::io::Error::other(e),
    })?;
    bytes.push(b'\n');
    Ok(bytes)
}
