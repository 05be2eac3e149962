//! Expressions: numbers and units, names (joints, aliases, people, params, `let`s, loop
//! variables), members (`a.r_hand`, `.x`, `.xz`), `@` keyframe access, lists and
//! operators. Comparisons become formulas; their use decides error or mask.

use super::Checker;
use super::units::Unit;
use super::values::*;
use crate::lang::diag::did_you_mean;
use crate::lang::ir::Domain;
use crate::lang::syntax::ast::*;
use crate::skeleton::{JOINT_NAMES, NUM_JOINTS, all_joint_names, joint_index};
use std::rc::Rc;

/// Factor from a written unit to SI.
pub fn unit_scale(u: UnitLit) -> f64 {
    match u {
        UnitLit::M | UnitLit::S | UnitLit::Rad | UnitLit::Percent => 1.0,
        UnitLit::Cm => 0.01,
        UnitLit::Mm | UnitLit::Ms => 0.001,
        UnitLit::Frames => 1.0 / crate::skeleton::FPS as f64,
        UnitLit::Deg => std::f64::consts::PI / 180.0,
    }
}

fn unit_of(u: Option<UnitLit>) -> Unit {
    match u {
        None | Some(UnitLit::Percent) => Unit::FREE,
        Some(UnitLit::M | UnitLit::Cm | UnitLit::Mm) => Unit::M,
        Some(UnitLit::S | UnitLit::Ms | UnitLit::Frames) => Unit::S,
        Some(UnitLit::Deg | UnitLit::Rad) => Unit::RAD,
    }
}

impl<'a> Checker<'a> {
    /// Elaborates an expression.
    pub fn expr(&mut self, e: &'a Expr, env: &Env<'a>, cx: &Cx) -> Val {
        // Inlining is call-by-name, so a few nested functions can multiply the work; a
        // budget keeps checking time bounded whatever the input.
        self.work += 1;
        if self.work > super::MAX_WORK {
            if self.work == super::MAX_WORK + 1 {
                self.error(cx, crate::lang::codes::TOO_COSTLY, e.span, format!("checking needs more than {} steps", super::MAX_WORK))
                    .label("expands too much")
                    .help("functions are inlined where they are called; avoid functions that use an argument many times inside other such functions");
            }
            return Val::Error;
        }
        match &e.kind {
            ExprKind::Number(v, u) => {
                if *u == Some(UnitLit::Percent) {
                    self.error(
                        cx,
                        crate::lang::codes::MISPLACED_PERCENT,
                        e.span,
                        "`%` is only meaningful as a time position",
                    )
                    .label("percent of the motion")
                    .help("use it in `at 50% { … }`, `during 0%..25% { … }` or `head@50%`");
                    return Val::Error;
                }
                let node = self.b.konst(&[v * u.map_or(1.0, unit_scale)], e.span);
                Val::Num(Num {
                    node,
                    unit: unit_of(*u),
                    vector: false,
                })
            }
            ExprKind::Name(n) => self.name(n, e.span, env, cx),
            ExprKind::List(items) => self.list(items, e.span, env, cx),
            ExprKind::Call(name, args) => self.call(name, args, e.span, env, cx),
            ExprKind::Member(base, field) => self.member(base, field, env, cx),
            ExprKind::At(base, time) => {
                let Some(t) = self.time_point(time, env, cx) else {
                    return Val::Error;
                };
                if !self.check_time(t, time.span, cx) {
                    return Val::Error;
                }
                let domain = self.b.domain(Domain::At(vec![t]));
                let inner = Cx {
                    domain,
                    ..cx.clone()
                };
                // Joints are read lazily; read this one now, at the keyframe.
                match self.expr(base, env, &inner) {
                    v @ Val::Joint { .. } => self
                        .num_of(v, base.span, &inner)
                        .map_or(Val::Error, Val::Num),
                    v => v,
                }
            }
            ExprKind::Unary(op, arg) => self.unary(*op, arg, e.span, env, cx),
            ExprKind::Binary(op, a, b) => self.binary(*op, a, b, e.span, env, cx),
            ExprKind::Error => Val::Error,
        }
    }

    /// Elaborates an expression that must be a number, vector or joint (as a point).
    pub fn num(&mut self, e: &'a Expr, env: &Env<'a>, cx: &Cx) -> Option<Num> {
        let v = self.expr(e, env, cx);
        self.num_of(v, e.span, cx)
    }

    /// A value as a number: joints become their positions.
    pub fn num_of(&mut self, v: Val, span: Span, cx: &Cx) -> Option<Num> {
        match v {
            Val::Num(n) => Some(n),
            Val::Joint {
                person: Some(p),
                joint,
            } => {
                let points = if p.is_one() && joint.is_one() {
                    vec![(p.get(0), joint.get(0))]
                } else {
                    (0..cx.lanes).map(|l| (p.get(l), joint.get(l))).collect()
                };
                let node = self.b.gather(cx.domain, points, span);
                Some(Num {
                    node,
                    unit: Unit::M,
                    vector: true,
                })
            }
            Val::Joint {
                person: None,
                joint,
            } => {
                let name = JOINT_NAMES[joint.get(0)];
                let first = self
                    .header
                    .people
                    .first()
                    .map_or("a".to_string(), |p| p.name.clone());
                self.error(
                    cx,
                    crate::lang::codes::NEEDS_PERSON,
                    span,
                    format!("whose `{name}`? this program has several people"),
                )
                .label("joint without a person")
                .help(format!("qualify it with a person, e.g. `{first}.{name}`"));
                None
            }
            Val::Error => None,
            other => {
                let hint = match other {
                    Val::Person(_) => {
                        "a person is not a point; use one of their joints, e.g. `a.pelvis`"
                    }
                    Val::JointSet(_) | Val::PersonSet(_) => {
                        "loop over a list with `for j in [...] { … }`"
                    }
                    _ => "a constraint has no value; compare numbers, e.g. `dist(a, b) < 0.1 m`",
                };
                self.error(
                    cx,
                    crate::lang::codes::TYPE_MISMATCH,
                    span,
                    format!("expected a number or point, found {}", other.describe()),
                )
                .label(other.describe())
                .help(hint);
                None
            }
        }
    }

    fn name(&mut self, n: &str, span: Span, env: &Env<'a>, cx: &Cx) -> Val {
        match lookup(env, n) {
            Some(Binding::Thunk {
                expr,
                env: tenv,
                site,
            }) => {
                let inner = Cx { site, ..cx.clone() };
                return self.expr(expr, &tenv, &inner);
            }
            Some(Binding::Loop(level)) => return self.loop_value(level, cx),
            None => {}
        }
        if let Some(p) = self.header.params.iter().find(|p| p.name == n) {
            let vector = p.value.len() == 3;
            return Val::Num(Num {
                node: p.node,
                unit: p.unit_value,
                vector,
            });
        }
        if let Some(i) = self.header.people.iter().position(|p| p.name == n) {
            return Val::Person(LaneVec::One(i));
        }
        if let Some(j) = joint_index(n) {
            let person = (!self.multi).then_some(LaneVec::One(0));
            return Val::Joint {
                person,
                joint: LaneVec::One(j),
            };
        }
        match n {
            "joints" => {
                let person = (!self.multi).then_some(0);
                return Val::JointSet((0..NUM_JOINTS).map(|j| (person, j)).collect());
            }
            "people" => return Val::PersonSet((0..self.header.people.len()).collect()),
            "me" if !self.multi => return Val::Person(LaneVec::One(0)),
            "time" => {
                // Seconds since the start, per frame of the current domain: a constant of
                // the frame (it does not depend on the motion), vectorised over frames.
                let node = self.b.time(cx.domain, span);
                return Val::Num(Num {
                    node,
                    unit: Unit::S,
                    vector: false,
                });
            }
            "start" | "mid" | "end" => {
                self.error(
                    cx,
                    crate::lang::codes::MISPLACED_TIME,
                    span,
                    format!("`{n}` is a time position, not a value"),
                )
                .label("only valid as a time")
                .help(format!("use it in `at {n} {{ … }}` or `head@{n}`"));
                return Val::Error;
            }
            _ => {}
        }
        if let Some(&e) = self.lib_lets.get(n) {
            let inner = Cx {
                site: cx.site.or(Some(span)),
                ..cx.clone()
            };
            return self.expr(e, &None, &inner);
        }
        if self.poisoned.contains(n) {
            return Val::Error;
        }
        if self.user_fns.contains_key(n)
            || self.lib_fns.contains_key(n)
            || super::builtins::find(n).is_some()
        {
            self.error(
                cx,
                crate::lang::codes::TYPE_MISMATCH,
                span,
                format!("`{n}` is a function"),
            )
            .label("not called")
            .help(format!("call it with arguments: `{n}(…)`"));
            return Val::Error;
        }
        self.unknown_name(n, span, env, cx);
        Val::Error
    }

    /// Reports an unknown name with the closest known one.
    fn unknown_name(&mut self, n: &str, span: Span, env: &Env<'a>, cx: &Cx) {
        // The user function whose body this use is in (user code only: inside a library
        // call, diagnostics move to the call site).
        let in_fn: Option<(&'a str, Span)> = if cx.site.is_none() {
            self.user_fns
                .values()
                .find(|f| f.span.start <= span.start && span.end <= f.span.end)
                .map(|f| (f.name.name.as_str(), f.span))
        } else {
            None
        };
        let later_let = self
            .top_lets
            .iter()
            .find(|(m, _)| *m == n)
            .map(|&(_, s)| s)
            .filter(|_| cx.site.is_none());
        if let Some(let_span) = later_let {
            let line = self.line_of(let_span.start);
            match in_fn {
                Some((f, fspan)) if let_span.start > fspan.start => {
                    self.error(
                        cx,
                        crate::lang::codes::UNKNOWN_NAME,
                        span,
                        format!("`{n}` is declared on line {line}, after the function `{f}`"),
                    )
                    .label("not visible in this function")
                    .help(format!(
                        "move the `let` above `def {f}`: a function sees its arguments, the \
                         `param`s, and the `let`s declared above it"
                    ));
                    return;
                }
                None if let_span.start > span.start => {
                    self.error(
                        cx,
                        crate::lang::codes::UNKNOWN_NAME,
                        span,
                        format!("`{n}` is declared on line {line}, after this use"),
                    )
                    .label("not declared yet")
                    .help("move the `let` above its first use: a `let` is visible below it");
                    return;
                }
                _ => {}
            }
        }
        if matches!(
            n,
            "s" | "ms" | "m" | "cm" | "mm" | "deg" | "rad" | "frame" | "frames"
        ) {
            self.error(
                cx,
                crate::lang::codes::UNKNOWN_NAME,
                span,
                format!("`{n}` is a unit, not a value"),
            )
            .label("a unit alone")
            .help(format!(
                "write a unit right after a number (`2 {n}`); a rate per second is written \
                 without spaces, `180 deg/s` or `1.5 m/s`"
            ));
            return;
        }
        let mut candidates: Vec<String> = all_joint_names().map(str::to_string).collect();
        let joint_count = candidates.len();
        candidates.extend(names(env).into_iter().map(str::to_string));
        candidates.extend(self.header.params.iter().map(|p| p.name.clone()));
        candidates.extend(self.header.people.iter().map(|p| p.name.clone()));
        candidates.extend(self.lib_lets.keys().map(|k| k.to_string()));
        candidates.extend(["joints", "people", "time"].map(String::from));
        let best = did_you_mean(n, candidates.iter().map(String::as_str)).map(str::to_string);
        let is_joint = best
            .as_ref()
            .is_some_and(|b| candidates[..joint_count].contains(b));
        let code = if is_joint {
            crate::lang::codes::UNKNOWN_JOINT
        } else {
            crate::lang::codes::UNKNOWN_NAME
        };
        let what = if is_joint { "joint" } else { "name" };
        let help = match (best, in_fn) {
            (Some(b), _) => format!("did you mean `{b}`?"),
            (None, Some((f, _))) => format!(
                "`{f}` sees its arguments, the `param`s, and the `let`s declared above it; \
                 joints are named like `head`, `l_hand`, `right_foot` (see `mprog joints`)"
            ),
            (None, None) => {
                "joints are named like `head`, `l_hand`, `right_foot` (see `mprog joints`); \
                 declare values with `let` or `param`"
                    .to_string()
            }
        };
        self.error(cx, code, span, format!("unknown {what} `{n}`"))
            .label("not defined")
            .help(help);
    }

    fn loop_value(&mut self, level: usize, cx: &Cx) -> Val {
        let items = cx.loops[level].clone();
        let idx = cx.loop_indices(level);
        let map = |f: &dyn Fn(&LoopItem) -> usize| match &idx {
            LaneVec::One(i) => LaneVec::One(f(&items[*i])),
            LaneVec::Lanes(v) => LaneVec::Lanes(Rc::new(v.iter().map(|&i| f(&items[i])).collect())),
        };
        match &items[0] {
            LoopItem::Person(_) => Val::Person(map(&|it| match it {
                LoopItem::Person(p) => *p,
                LoopItem::Joint(..) => 0,
            })),
            LoopItem::Joint(p, _) => {
                let person = p.map(|_| {
                    map(&|it| match it {
                        LoopItem::Joint(p, _) => p.unwrap_or(0),
                        LoopItem::Person(p) => *p,
                    })
                });
                let joint = map(&|it| match it {
                    LoopItem::Joint(_, j) => *j,
                    LoopItem::Person(_) => 0,
                });
                Val::Joint { person, joint }
            }
        }
    }

    fn list(&mut self, items: &'a [Expr], span: Span, env: &Env<'a>, cx: &Cx) -> Val {
        let vals: Vec<Val> = items.iter().map(|e| self.expr(e, env, cx)).collect();
        if vals.contains(&Val::Error) {
            return Val::Error;
        }
        if !vals.is_empty() && vals.iter().all(|v| matches!(v, Val::Joint { .. })) {
            let mut set = Vec::new();
            for (v, e) in vals.iter().zip(items) {
                let Val::Joint { person, joint } = v else {
                    continue;
                };
                match (person, joint) {
                    (None, LaneVec::One(j)) => set.push((None, *j)),
                    (Some(LaneVec::One(p)), LaneVec::One(j)) => set.push((Some(*p), *j)),
                    _ => {
                        self.error(
                            cx,
                            crate::lang::codes::TYPE_MISMATCH,
                            e.span,
                            "a loop variable cannot go into a joint list",
                        )
                        .help("list fixed joints, e.g. `[head, neck]`");
                        return Val::Error;
                    }
                }
            }
            if set.iter().any(|(p, _)| p.is_none()) && set.iter().any(|(p, _)| p.is_some()) {
                self.error(
                    cx,
                    crate::lang::codes::TYPE_MISMATCH,
                    span,
                    "mix of joints with and without a person",
                )
                .help("qualify all of them (`a.head`) or none (`head`)");
                return Val::Error;
            }
            return Val::JointSet(set);
        }
        if !vals.is_empty()
            && vals
                .iter()
                .all(|v| matches!(v, Val::Person(LaneVec::One(_))))
        {
            let set = vals
                .iter()
                .filter_map(|v| match v {
                    Val::Person(LaneVec::One(p)) => Some(*p),
                    _ => None,
                })
                .collect();
            return Val::PersonSet(set);
        }
        if vals.len() != 3 {
            self.error(
                cx,
                crate::lang::codes::BAD_LIST,
                span,
                format!("a vector needs 3 numbers, this list has {}", vals.len()),
            )
            .label("not [x, y, z]")
            .help("write a vector as `[x, y, z]`, or a list of joints such as `[l_hand, r_hand]`");
            return Val::Error;
        }
        let mut nums = Vec::new();
        for (v, e) in vals.into_iter().zip(items) {
            match self.num_of(v, e.span, cx) {
                Some(n) if !n.vector => nums.push(n),
                Some(_) => {
                    self.error(
                        cx,
                        crate::lang::codes::TYPE_MISMATCH,
                        e.span,
                        "a vector's entries must be scalars",
                    )
                    .label("a vector")
                    .help("take a component, e.g. `head.y`");
                    return Val::Error;
                }
                None => return Val::Error,
            }
        }
        let mut unit = Unit::FREE;
        for (n, e) in nums.iter().zip(items) {
            match unit.unify(n.unit) {
                Some(u) => unit = u,
                None => {
                    self.error(
                        cx,
                        crate::lang::codes::UNIT_MISMATCH,
                        e.span,
                        format!("vector entries mix {unit} and {}", n.unit),
                    )
                    .label(n.unit.to_string())
                    .help("all three entries need the same unit");
                    return Val::Error;
                }
            }
        }
        let node = self
            .b
            .compose([nums[0].node, nums[1].node, nums[2].node], span);
        Val::Num(Num {
            node,
            unit,
            vector: true,
        })
    }

    fn member(&mut self, base: &'a Expr, field: &'a Ident, env: &Env<'a>, cx: &Cx) -> Val {
        let f = field.name.as_str();
        if let ExprKind::Name(n) = &base.kind
            && !self.is_bound(n, env)
            && (joint_index(f).is_some() || lookup(env, f).is_some())
        {
            let people: Vec<&str> = self.header.people.iter().map(|p| p.name.as_str()).collect();
            let help = match did_you_mean(n, people.iter().copied()) {
                Some(s) if self.multi => {
                    format!("did you mean `{s}`? the people are: {}", people.join(", "))
                }
                _ if self.multi => format!("the people are: {}", people.join(", ")),
                _ => format!("this program has one person: write the joint alone, `{f}`"),
            };
            self.error(
                cx,
                crate::lang::codes::UNKNOWN_PERSON,
                base.span,
                format!("no person named `{n}`"),
            )
            .label("not declared in `people`")
            .help(help);
            return Val::Error;
        }
        let v = self.expr(base, env, cx);
        let span = base.span.to(field.span);
        match v {
            Val::Error => Val::Error,
            Val::Person(p) => {
                if let Some(j) = joint_index(f) {
                    return Val::Joint {
                        person: Some(p),
                        joint: LaneVec::One(j),
                    };
                }
                if let Some(Binding::Loop(level)) = lookup(env, f)
                    && let Val::Joint {
                        person: None,
                        joint,
                    } = self.loop_value(level, cx)
                {
                    return Val::Joint {
                        person: Some(p),
                        joint,
                    };
                }
                let help = match did_you_mean(f, all_joint_names()) {
                    Some(s) => format!("did you mean `{s}`?"),
                    None => "see `mprog joints` for joint names and aliases".to_string(),
                };
                self.error(
                    cx,
                    crate::lang::codes::UNKNOWN_JOINT,
                    field.span,
                    format!("unknown joint `{f}`"),
                )
                .label("not a joint")
                .help(help);
                Val::Error
            }
            other => {
                let Some(n) = self.num_of(other, base.span, cx) else {
                    return Val::Error;
                };
                if !n.vector {
                    self.error(
                        cx,
                        crate::lang::codes::TYPE_MISMATCH,
                        field.span,
                        format!("a scalar has no component `.{f}`"),
                    )
                    .label("scalar")
                    .help("components exist on vectors and joints, e.g. `head.y`");
                    return Val::Error;
                }
                let axis = match f {
                    "x" => 0,
                    "y" => 1,
                    "z" => 2,
                    "xz" => {
                        let x = self.b.component(n.node, 0, span);
                        let z = self.b.component(n.node, 2, span);
                        let zero = self.b.konst(&[0.0], span);
                        let node = self.b.compose([x, zero, z], span);
                        return Val::Num(Num { node, ..n });
                    }
                    _ => {
                        let hint = if joint_index(f).is_some() {
                            format!("`.{f}` reads a person's joint; the left side must be a person")
                        } else {
                            "vectors have `.x`, `.y`, `.z` and `.xz` (ground projection)"
                                .to_string()
                        };
                        self.error(
                            cx,
                            crate::lang::codes::UNKNOWN_COMPONENT,
                            field.span,
                            format!("no component `.{f}`"),
                        )
                        .label("not x, y, z or xz")
                        .help(hint);
                        return Val::Error;
                    }
                };
                let node = self.b.component(n.node, axis, span);
                Val::Num(Num {
                    node,
                    unit: n.unit,
                    vector: false,
                })
            }
        }
    }

    /// True when `n` means something as a value (not an unknown name).
    fn is_bound(&self, n: &str, env: &Env<'a>) -> bool {
        lookup(env, n).is_some()
            || self.header.params.iter().any(|p| p.name == n)
            || self.header.people.iter().any(|p| p.name == n)
            || joint_index(n).is_some()
            || self.lib_lets.contains_key(n)
            || matches!(n, "joints" | "people" | "time")
            || (n == "me" && !self.multi)
    }
}
