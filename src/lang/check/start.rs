//! Start placements: `people a "…" at [x, 0, z] facing [dx, 0, dz]`, and `start at … facing …`
//! for a one-person program. Each becomes a [`StartOverride`] the solvers apply from frame 0
//! (through `Ir::start_placements`, the same path as `spacing`).

use super::Checker;
use super::units::Unit;
use super::values::{Cx, Val};
use crate::lang::codes::BAD_START;
use crate::lang::ir::StartOverride;
use crate::lang::syntax::ast::{Expr, Item, Module, Span, StartPlace};

/// Farthest a person may start from the origin (m): keeps placements and their pictures
/// in a sensible world.
const MAX_START: f64 = 100.0;
/// Closest two people may start (m), pelvis to pelvis: the `spacing` floor.
const MIN_APART: f64 = 0.4;

impl<'a> Checker<'a> {
    /// Reads every declared start into `header.starts`.
    pub(super) fn declare_starts(&mut self, module: &'a Module, cx: &Cx) {
        let mut places: Vec<(usize, &'a StartPlace)> = Vec::new();
        let mut first_line: Option<Span> = None;
        for item in &module.items {
            match item {
                Item::People { people, .. } => {
                    for p in people {
                        let Some(place) = &p.start else { continue };
                        if let Some(i) = self
                            .header
                            .people
                            .iter()
                            .position(|q| q.name == p.name.name)
                        {
                            places.push((i, place));
                        }
                    }
                }
                Item::Start { place, span } => {
                    if let Some(f) = first_line {
                        self.duplicate_header(cx, "start", *span, f);
                        continue;
                    }
                    first_line = Some(*span);
                    if self.multi {
                        self.error(
                            cx,
                            BAD_START,
                            *span,
                            "`start` places the one person, and this program has several",
                        )
                        .label("which person?")
                        .help(
                            "write the placement after each person instead: \
                             `people a \"…\" at [0, 0, 0], b \"…\" at [1, 0, 0]`",
                        );
                        continue;
                    }
                    places.push((0, place));
                }
                _ => {}
            }
        }
        if places.is_empty() {
            return;
        }
        let mut starts = vec![StartOverride::default(); self.header.people.len()];
        let mut spans = vec![None; starts.len()];
        for (person, place) in places {
            spans[person] = Some(place.span);
            if let Some(e) = &place.at {
                starts[person].at = self.start_point(e, cx);
            }
            if let Some(e) = &place.facing {
                starts[person].yaw = self.start_facing(e, cx);
            }
        }
        self.header.starts = starts;
        self.check_people_apart(&spans, cx);
    }

    /// A constant `[x, 0, z]` in metres, within [`MAX_START`] of the origin.
    fn start_point(&mut self, e: &'a Expr, cx: &Cx) -> Option<[f64; 2]> {
        let v = self.start_vector(
            e,
            cx,
            "`at` needs a point on the floor, `[x, 0, z]` in metres",
        )?;
        if v[1].abs() > 1e-6 {
            self.error(
                cx,
                BAD_START,
                e.span,
                format!("a start {} m above the floor", v[1]),
            )
            .label("y must be 0")
            .help("people start standing on the floor: write `[x, 0, z]`");
            return None;
        }
        if v[0].hypot(v[2]) > MAX_START {
            self.error(
                cx,
                BAD_START,
                e.span,
                format!("a start {:.1} m from the origin", v[0].hypot(v[2])),
            )
            .label("too far")
            .help(format!("start within {MAX_START} m of the origin"));
            return None;
        }
        Some([v[0], v[2]])
    }

    /// A constant horizontal direction, as a yaw (radians; 0 faces +Z).
    fn start_facing(&mut self, e: &'a Expr, cx: &Cx) -> Option<f64> {
        let v = self.start_vector(e, cx, "`facing` needs a horizontal direction `[dx, 0, dz]`")?;
        let horizontal = v[0].hypot(v[2]);
        if v[1].abs() > 1e-6 || horizontal < 1e-6 {
            self.error(
                cx,
                BAD_START,
                e.span,
                "a facing direction must be horizontal and not zero",
            )
            .label("not horizontal")
            .help("write `[dx, 0, dz]`, e.g. `facing [0, 0, -1]` to face −Z");
            return None;
        }
        Some(v[0].atan2(v[2]))
    }

    /// Elaborates `e` and reads it as a constant 3-vector (metres or unitless).
    fn start_vector(&mut self, e: &'a Expr, cx: &Cx, need: &str) -> Option<[f64; 3]> {
        let val = self.expr(e, &None, cx);
        let n = match val {
            Val::Error => return None,
            Val::Num(n) if n.vector && (n.unit == Unit::M || n.unit.free) => n,
            _ => {
                let what = match val {
                    Val::Num(n) if n.vector => format!("a vector in {}", n.unit),
                    Val::Num(n) => format!("a quantity in {}", n.unit),
                    _ => val.describe().to_string(),
                };
                self.error(cx, BAD_START, e.span, format!("{need}, not {what}"))
                    .label("here")
                    .help("write a constant vector such as `[1, 0, 2]`");
                return None;
            }
        };
        let Some(v) = self.b.const_of(n.node).map(|v| v.to_vec()) else {
            self.error(cx, BAD_START, e.span, "a start placement must be constant")
                .label("depends on the motion")
                .help("write fixed numbers (or `param`s) such as `[1, 0, 2]`");
            return None;
        };
        if v.len() != 3 || v.iter().any(|x| !x.is_finite()) {
            return None;
        }
        // Rounded to the millimetre: the constant is stored in f32.
        Some(std::array::from_fn(|i| {
            (f64::from(v[i]) * 1e3).round() / 1e3
        }))
    }

    /// Two people whose starts are closer than [`MIN_APART`] would begin inside each other.
    fn check_people_apart(&mut self, spans: &[Option<Span>], cx: &Cx) {
        let ir_like = crate::lang::ir::Ir {
            people: self.header.people.len(),
            spacing: self.header.spacing,
            starts: self.header.starts.clone(),
            ..Default::default()
        };
        let places = ir_like.start_placements();
        for j in 1..places.len() {
            for i in 0..j {
                let d = f64::from((places[i].x - places[j].x).hypot(places[i].z - places[j].z));
                if d < MIN_APART - 1e-6 {
                    let (a, b) = (&self.header.people[i].name, &self.header.people[j].name);
                    let msg = format!("`{a}` and `{b}` start {d:.2} m apart");
                    let span = spans[j].or(spans[i]).unwrap_or(Span::new(0, 0));
                    self.error(cx, BAD_START, span, msg)
                        .label("too close")
                        .help(format!(
                            "bodies overlap closer than {MIN_APART} m; move one of them with `at [x, 0, z]`"
                        ));
                    return;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::lang::compile;
    use crate::scene::Placement;
    use glam::Vec3;

    fn placements(src: &str) -> Vec<Placement> {
        compile(src, "t.mprog", &[]).expect("checks").placements()
    }

    #[test]
    fn people_start_where_and_facing_as_declared() {
        let p = placements(
            "length 4s\nparam gap = 1.5 m\n\
             people a \"a person walks forward\" at [-gap / 2, 0, 0] facing [0, 0, 1],\n\
             b \"a person walks forward\" at [gap / 2, 0, 0],\n\
             c \"a person waves\" at [0, 0, 3] facing [0, 0, -1]\n\
             always { separation(a, b, 0.5 m) }\n",
        );
        assert_eq!(p.len(), 3);
        assert_eq!((p[0].x, p[0].z, p[0].yaw), (-0.75, 0.0, 0.0));
        // `b` declares no facing: it keeps the default placement's (a circle's).
        assert_eq!((p[1].x, p[1].z), (0.75, 0.0));
        assert_eq!(p[1].yaw, Placement::defaults(3, 2.0)[1].yaw);
        // `c` faces −Z: the canonical forward +Z maps onto −Z.
        let fwd = p[2].apply(Vec3::Z) - p[2].apply(Vec3::ZERO);
        assert!((fwd - Vec3::NEG_Z).length() < 1e-6, "{fwd}");
        assert!((p[2].apply(Vec3::ZERO) - Vec3::new(0.0, 0.0, 3.0)).length() < 1e-6);
    }

    #[test]
    fn one_person_starts_with_the_start_line() {
        let p = placements(
            "prompt \"a person walks forward\"\nlength 4s\nstart at [1, 0, 2] facing [1, 0, 0]\n\
             at end { pelvis.x > 2 m }\n",
        );
        let fwd = p[0].apply(Vec3::Z) - p[0].apply(Vec3::ZERO);
        assert!((fwd - Vec3::X).length() < 1e-6, "{fwd}");
        assert_eq!((p[0].x, p[0].z), (1.0, 2.0));
    }

    #[test]
    fn a_start_changes_what_is_feasible_at_frame_zero() {
        // Without a start, a pelvis 1.5 m from the origin on frame 0 is impossible
        // (`mprog::never_met`); starting there, it is met by construction.
        let goal = "length 4s\nat start { groundDist(pelvis, [-1.5, 0, 0]) < 30 cm }\n";
        let far = crate::lang::check_source(goal, "t.mprog", &[]);
        assert!(far.items.iter().any(|d| d.code == "mprog::never_met"));
        let placed = format!("start at [-1.5, 0, 0]\n{goal}");
        let near = crate::lang::check_source(&placed, "t.mprog", &[]);
        assert!(
            !near.items.iter().any(|d| d.code == "mprog::never_met"),
            "{}",
            near.render_plain()
        );
    }
}
