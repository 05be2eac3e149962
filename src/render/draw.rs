//! Thin drawing helpers over a plotters bitmap area in pixel coordinates (lines, discs,
//! polygons, arrows, text), plus rendering a whole picture into an in-memory RGB buffer.
//! Everything returns [`RenderError`] instead of plotters' generic errors.

use super::error::{RenderError, draw_err};
use super::font::{FAMILY, ensure_fonts};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// A bitmap drawing area in pixel coordinates.
pub(crate) type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// Pixel point.
pub(crate) type Px = (i32, i32);

/// Renders a `w`×`h` picture with `paint` into a packed RGB8 buffer (row-major, top row first).
pub(crate) fn render_rgb<F>(w: u32, h: u32, paint: F) -> Result<Vec<u8>, RenderError>
where
    F: FnOnce(&Area) -> Result<(), RenderError>,
{
    if w == 0 || h == 0 || w > 16_384 || h > 16_384 {
        return Err(RenderError::BadOption(format!("picture size {w}x{h} is not drawable")));
    }
    ensure_fonts()?;
    let mut buf = vec![255u8; w as usize * h as usize * 3];
    {
        let backend = BitMapBackend::with_buffer_and_format(&mut buf, (w, h)).map_err(draw_err)?;
        let area = backend.into_drawing_area();
        paint(&area)?;
        area.present().map_err(draw_err)?;
    }
    Ok(buf)
}

/// A straight line `width` pixels wide.
pub(crate) fn line(area: &Area, a: Px, b: Px, color: RGBColor, width: u32) -> Result<(), RenderError> {
    polyline(area, vec![a, b], color, width)
}

/// A connected line through `points`.
pub(crate) fn polyline(area: &Area, points: Vec<Px>, color: RGBColor, width: u32) -> Result<(), RenderError> {
    if points.len() < 2 {
        return Ok(());
    }
    area.draw(&PathElement::new(points, color.stroke_width(width)))
        .map_err(draw_err)
}

/// A filled circle.
pub(crate) fn disc(area: &Area, c: Px, r: i32, color: RGBColor) -> Result<(), RenderError> {
    area.draw(&Circle::new(c, r.max(1), color.filled())).map_err(draw_err)
}

/// A circle outline.
pub(crate) fn ring(area: &Area, c: Px, r: i32, color: RGBColor, width: u32) -> Result<(), RenderError> {
    area.draw(&Circle::new(c, r.max(1), color.stroke_width(width)))
        .map_err(draw_err)
}

/// A filled polygon.
pub(crate) fn polygon(area: &Area, points: Vec<Px>, color: RGBColor) -> Result<(), RenderError> {
    area.draw(&Polygon::new(points, color.filled())).map_err(draw_err)
}

/// An arrow from `a` to `b` with a filled head `head` pixels long.
pub(crate) fn arrow(area: &Area, a: Px, b: Px, color: RGBColor, width: u32, head: f32) -> Result<(), RenderError> {
    let (dx, dy) = ((b.0 - a.0) as f32, (b.1 - a.1) as f32);
    let len = (dx * dx + dy * dy).sqrt();
    if len < 1.0 {
        return disc(area, a, width as i32 + 1, color);
    }
    let (ux, uy) = (dx / len, dy / len);
    let head = head.min(len);
    let base = (b.0 as f32 - ux * head, b.1 as f32 - uy * head);
    let half = head * 0.5;
    line(area, a, (base.0.round() as i32, base.1.round() as i32), color, width)?;
    let corner = |s: f32| ((base.0 - uy * half * s).round() as i32, (base.1 + ux * half * s).round() as i32);
    polygon(area, vec![b, corner(1.0), corner(-1.0)], color)
}

/// Text at `at`, anchored by `h`/`v` (e.g. left/top), `size` pixels high.
pub(crate) fn text(
    area: &Area,
    s: &str,
    at: Px,
    size: f64,
    color: RGBColor,
    (h, v): (HPos, VPos),
) -> Result<(), RenderError> {
    if s.is_empty() {
        return Ok(());
    }
    let style = TextStyle::from((FAMILY, size).into_font())
        .color(&color)
        .pos(Pos::new(h, v));
    area.draw(&Text::new(s.to_string(), at, style)).map_err(draw_err)
}

/// Left/top anchor.
pub(crate) const TOP_LEFT: (HPos, VPos) = (HPos::Left, VPos::Top);
/// Right/top anchor.
pub(crate) const TOP_RIGHT: (HPos, VPos) = (HPos::Right, VPos::Top);
/// Centre/centre anchor.
pub(crate) const CENTRE: (HPos, VPos) = (HPos::Center, VPos::Center);
