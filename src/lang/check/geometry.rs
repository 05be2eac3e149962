//! Geometry a program names with constants, collected while checking so that pictures
//! and the viewer can draw it: the wall of `distToPlane(r_hand, [0, 0, 2], [0, 0, 1])`,
//! the target of `dist(l_hand, [0.5, 1.2, 0.3])`, the region of `inSquare(…)`.
//!
//! Only library calls whose geometry arguments fold to constants are drawn; anything that
//! moves with the motion (a hand's distance to the other hand) is not geometry.
//!
//! A joint's coordinate bounded by a constant (`head.y < 0.8 m`, `j.x < 1 m`) is a plane
//! too: horizontal for `.y`, a wall across the axis for `.x` and `.z`, when it holds on
//! every frame. Bounds at some times only (`at mid { head.y < 0.5 m }`), under an `if`, or
//! inside `or` / `not` are left out: they hold only somewhere, and a plane drawn across
//! the whole scene and clip would say otherwise.

use super::Checker;
use super::values::{Cx, Env, Formula, Val};
use crate::lang::ir::{NodeId, Op};
use crate::lang::syntax::ast::{BinOp, Expr};
use crate::scene::JointOf;
use crate::scene::Overlay;
use glam::Vec3;

/// Half-length of the segment drawn for an infinite line (m).
const LINE_HALF_LENGTH: f32 = 5.0;

impl<'a> Checker<'a> {
    /// Records the overlay of a call to library function `name`, if it has one.
    pub(super) fn note_geometry(&mut self, name: &str, args: &'a [Expr], env: &Env<'a>, cx: &Cx) {
        if name == "contact" {
            self.note_contact(args, env, cx);
            return;
        }
        let wanted: &[usize] = match name {
            "distToPlane" | "signedDistToPlane" | "distToLine" | "distToSegment" | "inBox"
            | "inSquare" => &[1, 2],
            "dist" | "distToPoint" | "groundDist" => &[1],
            _ => return,
        };
        if args.len() <= wanted.iter().copied().max().unwrap_or(0) {
            return;
        }
        // Elaborated again when the call is inlined; problems are reported there, once.
        let before = self.diags.len();
        let consts: Option<Vec<Vec<f32>>> = wanted
            .iter()
            .map(|&i| match self.expr(&args[i], env, cx) {
                Val::Num(n) => self.b.const_of(n.node).map(<[f32]>::to_vec),
                _ => None,
            })
            .collect();
        self.diags.truncate(before);
        let Some(c) = consts else { return };
        if let Some(o) = overlay(name, &c)
            && !self.overlays.contains(&o)
        {
            self.overlays.push(o);
        }
    }
}

impl<'a> Checker<'a> {
    /// Records the planes of a constraint's constant bounds on joint coordinates, if it
    /// holds on every frame (`conditional`: it sits under an `if`).
    pub(super) fn note_bounds(&mut self, f: &Formula, conditional: bool, cx: &Cx) {
        // Domain 0 is every frame (the builder registers it first).
        if conditional || cx.domain != 0 {
            return;
        }
        match f {
            Formula::And(x, y) => {
                self.note_bounds(x, false, cx);
                self.note_bounds(y, false, cx);
            }
            Formula::Cmp {
                op: BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge,
                a,
                b,
                ..
            } => {
                let bound = self
                    .joint_axis(*a)
                    .zip(self.scalar_const(*b))
                    .or_else(|| self.joint_axis(*b).zip(self.scalar_const(*a)));
                if let Some((axis, value)) = bound
                    && let Some(o) = bound_plane(axis, value)
                    && !self.overlays.contains(&o)
                {
                    self.overlays.push(o);
                }
            }
            _ => {}
        }
    }

    /// The axis when `node` is one coordinate of joint positions.
    fn joint_axis(&self, node: NodeId) -> Option<usize> {
        match &self.b.nodes[node].op {
            Op::Component { arg, axis } => matches!(
                self.b.nodes[*arg].op,
                Op::Gather { .. } | Op::MassCenter { .. }
            )
            .then_some(*axis),
            _ => None,
        }
    }

    fn scalar_const(&self, node: NodeId) -> Option<f32> {
        self.b.const_of(node).and_then(scalar)
    }
}

/// The plane `coordinate[axis] = value`; none for the floor itself.
fn bound_plane(axis: usize, value: f32) -> Option<Overlay> {
    if !value.is_finite() {
        return None;
    }
    match axis {
        1 if value.abs() > 1e-3 => Some(Overlay::HorizontalPlane { height: value }),
        0 => Some(Overlay::VerticalPlane {
            point: Vec3::new(value, 0.0, 0.0),
            normal: Vec3::X,
        }),
        2 => Some(Overlay::VerticalPlane {
            point: Vec3::new(0.0, 0.0, value),
            normal: Vec3::Z,
        }),
        _ => None,
    }
}

impl<'a> Checker<'a> {
    /// Records `contact(p.joint, q.joint, d)` between two fixed joints, with its frames.
    fn note_contact(&mut self, args: &'a [Expr], env: &Env<'a>, cx: &Cx) {
        if args.len() < 2 {
            return;
        }
        let before = self.diags.len();
        let ends: Option<Vec<JointOf>> = args[..2]
            .iter()
            .map(|a| match self.expr(a, env, cx) {
                Val::Joint { person, joint } if joint.is_one() => {
                    let person = match person {
                        None => 0,
                        Some(p) if p.is_one() => p.get(0),
                        Some(_) => return None,
                    };
                    Some(JointOf {
                        person,
                        joint: joint.get(0),
                    })
                }
                _ => None,
            })
            .collect();
        self.diags.truncate(before);
        if let Some([a, b]) = ends.as_deref() {
            let c = (*a, *b, cx.domain);
            if !self.contacts.contains(&c) {
                self.contacts.push(c);
            }
        }
    }
}

fn vec3(v: &[f32]) -> Option<Vec3> {
    (v.len() == 3).then(|| Vec3::new(v[0], v[1], v[2]))
}

fn scalar(v: &[f32]) -> Option<f32> {
    (v.len() == 1).then(|| v[0])
}

/// The overlay of `name` called with constant geometry arguments `c`.
fn overlay(name: &str, c: &[Vec<f32>]) -> Option<Overlay> {
    match name {
        "distToPlane" | "signedDistToPlane" => {
            let (point, normal) = (vec3(&c[0])?, vec3(&c[1])?);
            let horizontal = Vec3::new(normal.x, 0.0, normal.z).length();
            if horizontal < 1e-6 * normal.length() {
                Some(Overlay::HorizontalPlane { height: point.y })
            } else if normal.y.abs() < 1e-6 * normal.length() {
                Some(Overlay::VerticalPlane { point, normal })
            } else {
                None
            }
        }
        "distToLine" => {
            let (q, d) = (vec3(&c[0])?, vec3(&c[1])?.try_normalize()?);
            Some(Overlay::Segment {
                from: q - d * LINE_HALF_LENGTH,
                to: q + d * LINE_HALF_LENGTH,
            })
        }
        "distToSegment" => Some(Overlay::Segment {
            from: vec3(&c[0])?,
            to: vec3(&c[1])?,
        }),
        "inBox" => {
            let (a, b) = (vec3(&c[0])?, vec3(&c[1])?);
            Some(Overlay::Box {
                min: a.min(b),
                max: a.max(b),
            })
        }
        "inSquare" => {
            let (centre, half) = (vec3(&c[0])?, scalar(&c[1])?);
            let h = Vec3::new(half, 0.0, half);
            Some(Overlay::Box {
                min: Vec3::new(centre.x, 0.0, centre.z) - h,
                max: Vec3::new(centre.x, 0.0, centre.z) + h,
            })
        }
        "dist" | "distToPoint" => Some(Overlay::Point {
            at: vec3(&c[0])?,
            label: None,
        }),
        "groundDist" => {
            let at = vec3(&c[0])?;
            Some(Overlay::Point {
                at: Vec3::new(at.x, 0.0, at.z),
                label: None,
            })
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use crate::lang::compile;
    use crate::scene::Overlay;
    use glam::Vec3;

    fn overlays(body: &str) -> Vec<Overlay> {
        let p = compile(&format!("length 4s\n{body}\n"), "t.mprog", &[]).unwrap();
        p.overlays().to_vec()
    }

    #[test]
    fn constant_geometry_becomes_overlays() {
        assert_eq!(
            overlays("distToPlane(r_hand, [0, 0, 2], [0, 0, 1]) < 5 cm"),
            [Overlay::VerticalPlane {
                point: Vec3::new(0.0, 0.0, 2.0),
                normal: Vec3::Z
            }]
        );
        assert_eq!(
            overlays("signedDistToPlane(head, [0, 1.3, 0], [0, -1, 0]) > 0"),
            [Overlay::HorizontalPlane { height: 1.3 }]
        );
        assert_eq!(
            overlays("at end { dist(l_hand, [0.5, 1.2, 30 cm]) < 5 cm }"),
            [Overlay::Point {
                at: Vec3::new(0.5, 1.2, 0.3),
                label: None
            }]
        );
        assert_eq!(
            overlays("inSquare(pelvis, [0, 0, 0], 1 m)"),
            [Overlay::Box {
                min: Vec3::new(-1.0, 0.0, -1.0),
                max: Vec3::new(1.0, 0.0, 1.0)
            }]
        );
    }

    #[test]
    fn moving_geometry_and_repeats_are_left_out() {
        assert!(overlays("dist(l_hand, r_hand) < 5 cm").is_empty());
        assert!(overlays("distToPlane(r_hand, pelvis, [0, 0, 1]) < 5 cm").is_empty());
        let twice = overlays("dist(l_hand, [0, 1, 1]) < 5 cm\ndist(r_hand, [0, 1, 1]) < 5 cm");
        assert_eq!(twice.len(), 1);
    }

    #[test]
    fn constant_bounds_on_joint_coordinates_are_planes() {
        assert_eq!(
            overlays("head.y < 80 cm"),
            [Overlay::HorizontalPlane { height: 0.8 }]
        );
        assert_eq!(
            overlays("for j in joints { always { j.x < 1 m and j.z > -1 m } }"),
            [
                Overlay::VerticalPlane {
                    point: Vec3::new(1.0, 0.0, 0.0),
                    normal: Vec3::X
                },
                Overlay::VerticalPlane {
                    point: Vec3::new(0.0, 0.0, -1.0),
                    normal: Vec3::Z
                }
            ]
        );
        // Held only somewhere, only one of two, relative to the body, or the floor: no plane.
        assert!(overlays("if head.z > 2 m { head.y < 0.8 m }").is_empty());
        assert!(overlays("at 2s { head.y < 0.8 m }").is_empty());
        assert_eq!(overlays("always { head.y < 2 m }").len(), 1);
        assert!(overlays("head.y < 0.8 m or head.x > 1 m").is_empty());
        assert!(overlays("l_hand.y > head.y").is_empty());
        assert!(overlays("l_foot.y < 0 m").is_empty());
    }
}

#[cfg(test)]
mod program_tests {
    use crate::lang::compile;
    use crate::scene::Overlay;

    #[test]
    fn task_programs_draw_their_walls_and_regions() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/programs");
        let of = |file: &str| {
            let path = format!("{dir}/{file}");
            let src = std::fs::read_to_string(&path).unwrap();
            compile(&src, &path, &[]).unwrap().overlays().to_vec()
        };
        for entry in std::fs::read_dir(dir).unwrap() {
            let name = entry.unwrap().file_name().to_string_lossy().to_string();
            if name.ends_with(".mprog") {
                // Every program still compiles with the geometry pass.
                of(&name);
            }
        }
        assert!(
            of("geo1_hand_on_wall.mprog")
                .iter()
                .any(|o| matches!(o, Overlay::VerticalPlane { .. }))
        );
        let src = std::fs::read_to_string(format!("{dir}/ic_handshake.mprog")).unwrap();
        let handshake = compile(&src, "ic_handshake.mprog", &[]).unwrap();
        let c = handshake.contacts();
        assert_eq!(c.len(), 1, "{c:?}");
        assert_eq!(
            (c[0].a.person, c[0].a.joint, c[0].b.person, c[0].b.joint),
            (0, 21, 1, 21)
        );
        assert_eq!(c[0].frames, (40, 59));
        assert!(
            of("geo2_balance_beam.mprog")
                .iter()
                .any(|o| matches!(o, Overlay::Segment { .. }))
        );
        assert!(
            of("fig1_inside_square.mprog")
                .iter()
                .any(|o| matches!(o, Overlay::Box { .. }))
        );
        // HSI-3 keeps every joint inside -1 < x, z < 1: four walls.
        let walls = of("hsi3_square.mprog");
        assert_eq!(walls.len(), 4, "{walls:?}");
        assert!(
            walls
                .iter()
                .all(|o| matches!(o, Overlay::VerticalPlane { .. }))
        );
    }
}
