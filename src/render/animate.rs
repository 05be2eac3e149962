//! The animated GIF: every (subsampled) frame drawn as a caption line with the time and
//! frame counter over two panels — the side view on the left, the top view on the right —
//! with both cameras fixed over the whole clip, then encoded and written atomically.

use super::camera::Rect;
use super::draw::{Area, TOP_LEFT, TOP_RIGHT, line, render_rgb, text};
use super::encode::{GifWriter, Palette};
use super::error::RenderError;
use super::font::{ensure_fonts, fit_text, text_width};
use super::frames::{gif_delays, gif_frames};
use super::options::RenderOptions;
use super::scene::Scene;
use super::style::{GRID, TEXT};
use super::views::{TopMarks, draw_caption, draw_side, draw_top, label_height, side_view, top_caption, top_view};
use crate::fsutil::write_bytes_atomic;
use crate::motion::Motion;
use rayon::prelude::*;
use std::path::Path;

/// Share of the width given to the side view.
const SIDE_SHARE: f32 = 0.6;
/// Frames rendered in parallel between encoder writes (bounds memory).
const CHUNK: usize = 16;
/// Frames sampled to choose the palette.
const PALETTE_SAMPLES: usize = 8;

/// Where things go in one GIF frame.
struct Layout {
    w: u32,
    h: u32,
    title_h: f32,
    font: f64,
    side: Rect,
    top: Rect,
}

impl Layout {
    fn new(w: u32, h: u32) -> Result<Layout, RenderError> {
        if w < 160 || h < 100 {
            return Err(RenderError::BadOption(format!("GIF size {w}x{h} is too small (min 160x100)")));
        }
        let (wf, hf) = (w as f32, h as f32);
        let title_h = (hf * 0.075).clamp(16.0, 32.0).round();
        let side_w = (wf * SIDE_SHARE).round();
        let body = hf - title_h;
        Ok(Layout {
            w,
            h,
            title_h,
            font: f64::from(title_h) * 0.62,
            side: Rect { x: 0.0, y: title_h, w: side_w, h: body },
            top: Rect { x: side_w, y: title_h, w: wf - side_w, h: body },
        })
    }

    /// A panel without its caption line.
    fn inner(&self, r: Rect) -> Rect {
        let lh = label_height(self.font * 0.8);
        Rect { y: r.y + lh, h: r.h - lh, ..r }
    }
}

/// Renders `people` (one motion each, drawn together) as an animated GIF at `path`.
///
/// The GIF plays in real time at the motions' frame rate, showing every
/// `opts.frame_step`-th frame of `opts.frame_range`; `opts.size` is the frame size.
/// Nothing is written when an error is returned.
pub fn render_gif(people: &[Motion], opts: &RenderOptions, path: &Path) -> Result<(), RenderError> {
    let bytes = gif_bytes(people, opts)?;
    write_bytes_atomic(path, &bytes).map_err(|source| RenderError::Io { path: path.to_path_buf(), source })
}

/// The GIF file's bytes.
pub(crate) fn gif_bytes(people: &[Motion], opts: &RenderOptions) -> Result<Vec<u8>, RenderError> {
    let scene = Scene::new(people, opts)?;
    let frames = gif_frames(scene.len, opts)?;
    let delays = gif_delays(&frames, scene.fps, opts.frame_step)?;
    let layout = Layout::new(opts.size.0, opts.size.1)?;
    ensure_fonts()?;
    let paint = |frame: usize| {
        render_rgb(layout.w, layout.h, |area| paint_frame(area, &scene, &layout, frame, &opts.title))
    };
    let n = PALETTE_SAMPLES.min(frames.len());
    let samples: Vec<usize> = (0..n).map(|i| frames[i * (frames.len() - 1) / (n - 1).max(1)]).collect();
    let sample_rgb = samples.par_iter().map(|&f| paint(f)).collect::<Result<Vec<_>, _>>()?;
    let palette = Palette::from_samples(&sample_rgb);
    drop(sample_rgb);
    let mut writer = GifWriter::new(layout.w, layout.h, &palette)?;
    for (chunk, chunk_delays) in frames.chunks(CHUNK).zip(delays.chunks(CHUNK)) {
        let indexed = chunk
            .par_iter()
            .map(|&f| paint(f).map(|rgb| palette.quantise(&rgb)))
            .collect::<Result<Vec<_>, _>>()?;
        for (indices, &delay) in indexed.into_iter().zip(chunk_delays) {
            writer.push(indices, delay)?;
        }
    }
    writer.finish()
}

/// One GIF frame.
fn paint_frame(area: &Area, scene: &Scene, layout: &Layout, frame: usize, title: &str) -> Result<(), RenderError> {
    let font = layout.font;
    let last = scene.len - 1;
    let clock = format!("{:.2} s   frame {frame}/{last}", scene.time(frame));
    let clock_w = text_width(&clock, font);
    let y = ((layout.title_h as f64 - font) / 2.0).round() as i32;
    text(area, &clock, (layout.w as i32 - 6, y), font, TEXT, TOP_RIGHT)?;
    let room = f64::from(layout.w) - clock_w - 24.0;
    text(area, &fit_text(title, font, room), (6, y), font, TEXT, TOP_LEFT)?;

    let small = font * 0.8;
    let side = side_view(scene, layout.inner(layout.side));
    draw_side(area, scene, &side, frame, small)?;
    draw_caption(area, layout.side, "side", small)?;

    let top = top_view(scene, layout.inner(layout.top));
    draw_top(area, scene, &top, TopMarks::Current(frame), small)?;
    draw_caption(area, layout.top, &top_caption(&top), small)?;

    let x = layout.top.x as i32;
    line(area, (x, layout.title_h as i32), (x, layout.h as i32), GRID, 1)?;
    line(area, (0, layout.title_h as i32 - 1), (layout.w as i32, layout.title_h as i32 - 1), GRID, 1)
}
