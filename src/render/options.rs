//! What a caller can ask of a motion render: caption, picture sizes, which frames, the
//! camera, overlay geometry (points, segments, planes, boxes in world coordinates) drawn
//! into both views, and the prompt timeline. Plain data in, validated by the renderers.

pub use crate::scene::Overlay;
use std::ops::Range;

/// Options shared by [`render_gif`](super::render_gif) and
/// [`render_strip_png`](super::render_strip_png).
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    /// Caption drawn at the top (e.g. the prompt); empty for none.
    pub title: String,
    /// GIF frame size in pixels (width, height): side view on the left, top view on the
    /// right (stacked instead when the clip travels far enough that this draws it larger).
    pub size: (u32, u32),
    /// Width of the strip PNG in pixels; its height follows from the layout.
    pub strip_width: u32,
    /// GIF: draw every `frame_step`-th frame (1 = every frame). The GIF still plays at the
    /// motion's real speed: each GIF frame lasts `frame_step / fps` seconds.
    pub frame_step: usize,
    /// Restrict both outputs to these frames (`None`: the whole clip). Cameras, floor and
    /// trails still cover the whole clip, so renders of different ranges line up.
    pub frame_range: Option<Range<usize>>,
    /// Which frames the strip shows.
    pub strip_frames: StripFrames,
    /// Side-view camera heading in degrees about +Y (0: the view that shows a walk along
    /// +Z from the walker's right-front, moving rightwards). `None`: follow the clip's net
    /// travel direction (or the first frame's facing when it barely travels).
    pub camera_yaw_deg: Option<f32>,
    /// Extra geometry drawn into both views.
    pub overlays: Vec<Overlay>,
    /// Each person's prompt timeline (person order; an empty list for a person without
    /// one). Drawn when some person has more than one prompt: each frame's caption names
    /// the prompt active then, a bar under the views shows the spans, and the strip picks
    /// its frames so that every span gets one when it can.
    pub timeline: Vec<Vec<TimelineSpan>>,
}

/// One prompt of a timeline: the frames `from..to` (half-open) it covers.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TimelineSpan {
    /// First frame.
    pub from: usize,
    /// One past the last frame.
    pub to: usize,
    /// The prompt.
    pub prompt: String,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            title: String::new(),
            size: (640, 320),
            strip_width: 1280,
            // Every frame: with changed-rectangle encoding a 10 s clip is a few hundred kB.
            frame_step: 1,
            frame_range: None,
            strip_frames: StripFrames::Count(8),
            camera_yaw_deg: None,
            overlays: Vec::new(),
            timeline: Vec::new(),
        }
    }
}

impl RenderOptions {
    /// Default options with a caption.
    pub fn titled(title: impl Into<String>) -> Self {
        RenderOptions {
            title: title.into(),
            ..Self::default()
        }
    }
}

/// Frames shown by the strip PNG.
#[derive(Clone, Debug, PartialEq)]
pub enum StripFrames {
    /// This many evenly spaced frames, first and last included (fewer if the clip is
    /// shorter); at most 64.
    Count(usize),
    /// Exactly these frame indices, in this order; at most 64.
    Indices(Vec<usize>),
}
