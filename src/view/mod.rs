//! Interactive viewer: motions in, ONE self-contained HTML file out (inline JS and CSS; no
//! network, no CDN, no fonts to fetch) that plays them in 3-D in any browser.
//!
//! The page shows
//! * a canvas with a perspective camera: drag to orbit, wheel to zoom, shift-drag to pan;
//!   a 1 m floor grid with the +X / +Z axes at the origin;
//! * every person as a stick figure in their own colour family (dark = the body's right
//!   side, light = its left, as in the GIF renders), a floor shadow and the root trail;
//! * the program's geometry from `meta.overlays`, contacts from `meta.contacts` (dashed
//!   when inactive, bright when the frame is in range) and, from `meta.statement_errors`,
//!   one small chart per statement under the canvas with a cursor at the current frame
//!   (schema: [`schema`]);
//! * from `meta.timeline`, a bar under the time slider with one segment per prompt (one
//!   row per person; click to seek), the prompt active at the current frame next to the
//!   frame counter, and the spans shaded in the error charts;
//! * play/pause, a time slider with frame counter and seconds, speed control, and keys:
//!   space (play/pause), ← / → (one frame; with shift ten), ↑ / ↓ (speed), Home / End,
//!   R (reset the camera).
//!
//! The URL hash sets the start state, for links and screenshots: `#frame=40` opens paused
//! at frame 40; `play=1`, `speed=0.5`, `yaw=30` / `pitch=20` (degrees) and `zoom=1.5` may
//! be added (`#frame=40&yaw=90`).
//!
//! ```no_run
//! # fn demo(walk: mprog::motion::Motion) -> Result<(), mprog::view::ViewError> {
//! let meta = mprog::motion::Meta::new();
//! mprog::view::write_html(&[walk], &meta, "a person walks", "walk.html".as_ref())?;
//! # Ok(()) }
//! ```
//!
//! The motion is embedded as millimetre deltas ([`data`]); bad input (no people, empty or
//! non-finite motions, different frame rates, a malformed `meta` field) is a [`ViewError`]
//! and no file is written.

pub mod data;
mod page;
pub mod program;
pub mod schema;

#[cfg(test)]
mod tests;

pub use schema::{
    Contact, JointOf, StatementError, TimelineSpan, ViewExtras, contacts_to_meta, extras_from_meta,
    overlays_from_meta, overlays_to_meta, statement_errors_to_meta, timeline_from_meta,
    timeline_to_meta,
};

use crate::motion::Meta;
use crate::motion::Motion;
use std::path::Path;

/// What can go wrong making a viewer page.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    /// The motions cannot be shown.
    #[error("cannot view these motions: {0}")]
    BadMotion(String),
    /// A viewer field of `meta` is malformed.
    #[error("{field}: {message}")]
    BadMeta {
        /// Where, e.g. `meta.overlays[2]`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// Writing the file failed.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
}

/// Writes the viewer page of `people` (named `person 1`, `person 2`, …) with the extras
/// found in `meta` to `path`, atomically.
pub fn write_html(
    people: &[Motion],
    meta: &Meta,
    title: &str,
    path: &Path,
) -> Result<(), ViewError> {
    let html = html_string(people, meta, title)?;
    crate::fsutil::write_bytes_atomic(path, html.as_bytes()).map_err(|source| ViewError::Io {
        path: path.display().to_string(),
        source,
    })
}

/// The viewer page as a string (see [`write_html`]).
pub fn html_string(people: &[Motion], meta: &Meta, title: &str) -> Result<String, ViewError> {
    let names: Vec<String> = (1..=people.len()).map(|i| format!("person {i}")).collect();
    html_string_named(people, &names, meta, title)
}

/// [`html_string`] with the people's names.
pub fn html_string_named(
    people: &[Motion],
    names: &[String],
    meta: &Meta,
    title: &str,
) -> Result<String, ViewError> {
    check_people(people)?;
    if names.len() != people.len() {
        return Err(ViewError::BadMotion(format!(
            "{} names for {} people",
            names.len(),
            people.len()
        )));
    }
    let frames = people.iter().map(Motion::len).max().unwrap_or(0);
    let extras = extras_from_meta(meta, people.len(), frames)?;
    let block = data::data_block(people, names, &extras, title);
    Ok(page::page(title, &block))
}

fn check_people(people: &[Motion]) -> Result<(), ViewError> {
    let bad = |m: String| Err(ViewError::BadMotion(m));
    let Some(first) = people.first() else {
        return bad("there are no people".into());
    };
    for (i, m) in people.iter().enumerate() {
        if m.is_empty() {
            return bad(format!("person {} has no frames", i + 1));
        }
        if let Some(f) = m
            .frames
            .iter()
            .position(|p| !p.iter().all(|v| v.is_finite()))
        {
            return bad(format!(
                "person {} has non-finite positions at frame {f}",
                i + 1
            ));
        }
        if !(m.fps.is_finite() && m.fps > 0.0) {
            return bad(format!("person {} has frame rate {}", i + 1, m.fps));
        }
        if m.fps != first.fps {
            return bad(format!(
                "person {} is at {} fps but person 1 at {} fps; resample them to one rate",
                i + 1,
                m.fps,
                first.fps
            ));
        }
        // Positions are stored in millimetres as integers; keep them far from overflow.
        if m.frames
            .iter()
            .flatten()
            .any(|p| p.abs().max_element() > 1.0e6)
        {
            return bad(format!(
                "person {} is more than 1000 km from the origin",
                i + 1
            ));
        }
    }
    Ok(())
}
