//! Stick figures: every person's pose at one frame drawn through a camera as bones along
//! the kinematic chains (dark right side, light left side, mid-tone spine) and a head disc,
//! all people's pieces painted farthest first so nearer limbs cover farther ones.

use super::camera::View;
use super::draw::{Area, disc, line, ring};
use super::error::RenderError;
use super::scene::Scene;
use super::style::{PersonColors, bone_width, chain_side, person_colors};
use crate::motion::Pose;
use crate::skeleton::KINEMATIC_CHAINS;
use glam::Vec3;
use plotters::style::RGBColor;

/// Head joint and the neck below it.
const HEAD: usize = 15;
const NECK: usize = 12;
/// Head disc radius (metres) and how far its centre sits above the head joint.
const HEAD_RADIUS: f32 = 0.095;
const HEAD_LIFT: f32 = 0.03;

/// One paintable piece of a figure.
enum Piece {
    Bone(Vec3, Vec3, RGBColor),
    Head(Vec3, RGBColor),
}

impl Piece {
    fn depth(&self, view: &View) -> f32 {
        match self {
            Piece::Bone(a, b, _) => view.depth((*a + *b) * 0.5),
            Piece::Head(c, _) => view.depth(*c),
        }
    }
}

/// Pieces of one pose in one person's colours.
fn pieces(pose: &Pose, colors: &PersonColors, out: &mut Vec<Piece>) {
    for (c, chain) in KINEMATIC_CHAINS.iter().enumerate() {
        let color = colors.of(chain_side(c));
        for w in chain.windows(2) {
            out.push(Piece::Bone(pose[w[0]], pose[w[1]], color));
        }
    }
    let up = (pose[HEAD] - pose[NECK]).normalize_or_zero();
    out.push(Piece::Head(pose[HEAD] + up * HEAD_LIFT, colors.centre));
}

/// Draws all people at `frame`. `from_above` (top view) outlines the head so it does not
/// hide the shoulders, and uses hairlines when the map is small.
pub(crate) fn draw_figures(
    area: &Area,
    scene: &Scene,
    view: &View,
    frame: usize,
    from_above: bool,
) -> Result<(), RenderError> {
    let mut all = Vec::new();
    for person in 0..scene.people() {
        pieces(scene.pose(person, frame), &person_colors(person), &mut all);
    }
    draw_pieces(area, view, all, from_above)
}

fn draw_pieces(
    area: &Area,
    view: &View,
    mut all: Vec<Piece>,
    from_above: bool,
) -> Result<(), RenderError> {
    // Painter's algorithm: farthest first.
    all.sort_by(|a, b| b.depth(view).total_cmp(&a.depth(view)));
    let width = if from_above && view.scale < 80.0 {
        1
    } else {
        bone_width(view.scale)
    };
    let r = ((HEAD_RADIUS * view.scale).round() as i32).max(3);
    for piece in all {
        match piece {
            Piece::Bone(a, b, color) => line(area, view.px(a), view.px(b), color, width)?,
            Piece::Head(c, color) if from_above => ring(area, view.px(c), r, color, width.min(2))?,
            Piece::Head(c, color) => disc(area, view.px(c), r, color)?,
        }
    }
    Ok(())
}
