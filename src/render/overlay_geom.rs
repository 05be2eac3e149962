//! Overlay geometry as drawable 3-D pieces: every [`Overlay`] becomes line segments,
//! labelled dots and flat quadrilaterals in world coordinates, with unbounded planes clipped to the scene's floor
//! rectangle and height range. Both views project these same pieces.

use super::options::Overlay;
use glam::{Vec2, Vec3};

/// A drawable piece of an overlay, in world coordinates.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Prim {
    /// A line segment.
    Line(Vec3, Vec3),
    /// A marked point with an optional label.
    Dot(Vec3, Option<String>),
    /// A flat quadrilateral (a clipped plane), corners in order around its edge.
    Quad([Vec3; 4]),
}

impl Prim {
    /// Every corner or end point (what a camera must keep in view).
    pub fn points(&self) -> Vec<Vec3> {
        match self {
            Prim::Line(a, b) => vec![*a, *b],
            Prim::Dot(p, _) => vec![*p],
            Prim::Quad(q) => q.to_vec(),
        }
    }
}

/// Turns overlays (already validated) into lines and dots inside the given floor
/// rectangle `(x, z)` and height range.
pub(crate) fn overlay_prims(
    overlays: &[Overlay],
    floor_lo: Vec2,
    floor_hi: Vec2,
    y_lo: f32,
    y_hi: f32,
) -> Vec<Prim> {
    let mut out = Vec::new();
    for o in overlays {
        match o {
            Overlay::Point { at, label } => out.push(Prim::Dot(*at, label.clone())),
            Overlay::Segment { from, to } => out.push(Prim::Line(*from, *to)),
            Overlay::VerticalPlane { point, normal } => {
                let along = Vec2::new(-normal.z, normal.x).normalize();
                let base = Vec2::new(point.x, point.z);
                if let Some((a, b)) = clip_line(base, along, floor_lo, floor_hi) {
                    let at = |p: Vec2, y: f32| Vec3::new(p.x, y, p.y);
                    out.push(Prim::Quad([
                        at(a, y_lo),
                        at(b, y_lo),
                        at(b, y_hi),
                        at(a, y_hi),
                    ]));
                }
            }
            Overlay::HorizontalPlane { height } => {
                let at = |x: f32, z: f32| Vec3::new(x, *height, z);
                let (l, h) = (floor_lo, floor_hi);
                out.push(Prim::Quad([
                    at(l.x, l.y),
                    at(h.x, l.y),
                    at(h.x, h.y),
                    at(l.x, h.y),
                ]));
            }
            Overlay::Box { min, max } => {
                let corner = |i: usize| {
                    Vec3::new(
                        if i & 1 == 0 { min.x } else { max.x },
                        if i & 2 == 0 { min.y } else { max.y },
                        if i & 4 == 0 { min.z } else { max.z },
                    )
                };
                // The 12 edges join corners whose indices differ in exactly one bit.
                for i in 0..8 {
                    for bit in [1, 2, 4] {
                        if i & bit == 0 {
                            out.push(Prim::Line(corner(i), corner(i | bit)));
                        }
                    }
                }
            }
        }
    }
    out
}

/// Part of the infinite line `base + s·dir` inside the rectangle (Liang–Barsky).
fn clip_line(base: Vec2, dir: Vec2, lo: Vec2, hi: Vec2) -> Option<(Vec2, Vec2)> {
    let (mut t0, mut t1) = (f32::NEG_INFINITY, f32::INFINITY);
    for (p, d, l, h) in [(base.x, dir.x, lo.x, hi.x), (base.y, dir.y, lo.y, hi.y)] {
        if d.abs() < 1e-9 {
            if p < l || p > h {
                return None;
            }
        } else {
            let (a, b) = ((l - p) / d, (h - p) / d);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
    }
    (t0 <= t1).then(|| (base + dir * t0, base + dir * t1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wall_is_clipped_to_the_floor_rectangle() {
        let wall = Overlay::VerticalPlane {
            point: Vec3::new(0.0, 0.0, 2.0),
            normal: Vec3::Z,
        };
        let prims = overlay_prims(&[wall], Vec2::new(-1.0, 0.0), Vec2::new(3.0, 5.0), 0.0, 2.0);
        assert_eq!(prims.len(), 1);
        // The bottom edge runs along x at z = 2 across the whole floor width.
        let Prim::Quad([a, b, c, _]) = &prims[0] else {
            panic!("expected a quad")
        };
        assert_eq!(c.y, 2.0);
        let (xa, xb) = (a.x.min(b.x), a.x.max(b.x));
        assert!(
            (xa + 1.0).abs() < 1e-5 && (xb - 3.0).abs() < 1e-5,
            "{a} {b}"
        );
        assert!((a.z - 2.0).abs() < 1e-5 && (b.z - 2.0).abs() < 1e-5);
        assert_eq!((a.y, b.y), (0.0, 0.0));
    }

    #[test]
    fn diagonal_wall_and_box_edges() {
        let d = clip_line(
            Vec2::ZERO,
            Vec2::new(1.0, 1.0).normalize(),
            Vec2::splat(-1.0),
            Vec2::new(2.0, 0.5),
        );
        let (a, b) = d.unwrap();
        assert!((a - Vec2::splat(-1.0)).length() < 1e-5 && (b - Vec2::splat(0.5)).length() < 1e-5);
        assert!(clip_line(Vec2::new(5.0, 0.0), Vec2::Y, Vec2::ZERO, Vec2::ONE).is_none());
        let bx = Overlay::Box {
            min: Vec3::ZERO,
            max: Vec3::ONE,
        };
        let prims = overlay_prims(&[bx], Vec2::ZERO, Vec2::ONE, 0.0, 1.0);
        assert_eq!(prims.len(), 12);
        for p in prims {
            let Prim::Line(a, b) = p else {
                panic!("expected a line")
            };
            assert!(((a - b).length() - 1.0).abs() < 1e-6);
        }
    }
}
