//! BVH errors: what went wrong ([`BvhErrorKind`]) and where ([`BvhError`]: the file or
//! source name and, when it applies, the 1-based line number).
//!
//! Displayed as `walk.bvh:135: motion line has 131 values, expected 132 …`, the
//! convention compilers use, so messages can be clicked in editors.

use std::fmt;

/// A BVH import error with its location.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}: {kind}", Location(origin, *line))]
pub struct BvhError {
    /// File path or the name given to [`super::import_bvh_str`].
    pub origin: String,
    /// 1-based line number, when the error belongs to one line.
    pub line: Option<usize>,
    /// What is wrong.
    pub kind: BvhErrorKind,
}

/// `origin` or `origin:line` (also the rig errors' location).
pub(crate) struct Location<'a>(pub(crate) &'a str, pub(crate) Option<usize>);

impl fmt::Display for Location<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.1 {
            Some(line) => write!(f, "{}:{line}", self.0),
            None => write!(f, "{}", self.0),
        }
    }
}

/// What is wrong with a BVH input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BvhErrorKind {
    #[error("cannot read the file: {0}")]
    Io(String),
    #[error("the file is {size} bytes, over the limit of {limit} bytes for a BVH file")]
    FileTooLarge { size: u64, limit: u64 },
    #[error("not a text file: found a NUL byte (binary data)")]
    Binary,
    #[error("not UTF-8 text: invalid byte sequence")]
    NotUtf8,
    #[error("the file must start with `HIERARCHY`, found `{0}`")]
    MissingHierarchy(String),
    #[error("expected {expected}, found `{found}`")]
    Expected { expected: String, found: String },
    #[error(
        "unknown keyword `{0}` in the HIERARCHY section (expected JOINT, End Site, OFFSET, CHANNELS or `}}`)"
    )]
    UnknownKeyword(String),
    #[error("`{0}` needs a name on the same line")]
    MissingName(String),
    #[error("invalid number `{0}`")]
    BadNumber(String),
    #[error("value `{0}` is not a finite number")]
    NonFinite(String),
    #[error("joint `{0}` has no OFFSET line")]
    MissingOffset(String),
    #[error("joint `{0}` has a second {1} line")]
    Duplicate(String, &'static str),
    #[error("joint `{0}` has no CHANNELS line")]
    MissingChannels(String),
    #[error("CHANNELS declares {declared} channels but lists {found}")]
    ChannelCount { declared: usize, found: usize },
    #[error(
        "unknown channel `{0}` (expected Xposition, Yposition, Zposition, Xrotation, Yrotation or Zrotation)"
    )]
    UnknownChannel(String),
    #[error("the file ends inside the hierarchy: joint `{0}` is never closed with `}}`")]
    UnclosedJoint(String),
    #[error("joints are nested more than {0} levels deep")]
    TooDeep(usize),
    #[error("no joints: the HIERARCHY section has no ROOT")]
    NoJoints,
    #[error("no joint has channels: a BVH file needs at least one CHANNELS entry")]
    NoChannels,
    #[error("no MOTION section after the hierarchy")]
    MissingMotion,
    #[error("expected `{0}:` in the MOTION header")]
    MissingHeader(&'static str),
    #[error("`Frames:` must be a whole number, found `{0}`")]
    BadFrameCount(String),
    #[error("`Frames: 0`: the file has no motion")]
    ZeroFrames,
    #[error("`Frame Time:` must be a positive number of seconds, found `{0}`")]
    BadFrameTime(String),
    #[error("{what} is {count}, over the limit of {limit} (raise `max_values` to accept it)")]
    TooBig {
        what: &'static str,
        count: u64,
        limit: u64,
    },
    #[error("motion line has {found} values, expected {expected} (one per channel)")]
    ValueCount { found: usize, expected: usize },
    #[error("the file ends after {found} of the {declared} frames that `Frames:` declares")]
    MissingFrames { found: usize, declared: usize },
    #[error("more frame lines than the {declared} that `Frames:` declares")]
    ExtraFrames { declared: usize },
    #[error(
        "cannot map the skeleton to the HumanML3D joints: no source joint for {missing:?} (source joints: {available})"
    )]
    Unmapped {
        missing: Vec<&'static str>,
        available: String,
    },
    #[error(
        "frame {frame} of the file: the position of `{joint}` is not finite (values too large to add up along the skeleton)"
    )]
    NonFinitePosition { frame: usize, joint: &'static str },
    #[error("invalid import option: {0}")]
    BadOption(String),
    #[error("ASF/AMC: {0}")]
    Asf(String),
}

impl BvhError {
    /// An error at a line of `origin`.
    pub fn at(origin: &str, line: usize, kind: BvhErrorKind) -> Self {
        BvhError {
            origin: origin.to_string(),
            line: Some(line),
            kind,
        }
    }

    /// An error about the whole input.
    pub fn whole(origin: &str, kind: BvhErrorKind) -> Self {
        BvhError {
            origin: origin.to_string(),
            line: None,
            kind,
        }
    }
}
