//! Fixed orthographic cameras: the side (three-quarter) view and the top view, each fitted
//! once to a set of world points and a pixel rectangle, mapping world positions (metres,
//! Y up) to pixel positions (x right, y down) plus a depth for painter's ordering.

use glam::Vec3;

/// How far the side camera turns from a pure profile towards the person's front.
const THREE_QUARTER_DEG: f32 = 30.0;
/// How far the side camera looks down, so the floor grid reads as a floor.
const PITCH_DEG: f32 = 20.0;

/// A pixel rectangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Rect {
    /// Left edge.
    pub x: f32,
    /// Top edge.
    pub y: f32,
    /// Width.
    pub w: f32,
    /// Height.
    pub h: f32,
}

/// Orthonormal camera axes: screen right, screen up, and the viewing direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Basis {
    /// World direction that points right on screen.
    pub right: Vec3,
    /// World direction that points up on screen.
    pub up: Vec3,
    /// Viewing direction (away from the camera): larger depth is farther.
    pub forward: Vec3,
}

impl Basis {
    /// Three-quarter side view for heading `yaw`: at yaw 0 the camera stands at the right
    /// front of someone facing +Z, so +Z runs rightwards and slightly towards the viewer.
    pub fn side(yaw: f32) -> Basis {
        let (t, p) = (THREE_QUARTER_DEG.to_radians(), PITCH_DEG.to_radians());
        // At yaw 0 the camera looks along +X (from the person's right side), turned by t
        // towards their front (+Z) and tilted down by p; then the whole rig turns by yaw.
        let d0 = Vec3::new(p.cos() * t.cos(), -p.sin(), -p.cos() * t.sin());
        let forward = glam::Quat::from_rotation_y(yaw) * d0;
        let right = forward.cross(Vec3::Y).normalize();
        let up = right.cross(forward);
        Basis { right, up, forward }
    }

    /// Top view seen from above, its screen-right the world axis (±X or ±Z) closest to
    /// `side`'s screen-right, so both views show travel in the same direction.
    pub fn top(side: &Basis) -> Basis {
        let candidates = [Vec3::X, Vec3::NEG_X, Vec3::Z, Vec3::NEG_Z];
        let right = candidates
            .into_iter()
            .max_by(|a, b| a.dot(side.right).total_cmp(&b.dot(side.right)))
            .unwrap_or(Vec3::Z);
        let forward = Vec3::NEG_Y;
        Basis {
            right,
            up: right.cross(forward),
            forward,
        }
    }
}

/// A basis fitted to a pixel rectangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct View {
    /// Camera axes.
    pub basis: Basis,
    /// Pixels per metre.
    pub scale: f32,
    ox: f32,
    oy: f32,
}

impl View {
    /// Fits `points` into `rect` minus `margin` pixels on every side, same scale on both
    /// axes, centred.
    pub fn fit(basis: Basis, points: &[Vec3], rect: Rect, margin: f32) -> View {
        let (mut u0, mut u1, mut v0, mut v1) = (f32::MAX, f32::MIN, f32::MAX, f32::MIN);
        for p in points {
            let (u, v) = (p.dot(basis.right), p.dot(basis.up));
            (u0, u1, v0, v1) = (u0.min(u), u1.max(u), v0.min(v), v1.max(v));
        }
        if points.is_empty() {
            (u0, u1, v0, v1) = (-1.0, 1.0, -1.0, 1.0);
        }
        let avail_w = (rect.w - 2.0 * margin).max(1.0);
        let avail_h = (rect.h - 2.0 * margin).max(1.0);
        let scale = (avail_w / (u1 - u0).max(1e-3)).min(avail_h / (v1 - v0).max(1e-3));
        View {
            basis,
            scale,
            ox: rect.x + rect.w / 2.0 - scale * (u0 + u1) / 2.0,
            oy: rect.y + rect.h / 2.0 + scale * (v0 + v1) / 2.0,
        }
    }

    /// Pixel position of a world point (sub-pixel).
    pub fn pxf(&self, p: Vec3) -> (f32, f32) {
        (
            self.ox + self.scale * p.dot(self.basis.right),
            self.oy - self.scale * p.dot(self.basis.up),
        )
    }

    /// Pixel position of a world point.
    pub fn px(&self, p: Vec3) -> (i32, i32) {
        let (x, y) = self.pxf(p);
        (x.round() as i32, y.round() as i32)
    }

    /// Distance along the viewing direction (larger is farther from the camera).
    pub fn depth(&self, p: Vec3) -> f32 {
        p.dot(self.basis.forward)
    }
}

/// The 8 corners of the box `[lo, hi]`.
pub(crate) fn box_corners(lo: Vec3, hi: Vec3) -> [Vec3; 8] {
    std::array::from_fn(|i| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect() -> Rect {
        Rect {
            x: 10.0,
            y: 20.0,
            w: 200.0,
            h: 100.0,
        }
    }

    #[test]
    fn side_view_is_upright_and_walks_right() {
        let b = Basis::side(0.0);
        let v = View::fit(
            b,
            &box_corners(Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 2.0, 4.0)),
            rect(),
            5.0,
        );
        // Up is up on screen (smaller pixel y) and +Z goes right.
        assert!(v.pxf(Vec3::Y).1 < v.pxf(Vec3::ZERO).1);
        assert!(v.pxf(Vec3::Z).0 > v.pxf(Vec3::ZERO).0);
        // The camera is on the person's right (−X) and front (+Z): those are nearer.
        assert!(v.depth(Vec3::NEG_X) < v.depth(Vec3::X));
        assert!(v.depth(Vec3::Z) < v.depth(Vec3::NEG_Z));
        // Seen from the front-right, the person's left (+X) is right of their right on
        // screen, as when facing someone.
        assert!(v.pxf(Vec3::X).0 > v.pxf(Vec3::NEG_X).0);
        // A right-handed, non-mirrored basis.
        assert!((b.right.cross(b.up) - (-b.forward)).length() < 1e-5);
    }

    #[test]
    fn top_view_is_seen_from_above_not_mirrored() {
        let t = Basis::top(&Basis::side(0.0));
        assert_eq!(t.right, Vec3::Z);
        // Facing +Z (right on screen), the person's left (+X) is up on screen.
        assert_eq!(t.up, Vec3::X);
        let turned = Basis::top(&Basis::side(std::f32::consts::FRAC_PI_2));
        assert_eq!(turned.right, Vec3::X);
        assert!((turned.right.cross(turned.up) - Vec3::Y).length() < 1e-6);
    }

    #[test]
    fn fit_keeps_points_inside_and_centred() {
        let pts = box_corners(Vec3::new(-3.0, 0.0, 0.0), Vec3::new(5.0, 1.8, 10.0));
        for b in [Basis::side(0.3), Basis::top(&Basis::side(0.3))] {
            let v = View::fit(b, &pts, rect(), 5.0);
            for p in pts {
                let (x, y) = v.pxf(p);
                assert!(
                    (14.9..=205.1).contains(&x) && (24.9..=115.1).contains(&y),
                    "{x} {y}"
                );
            }
        }
    }
}
