//! The strip PNG: a caption, a grid of K side-view cells (evenly spaced or chosen frames)
//! that all share one fixed camera and floor — so progress through space shows as the
//! figure moving across cells — and below them the top view of the root trails with
//! numbered markers at the cells' frames. With a prompt timeline each cell also names the
//! prompt active at its frame, a bar of the spans with the cells' frames numbered sits
//! between the cells and the top view, and evenly spaced frames move so that every span
//! gets a cell when it can.

use super::camera::{Basis, Rect, box_corners};
use super::draw::{Area, TOP_LEFT, polyline, render_rgb, text};
use super::encode::encode_png;
use super::error::RenderError;
use super::font::{ensure_fonts, fit_text};
use super::frames::{clip_range, strip_frames};
use super::options::{RenderOptions, StripFrames};
use super::scene::Scene;
use super::style::{GRID, TEXT};
use super::timeline::{BarMarks, Timeline, cover_spans};
use super::views::{
    TopMarks, draw_caption, draw_side, draw_top, label_height, side_view, top_caption, top_view,
};
use crate::fsutil::write_bytes_atomic;
use crate::motion::Motion;
use std::path::Path;

/// Caption text size (pixels).
const FONT: f64 = 16.0;
/// Pixels around the scene inside a cell (matches the side view's own margin).
const CELL_MARGIN: f32 = 8.0;

/// Where things go in the strip.
struct Layout {
    w: u32,
    h: u32,
    title_h: f32,
    /// Height of a cell's caption (one line, two with a timeline).
    caption_h: f32,
    cells: Vec<Rect>,
    /// The timeline bar, when there is one.
    bar: Option<Rect>,
    top: Rect,
}

impl Layout {
    /// Picks the column count that draws the figures largest while the grid stays at
    /// most 1.5× as tall as it is wide.
    fn new(
        scene: &Scene,
        k: usize,
        width: u32,
        timeline: Option<&Timeline>,
    ) -> Result<Layout, RenderError> {
        if !(320..=8192).contains(&width) {
            return Err(RenderError::BadOption(format!(
                "strip width {width} is outside 320..=8192"
            )));
        }
        let wf = width as f32;
        let title_h = (FONT * 1.9).round() as f32;
        let lh = label_height(FONT * 0.8);
        let caption_h = if timeline.is_some() { 2.0 * lh } else { lh };
        let extent = |basis: Basis, pts: &[glam::Vec3]| {
            let span = |axis: glam::Vec3| {
                let v = pts.iter().map(|p| p.dot(axis));
                v.clone().fold(f32::MIN, f32::max) - v.fold(f32::MAX, f32::min)
            };
            (span(basis.right).max(1e-3), span(basis.up).max(1e-3))
        };
        let side = Basis::side(scene.yaw);
        let (du, dv) = extent(side, &scene.fit_points());
        let cell_h = |c: usize| {
            (wf / c as f32 - 2.0 * CELL_MARGIN) * dv / du + 2.0 * CELL_MARGIN + caption_h
        };
        let rows = |c: usize| k.div_ceil(c);
        let cols = (1..=k)
            .find(|&c| rows(c) as f32 * cell_h(c) <= 1.5 * wf)
            .unwrap_or(k);
        let (cw, ch) = ((wf / cols as f32).floor(), cell_h(cols).ceil());
        let cells = (0..k)
            .map(|i| Rect {
                x: (i % cols) as f32 * cw,
                y: title_h + (i / cols) as f32 * ch,
                w: cw,
                h: ch,
            })
            .collect();
        let (l, h) = (scene.floor_lo, scene.floor_hi);
        let floor = box_corners(
            glam::Vec3::new(l.x, 0.0, l.y),
            glam::Vec3::new(h.x, 0.0, h.y),
        );
        let (tu, tv) = extent(Basis::top(&side), &floor);
        let top_h = (wf * tv / tu).clamp(0.2 * wf, 0.35 * wf).round();
        let grid_end = title_h + rows(cols) as f32 * ch;
        let bar = timeline.map(|t| Rect {
            x: 0.0,
            y: grid_end,
            w: wf,
            h: t.bar_height(FONT * 0.8, true).ceil(),
        });
        let top = Rect {
            x: 0.0,
            y: bar.map_or(grid_end, |b| b.y + b.h),
            w: wf,
            h: top_h,
        };
        Ok(Layout {
            w: width,
            h: (top.y + top.h).ceil() as u32,
            title_h,
            caption_h,
            cells,
            bar,
            top,
        })
    }
}

/// Renders `people` as one PNG at `path`: `opts.strip_frames` side views sharing one
/// camera, plus the top view of the trails, `opts.strip_width` pixels wide.
/// Nothing is written when an error is returned.
pub fn render_strip_png(
    people: &[Motion],
    opts: &RenderOptions,
    path: &Path,
) -> Result<(), RenderError> {
    let bytes = strip_bytes(people, opts)?;
    write_bytes_atomic(path, &bytes).map_err(|source| RenderError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// The strip PNG file's bytes.
pub fn strip_bytes(people: &[Motion], opts: &RenderOptions) -> Result<Vec<u8>, RenderError> {
    let scene = Scene::new(people, opts)?;
    let timeline = Timeline::new(opts, scene.len)?;
    let mut frames = strip_frames(scene.len, opts)?;
    if let (Some(t), StripFrames::Count(_)) = (&timeline, &opts.strip_frames) {
        let spans: Vec<_> = t.spans().collect();
        frames = cover_spans(frames, &spans, &clip_range(scene.len, opts)?);
    }
    ensure_fonts()?;
    let layout = Layout::new(&scene, frames.len(), opts.strip_width, timeline.as_ref())?;
    let rgb = render_rgb(layout.w, layout.h, |area| {
        paint(
            area,
            &scene,
            &layout,
            &frames,
            &opts.title,
            timeline.as_ref(),
        )
    })?;
    encode_png(&rgb, layout.w, layout.h)
}

fn paint(
    area: &Area,
    scene: &Scene,
    layout: &Layout,
    frames: &[usize],
    title: &str,
    timeline: Option<&Timeline>,
) -> Result<(), RenderError> {
    let y = ((f64::from(layout.title_h) - FONT) / 2.0).round() as i32;
    let title = fit_text(title, FONT, f64::from(layout.w) - 12.0);
    text(area, &title, (6, y), FONT, TEXT, TOP_LEFT)?;
    let small = FONT * 0.8;
    let lh = label_height(small);
    for (k, (&cell, &frame)) in layout.cells.iter().zip(frames).enumerate() {
        let inner = Rect {
            y: cell.y + layout.caption_h,
            h: cell.h - layout.caption_h,
            ..cell
        };
        let view = side_view(scene, inner);
        draw_side(area, scene, &view, frame, small)?;
        let caption = format!("#{}   {:.2} s   frame {frame}", k + 1, scene.time(frame));
        draw_caption(area, cell, &caption, small)?;
        if let Some(t) = timeline {
            let prompt = fit_text(&t.caption(frame), small, f64::from(cell.w) - 10.0);
            let line2 = Rect {
                y: cell.y + lh,
                ..cell
            };
            text(
                area,
                &prompt,
                (line2.x as i32 + 4, line2.y as i32 + 2),
                small,
                TEXT,
                TOP_LEFT,
            )?;
        }
        outline(area, cell)?;
    }
    if let (Some(t), Some(bar)) = (timeline, layout.bar) {
        t.draw_bar(area, bar, &BarMarks::Numbered(frames), small)?;
        outline(area, bar)?;
    }
    let view = top_view(
        scene,
        Rect {
            y: layout.top.y + lh,
            h: layout.top.h - lh,
            ..layout.top
        },
    );
    draw_top(area, scene, &view, TopMarks::Numbered(frames), small)?;
    draw_caption(area, layout.top, &top_caption(scene, &view), small)?;
    outline(area, layout.top)
}

/// A thin frame around a cell.
fn outline(area: &Area, r: Rect) -> Result<(), RenderError> {
    let (x0, y0) = (r.x as i32, r.y as i32);
    let (x1, y1) = ((r.x + r.w) as i32 - 1, (r.y + r.h) as i32 - 1);
    polyline(
        area,
        vec![(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)],
        GRID,
        1,
    )
}
