//! The two views of a scene, each fitted once to the whole clip and drawn into a pixel
//! rectangle: the side (three-quarter) view with floor, shadows and figures, and the top
//! view with the floor map, root trails and either the current pose or numbered markers.

use super::camera::{Basis, Rect, View, box_corners};
use super::draw::{Area, TOP_LEFT, arrow, disc, text};
use super::error::RenderError;
use super::figure::draw_figures;
use super::layers::{
    draw_floor, draw_marker, draw_metre_labels, draw_overlay_dots, draw_overlay_lines,
    draw_shadows, draw_trails,
};
use super::scene::{Scene, facing};
use super::style::{SUBTLE, person_colors};
use glam::Vec3;

/// Pixels kept free around the fitted scene.
const SIDE_MARGIN: f32 = 8.0;
/// The top view also needs room for its metre labels.
const TOP_MARGIN: f32 = 20.0;
/// Length of the facing arrow in the top view (metres).
const ARROW_M: f32 = 0.45;

/// Height of a panel's name line for text of `size` pixels.
pub(crate) fn label_height(size: f64) -> f32 {
    (size * 1.4).round() as f32
}

/// The side camera fitted to `rect` (below the panel's name line).
pub(crate) fn side_view(scene: &Scene, rect: Rect) -> View {
    View::fit(
        Basis::side(scene.yaw),
        &scene.fit_points(),
        rect,
        SIDE_MARGIN,
    )
}

/// The top camera fitted to `rect`; only the floor rectangle matters from above.
pub(crate) fn top_view(scene: &Scene, rect: Rect) -> View {
    let (l, h) = (scene.floor_lo, scene.floor_hi);
    let floor = box_corners(Vec3::new(l.x, 0.0, l.y), Vec3::new(h.x, 0.0, h.y));
    View::fit(
        Basis::top(&Basis::side(scene.yaw)),
        &floor,
        rect,
        TOP_MARGIN,
    )
}

/// Screen-space name of a world axis direction.
fn axis_name(v: Vec3) -> &'static str {
    match (v.x.round() as i32, v.z.round() as i32) {
        (1, _) => "+x",
        (-1, _) => "-x",
        (_, 1) => "+z",
        _ => "-z",
    }
}

/// Panel caption for the top view, naming its axes and grid spacing.
pub(crate) fn top_caption(scene: &Scene, view: &View) -> String {
    let (right, up) = (axis_name(view.basis.right), axis_name(view.basis.up));
    format!(
        "top view, looking down (to the right: {right}, upwards: {up}; grid {} m); dark limbs: right side, light: left",
        scene.grid_step()
    )
}

/// Side view of every person at `frame`.
pub(crate) fn draw_side(
    area: &Area,
    scene: &Scene,
    view: &View,
    frame: usize,
    text_size: f64,
) -> Result<(), RenderError> {
    draw_floor(area, scene, view)?;
    draw_overlay_lines(area, scene, view, false)?;
    draw_trails(area, scene, view, 1, 0.55)?;
    draw_shadows(area, scene, view, frame)?;
    draw_figures(area, scene, view, frame, false)?;
    draw_overlay_dots(area, scene, view, true, text_size)
}

/// What the top view marks besides the trails.
pub(crate) enum TopMarks<'f> {
    /// The pose, root and facing at this frame.
    Current(usize),
    /// Numbered markers (1, 2, …) with facing arrows at these frames.
    Numbered(&'f [usize]),
}

/// Top view: floor map, trails, overlays and the marks.
pub(crate) fn draw_top(
    area: &Area,
    scene: &Scene,
    view: &View,
    marks: TopMarks,
    text_size: f64,
) -> Result<(), RenderError> {
    draw_floor(area, scene, view)?;
    draw_metre_labels(area, scene, view, text_size * 0.85)?;
    draw_overlay_lines(area, scene, view, true)?;
    draw_trails(area, scene, view, 2, 0.35)?;
    let arrow_px = (ARROW_M * view.scale).max(14.0);
    let facing_arrow = |person: usize, frame: usize| -> Result<(), RenderError> {
        let pose = scene.pose(person, frame);
        let root = Vec3::new(pose[0].x, 0.0, pose[0].z);
        if let Some(f) = facing(pose) {
            let tip = root + f * arrow_px / view.scale;
            let head = (arrow_px * 0.35).clamp(5.0, 12.0);
            arrow(
                area,
                view.px(root),
                view.px(tip),
                person_colors(person).right,
                2,
                head,
            )?;
        }
        Ok(())
    };
    match marks {
        TopMarks::Current(frame) => {
            draw_figures(area, scene, view, frame, true)?;
            for person in 0..scene.people() {
                facing_arrow(person, frame)?;
                let root = scene.pose(person, frame)[0];
                disc(
                    area,
                    view.px(Vec3::new(root.x, 0.0, root.z)),
                    4,
                    person_colors(person).right,
                )?;
            }
        }
        TopMarks::Numbered(frames) => {
            for person in 0..scene.people() {
                for &frame in frames.iter() {
                    facing_arrow(person, frame)?;
                }
                for (k, &frame) in frames.iter().enumerate() {
                    let root = scene.pose(person, frame)[0];
                    let at = view.px(Vec3::new(root.x, 0.0, root.z));
                    draw_marker(
                        area,
                        at,
                        k + 1,
                        person_colors(person).centre,
                        text_size * 0.8,
                    )?;
                }
            }
        }
    }
    draw_overlay_dots(area, scene, view, false, text_size)
}

/// A panel's name in its top-left corner.
pub(crate) fn draw_caption(
    area: &Area,
    rect: Rect,
    caption: &str,
    size: f64,
) -> Result<(), RenderError> {
    text(
        area,
        caption,
        (rect.x as i32 + 4, rect.y as i32 + 2),
        size,
        SUBTLE,
        TOP_LEFT,
    )
}
