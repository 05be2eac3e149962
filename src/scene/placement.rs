//! World placement of each person: a rigid motion of the horizontal plane (yaw about +Y,
//! then an XZ translation) applied to the joints the model generates in its canonical frame
//! (frame 0 at the origin, facing +Z).
//!
//! Defaults: one person stays put; two people get InterControl's placement (person B:
//! x → −x, z → −z + 2, i.e. facing each other 2 m apart); P > 2 people stand on a circle,
//! neighbours `spacing` metres apart, all facing its centre, person 0 at the origin facing
//! +Z (the two-person case is the same rule).

use glam::Vec3;

/// A yaw rotation about +Y (radians, turning +Z towards +X) followed by a translation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Rotation about +Y in radians; `R(yaw)·(0, 0, 1) = (sin yaw, 0, cos yaw)`.
    pub yaw: f32,
    /// Translation along X (metres).
    pub x: f32,
    /// Translation along Z (metres).
    pub z: f32,
}

/// Spacing of the default placements (metres between neighbours).
pub const DEFAULT_SPACING: f32 = 2.0;

fn snap(v: f64) -> f32 {
    if v.abs() < 1e-9 { 0.0 } else { v as f32 }
}

impl Placement {
    /// No rotation, no translation.
    pub const IDENTITY: Placement = Placement {
        yaw: 0.0,
        x: 0.0,
        z: 0.0,
    };

    /// `(cos yaw, sin yaw)`, computed in f64 with exact zeros (so a half turn is exactly
    /// x → −x, z → −z).
    pub fn cos_sin(&self) -> (f32, f32) {
        let (s, c) = (self.yaw as f64).sin_cos();
        (snap(c), snap(s))
    }

    /// Moves a point.
    pub fn apply(&self, p: Vec3) -> Vec3 {
        let (c, s) = self.cos_sin();
        Vec3::new(c * p.x + s * p.z + self.x, p.y, -s * p.x + c * p.z + self.z)
    }

    /// `self ∘ inner`: first `inner`, then `self`.
    pub fn compose(&self, inner: &Placement) -> Placement {
        let t = self.apply(Vec3::new(inner.x, 0.0, inner.z));
        Placement {
            yaw: self.yaw + inner.yaw,
            x: t.x,
            z: t.z,
        }
    }

    /// The default placement of `people` people `spacing` metres apart (see the module doc).
    pub fn defaults(people: usize, spacing: f32) -> Vec<Placement> {
        if people <= 1 {
            return vec![Placement::IDENTITY; people];
        }
        let p = people as f64;
        let r = spacing as f64 / (2.0 * (std::f64::consts::PI / p).sin());
        (0..people)
            .map(|i| {
                let a = 2.0 * std::f64::consts::PI * i as f64 / p;
                Placement {
                    yaw: a as f32,
                    x: snap(-r * a.sin()),
                    z: snap(r - r * a.cos()),
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_people_face_each_other_two_metres_apart() {
        let p = Placement::defaults(2, DEFAULT_SPACING);
        assert_eq!(p[0], Placement::IDENTITY);
        // InterControl: x → −x, z → −z + 2.
        let q = p[1].apply(Vec3::new(0.3, 1.0, 0.5));
        assert!((q - Vec3::new(-0.3, 1.0, 1.5)).length() < 1e-6, "{q}");
    }

    #[test]
    fn compose_applies_inner_first() {
        let a = Placement {
            yaw: 0.7,
            x: 1.0,
            z: -2.0,
        };
        let b = Placement {
            yaw: -0.3,
            x: 0.5,
            z: 0.25,
        };
        let p = Vec3::new(0.2, 1.1, -0.4);
        let d = a.compose(&b).apply(p) - a.apply(b.apply(p));
        assert!(d.length() < 1e-5, "{d}");
    }

    #[test]
    fn circle_neighbours_are_spaced_and_face_the_centre() {
        let p = Placement::defaults(5, 2.0);
        let pos: Vec<Vec3> = p.iter().map(|q| q.apply(Vec3::ZERO)).collect();
        for i in 0..5 {
            let d = (pos[i] - pos[(i + 1) % 5]).length();
            assert!((d - 2.0).abs() < 1e-5, "spacing {d}");
        }
        let centre = pos.iter().copied().sum::<Vec3>() / 5.0;
        for (q, at) in p.iter().zip(&pos) {
            let ahead = q.apply(Vec3::new(0.0, 0.0, 1.0)) - *at;
            let to_centre = (centre - *at).normalize();
            assert!(
                ahead.dot(to_centre) > 0.999,
                "person does not face the centre"
            );
        }
    }
}
