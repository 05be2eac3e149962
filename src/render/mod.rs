//! Pictures: stick-figure renders of motions (animated GIF, strip PNG) and line plots.
//!
//! Motions in, image files out. Every person (one [`Motion`] each) is drawn as a stick
//! figure along [`KINEMATIC_CHAINS`](crate::skeleton::KINEMATIC_CHAINS) in their own colour
//! family — dark for the body's right side, light for its left, mid-tone spine and head
//! disc — in two views whose cameras are fitted once to the whole clip, so people visibly
//! move through space:
//!
//! * **side view**: orthographic three-quarter view (from the right-front of the direction
//!   of travel, looking 20° down) of the floor with its 1 m grid, the root trails on the
//!   floor, body shadows with dark footprints, and the figures painted far to near;
//! * **top view**: the floor map seen from above with metre labels, each root trail, and
//!   the current pose, root and facing arrow (GIF) or numbered markers (strip).
//!
//! Overlays ([`Overlay`]: points, segments, walls, horizontal planes, boxes) are drawn in
//! both views in magenta. A prompt timeline ([`RenderOptions::timeline`]) with more than
//! one prompt adds the active prompt to each frame's caption and a bar of the spans.
//!
//! ```no_run
//! use mprog::render::{Overlay, RenderOptions, render_to_path};
//! # fn demo(walk: mprog::motion::Motion) -> Result<(), mprog::render::RenderError> {
//! let mut opts = RenderOptions::titled("a person walks forward");
//! opts.overlays.push(Overlay::Point { at: glam::Vec3::new(0.0, 1.0, 3.0), label: Some("target".into()) });
//! render_to_path(&[walk.clone()], &opts, "out/walk.gif".as_ref())?;
//! render_to_path(&[walk], &opts, "out/walk.png".as_ref())?;
//! # Ok(()) }
//! ```
//!
//! Bad input (no people, empty motions, non-finite coordinates, mismatched frame rates,
//! frames out of range, degenerate overlays) is a [`RenderError`], never a panic, and no
//! output file is written then: every file goes through
//! [`fsutil::write_bytes_atomic`](crate::fsutil::write_bytes_atomic).
//!
//! Line plots ([`plot_lines`]) draw named [`Series`] with axes, legend, optional log-y and
//! labelled bands ([`Band`]: a prompt timeline's spans).

mod animate;
mod camera;
mod draw;
mod encode;
mod error;
mod figure;
mod font;
mod frames;
mod layers;
mod options;
mod overlay_geom;
mod plot;
mod scene;
mod strip;
mod style;
mod timeline;
mod views;

#[cfg(test)]
pub(crate) mod test_motion;
#[cfg(test)]
mod test_util;
#[cfg(test)]
mod tests;

pub use animate::{gif_bytes, render_gif};
pub use error::RenderError;
pub use options::{Overlay, RenderOptions, StripFrames, TimelineSpan};
pub use plot::{Band, PlotOptions, Series, plot_lines};
pub use strip::{render_strip_png, strip_bytes};

use crate::motion::Motion;
use std::path::Path;

/// Renders by the extension of `path`: `.gif` → [`render_gif`], `.png` →
/// [`render_strip_png`] (case-insensitive); anything else is [`RenderError::UnknownFormat`].
pub fn render_to_path(
    people: &[Motion],
    opts: &RenderOptions,
    path: &Path,
) -> Result<(), RenderError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("gif") => render_gif(people, opts, path),
        Some("png") => render_strip_png(people, opts, path),
        _ => Err(RenderError::UnknownFormat(path.to_path_buf())),
    }
}
