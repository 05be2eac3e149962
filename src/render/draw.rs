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
        return Err(RenderError::BadOption(format!(
            "picture size {w}x{h} is not drawable"
        )));
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
pub(crate) fn line(
    area: &Area,
    a: Px,
    b: Px,
    color: RGBColor,
    width: u32,
) -> Result<(), RenderError> {
    polyline(area, vec![a, b], color, width)
}

/// A translucent filled polygon (`alpha` of `color` over what is there).
pub(crate) fn veil(
    area: &Area,
    points: Vec<Px>,
    color: RGBColor,
    alpha: f64,
) -> Result<(), RenderError> {
    area.draw(&Polygon::new(points, color.mix(alpha).filled()))
        .map_err(draw_err)
}

/// A connected line through `points`.
///
/// Plotters fills thick paths as one mitred polygon, which spikes at sharp turns and
/// near-zero segments (a shadow's spine seen from above is such a path), and its polygon
/// fill leaves bumps on short thick segments. So: 1 px lines go straight to plotters;
/// 2 px lines are two parallel 1 px lines; wider ones are drawn segment by segment with
/// round joins, after merging points closer together than the stroke is wide.
pub(crate) fn polyline(
    area: &Area,
    points: Vec<Px>,
    color: RGBColor,
    width: u32,
) -> Result<(), RenderError> {
    if points.len() < 2 || width == 0 {
        return Ok(());
    }
    let thin = |pts: Vec<Px>| {
        area.draw(&PathElement::new(pts, color.stroke_width(1)))
            .map_err(draw_err)
    };
    match width {
        1 => thin(points),
        2 => {
            for pair in points.windows(2) {
                let (a, b) = (pair[0], pair[1]);
                let (dx, dy) = if (b.0 - a.0).abs() >= (b.1 - a.1).abs() {
                    (0, 1)
                } else {
                    (1, 0)
                };
                thin(vec![a, b])?;
                thin(vec![(a.0 + dx, a.1 + dy), (b.0 + dx, b.1 + dy)])?;
            }
            Ok(())
        }
        _ => {
            let near =
                |a: Px, b: Px| (a.0 - b.0).pow(2) + (a.1 - b.1).pow(2) < (width * width) as i32;
            let last = points[points.len() - 1];
            let mut kept = vec![points[0]];
            for &p in &points[1..points.len() - 1] {
                if !near(p, kept[kept.len() - 1]) && !near(p, last) {
                    kept.push(p);
                }
            }
            kept.push(last);
            for (k, pair) in kept.windows(2).enumerate() {
                if pair[0] != pair[1] {
                    area.draw(&PathElement::new(
                        vec![pair[0], pair[1]],
                        color.stroke_width(width),
                    ))
                    .map_err(draw_err)?;
                }
                if k + 2 < kept.len() {
                    disc(area, pair[1], (width as i32) / 2, color)?;
                }
            }
            Ok(())
        }
    }
}

/// A filled circle.
pub(crate) fn disc(area: &Area, c: Px, r: i32, color: RGBColor) -> Result<(), RenderError> {
    area.draw(&Circle::new(c, r.max(1), color.filled()))
        .map_err(draw_err)
}

/// A circle outline.
pub(crate) fn ring(
    area: &Area,
    c: Px,
    r: i32,
    color: RGBColor,
    width: u32,
) -> Result<(), RenderError> {
    area.draw(&Circle::new(c, r.max(1), color.stroke_width(width)))
        .map_err(draw_err)
}

/// A filled polygon.
pub(crate) fn polygon(area: &Area, points: Vec<Px>, color: RGBColor) -> Result<(), RenderError> {
    area.draw(&Polygon::new(points, color.filled()))
        .map_err(draw_err)
}

/// An arrow from `a` to `b` with a filled head `head` pixels long.
pub(crate) fn arrow(
    area: &Area,
    a: Px,
    b: Px,
    color: RGBColor,
    width: u32,
    head: f32,
) -> Result<(), RenderError> {
    let (dx, dy) = ((b.0 - a.0) as f32, (b.1 - a.1) as f32);
    let len = (dx * dx + dy * dy).sqrt();
    if len < 1.0 {
        return disc(area, a, width as i32 + 1, color);
    }
    let (ux, uy) = (dx / len, dy / len);
    let head = head.min(len);
    let base = (b.0 as f32 - ux * head, b.1 as f32 - uy * head);
    let half = head * 0.5;
    line(
        area,
        a,
        (base.0.round() as i32, base.1.round() as i32),
        color,
        width,
    )?;
    let corner = |s: f32| {
        (
            (base.0 - uy * half * s).round() as i32,
            (base.1 + ux * half * s).round() as i32,
        )
    };
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
    area.draw(&Text::new(s.to_string(), at, style))
        .map_err(draw_err)
}

/// Left/top anchor.
pub(crate) const TOP_LEFT: (HPos, VPos) = (HPos::Left, VPos::Top);
/// Right/top anchor.
pub(crate) const TOP_RIGHT: (HPos, VPos) = (HPos::Right, VPos::Top);
/// Centre/centre anchor.
pub(crate) const CENTRE: (HPos, VPos) = (HPos::Center, VPos::Center);
