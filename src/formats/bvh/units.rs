//! Length units and up axis of a BVH source.
//!
//! In: the 22 retargeted joints of a few frames, in file units. Out: the factor that
//! turns file units into metres. Detection measures the body along its bones
//! (ankle–knee–hip–pelvis–spine–neck–head, about 1.35 m for an adult, whatever the
//! pose) and picks metres, centimetres or millimetres, whichever gives the most human
//! size. Inches are never guessed (too close to centimetres); ask for them explicitly.

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

/// Typical ankle-to-head bone-path length of an adult, metres.
const TYPICAL_BODY_PATH: f32 = 1.35;

/// Ankle-to-head length along the bones (left side), in the poses' units.
pub fn body_path_length(pose: &Pose) -> f32 {
    BODY_PATH
        .iter()
        .map(|&(a, b)| pose[a].distance(pose[b]))
        .sum()
}

/// Metres per file unit guessed from poses (median over the given frames).
pub fn detect_scale(poses: &[Pose]) -> f32 {
    let mut lengths: Vec<f32> = poses.iter().map(body_path_length).collect();
    lengths.sort_by(f32::total_cmp);
    let median = lengths.get(lengths.len() / 2).copied().unwrap_or(0.0);
    if median <= 0.0 {
        return 1.0;
    }
    [1.0f32, 0.01, 0.001]
        .into_iter()
        .min_by(|a, b| {
            let da = (median * a / TYPICAL_BODY_PATH).ln().abs();
            let db = (median * b / TYPICAL_BODY_PATH).ln().abs();
            da.total_cmp(&db)
        })
        .expect("three candidates")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::rest_pose;

    #[test]
    fn detects_metres_centimetres_millimetres() {
        let metres = rest_pose();
        let scaled = |s: f32| -> Vec<Pose> { vec![metres.map(|p| p * s)] };
        assert_eq!(detect_scale(&scaled(1.0)), 1.0);
        assert_eq!(detect_scale(&scaled(100.0)), 0.01);
        assert_eq!(detect_scale(&scaled(1000.0)), 0.001);
        // A child (0.6 scale) in centimetres is still centimetres.
        assert_eq!(detect_scale(&scaled(60.0)), 0.01);
    }

    #[test]
    fn z_up_maps_to_y_up() {
        assert_eq!(
            UpAxis::Z.to_y_up(Vec3::new(1.0, 2.0, 3.0)),
            Vec3::new(1.0, 3.0, -2.0)
        );
    }
}
