//! The animated GIF: every (subsampled) frame drawn as a caption line with the time and
//! frame counter over two panels — the side view on the left, the top view on the right —
//! with both cameras fixed over the whole clip, then encoded and written atomically. With
//! a prompt timeline the side view's caption names the prompt active at the frame and a
//! bar of the spans with a cursor at the frame runs along the bottom.

use super::camera::{Rect, View};
use super::draw::{Area, TOP_LEFT, TOP_RIGHT, line, render_rgb, text};
use super::encode::{GifWriter, Palette};
use super::error::RenderError;
use super::font::{ensure_fonts, fit_text, text_width};
use super::frames::{gif_delays, gif_frames};
use super::options::RenderOptions;
use super::scene::Scene;
use super::style::{GRID, TEXT};
use super::timeline::{BarMarks, Timeline};
use super::views::{
    TopMarks, draw_caption, draw_side, draw_top, label_height, side_view, top_caption, top_view,
};
use crate::fsutil::write_bytes_atomic;
use crate::motion::Motion;
use rayon::prelude::*;
use std::path::Path;

/// Share of the width given to the side view when the views sit side by side.
const SIDE_SHARE: f32 = 0.6;
/// Share of the height given to the side view when the views are stacked.
const STACKED_SIDE_SHARE: f32 = 0.66;
/// How much larger stacking must draw the figures before it replaces side by side.
const STACK_GAIN: f32 = 1.25;
/// Frames rendered in parallel between encoder writes (bounds memory).
const CHUNK: usize = 16;
/// Frames sampled to choose the palette.
const PALETTE_SAMPLES: usize = 8;

/// Where things go in one GIF frame, with both cameras fitted once for the whole clip.
struct Layout {
    w: u32,
    h: u32,
    title_h: f32,
    font: f64,
    side: Rect,
    top: Rect,
    /// The timeline bar along the bottom, when there is one.
    bar: Option<Rect>,
    side_view: View,
    top_view: View,
}

impl Layout {
    /// Side by side (side view on the left), unless the clip travels so far that stacking
    /// the views (side view on top, full width) draws the figures much larger.
    fn new(
        scene: &Scene,
        w: u32,
        h: u32,
        timeline: Option<&Timeline>,
    ) -> Result<Layout, RenderError> {
        if w < 160 || h < 100 {
            return Err(RenderError::BadOption(format!(
                "GIF size {w}x{h} is too small (min 160x100)"
            )));
        }
        let (wf, hf) = (w as f32, h as f32);
        let title_h = (hf * 0.075).clamp(16.0, 32.0).round();
        let font = f64::from(title_h) * 0.62;
        let bar_h = timeline.map_or(0.0, |t| t.bar_height(font * 0.8, false).ceil());
        let body = hf - title_h - bar_h;
        if body < 60.0 {
            return Err(RenderError::BadOption(format!(
                "GIF size {w}x{h} leaves no room for the views under the timeline"
            )));
        }
        let bar = timeline.map(|_| Rect {
            x: 0.0,
            y: hf - bar_h,
            w: wf,
            h: bar_h,
        });
        let side_w = (wf * SIDE_SHARE).round();
        let beside = (
            Rect {
                x: 0.0,
                y: title_h,
                w: side_w,
                h: body,
            },
            Rect {
                x: side_w,
                y: title_h,
                w: wf - side_w,
                h: body,
            },
        );
        let side_h = (body * STACKED_SIDE_SHARE).round();
        let stacked = (
            Rect {
                x: 0.0,
                y: title_h,
                w: wf,
                h: side_h,
            },
            Rect {
                x: 0.0,
                y: title_h + side_h,
                w: wf,
                h: body - side_h,
            },
        );
        let inner = |r: Rect| {
            let lh = label_height(font * 0.8);
            Rect {
                y: r.y + lh,
                h: r.h - lh,
                ..r
            }
        };
        let scale = |r: Rect| side_view(scene, inner(r)).scale;
        let (side, top) = if scale(stacked.0) > STACK_GAIN * scale(beside.0) {
            stacked
        } else {
            beside
        };
        Ok(Layout {
            w,
            h,
            title_h,
            font,
            side,
            top,
            bar,
            side_view: side_view(scene, inner(side)),
            top_view: top_view(scene, inner(top)),
        })
    }
}

/// Renders `people` (one motion each, drawn together) as an animated GIF at `path`.
///
/// The GIF plays in real time at the motions' frame rate, showing every
/// `opts.frame_step`-th frame of `opts.frame_range`; `opts.size` is the frame size.
/// Nothing is written when an error is returned.
pub fn render_gif(people: &[Motion], opts: &RenderOptions, path: &Path) -> Result<(), RenderError> {
    let bytes = gif_bytes(people, opts)?;
    write_bytes_atomic(path, &bytes).map_err(|source| RenderError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// The GIF file's bytes.
pub fn gif_bytes(people: &[Motion], opts: &RenderOptions) -> Result<Vec<u8>, RenderError> {
    let scene = Scene::new(people, opts)?;
    let frames = gif_frames(scene.len, opts)?;
    let delays = gif_delays(&frames, scene.fps, opts.frame_step)?;
    let timeline = Timeline::new(opts, scene.len)?;
    let layout = Layout::new(&scene, opts.size.0, opts.size.1, timeline.as_ref())?;
    ensure_fonts()?;
    let paint = |frame: usize| {
        render_rgb(layout.w, layout.h, |area| {
            paint_frame(area, &scene, &layout, frame, &opts.title, timeline.as_ref())
        })
    };
    let n = PALETTE_SAMPLES.min(frames.len());
    let samples: Vec<usize> = (0..n)
        .map(|i| frames[i * (frames.len() - 1) / (n - 1).max(1)])
        .collect();
    let sample_rgb = samples
        .par_iter()
        .map(|&f| paint(f))
        .collect::<Result<Vec<_>, _>>()?;
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
fn paint_frame(
    area: &Area,
    scene: &Scene,
    layout: &Layout,
    frame: usize,
    title: &str,
    timeline: Option<&Timeline>,
) -> Result<(), RenderError> {
    let font = layout.font;
    let last = scene.len - 1;
    let clock = format!("{:.2} s   frame {frame}/{last}", scene.time(frame));
    let clock_w = text_width(&clock, font);
    let y = ((layout.title_h as f64 - font) / 2.0).round() as i32;
    text(
        area,
        &clock,
        (layout.w as i32 - 6, y),
        font,
        TEXT,
        TOP_RIGHT,
    )?;
    let room = f64::from(layout.w) - clock_w - 24.0;
    text(
        area,
        &fit_text(title, font, room),
        (6, y),
        font,
        TEXT,
        TOP_LEFT,
    )?;

    let small = font * 0.8;
    draw_side(area, scene, &layout.side_view, frame, small)?;
    let side_caption = match timeline {
        Some(t) => fit_text(
            &format!("side view — {}", t.caption(frame)),
            small,
            f64::from(layout.side.w) - 10.0,
        ),
        None => "side view".to_string(),
    };
    draw_caption(area, layout.side, &side_caption, small)?;
    draw_top(
        area,
        scene,
        &layout.top_view,
        TopMarks::Current(frame),
        small,
    )?;
    draw_caption(
        area,
        layout.top,
        &top_caption(scene, &layout.top_view),
        small,
    )?;

    let (tx, ty) = (layout.top.x as i32, layout.top.y as i32);
    if let (Some(t), Some(bar)) = (timeline, layout.bar) {
        t.draw_bar(area, bar, &BarMarks::Cursor(frame), small)?;
        line(
            area,
            (0, bar.y as i32),
            (layout.w as i32, bar.y as i32),
            GRID,
            1,
        )?;
    }
    let bottom = layout.bar.map_or(layout.h as i32, |b| b.y as i32);
    if tx > 0 {
        line(area, (tx, ty), (tx, bottom), GRID, 1)?;
    } else {
        line(area, (0, ty), (layout.w as i32, ty), GRID, 1)?;
    }
    line(
        area,
        (0, layout.title_h as i32 - 1),
        (layout.w as i32, layout.title_h as i32 - 1),
        GRID,
        1,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::test_motion::walk;
    use crate::skeleton::rest_pose;
    use glam::Vec3;

    #[test]
    fn long_walks_stack_the_views_short_clips_keep_them_side_by_side() {
        let opts = RenderOptions::default();
        let still = [Motion::new(vec![rest_pose(); 5])];
        let beside = Layout::new(&Scene::new(&still, &opts).unwrap(), 640, 320, None).unwrap();
        assert!(beside.top.x > 0.0 && beside.top.y == beside.side.y);
        let long = [walk(200, 1.2, Vec3::ZERO, Vec3::Z)];
        let stacked = Layout::new(&Scene::new(&long, &opts).unwrap(), 640, 320, None).unwrap();
        assert!(stacked.top.x == 0.0 && stacked.top.y > stacked.side.y);
        // Stacking must actually draw the walker larger than side by side would.
        assert!(
            stacked.side_view.scale
                > STACK_GAIN * side_view(&Scene::new(&long, &opts).unwrap(), beside.side).scale
        );
        assert!(Layout::new(&Scene::new(&still, &opts).unwrap(), 100, 50, None).is_err());
    }
}
