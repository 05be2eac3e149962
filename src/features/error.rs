//! Errors of the feature code: bad motions in, malformed feature arrays or statistics in.

use thiserror::Error;

/// What can go wrong turning positions into features or features into positions.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum FeatureError {
    /// The motion is too short for the operation.
    #[error("the motion has {frames} frame(s); at least {needed} are needed")]
    TooFewFrames {
        /// Frames given.
        frames: usize,
        /// Frames required.
        needed: usize,
    },
    /// A joint coordinate is NaN or infinite.
    #[error("joint {joint} ({name}) at frame {frame} is not finite")]
    NonFinite {
        /// Frame index.
        frame: usize,
        /// Joint index.
        joint: usize,
        /// Joint name.
        name: &'static str,
    },
    /// A bone has (almost) zero length, so its direction, and its rotation, are undefined.
    #[error("bone to joint {joint} ({name}) has zero length at frame {frame}")]
    ZeroBone {
        /// Frame index.
        frame: usize,
        /// Child joint of the bone.
        joint: usize,
        /// Child joint name.
        name: &'static str,
    },
    /// Hips and shoulders give no horizontal facing direction (e.g. they coincide, or the
    /// across vector is vertical).
    #[error(
        "the facing direction is undefined at frame {frame}: hips and shoulders give no horizontal across vector"
    )]
    DegenerateFacing {
        /// Frame index.
        frame: usize,
    },
    /// Features are defined per frame at 20 fps; other rates must be resampled first.
    #[error(
        "the motion runs at {fps} fps; HumanML3D features need 20 fps (resample it with Motion::resample)"
    )]
    WrongFps {
        /// Frame rate of the motion.
        fps: f32,
    },
    /// A flat feature array whose length is not a multiple of the feature width.
    #[error("feature array of length {len} is not a whole number of {dim}-wide frames")]
    BadFeatureLength {
        /// Length given.
        len: usize,
        /// Expected width of a frame.
        dim: usize,
    },
    /// Mean/Std of the wrong length, or a zero or non-finite Std.
    #[error("normalisation statistics: {0}")]
    BadStats(String),
}
