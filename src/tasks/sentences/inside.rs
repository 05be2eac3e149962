//! Whether a motion stays inside the real envelope, measured directly and apart from the
//! plausibility report, so the bench can check the report: torso acceleration, the floor,
//! a rigid pelvis, people apart.

use crate::motion::Motion;
use crate::skeleton::rest_pose;

/// The largest pelvis/chest/head acceleration of real mocap at 20 fps is 0.074–0.079
/// m/frame² (12,305 Bandai frames, issue 48); issue 50's bar for seams is 0.08.
pub const TORSO_ACCEL_LIMIT: f32 = 0.08;
/// Floor penetration beyond 2 cm (issue 48).
pub const FLOOR_LIMIT: f32 = -0.02;
/// Hip width may differ from the skeleton's by this share (real clips: 0.17–0.21 m).
pub const HIP_WIDTH_TOLERANCE: f32 = 0.15;
/// Two pelvises closer than this (horizontally) are inside each other.
pub const PELVIS_APART: f32 = 0.25;

const TORSO: [usize; 3] = [0, 9, 15];

/// The measured figures.
#[derive(Clone, Debug, PartialEq)]
pub struct Inside {
    /// Largest acceleration of pelvis, chest (spine3) or head, m/frame².
    pub torso_accel: f32,
    /// Lowest joint height, m.
    pub lowest: f32,
    /// Smallest and largest hip width as a share of the skeleton's.
    pub hip_width: (f32, f32),
    /// Smallest horizontal distance between two people's pelvises (none for one person).
    pub closest: Option<f32>,
}

impl Inside {
    /// Measures every person.
    pub fn measure(people: &[Motion]) -> Self {
        let rest = rest_pose();
        let rest_width = rest[1].distance(rest[2]);
        let mut torso_accel = 0.0f32;
        let mut lowest = f32::INFINITY;
        let mut hip_width = (f32::INFINITY, 0.0f32);
        for m in people {
            for w in m.frames.windows(3) {
                for &j in &TORSO {
                    let a = (w[2][j] - 2.0 * w[1][j] + w[0][j]).length();
                    torso_accel = torso_accel.max(if a.is_finite() { a } else { f32::INFINITY });
                }
            }
            for pose in &m.frames {
                for p in pose {
                    lowest = lowest.min(if p.y.is_finite() {
                        p.y
                    } else {
                        f32::NEG_INFINITY
                    });
                }
                let r = pose[1].distance(pose[2]) / rest_width;
                hip_width = (hip_width.0.min(r), hip_width.1.max(r));
            }
        }
        let mut closest: Option<f32> = None;
        for (a, ma) in people.iter().enumerate() {
            for mb in &people[a + 1..] {
                for (pa, pb) in ma.frames.iter().zip(&mb.frames) {
                    let d = (pa[0] - pb[0]).with_y(0.0).length();
                    closest = Some(closest.map_or(d, |c| c.min(d)));
                }
            }
        }
        Inside {
            torso_accel,
            lowest,
            hip_width,
            closest,
        }
    }

    /// What is outside, in words; empty when inside.
    pub fn outside(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.torso_accel.is_nan() || self.torso_accel > TORSO_ACCEL_LIMIT {
            out.push(format!(
                "torso acceleration {:.3} m/frame² (> {TORSO_ACCEL_LIMIT})",
                self.torso_accel
            ));
        }
        if self.lowest.is_nan() || self.lowest < FLOOR_LIMIT {
            out.push(format!(
                "a joint {:.1} cm under the floor",
                -100.0 * self.lowest
            ));
        }
        let (lo, hi) = self.hip_width;
        if !(lo >= 1.0 - HIP_WIDTH_TOLERANCE && hi <= 1.0 + HIP_WIDTH_TOLERANCE) {
            out.push(format!("hip width {lo:.2}–{hi:.2} of the skeleton's"));
        }
        if let Some(c) = self.closest
            && (c.is_nan() || c < PELVIS_APART)
        {
            out.push(format!("pelvises {c:.2} m apart (< {PELVIS_APART})"));
        }
        out
    }

    /// Inside the envelope on every count.
    pub fn ok(&self) -> bool {
        self.outside().is_empty()
    }
}
