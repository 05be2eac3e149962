//! Scene layers below and around the figures, drawn through any fitted view: the floor
//! with its 1 m grid, metre labels, root trails on the floor, body shadows and footprints,
//! and overlay lines and dots.

use super::camera::View;
use super::draw::{Area, CENTRE, TOP_LEFT, disc, line, polygon, polyline, ring, text, veil};
use super::error::RenderError;
use super::overlay_geom::Prim;
use super::scene::Scene;
use super::style::{
    FLOOR, FLOOR_EDGE, FOOT, GRID, OVERLAY, SHADOW, SUBTLE, bone_width, fade, person_colors,
};
use crate::skeleton::{FOOT_LEFT, FOOT_RIGHT, KINEMATIC_CHAINS};
use glam::Vec3;
use plotters::style::text_anchor::{HPos, VPos};

/// On the floor plane.
fn on_floor(p: Vec3) -> Vec3 {
    Vec3::new(p.x, 0.0, p.z)
}

/// Floor rectangle corners at y = 0, in order around the edge.
fn floor_corners(scene: &Scene) -> [Vec3; 4] {
    let (l, h) = (scene.floor_lo, scene.floor_hi);
    [
        Vec3::new(l.x, 0.0, l.y),
        Vec3::new(h.x, 0.0, l.y),
        Vec3::new(h.x, 0.0, h.y),
        Vec3::new(l.x, 0.0, h.y),
    ]
}

/// Floor fill, grid lines every [`Scene::grid_step`] metres, border.
pub(crate) fn draw_floor(area: &Area, scene: &Scene, view: &View) -> Result<(), RenderError> {
    let corners = floor_corners(scene);
    polygon(area, corners.iter().map(|c| view.px(*c)).collect(), FLOOR)?;
    let (l, h, step) = (scene.floor_lo, scene.floor_hi, scene.grid_step());
    for i in ((l.x / step).ceil() as i64)..=((h.x / step).floor() as i64) {
        let x = i as f32 * step;
        line(
            area,
            view.px(Vec3::new(x, 0.0, l.y)),
            view.px(Vec3::new(x, 0.0, h.y)),
            GRID,
            1,
        )?;
    }
    for i in ((l.y / step).ceil() as i64)..=((h.y / step).floor() as i64) {
        let z = i as f32 * step;
        line(
            area,
            view.px(Vec3::new(l.x, 0.0, z)),
            view.px(Vec3::new(h.x, 0.0, z)),
            GRID,
            1,
        )?;
    }
    let mut border: Vec<_> = corners.iter().map(|c| view.px(*c)).collect();
    border.push(border[0]);
    polyline(area, border, FLOOR_EDGE, 1)
}

/// Metre labels along the bottom and left edges of the floor (top view only: its axes
/// are world axes), spaced at least ~30 px apart.
pub(crate) fn draw_metre_labels(
    area: &Area,
    scene: &Scene,
    view: &View,
    size: f64,
) -> Result<(), RenderError> {
    let base = scene.grid_step();
    let step = [1.0f32, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0]
        .into_iter()
        .map(|m| m * base)
        .find(|s| s * view.scale >= 30.0)
        .unwrap_or(200.0 * base);
    let corners = floor_corners(scene).map(|c| view.pxf(c));
    let bottom = corners.iter().map(|c| c.1).fold(f32::MIN, f32::max);
    let left = corners.iter().map(|c| c.0).fold(f32::MAX, f32::min);
    let b = view.basis;
    for (axis, horizontal) in [(b.right, true), (b.up, false)] {
        let values = floor_corners(scene).map(|c| c.dot(axis));
        let lo = values.iter().copied().fold(f32::MAX, f32::min);
        let hi = values.iter().copied().fold(f32::MIN, f32::max);
        let mut v = (lo / step).ceil() * step;
        while v <= hi + 1e-4 {
            let (x, y) = view.pxf(axis * v);
            // `axis` is ±X or ±Z: the label is the world coordinate, not the projection.
            let sign = axis.x + axis.y + axis.z;
            let label = format!("{}", (v * sign).round() as i64);
            if horizontal {
                let at = (x.round() as i32, bottom.round() as i32 + 2);
                text(area, &label, at, size, SUBTLE, (HPos::Center, VPos::Top))?;
            } else {
                let at = (left.round() as i32 - 3, y.round() as i32);
                text(area, &label, at, size, SUBTLE, (HPos::Right, VPos::Center))?;
            }
            v += step;
        }
    }
    Ok(())
}

/// Each person's root path over the whole clip, on the floor.
pub(crate) fn draw_trails(
    area: &Area,
    scene: &Scene,
    view: &View,
    width: u32,
    faded: f32,
) -> Result<(), RenderError> {
    for person in 0..scene.people() {
        let pts = scene
            .root_trail(person)
            .into_iter()
            .map(|p| view.px(on_floor(p)))
            .collect();
        polyline(area, pts, fade(person_colors(person).centre, faded), width)?;
    }
    Ok(())
}

/// Every person's bones flattened onto the floor, with darker footprints (ankle to toe),
/// so height above the floor and foot contacts can be read in the side view.
pub(crate) fn draw_shadows(
    area: &Area,
    scene: &Scene,
    view: &View,
    frame: usize,
) -> Result<(), RenderError> {
    let width = bone_width(view.scale);
    for person in 0..scene.people() {
        let pose = scene.pose(person, frame);
        for chain in KINEMATIC_CHAINS {
            let pts = chain.iter().map(|&j| view.px(on_floor(pose[j]))).collect();
            polyline(area, pts, SHADOW, width)?;
        }
        for [ankle, toe] in [FOOT_LEFT, FOOT_RIGHT] {
            line(
                area,
                view.px(on_floor(pose[ankle])),
                view.px(on_floor(pose[toe])),
                FOOT,
                width,
            )?;
        }
    }
    Ok(())
}

/// Overlay lines and planes (planes as a light veil with an outline, so a wall reads as
/// a surface; boxes and segments as lines). A plane seen edge-on or face-on from straight
/// above (the top view) is a line or the whole floor: `from_above` draws walls as lines
/// and leaves horizontal planes out.
pub(crate) fn draw_overlay_lines(
    area: &Area,
    scene: &Scene,
    view: &View,
    from_above: bool,
) -> Result<(), RenderError> {
    for prim in &scene.prims {
        match prim {
            Prim::Line(a, b) => line(area, view.px(*a), view.px(*b), OVERLAY, 2)?,
            Prim::Quad(q) if from_above => {
                // A wall's bottom edge is its trace on the map; a horizontal plane has none.
                if (q[2].y - q[1].y).abs() > 1e-6 {
                    line(area, view.px(q[0]), view.px(q[1]), OVERLAY, 2)?;
                }
            }
            Prim::Quad(q) => {
                let mut pts: Vec<_> = q.iter().map(|p| view.px(*p)).collect();
                veil(area, pts.clone(), OVERLAY, 0.08)?;
                pts.push(pts[0]);
                polyline(area, pts, OVERLAY, 1)?;
            }
            Prim::Dot(..) => {}
        }
    }
    Ok(())
}

/// Overlay points with labels; `drop_to_floor` adds a dashed-looking stem down to a floor
/// cross so a point's height reads in a projected view.
pub(crate) fn draw_overlay_dots(
    area: &Area,
    scene: &Scene,
    view: &View,
    drop_to_floor: bool,
    label_size: f64,
) -> Result<(), RenderError> {
    for prim in &scene.prims {
        let Prim::Dot(p, label) = prim else { continue };
        let at = view.px(*p);
        if drop_to_floor && p.y.abs() > 1e-3 {
            let foot = view.px(on_floor(*p));
            line(area, at, foot, fade(OVERLAY, 0.55), 1)?;
            let (x, y) = foot;
            line(area, (x - 4, y), (x + 4, y), OVERLAY, 1)?;
            line(area, (x, y - 3), (x, y + 3), OVERLAY, 1)?;
        }
        disc(area, at, 4, OVERLAY)?;
        ring(area, at, 6, OVERLAY, 1)?;
        if let Some(label) = label {
            text(
                area,
                label,
                (at.0 + 9, at.1 - 6),
                label_size,
                OVERLAY,
                TOP_LEFT,
            )?;
        }
    }
    Ok(())
}

/// A numbered marker (strip top view: where each strip cell's frame is).
pub(crate) fn draw_marker(
    area: &Area,
    at: (i32, i32),
    n: usize,
    color: plotters::style::RGBColor,
    size: f64,
) -> Result<(), RenderError> {
    let r = (size * 0.75).round() as i32;
    disc(area, at, r, color)?;
    text(
        area,
        &n.to_string(),
        at,
        size,
        super::style::BACKGROUND,
        CENTRE,
    )
}
