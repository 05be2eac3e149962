//! Length units and up axis of a BVH source.
//!
//! In: the 22 retargeted joints of a few frames, in file units. Out: the factor that
//! turns file units into metres, taken from the skeleton itself: the leg measured along
//! its bones (hip–knee–ankle, both sides, median over frames: bones are rigid, so any
//! pose gives it). When metres, centimetres or millimetres make that leg human
//! ([`HUMAN_LEG`]), that unit is kept, so real body sizes survive; otherwise (CMU's
//! 1/0.45-inch units, inches, arbitrary exporter scales) the leg is scaled to
//! [`TYPICAL_LEG`], an adult's.

use crate::motion::Pose;
use glam::Vec3;

/// How to read lengths in the file.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Units {
    /// Detect from the skeleton size.
    #[default]
    Auto,
    Metres,
    Centimetres,
    Millimetres,
    Inches,
    /// Multiply file lengths by this to get metres.
    Scale(f32),
}

impl Units {
    /// Metres per file unit; `None` for [`Units::Auto`].
    pub fn scale(self) -> Option<f32> {
        match self {
            Units::Auto => None,
            Units::Metres => Some(1.0),
            Units::Centimetres => Some(0.01),
            Units::Millimetres => Some(0.001),
            Units::Inches => Some(0.0254),
            Units::Scale(s) => Some(s),
        }
    }
}

/// Which file axis points up.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum UpAxis {
    /// Y up (BVH's usual convention and mprog's): no change.
    #[default]
    Y,
    /// Z up: rotated −90° about X, so that file +Z becomes +Y and file +Y becomes −Z.
    Z,
}

impl UpAxis {
    /// Converts a file-space point to Y up.
    pub fn to_y_up(self, p: Vec3) -> Vec3 {
        match self {
            UpAxis::Y => p,
            UpAxis::Z => Vec3::new(p.x, p.z, -p.y),
        }
    }
}

/// Bone path from the ankle to the head, as joint index pairs.
const BODY_PATH: [(usize, usize); 8] = [
    (7, 4),
    (4, 1),
    (1, 0),
    (0, 3),
    (3, 6),
    (6, 9),
    (9, 12),
    (12, 15),
];

/// Hip–knee–ankle length of HumanML3D's uniform skeleton (and of CMU's and HDM05's
/// actors to 3 %), metres.
pub const TYPICAL_LEG: f32 = 0.83;

/// Leg lengths (metres) accepted as a human's in a standard unit: a small child to a
/// very tall adult. Units differ by 100×, so only one can land here.
pub const HUMAN_LEG: std::ops::RangeInclusive<f32> = 0.4..=1.3;

/// How [`detect_scale`] chose its factor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ScaleFrom {
    /// A standard unit (1, 0.01 or 0.001 m) made the leg human.
    Unit,
    /// No standard unit did: the leg was scaled to [`TYPICAL_LEG`].
    LegLength,
}

/// Ankle-to-head length along the bones (left side), in the poses' units.
pub fn body_path_length(pose: &Pose) -> f32 {
    BODY_PATH
        .iter()
        .map(|&(a, b)| pose[a].distance(pose[b]))
        .sum()
}

/// Hip–knee–ankle length along the bones, mean of both legs, in the pose's units.
pub fn leg_length(pose: &Pose) -> f32 {
    let side = |hip: usize, knee: usize, ankle: usize| {
        pose[hip].distance(pose[knee]) + pose[knee].distance(pose[ankle])
    };
    0.5 * (side(1, 4, 7) + side(2, 5, 8))
}

/// Metres per file unit from the skeleton's leg (median over the given frames).
pub fn detect_scale(poses: &[Pose]) -> (f32, ScaleFrom) {
    let mut lengths: Vec<f32> = poses.iter().map(leg_length).collect();
    lengths.sort_by(f32::total_cmp);
    let median = lengths.get(lengths.len() / 2).copied().unwrap_or(0.0);
    if !(median.is_finite() && median > 0.0) {
        return (1.0, ScaleFrom::Unit);
    }
    match [1.0f32, 0.01, 0.001]
        .into_iter()
        .find(|unit| HUMAN_LEG.contains(&(median * unit)))
    {
        Some(unit) => (unit, ScaleFrom::Unit),
        None => (TYPICAL_LEG / median, ScaleFrom::LegLength),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::rest_pose;

    #[test]
    fn detects_metres_centimetres_millimetres() {
        let metres = rest_pose();
        let scaled = |s: f32| -> Vec<Pose> { vec![metres.map(|p| p * s)] };
        assert_eq!(detect_scale(&scaled(1.0)), (1.0, ScaleFrom::Unit));
        assert_eq!(detect_scale(&scaled(100.0)), (0.01, ScaleFrom::Unit));
        assert_eq!(detect_scale(&scaled(1000.0)), (0.001, ScaleFrom::Unit));
        // A child (0.6 scale) in centimetres is still centimetres.
        assert_eq!(detect_scale(&scaled(60.0)), (0.01, ScaleFrom::Unit));
    }

    #[test]
    fn other_units_take_the_scale_from_the_leg() {
        // CMU units (1/0.45 inch ≈ 5.64 cm): the rest leg 0.826 m is 14.6 units.
        let units = rest_pose().map(|p| p / 0.05644);
        let (scale, from) = detect_scale(&[units]);
        assert_eq!(from, ScaleFrom::LegLength);
        let leg = leg_length(&units) * scale;
        assert!((leg - TYPICAL_LEG).abs() < 1e-4, "{leg}");
        assert!((scale - 0.05644).abs() < 0.002, "{scale}");
    }

    #[test]
    fn z_up_maps_to_y_up() {
        assert_eq!(
            UpAxis::Z.to_y_up(Vec3::new(1.0, 2.0, 3.0)),
            Vec3::new(1.0, 3.0, -2.0)
        );
    }
}
