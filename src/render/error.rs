//! The one error type of the render module: what was wrong with the motions, the options
//! or the overlays handed in, or what failed while drawing, encoding or writing a picture.

use std::path::PathBuf;

/// Everything that can go wrong while rendering a motion or a plot.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// No people were given.
    #[error("nothing to render: no motions given")]
    NoPeople,
    /// A person's motion has zero frames.
    #[error("person {person}: the motion has no frames")]
    EmptyMotion {
        /// Index of the person in the slice.
        person: usize,
    },
    /// A joint coordinate is NaN or infinite.
    #[error("person {person}, frame {frame}, joint {joint}: coordinate is not finite")]
    NonFinite {
        /// Index of the person in the slice.
        person: usize,
        /// Frame index.
        frame: usize,
        /// Joint index.
        joint: usize,
    },
    /// A frame rate that is not a positive finite number.
    #[error("person {person}: frame rate {fps} is not a positive number")]
    BadFps {
        /// Index of the person in the slice.
        person: usize,
        /// The offending frame rate.
        fps: f32,
    },
    /// People with different frame rates cannot share one timeline.
    #[error("person {person} has {fps} fps but person 0 has {first} fps; resample first")]
    FpsMismatch {
        /// Index of the person in the slice.
        person: usize,
        /// That person's frame rate.
        fps: f32,
        /// Person 0's frame rate.
        first: f32,
    },
    /// A frame index outside the clip.
    #[error("frame {frame} is outside the clip of {len} frames")]
    FrameOutOfRange {
        /// Requested frame.
        frame: usize,
        /// Number of frames in the clip.
        len: usize,
    },
    /// An option value that cannot be honoured.
    #[error("bad render option: {0}")]
    BadOption(String),
    /// An overlay primitive that cannot be drawn.
    #[error("overlay {index}: {reason}")]
    BadOverlay {
        /// Index in `RenderOptions::overlays`.
        index: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// A plot input that cannot be drawn.
    #[error("bad plot input: {0}")]
    BadPlot(String),
    /// The output path has an extension the renderer does not write.
    #[error("cannot tell the picture format of {0:?}: use .gif or .png")]
    UnknownFormat(PathBuf),
    /// The drawing library failed.
    #[error("drawing failed: {0}")]
    Draw(String),
    /// Encoding the picture failed.
    #[error("encoding failed: {0}")]
    Encode(String),
    /// Writing the file failed.
    #[error("writing {path:?}: {source}")]
    Io {
        /// The file being written.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
}

/// Converts any plotters error into [`RenderError::Draw`].
pub(crate) fn draw_err<E: std::fmt::Display>(e: E) -> RenderError {
    RenderError::Draw(e.to_string())
}
