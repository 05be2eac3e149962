//! Function calls: user and library functions are inlined with call-by-name arguments
//! (each argument is re-elaborated where the body uses it, so `x@0` and `vel(x)` inside a
//! function read the caller's expression at other frames); built-ins become IR ops.

use super::Checker;
use super::builtins::{self, BuiltinDoc};
use super::units::Unit;
use super::values::*;
use crate::lang::diag::did_you_mean;
use crate::lang::ir::{BinaryOp, Domain, Shift, UnaryOp};
use crate::lang::syntax::ast::*;
use crate::skeleton::{FPS, PARENTS, joint_mass_weights};
use std::rc::Rc;

/// How far (degrees) the neck→head bone leans forward of the head's up when the head is
/// level: HumanML3D's head joint sits ahead of the neck. From clip 012314's upright frames
/// (20–30°); `gaze` raises its direction by this much.
pub const NEUTRAL_HEAD_PITCH: f64 = 25.0;

/// Deepest nesting of function calls (inlining) allowed.
pub const MAX_CALL_DEPTH: usize = 32;

impl<'a> Checker<'a> {
    /// Elaborates `name(args)`.
    pub fn call(
        &mut self,
        name: &'a Ident,
        args: &'a [Expr],
        span: Span,
        env: &Env<'a>,
        cx: &Cx,
    ) -> Val {
        let n = name.name.as_str();
        if let Some(&f) = self.user_fns.get(n) {
            return self.inline(f, args, span, env, cx, cx.site);
        }
        if let Some(b) = builtins::find(n) {
            if args.len() < b.min_args || args.len() > b.max_args {
                self.arity_error(n, b.signature, args.len(), span, cx);
                return Val::Error;
            }
            return self.builtin(b, args, span, env, cx);
        }
        if let Some(&f) = self.lib_fns.get(n) {
            self.note_geometry(n, args, env, cx);
            return self.inline(f, args, span, env, cx, cx.site.or(Some(span)));
        }
        if self.poisoned.contains(n) {
            return Val::Error;
        }
        let mut candidates: Vec<&str> = builtins::BUILTINS.iter().map(|b| b.name).collect();
        candidates.extend(self.lib_fns.keys().copied());
        candidates.extend(self.user_fns.keys().copied());
        let help = match did_you_mean(n, candidates.iter().copied()) {
            Some(s) => format!("did you mean `{s}`?"),
            None => "define it with `def name(a, b) = …`; library functions include distToPoint, \
                     midPoint, distToPlane, vel, massCtr (see `mprog docs`)"
                .to_string(),
        };
        self.error(
            cx,
            crate::lang::codes::UNKNOWN_FUNCTION,
            name.span,
            format!("unknown function `{n}`"),
        )
        .label("not defined")
        .help(help);
        Val::Error
    }

    fn arity_error(&mut self, n: &str, signature: &str, got: usize, span: Span, cx: &Cx) {
        self.error(
            cx,
            crate::lang::codes::ARITY,
            span,
            format!(
                "`{n}` called with {got} argument{}",
                if got == 1 { "" } else { "s" }
            ),
        )
        .label("wrong number of arguments")
        .help(format!("it is `{signature}`"));
    }

    fn inline(
        &mut self,
        f: &'a FnDef,
        args: &'a [Expr],
        span: Span,
        env: &Env<'a>,
        cx: &Cx,
        site: Option<Span>,
    ) -> Val {
        let n = f.name.name.as_str();
        if f.params.len() != args.len() {
            let params: Vec<&str> = f.params.iter().map(|p| p.name.as_str()).collect();
            self.arity_error(
                n,
                &format!("{n}({})", params.join(", ")),
                args.len(),
                span,
                cx,
            );
            return Val::Error;
        }
        if cx.depth >= MAX_CALL_DEPTH {
            self.error(
                cx,
                crate::lang::codes::TOO_DEEP,
                span,
                format!("function calls nested more than {MAX_CALL_DEPTH} deep"),
            )
            .label("too deep")
            .help("simplify the chain of functions calling functions");
            return Val::Error;
        }
        // A user function sees the top-level `let`s declared above it; a library one
        // sees only its arguments and the library.
        let mut fenv: Env<'a> = match (self.user_fns.get(n), self.fn_envs.get(n)) {
            (Some(g), Some(env)) if std::ptr::eq(*g, f) => env.clone(),
            _ => None,
        };
        for (p, a) in f.params.iter().zip(args) {
            fenv = bind(
                &fenv,
                p.name.as_str(),
                Binding::Thunk {
                    expr: a,
                    env: env.clone(),
                    site: cx.site,
                },
            );
        }
        let fcx = Cx {
            site,
            depth: cx.depth + 1,
            ..cx.clone()
        };
        match &f.body {
            FnBody::Expr(e) => self.expr(e, &fenv, &fcx),
            FnBody::Block(items) => {
                let mut vals = Vec::new();
                for item in items {
                    match item {
                        FnItem::Let { name, value } => {
                            self.expr(value, &fenv, &fcx);
                            fenv = bind(
                                &fenv,
                                name.name.as_str(),
                                Binding::Thunk {
                                    expr: value,
                                    env: fenv.clone(),
                                    site,
                                },
                            );
                        }
                        FnItem::Expr(e) => vals.push((self.expr(e, &fenv, &fcx), e.span)),
                    }
                }
                if vals.iter().any(|(v, _)| *v == Val::Error) {
                    return Val::Error;
                }
                match vals.len() {
                    0 => {
                        self.error(
                            &fcx,
                            crate::lang::codes::EMPTY_FUNCTION,
                            f.span,
                            format!("`{n}` computes nothing"),
                        )
                        .help("end the body with an expression");
                        Val::Error
                    }
                    1 => vals.pop().map_or(Val::Error, |(v, _)| v),
                    _ => {
                        let mut acc: Option<Rc<Formula>> = None;
                        for (v, s) in vals {
                            let Val::Formula(fm) = v else {
                                self.error(&fcx, crate::lang::codes::TYPE_MISMATCH, s, format!("{} in a body with several expressions", v.describe()))
                                    .label("not a constraint")
                                    .help("a body with several expressions returns all of them as constraints (AND); use `let` for values");
                                return Val::Error;
                            };
                            acc = Some(match acc {
                                None => fm,
                                Some(prev) => Rc::new(Formula::And(prev, fm)),
                            });
                        }
                        acc.map_or(Val::Error, Val::Formula)
                    }
                }
            }
        }
    }

    fn nums(&mut self, args: &'a [Expr], env: &Env<'a>, cx: &Cx) -> Option<Vec<Num>> {
        let out: Vec<Option<Num>> = args.iter().map(|a| self.num(a, env, cx)).collect();
        out.into_iter().collect()
    }

    /// Whether `n` is a vector (`vector`) or a scalar, as argument `e` of `fname` must be;
    /// reports it when not.
    pub(super) fn want(&mut self, n: &Num, vector: bool, e: &Expr, fname: &str, cx: &Cx) -> bool {
        if n.vector == vector {
            return true;
        }
        let (want, got) = if vector {
            ("a vector", "a scalar")
        } else {
            ("a scalar", "a vector")
        };
        self.error(
            cx,
            crate::lang::codes::TYPE_MISMATCH,
            e.span,
            format!("`{fname}` needs {want} here, found {got}"),
        )
        .label(got)
        .help(if vector {
            "pass a joint or `[x, y, z]`"
        } else {
            "take a component (`.y`) or a length (`norm(v)`)"
        });
        false
    }

    fn person_arg(
        &mut self,
        args: &'a [Expr],
        index: usize,
        b: &BuiltinDoc,
        span: Span,
        env: &Env<'a>,
        cx: &Cx,
    ) -> Option<LaneVec> {
        match args.get(index) {
            Some(e) => match self.expr(e, env, cx) {
                Val::Person(p) => Some(p),
                Val::Error => None,
                other => {
                    self.error(
                        cx,
                        crate::lang::codes::TYPE_MISMATCH,
                        e.span,
                        format!("`{}` needs a person, found {}", b.name, other.describe()),
                    )
                    .label(other.describe())
                    .help("pass a person's name, e.g. `massCtr(a)`");
                    None
                }
            },
            None if !self.multi => Some(LaneVec::One(0)),
            None => {
                let first = self.header.people[0].name.clone();
                self.error(
                    cx,
                    crate::lang::codes::NEEDS_PERSON,
                    span,
                    format!("`{}` needs to know which person", b.name),
                )
                .label("no person given")
                .help(format!(
                    "this program has several people; write e.g. `{}({first})`",
                    b.name
                ));
                None
            }
        }
    }

    fn builtin(
        &mut self,
        b: &BuiltinDoc,
        args: &'a [Expr],
        span: Span,
        env: &Env<'a>,
        cx: &Cx,
    ) -> Val {
        let num = |node, unit, vector| Val::Num(Num { node, unit, vector });
        match b.name {
            "vel" | "acc" => self.difference(b.name == "acc", &args[0], span, env, cx),
            "parent" => match self.expr(&args[0], env, cx) {
                Val::Joint { person, joint } => {
                    let joint = match joint {
                        LaneVec::One(j) => LaneVec::One(PARENTS[j]),
                        LaneVec::Lanes(v) => {
                            LaneVec::Lanes(Rc::new(v.iter().map(|&j| PARENTS[j]).collect()))
                        }
                    };
                    Val::Joint { person, joint }
                }
                Val::Error => Val::Error,
                other => {
                    self.error(
                        cx,
                        crate::lang::codes::TYPE_MISMATCH,
                        args[0].span,
                        format!("`parent` needs a joint, found {}", other.describe()),
                    )
                    .label(other.describe())
                    .help("e.g. `parent(l_elbow)` is `l_shoulder`");
                    Val::Error
                }
            },
            "massCtr" | "massCtrNoHead" => {
                let Some(p) = self.person_arg(args, 0, b, span, env, cx) else {
                    return Val::Error;
                };
                let persons = self.per_lane(&p, cx);
                let weights = joint_mass_weights(b.name == "massCtr").to_vec();
                num(
                    self.b.mass_center(cx.domain, persons, weights, span),
                    Unit::M,
                    true,
                )
            }
            "facing" => {
                let Some(p) = self.person_arg(args, 0, b, span, env, cx) else {
                    return Val::Error;
                };
                num(self.facing(&p, span, cx), Unit::ONE, true)
            }
            "bodyFront" | "bodyLeft" | "bodyUp" | "gaze" => {
                let Some(p) = self.person_arg(args, 0, b, span, env, cx) else {
                    return Val::Error;
                };
                let node = if b.name == "gaze" {
                    self.gaze(&p, span, cx)
                } else {
                    let [left, up, front] = self.body_axes(&p, span, cx);
                    match b.name {
                        "bodyFront" => front,
                        "bodyLeft" => left,
                        _ => up,
                    }
                };
                num(node, Unit::ONE, true)
            }
            "supportDist" => {
                let Some(point) = self.num(&args[0], env, cx) else {
                    return Val::Error;
                };
                if !self.want(&point, true, &args[0], b.name, cx) {
                    return Val::Error;
                }
                if point.unit.unify(Unit::M).is_none() {
                    self.error(
                        cx,
                        crate::lang::codes::UNIT_MISMATCH,
                        args[0].span,
                        format!("`supportDist` needs a point in m, found {}", point.unit),
                    )
                    .help("pass a position such as `massCtr()`");
                    return Val::Error;
                }
                let Some(p) = self.person_arg(args, 1, b, span, env, cx) else {
                    return Val::Error;
                };
                let persons = self.per_lane(&p, cx);
                let lanes = persons.len();
                let feet: Vec<(usize, usize)> = persons
                    .iter()
                    .flat_map(|&q| [(q, 7), (q, 10), (q, 8), (q, 11)])
                    .collect();
                let feet = self.b.gather(cx.domain, feet, span);
                let lanes = lanes.max(self.b.nodes[point.node].lanes);
                num(
                    self.b.support_dist(point.node, feet, lanes, span),
                    Unit::M,
                    false,
                )
            }
            _ => {
                let Some(v) = self.nums(args, env, cx) else {
                    return Val::Error;
                };
                self.numeric_builtin(b, &v, args, span, cx)
            }
        }
    }

    fn per_lane(&self, p: &LaneVec, cx: &Cx) -> Vec<usize> {
        match p {
            LaneVec::One(q) => vec![*q],
            LaneVec::Lanes(_) => (0..cx.lanes).map(|l| p.get(l)).collect(),
        }
    }

    /// `vel(x)` / `acc(x)`: x re-elaborated on shifted frame domains.
    fn difference(
        &mut self,
        second: bool,
        arg: &'a Expr,
        span: Span,
        env: &Env<'a>,
        cx: &Cx,
    ) -> Val {
        let fps = f64::from(FPS);
        let at = |s: &mut Self, shift: Shift| {
            let domain = s.b.domain(Domain::Shift(cx.domain, shift));
            s.num(
                arg,
                env,
                &Cx {
                    domain,
                    ..cx.clone()
                },
            )
        };
        let node = if second {
            let (Some(a0), Some(a1), Some(a2)) = (
                at(self, Shift::Acc(0)),
                at(self, Shift::Acc(1)),
                at(self, Shift::Acc(2)),
            ) else {
                return Val::Error;
            };
            let d1 = self.b.binary(BinaryOp::Sub, a2.node, a1.node, span);
            let d0 = self.b.binary(BinaryOp::Sub, a1.node, a0.node, span);
            let dd = self.b.binary(BinaryOp::Sub, d1, d0, span);
            let k = self.b.konst(&[fps * fps], span);
            let scaled = self.b.binary(BinaryOp::Mul, dd, k, span);
            let node = self.b.relabel(scaled, cx.domain, span);
            return Val::Num(Num {
                node,
                unit: a0.unit.per(Unit::S.pow(2)),
                vector: a0.vector,
            });
        } else {
            let (Some(hi), Some(lo)) = (at(self, Shift::VelHi), at(self, Shift::VelLo)) else {
                return Val::Error;
            };
            let d = self.b.binary(BinaryOp::Sub, hi.node, lo.node, span);
            let k = self.b.konst(&[fps], span);
            let scaled = self.b.binary(BinaryOp::Mul, d, k, span);
            Num {
                node: self.b.relabel(scaled, cx.domain, span),
                unit: hi.unit.per(Unit::S),
                vector: hi.vector,
            }
        };
        Val::Num(node)
    }

    /// Forward direction of a person: up × normalise(n(r_hip − l_hip) + n(r_sh − l_sh)).
    fn facing(&mut self, p: &LaneVec, span: Span, cx: &Cx) -> usize {
        let persons = self.per_lane(p, cx);
        let joint = |s: &mut Self, j: usize| {
            let pts = persons.iter().map(|&q| (q, j)).collect();
            s.b.gather(cx.domain, pts, span)
        };
        let (rh, lh, rs, ls) = (
            joint(self, 2),
            joint(self, 1),
            joint(self, 17),
            joint(self, 16),
        );
        let hips = self.b.binary(BinaryOp::Sub, rh, lh, span);
        let shoulders = self.b.binary(BinaryOp::Sub, rs, ls, span);
        let hips = self.normalize(hips, span);
        let shoulders = self.normalize(shoulders, span);
        let across = self.b.binary(BinaryOp::Add, hips, shoulders, span);
        let ax = self.b.component(across, 0, span);
        let az = self.b.component(across, 2, span);
        let zero = self.b.konst(&[0.0], span);
        let nx = self.b.unary(UnaryOp::Neg, ax, span);
        let fwd = self.b.compose([az, zero, nx], span);
        self.normalize(fwd, span)
    }

    /// Joint `j` of each lane's person, on the current frames.
    fn joint_of(&mut self, persons: &[usize], j: usize, span: Span, cx: &Cx) -> usize {
        let pts = persons.iter().map(|&q| (q, j)).collect();
        self.b.gather(cx.domain, pts, span)
    }

    /// The torso's own frame `[left, up, front]`, unit vectors, right-handed
    /// (left × up = front): up runs from the pelvis to the neck; front is perpendicular to
    /// up and to the hips' and shoulders' right-to-left direction; left = up × front is
    /// that direction made perpendicular to up. Standing facing +Z with the left at +X it
    /// is (+X, +Y, +Z).
    fn body_axes(&mut self, p: &LaneVec, span: Span, cx: &Cx) -> [usize; 3] {
        let persons = self.per_lane(p, cx);
        let [pelvis, lh, rh, neck, ls, rs] =
            [0, 1, 2, 12, 16, 17].map(|j| self.joint_of(&persons, j, span, cx));
        let hips = self.b.binary(BinaryOp::Sub, lh, rh, span);
        let shoulders = self.b.binary(BinaryOp::Sub, ls, rs, span);
        let hips = self.normalize(hips, span);
        let shoulders = self.normalize(shoulders, span);
        let across = self.b.binary(BinaryOp::Add, hips, shoulders, span);
        let spine = self.b.binary(BinaryOp::Sub, neck, pelvis, span);
        let up = self.normalize(spine, span);
        let front = self.b.cross(across, up, span);
        let front = self.normalize(front, span);
        let left = self.b.cross(up, front, span);
        [left, up, front]
    }

    /// Where the head faces: perpendicular to the shoulder line L (left − right shoulder)
    /// and to the neck→head bone h, i.e. g0 = normalise(L × h), then raised by
    /// [`NEUTRAL_HEAD_PITCH`] about L (g0·cos α + (g0 × L̂)·sin α), since the head joint
    /// sits ahead of the neck's axis when the head is level.
    fn gaze(&mut self, p: &LaneVec, span: Span, cx: &Cx) -> usize {
        let persons = self.per_lane(p, cx);
        let [neck, head, ls, rs] = [12, 15, 16, 17].map(|j| self.joint_of(&persons, j, span, cx));
        let shoulders = self.b.binary(BinaryOp::Sub, ls, rs, span);
        let l = self.normalize(shoulders, span);
        let bone = self.b.binary(BinaryOp::Sub, head, neck, span);
        let g0 = self.b.cross(l, bone, span);
        let g0 = self.normalize(g0, span);
        let raised = self.b.cross(g0, l, span);
        let (s, c) = NEUTRAL_HEAD_PITCH.to_radians().sin_cos();
        let (ks, kc) = (self.b.konst(&[s], span), self.b.konst(&[c], span));
        let a = self.b.binary(BinaryOp::Mul, g0, kc, span);
        let b = self.b.binary(BinaryOp::Mul, raised, ks, span);
        self.b.binary(BinaryOp::Add, a, b, span)
    }

    /// `v / norm(v)`.
    pub(super) fn normalize(&mut self, v: usize, span: Span) -> usize {
        let n = self.b.norm(v, span);
        self.b.binary(BinaryOp::Div, v, n, span)
    }
}
