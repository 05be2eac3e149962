//! Statements: time blocks become frame domains (nested blocks intersect), `for` loops
//! become lanes, `if` conditions become masks (or pick a branch when they are constant),
//! weights multiply, and every constraint becomes one IR statement whose error is the
//! formula's PMG error: `==` → |a−b| (distance for vectors), `<` → max(a−b, 0),
//! `>` → max(b−a, 0), `and` → sum, `or` → min, `not` → −E.

use super::values::*;
use super::{Checker, units::Unit};
use crate::lang::ir::{BinaryOp, Domain, NodeId, Op, Statement, UnaryOp};
use crate::lang::syntax::ast::*;
use crate::skeleton::joint_index;
use std::rc::Rc;

/// A single-frame `at` this close to the end (frames) is an end state for
/// `mprog::keyframe_pose`: 0.25 s.
const END_FRAMES: usize = 5;

/// Most loop lanes (product of nested loop sizes) a statement may have.
pub const MAX_LANES: usize = 4096;

/// An `if` condition in force: re-elaborated for each statement in its context.
#[derive(Clone)]
pub struct Cond<'a> {
    expr: &'a Expr,
    env: Env<'a>,
    negate: bool,
}

/// Statement context: where, how often, how heavy, under which conditions.
#[derive(Clone)]
pub struct Scx<'a> {
    pub cx: Cx,
    pub weight: f64,
    pub conds: Rc<Vec<Cond<'a>>>,
}

impl<'a> Checker<'a> {
    /// Checks the top-level statements in order.
    pub fn body(&mut self, module: &'a Module) {
        let scx = Scx {
            cx: Cx::top(),
            weight: 1.0,
            conds: Rc::new(Vec::new()),
        };
        let mut env: Env<'a> = None;
        for item in &module.items {
            if let Item::Stmt(s) = item {
                let errors = self.error_count();
                let emitted = self.statements.len();
                env = self.stmt(s, env, &scx);
                // A statement with an error is dropped whole (a bad time falls back to
                // every frame): what is kept is right, for the IR warnings of a program
                // that has errors elsewhere.
                if self.error_count() > errors {
                    self.statements.truncate(emitted);
                }
            }
        }
    }

    /// Records what each user function sees: the top-level `let`s declared above it (in
    /// source order, as the statements see them), and where every top-level `let` is.
    pub fn scope_of_functions(&mut self, module: &'a Module) {
        let mut env: Env<'a> = None;
        for item in &module.items {
            match item {
                Item::Stmt(Stmt::Let {
                    name, value, span, ..
                }) => {
                    let n = name.name.as_str();
                    self.top_lets.push((n, *span));
                    // A reserved name is reported (and left unbound) by `stmt`.
                    if joint_index(n).is_none() && !super::header::RESERVED.contains(&n) {
                        env = bind(
                            &env,
                            n,
                            Binding::Thunk {
                                expr: value,
                                env: env.clone(),
                                site: None,
                            },
                        );
                    }
                }
                Item::Def(f) => {
                    self.fn_envs
                        .entry(f.name.name.as_str())
                        .or_insert_with(|| env.clone());
                }
                _ => {}
            }
        }
    }

    /// The functions `f` calls through the top-level `let`s it sees (`let k = f(1)` above
    /// `def f(a) = k + a` is a recursion): names its body reads that are no argument or
    /// block `let` of its own, followed into the `let`s' values.
    pub fn calls_through_lets(&self, f: &'a FnDef) -> Vec<&'a str> {
        let Some(env) = self.fn_envs.get(f.name.name.as_str()) else {
            return Vec::new();
        };
        let mut own: Vec<&str> = f.params.iter().map(|p| p.name.as_str()).collect();
        let mut roots: Vec<&'a Expr> = Vec::new();
        match &f.body {
            FnBody::Expr(e) => roots.push(e),
            FnBody::Block(items) => {
                for i in items {
                    match i {
                        FnItem::Let { name, value } => {
                            own.push(name.name.as_str());
                            roots.push(value);
                        }
                        FnItem::Expr(e) => roots.push(e),
                    }
                }
            }
        }
        let mut out = Vec::new();
        let mut seen: Vec<*const Expr> = Vec::new();
        // (expression, the scope its names resolve in, whether it is the function's own)
        let mut stack: Vec<(&'a Expr, Env<'a>, bool)> =
            roots.into_iter().map(|e| (e, env.clone(), true)).collect();
        while let Some((e, scope, body)) = stack.pop() {
            match &e.kind {
                ExprKind::Name(n) if !(body && own.contains(&n.as_str())) => {
                    if let Some(Binding::Thunk { expr, env, .. }) = lookup(&scope, n)
                        && !seen.contains(&(expr as *const Expr))
                    {
                        seen.push(expr);
                        stack.push((expr, env, false));
                    }
                }
                ExprKind::Call(name, args) => {
                    out.push(name.name.as_str());
                    stack.extend(args.iter().map(|a| (a, scope.clone(), body)));
                }
                ExprKind::List(items) => {
                    stack.extend(items.iter().map(|a| (a, scope.clone(), body)));
                }
                ExprKind::Member(a, _) | ExprKind::Unary(_, a) => {
                    stack.push((a, scope.clone(), body));
                }
                ExprKind::At(a, b) | ExprKind::Binary(_, a, b) => {
                    stack.push((a, scope.clone(), body));
                    stack.push((b, scope.clone(), body));
                }
                _ => {}
            }
        }
        out
    }

    fn error_count(&self) -> usize {
        self.diags
            .iter()
            .filter(|d| d.severity == crate::lang::diag::Severity::Error)
            .count()
    }

    fn block(&mut self, stmts: &'a [Stmt], env: &Env<'a>, scx: &Scx<'a>) {
        let mut env = env.clone();
        for s in stmts {
            env = self.stmt(s, env, scx);
        }
    }

    fn stmt(&mut self, s: &'a Stmt, env: Env<'a>, scx: &Scx<'a>) -> Env<'a> {
        let cx = &scx.cx;
        match s {
            Stmt::Let { name, value, .. } => {
                let n = name.name.as_str();
                if joint_index(n).is_some() || super::header::RESERVED.contains(&n) {
                    self.error(
                        cx,
                        crate::lang::codes::RESERVED_NAME,
                        name.span,
                        format!("`{n}` cannot be redefined"),
                    )
                    .label("a joint or keyword")
                    .help("choose another name for the `let`");
                    return env;
                }
                self.expr(value, &env, cx);
                return bind(
                    &env,
                    n,
                    Binding::Thunk {
                        expr: value,
                        env: env.clone(),
                        site: None,
                    },
                );
            }
            Stmt::Time {
                kind,
                weight,
                body,
                span,
            } => {
                // A bad time is already reported; still check the body for more errors.
                let d = self.time_domain(kind, *span, &env, cx).unwrap_or(0);
                let domain = if cx.domain == 0 {
                    d
                } else {
                    self.b.domain(Domain::Intersect(cx.domain, d))
                };
                let w = self.weight(weight.as_ref(), &env, cx);
                let inner = Scx {
                    cx: Cx {
                        domain,
                        ..cx.clone()
                    },
                    weight: scx.weight * w,
                    ..scx.clone()
                };
                let emitted = self.statements.len();
                self.block(body, &env, &inner);
                if let TimeKind::At(times) = kind
                    && let [t] = times.as_slice()
                {
                    self.keyframe_pose([d, domain], t, *span, emitted, cx);
                }
            }
            Stmt::Weight { weight, body, .. } => {
                let w = self.weight(Some(weight), &env, cx);
                let inner = Scx {
                    weight: scx.weight * w,
                    ..scx.clone()
                };
                self.block(body, &env, &inner);
            }
            Stmt::For { var, set, body, .. } => self.for_loop(var, set, body, &env, scx),
            Stmt::If {
                cond,
                then,
                otherwise,
                ..
            } => self.if_stmt(cond, then, otherwise.as_deref(), &env, scx),
            Stmt::Minimize {
                value,
                sign,
                weight,
                span,
            } => {
                let w = self.weight(weight.as_ref(), &env, cx);
                let Some(n) = self.num(value, &env, cx) else {
                    return env;
                };
                if n.vector {
                    self.error(
                        cx,
                        crate::lang::codes::TYPE_MISMATCH,
                        value.span,
                        "`minimize` needs a scalar, found a vector",
                    )
                    .label("vector")
                    .help("minimise a length, e.g. `minimize norm(v)`");
                    return env;
                }
                let k = self.b.konst(&[*sign], value.span);
                let error = self.b.binary(BinaryOp::Mul, n.node, k, value.span);
                self.emit(error, n.unit, *span, scx.weight * w, true, scx);
            }
            Stmt::Constraint {
                value,
                weight,
                span,
            } => {
                let w = self.weight(weight.as_ref(), &env, cx);
                match self.expr(value, &env, cx) {
                    Val::Formula(f) => {
                        self.note_bounds(&f, !scx.conds.is_empty(), cx);
                        let error = self.formula_error(&f);
                        self.emit(error, f.unit(), *span, scx.weight * w, false, scx);
                    }
                    Val::Error => {}
                    other => {
                        self.error(
                            cx,
                            crate::lang::codes::NOT_A_CONSTRAINT,
                            value.span,
                            format!(
                                "a statement must be a constraint, found {}",
                                other.describe()
                            ),
                        )
                        .label("nothing to satisfy")
                        .help("compare it, e.g. `… == 0.4 m`, `… < 1 m`, or write `minimize …`");
                    }
                }
            }
        }
        env
    }

    /// `mprog::keyframe_pose`: a one-time `at` block on one of the last [`END_FRAMES`]
    /// frames (`at end`) whose constraints fix the body's posture there: the absolute
    /// height of the pelvis, a spine joint, the neck, the head or the centre of mass, or
    /// absolute heights of two or more joints other than the feet and ankles. A height is
    /// absolute when the statement reads the `.y` of one joint on the block's frame
    /// (`pelvis.y < 0.5 m`, `head.y < pelvis@start.y`), not a difference of two
    /// (`r_hand.y > head.y`). Ground positions, facing and contacts of a hand or two are
    /// not posture.
    fn keyframe_pose(
        &mut self,
        domains: [usize; 2],
        t: &Expr,
        span: Span,
        emitted: usize,
        cx: &Cx,
    ) {
        let frame = match &self.b.domains[domains[0]] {
            Domain::At(points) if points.len() == 1 => points[0].frame(self.header.length),
            _ => return,
        };
        // End states only: an interior keyframe is usually a moment (a squat's bottom, a
        // jump's apex, a duck under a bar), which the motion passes through on purpose.
        if frame + END_FRAMES < self.header.length {
            return;
        }
        const TORSO: [usize; 6] = [0, 3, 6, 9, 12, 15];
        const FEET: [usize; 4] = [7, 8, 10, 11];
        let mut torso: Option<String> = None;
        let mut heights: Vec<(usize, usize)> = Vec::new();
        for s in &self.statements[emitted..] {
            if s.objective {
                continue;
            }
            // Joint reads under a `.y`, on the statement's own frames.
            let mut seen = std::collections::HashSet::new();
            let mut stack = vec![(s.error, false)];
            let mut reads: Vec<NodeId> = Vec::new();
            while let Some((n, y)) = stack.pop() {
                if !seen.insert((n, y)) {
                    continue;
                }
                let node = &self.b.nodes[n];
                match &node.op {
                    Op::Component { arg, axis } => stack.push((*arg, *axis == 1)),
                    Op::Gather { domain: d, .. } | Op::MassCenter { domain: d, .. } => {
                        if y && domains.contains(d) && !reads.contains(&n) {
                            reads.push(n);
                        }
                    }
                    op => stack.extend(op.args().into_iter().map(|a| (a, y))),
                }
            }
            // One joint read: an absolute height. Two or more: a difference of heights.
            let [n] = reads.as_slice() else { continue };
            match &self.b.nodes[*n].op {
                Op::MassCenter { .. } => {
                    torso.get_or_insert_with(|| "the centre of mass".to_string());
                }
                Op::Gather { points, .. } => {
                    for &(p, j) in points {
                        if TORSO.contains(&j) {
                            torso.get_or_insert_with(|| {
                                format!("the {}", crate::skeleton::JOINT_NAMES[j])
                            });
                        } else if !FEET.contains(&j) && !heights.contains(&(p, j)) {
                            heights.push((p, j));
                        }
                    }
                }
                _ => {}
            }
        }
        let what = match (&torso, heights.len()) {
            (Some(t), _) => format!("the height of {t}"),
            (None, k) if k >= 2 => {
                let names: Vec<&str> = heights
                    .iter()
                    .map(|&(_, j)| crate::skeleton::JOINT_NAMES[j])
                    .collect();
                format!("the heights of the {}", names.join(", the "))
            }
            _ => return,
        };
        let time = self
            .source
            .get(t.span.start..t.span.end)
            .unwrap_or("end")
            .to_string();
        let window = if time == "end" {
            "during end - 0.5s..end + 1".to_string()
        } else {
            format!("during {time} - 0.5s..end + 1")
        };
        self.error(
            cx,
            crate::lang::codes::KEYFRAME_POSE,
            Span::new(span.start, t.span.end),
            format!("`at {time}` fixes a whole-body pose ({what}) on a single frame"),
        )
        .label("one frame")
        .help(format!(
            "only the last frame would be in this pose, so the body snaps into it at the very \
             end; hold the end state over a window instead: `{window} {{ … }}`"
        ))
        .warning();
    }

    fn weight(&mut self, e: Option<&'a Expr>, env: &Env<'a>, cx: &Cx) -> f64 {
        let Some(e) = e else { return 1.0 };
        let v = self.expr(e, env, cx);
        let value = match v {
            Val::Num(n) if !n.vector && n.unit.is_plain() => {
                self.b.const_of(n.node).map(|c| f64::from(c[0]))
            }
            Val::Error => return 1.0,
            _ => None,
        };
        match value {
            Some(w) if w >= 0.0 && w.is_finite() => w,
            Some(_) => {
                self.error(
                    cx,
                    crate::lang::codes::BAD_WEIGHT,
                    e.span,
                    "a weight must be zero or positive",
                )
                .label("negative")
                .help("to push a value up instead of down use `maximize …` or `not (…)`");
                1.0
            }
            None => {
                self.error(
                    cx,
                    crate::lang::codes::BAD_WEIGHT,
                    e.span,
                    "a weight must be a constant plain number",
                )
                .label("not a constant number")
                .help("write e.g. `weight 10`; weights cannot depend on the motion or carry units");
                1.0
            }
        }
    }

    fn time_domain(
        &mut self,
        kind: &'a TimeKind,
        span: Span,
        env: &Env<'a>,
        cx: &Cx,
    ) -> Option<usize> {
        match kind {
            TimeKind::Always => Some(0),
            TimeKind::At(times) => {
                let mut points = Vec::new();
                let mut ok = true;
                for t in times {
                    match self.time_point(t, env, cx) {
                        Some(p) if self.check_time(p, t.span, cx) => points.push(p),
                        _ => ok = false,
                    }
                }
                ok.then(|| self.b.domain(Domain::At(points)))
            }
            TimeKind::During(a, b) => {
                let (pa, pb) = (self.time_point(a, env, cx)?, self.time_point(b, env, cx)?);
                self.check_range(
                    pa,
                    pb,
                    a.span.to(b.span).to(Span::new(span.start, a.span.start)),
                    cx,
                )
                .then(|| self.b.domain(Domain::During(pa, pb)))
            }
        }
    }

    fn for_loop(
        &mut self,
        var: &'a Ident,
        set: &'a Expr,
        body: &'a [Stmt],
        env: &Env<'a>,
        scx: &Scx<'a>,
    ) {
        let cx = &scx.cx;
        let items: Vec<LoopItem> = match self.expr(set, env, cx) {
            Val::JointSet(s) => s.into_iter().map(|(p, j)| LoopItem::Joint(p, j)).collect(),
            Val::PersonSet(s) => s.into_iter().map(LoopItem::Person).collect(),
            Val::Error => return,
            other => {
                self.error(
                    cx,
                    crate::lang::codes::NOT_A_SET,
                    set.span,
                    format!(
                        "`for` needs a list of joints or people, found {}",
                        other.describe()
                    ),
                )
                .label(other.describe())
                .help("loop over `[head, neck]`, `joints` or `people`");
                return;
            }
        };
        if items.is_empty() {
            return;
        }
        let lanes = cx.lanes * items.len();
        if lanes > MAX_LANES {
            self.error(
                cx,
                crate::lang::codes::TOO_COSTLY,
                set.span,
                format!("nested loops make {lanes} iterations (limit {MAX_LANES})"),
            )
            .label("too many iterations")
            .help("loop over shorter lists");
            return;
        }
        let mut loops = (*cx.loops).clone();
        loops.push(Rc::new(items));
        let level = loops.len() - 1;
        let inner = Scx {
            cx: Cx {
                loops: Rc::new(loops),
                lanes,
                ..cx.clone()
            },
            ..scx.clone()
        };
        let env = bind(env, var.name.as_str(), Binding::Loop(level));
        self.block(body, &env, &inner);
    }

    fn if_stmt(
        &mut self,
        cond: &'a Expr,
        then: &'a [Stmt],
        otherwise: Option<&'a [Stmt]>,
        env: &Env<'a>,
        scx: &Scx<'a>,
    ) {
        let cx = &scx.cx;
        let f = match self.expr(cond, env, cx) {
            Val::Formula(f) => f,
            Val::Error => return,
            other => {
                self.error(
                    cx,
                    crate::lang::codes::NOT_A_CONDITION,
                    cond.span,
                    format!(
                        "an `if` condition must be a comparison, found {}",
                        other.describe()
                    ),
                )
                .label(other.describe())
                .help("e.g. `if head.z > 2 m and head.z < 3 m { … }`");
                return;
            }
        };
        let Some(mask) = self.formula_mask(&f, cx) else {
            return;
        };
        if let Some(v) = self.b.const_of(mask).map(|c| c[0]) {
            // A condition that does not depend on the motion picks its branch now.
            if v > 0.5 {
                self.block(then, env, scx);
            } else if let Some(o) = otherwise {
                self.block(o, env, scx);
            }
            return;
        }
        for (body, negate) in [(Some(then), false), (otherwise, true)] {
            let Some(body) = body else { continue };
            let mut conds = (*scx.conds).clone();
            conds.push(Cond {
                expr: cond,
                env: env.clone(),
                negate,
            });
            let inner = Scx {
                conds: Rc::new(conds),
                ..scx.clone()
            };
            self.block(body, env, &inner);
        }
    }

    /// The error of a formula (PMG semantics).
    pub fn formula_error(&mut self, f: &Formula) -> NodeId {
        match f {
            Formula::Cmp { op, a, b, span, .. } => {
                let (a, b, span) = (*a, *b, *span);
                match op {
                    BinOp::Eq => {
                        let d = self.b.binary(BinaryOp::Sub, a, b, span);
                        if self.b.nodes[d].channels == 3 {
                            self.b.norm(d, span)
                        } else {
                            self.b.unary(UnaryOp::Abs, d, span)
                        }
                    }
                    BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge => {
                        let (x, y) = if matches!(op, BinOp::Lt | BinOp::Le) {
                            (a, b)
                        } else {
                            (b, a)
                        };
                        let d = self.b.binary(BinaryOp::Sub, x, y, span);
                        let r = self.b.unary(UnaryOp::Relu, d, span);
                        self.b.sum_channels(r, span)
                    }
                    _ => self.b.konst(&[0.0], span),
                }
            }
            Formula::And(x, y) => {
                let (ex, ey) = (self.formula_error(x), self.formula_error(y));
                let span = self.b.nodes[ex].span.to(self.b.nodes[ey].span);
                self.b.binary(BinaryOp::Add, ex, ey, span)
            }
            Formula::Or(x, y) => {
                let (ex, ey) = (self.formula_error(x), self.formula_error(y));
                let span = self.b.nodes[ex].span.to(self.b.nodes[ey].span);
                self.b.binary(BinaryOp::Min, ex, ey, span)
            }
            Formula::Not(x) => {
                let e = self.formula_error(x);
                let span = self.b.nodes[e].span;
                self.b.unary(UnaryOp::Neg, e, span)
            }
        }
    }

    /// The 0/1 mask of a formula used as a condition.
    fn formula_mask(&mut self, f: &Formula, cx: &Cx) -> Option<NodeId> {
        Some(match f {
            Formula::Cmp { op, a, b, span, .. } => {
                let (a, b, span) = (*a, *b, *span);
                match op {
                    BinOp::Lt => self.b.less(a, b, span),
                    BinOp::Gt => self.b.less(b, a, span),
                    BinOp::Le => {
                        let m = self.b.less(b, a, span);
                        self.b.unary(UnaryOp::OneMinus, m, span)
                    }
                    BinOp::Ge => {
                        let m = self.b.less(a, b, span);
                        self.b.unary(UnaryOp::OneMinus, m, span)
                    }
                    _ => {
                        self.error(cx, crate::lang::codes::EXACT_EQUALITY, span, "`==` in a condition tests exact equality of real numbers")
                            .label("almost never true")
                            .help("test closeness instead, e.g. `abs(a - b) < 1 cm` or `dist(p, q) < 5 cm`");
                        return None;
                    }
                }
            }
            Formula::And(x, y) => {
                let (mx, my) = (self.formula_mask(x, cx)?, self.formula_mask(y, cx)?);
                let span = self.b.nodes[mx].span.to(self.b.nodes[my].span);
                self.b.binary(BinaryOp::Mul, mx, my, span)
            }
            Formula::Or(x, y) => {
                let (mx, my) = (self.formula_mask(x, cx)?, self.formula_mask(y, cx)?);
                let span = self.b.nodes[mx].span.to(self.b.nodes[my].span);
                self.b.binary(BinaryOp::Max, mx, my, span)
            }
            Formula::Not(x) => {
                let m = self.formula_mask(x, cx)?;
                let span = self.b.nodes[m].span;
                self.b.unary(UnaryOp::OneMinus, m, span)
            }
        })
    }

    /// Records one statement, with the mask of the `if`s around it.
    fn emit(
        &mut self,
        error: NodeId,
        unit: Unit,
        span: Span,
        weight: f64,
        objective: bool,
        scx: &Scx<'a>,
    ) {
        let cx = &scx.cx;
        let mut mask: Option<NodeId> = None;
        for c in scx.conds.iter() {
            let Val::Formula(f) = self.expr(c.expr, &c.env, cx) else {
                return;
            };
            let Some(mut m) = self.formula_mask(&f, cx) else {
                return;
            };
            if c.negate {
                m = self.b.unary(UnaryOp::OneMinus, m, c.expr.span);
            }
            mask = Some(match mask {
                None => m,
                Some(prev) => self.b.binary(BinaryOp::Mul, prev, m, c.expr.span),
            });
        }
        if !self.b.nodes[error].motion {
            self.error(
                cx,
                crate::lang::codes::NO_MOTION,
                span,
                "this constraint does not depend on the motion",
            )
            .label("constant")
            .help(
                "it only adds a constant to the error; did you mean to use a joint, e.g. `head.y`?",
            )
            .warning();
        }
        let line = self.line_of(span.start);
        let text = self
            .source
            .get(span.start..span.end)
            .unwrap_or("")
            .lines()
            .next()
            .unwrap_or("")
            .trim();
        let text: String = if text.chars().count() > 60 {
            text.chars().take(57).chain("...".chars()).collect()
        } else {
            text.to_string()
        };
        let unit = if unit.free {
            "1".to_string()
        } else {
            unit.to_string()
        };
        self.statements.push(Statement {
            error,
            mask,
            domain: cx.domain,
            lanes: cx.lanes,
            weight,
            span,
            line,
            label: format!("line {line}: {text}"),
            unit,
            objective,
        });
    }
}
