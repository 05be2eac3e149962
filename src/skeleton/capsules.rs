//! The body as capsules: segments between joints with a radius, for telling when two
//! people go through each other (the plausibility report flags it, `guide`'s late steps
//! keep it from happening), and the closest points of two segments.

use glam::Vec3;

/// A body capsule: a segment between two joints with a radius (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Capsule {
    /// Name in reports.
    pub name: &'static str,
    /// Its two joints.
    pub joints: [usize; 2],
    /// Radius (m).
    pub radius: f32,
}

/// The capsules compared between people. Forearms and hands are left out: programs ask
/// hands to touch other people.
pub const CAPSULES: [Capsule; 8] = [
    Capsule {
        name: "torso",
        joints: [0, 12],
        radius: 0.11,
    },
    Capsule {
        name: "head",
        joints: [12, 15],
        radius: 0.09,
    },
    Capsule {
        name: "left thigh",
        joints: [1, 4],
        radius: 0.07,
    },
    Capsule {
        name: "right thigh",
        joints: [2, 5],
        radius: 0.07,
    },
    Capsule {
        name: "left shin",
        joints: [4, 7],
        radius: 0.05,
    },
    Capsule {
        name: "right shin",
        joints: [5, 8],
        radius: 0.05,
    },
    Capsule {
        name: "left upper arm",
        joints: [16, 18],
        radius: 0.045,
    },
    Capsule {
        name: "right upper arm",
        joints: [17, 19],
        radius: 0.045,
    },
];

/// Closest distance between segments [p1, q1] and [p2, q2].
pub fn segment_distance(p1: Vec3, q1: Vec3, p2: Vec3, q2: Vec3) -> f32 {
    let (s, t) = segment_closest(p1, q1, p2, q2);
    ((p1 + (q1 - p1) * s) - (p2 + (q2 - p2) * t)).length()
}

/// Where segments [p1, q1] and [p2, q2] come closest: the fractions `(s, t)` along each.
pub fn segment_closest(p1: Vec3, q1: Vec3, p2: Vec3, q2: Vec3) -> (f32, f32) {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.dot(d1);
    let e = d2.dot(d2);
    let f = d2.dot(r);
    let eps = 1e-9;
    if a <= eps && e <= eps {
        (0.0, 0.0)
    } else if a <= eps {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(r);
        if e <= eps {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let mut s = if denom > eps {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    }
}
