//! Colours and stroke sizes shared by the views: one colour family per person (dark shade
//! for the body's right side, light shade for its left, a middle shade for the spine and
//! head), neutral greys for floor, grid and shadows, magenta for overlays.

use crate::skeleton::{JOINT_NAMES, KINEMATIC_CHAINS};
use plotters::style::RGBColor;

/// Background.
pub(crate) const BACKGROUND: RGBColor = RGBColor(255, 255, 255);
/// Floor fill.
pub(crate) const FLOOR: RGBColor = RGBColor(242, 242, 238);
/// Floor grid lines (1 m).
pub(crate) const GRID: RGBColor = RGBColor(205, 205, 200);
/// Floor border.
pub(crate) const FLOOR_EDGE: RGBColor = RGBColor(160, 160, 155);
/// Body shadow on the floor.
pub(crate) const SHADOW: RGBColor = RGBColor(190, 190, 186);
/// Feet marks on the floor.
pub(crate) const FOOT: RGBColor = RGBColor(105, 105, 100);
/// Overlay geometry.
pub(crate) const OVERLAY: RGBColor = RGBColor(210, 0, 150);
/// Main text.
pub(crate) const TEXT: RGBColor = RGBColor(20, 20, 20);
/// Secondary text (panel names, ticks).
pub(crate) const SUBTLE: RGBColor = RGBColor(110, 110, 110);

/// The colours of one person.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PersonColors {
    /// Right arm and leg.
    pub right: RGBColor,
    /// Left arm and leg.
    pub left: RGBColor,
    /// Spine, head, root marker.
    pub centre: RGBColor,
}

/// Colour family of person `i` (cycles after five people).
pub(crate) fn person_colors(i: usize) -> PersonColors {
    const FAMILIES: [(RGBColor, RGBColor, RGBColor); 5] = [
        (
            RGBColor(20, 70, 170),
            RGBColor(110, 170, 250),
            RGBColor(45, 110, 210),
        ), // blue
        (
            RGBColor(170, 30, 30),
            RGBColor(250, 135, 115),
            RGBColor(215, 70, 60),
        ), // red
        (
            RGBColor(20, 115, 45),
            RGBColor(120, 210, 125),
            RGBColor(55, 160, 80),
        ), // green
        (
            RGBColor(105, 40, 150),
            RGBColor(195, 150, 235),
            RGBColor(150, 90, 200),
        ), // purple
        (
            RGBColor(175, 95, 0),
            RGBColor(250, 190, 90),
            RGBColor(220, 140, 30),
        ), // orange
    ];
    let (right, left, centre) = FAMILIES[i % FAMILIES.len()];
    PersonColors {
        right,
        left,
        centre,
    }
}

/// Which side of the body a kinematic chain belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Side {
    /// The person's left.
    Left,
    /// The person's right.
    Right,
    /// Spine and head.
    Centre,
}

/// Side of chain `c` of [`KINEMATIC_CHAINS`], read off its end joint's name.
pub(crate) fn chain_side(c: usize) -> Side {
    let end = JOINT_NAMES[*KINEMATIC_CHAINS[c].last().unwrap_or(&0)];
    if end.starts_with("left_") {
        Side::Left
    } else if end.starts_with("right_") {
        Side::Right
    } else {
        Side::Centre
    }
}

impl PersonColors {
    /// Colour of a body side.
    pub fn of(&self, side: Side) -> RGBColor {
        match side {
            Side::Left => self.left,
            Side::Right => self.right,
            Side::Centre => self.centre,
        }
    }
}

/// Bone stroke width for a view with `ppm` pixels per metre: about 2.5 cm, readable at
/// small sizes, never a blob at large ones.
pub(crate) fn bone_width(ppm: f32) -> u32 {
    (ppm * 0.025).clamp(2.0, 6.0).round() as u32
}

/// `c` mixed towards white by `t` in [0, 1].
pub(crate) fn fade(c: RGBColor, t: f32) -> RGBColor {
    let m = |v: u8| (f32::from(v) + (255.0 - f32::from(v)) * t.clamp(0.0, 1.0)).round() as u8;
    RGBColor(m(c.0), m(c.1), m(c.2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chain_sides_match_the_skeleton_table() {
        // t2m chains: right leg, left leg, spine, right arm, left arm.
        let sides: Vec<Side> = (0..KINEMATIC_CHAINS.len()).map(chain_side).collect();
        assert_eq!(
            sides,
            [
                Side::Right,
                Side::Left,
                Side::Centre,
                Side::Right,
                Side::Left
            ]
        );
    }

    #[test]
    fn sides_and_people_are_distinguishable() {
        for i in 0..5 {
            let c = person_colors(i);
            assert_ne!(c.left, c.right);
            assert_ne!(person_colors(i).right, person_colors(i + 1).right);
        }
        assert_eq!(person_colors(0), person_colors(5));
        assert_eq!(fade(RGBColor(0, 100, 255), 0.5), RGBColor(128, 178, 255));
    }
}
