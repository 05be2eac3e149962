//! Operators: `-` and `not`, `and`/`or` on formulas, comparisons (which become formulas)
//! and arithmetic, with checks of kinds (scalar or vector) and units.

use super::Checker;
use super::units::Unit;
use super::values::*;
use crate::lang::ir::{BinaryOp, UnaryOp};
use crate::lang::syntax::ast::*;
use std::rc::Rc;

impl<'a> Checker<'a> {
    pub(super) fn unary(
        &mut self,
        op: UnOp,
        arg: &'a Expr,
        span: Span,
        env: &Env<'a>,
        cx: &Cx,
    ) -> Val {
        let v = self.expr(arg, env, cx);
        match (op, v) {
            (_, Val::Error) => Val::Error,
            (UnOp::Not, Val::Formula(f)) => Val::Formula(Rc::new(Formula::Not(f))),
            (UnOp::Not, other) => {
                self.error(
                    cx,
                    crate::lang::codes::TYPE_MISMATCH,
                    arg.span,
                    format!("`not` needs a constraint, found {}", other.describe()),
                )
                .label(other.describe())
                .help("negate a comparison, e.g. `not (head.y < 1 m)`");
                Val::Error
            }
            (UnOp::Neg, Val::Formula(_)) => {
                self.error(
                    cx,
                    crate::lang::codes::TYPE_MISMATCH,
                    arg.span,
                    "`-` cannot negate a constraint",
                )
                .help("use `not` to ask for the opposite of a constraint");
                Val::Error
            }
            (UnOp::Neg, other) => {
                let Some(n) = self.num_of(other, arg.span, cx) else {
                    return Val::Error;
                };
                let node = self.b.unary(UnaryOp::Neg, n.node, span);
                Val::Num(Num { node, ..n })
            }
        }
    }

    pub(super) fn binary(
        &mut self,
        op: BinOp,
        a: &'a Expr,
        b: &'a Expr,
        span: Span,
        env: &Env<'a>,
        cx: &Cx,
    ) -> Val {
        let va = self.expr(a, env, cx);
        let vb = self.expr(b, env, cx);
        if va == Val::Error || vb == Val::Error {
            return Val::Error;
        }
        if matches!(op, BinOp::And | BinOp::Or) {
            return match (va, vb) {
                (Val::Formula(x), Val::Formula(y)) => Val::Formula(Rc::new(if op == BinOp::And {
                    Formula::And(x, y)
                } else {
                    Formula::Or(x, y)
                })),
                (x, y) => {
                    let (bad, e) = if matches!(x, Val::Formula(_)) {
                        (y, b)
                    } else {
                        (x, a)
                    };
                    self.error(
                        cx,
                        crate::lang::codes::TYPE_MISMATCH,
                        e.span,
                        format!(
                            "`{}` joins constraints, found {}",
                            op.symbol(),
                            bad.describe()
                        ),
                    )
                    .label(bad.describe())
                    .help("both sides must be comparisons, e.g. `head.y > 1 m and head.y < 2 m`");
                    Val::Error
                }
            };
        }
        if op.is_comparison() && (matches!(va, Val::Formula(_)) || matches!(vb, Val::Formula(_))) {
            self.error(
                cx,
                crate::lang::codes::CHAINED_COMPARISON,
                span,
                "comparisons cannot be chained",
            )
            .label("comparison of a comparison")
            .help("write `a < b and b < c`");
            return Val::Error;
        }
        let (Some(x), Some(y)) = (self.num_of(va, a.span, cx), self.num_of(vb, b.span, cx)) else {
            return Val::Error;
        };
        self.arith(op, x, y, (a.span, b.span), span, cx)
    }

    /// Arithmetic and comparisons on two numbers (checks kinds and units).
    pub fn arith(
        &mut self,
        op: BinOp,
        x: Num,
        y: Num,
        spans: (Span, Span),
        span: Span,
        cx: &Cx,
    ) -> Val {
        let kind = |n: &Num| if n.vector { "vector" } else { "scalar" };
        let unify = |s: &mut Self, what: &str| -> Option<Unit> {
            let u = x.unit.unify(y.unit);
            if u.is_none() {
                s.error(
                    cx,
                    crate::lang::codes::UNIT_MISMATCH,
                    span,
                    format!("cannot {what} {} and {}", x.unit, y.unit),
                )
                .label(format!("{} vs {}", x.unit, y.unit))
                .help(unit_hint(x.unit, y.unit));
            }
            u
        };
        match op {
            BinOp::Eq | BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge => {
                if x.vector != y.vector && op == BinOp::Eq {
                    self.error(cx, crate::lang::codes::TYPE_MISMATCH, span, format!("`==` compares a {} with a {}", kind(&x), kind(&y)))
                        .label("different kinds")
                        .help("compare a vector with a vector (distance) or a component with a number, e.g. `head.y == 1.6 m`");
                    return Val::Error;
                }
                if op != BinOp::Eq && !x.vector && y.vector {
                    self.error(cx, crate::lang::codes::TYPE_MISMATCH, span, format!("`{}` compares a scalar with a vector", op.symbol()))
                        .label("different kinds")
                        .help("put the vector on the left (all components), or compare components such as `.y`");
                    return Val::Error;
                }
                let Some(unit) = unify(self, "compare") else {
                    return Val::Error;
                };
                Val::Formula(Rc::new(Formula::Cmp {
                    op,
                    a: x.node,
                    b: y.node,
                    unit,
                    span,
                }))
            }
            BinOp::Add | BinOp::Sub => {
                if x.vector != y.vector {
                    self.error(
                        cx,
                        crate::lang::codes::TYPE_MISMATCH,
                        span,
                        format!(
                            "cannot {} a {} and a {}",
                            if op == BinOp::Add { "add" } else { "subtract" },
                            kind(&x),
                            kind(&y)
                        ),
                    )
                    .label("different kinds")
                    .help("vectors combine with vectors; use `[x, y, z]` or a component like `.y`");
                    return Val::Error;
                }
                let verb = if op == BinOp::Add { "add" } else { "subtract" };
                let Some(unit) = unify(self, verb) else {
                    return Val::Error;
                };
                let bop = if op == BinOp::Add {
                    BinaryOp::Add
                } else {
                    BinaryOp::Sub
                };
                let node = self.b.binary(bop, x.node, y.node, span);
                Val::Num(Num {
                    node,
                    unit,
                    vector: x.vector,
                })
            }
            BinOp::Mul => {
                if x.vector && y.vector {
                    self.error(
                        cx,
                        crate::lang::codes::TYPE_MISMATCH,
                        span,
                        "cannot multiply two vectors",
                    )
                    .label("vector * vector")
                    .help("use `dot(u, v)` or `cross(u, v)`");
                    return Val::Error;
                }
                let node = self.b.binary(BinaryOp::Mul, x.node, y.node, span);
                Val::Num(Num {
                    node,
                    unit: x.unit.times(y.unit),
                    vector: x.vector || y.vector,
                })
            }
            BinOp::Div => {
                if y.vector {
                    self.error(
                        cx,
                        crate::lang::codes::TYPE_MISMATCH,
                        spans.1,
                        "cannot divide by a vector",
                    )
                    .label("vector")
                    .help("divide by a scalar, e.g. `norm(v)`");
                    return Val::Error;
                }
                if self.b.const_of(y.node).is_some_and(|v| v.contains(&0.0)) {
                    self.error(
                        cx,
                        crate::lang::codes::DIVISION_BY_ZERO,
                        spans.1,
                        "division by zero",
                    )
                    .label("is 0")
                    .help("divide by a non-zero constant");
                    return Val::Error;
                }
                let node = self.b.binary(BinaryOp::Div, x.node, y.node, span);
                Val::Num(Num {
                    node,
                    unit: x.unit.per(y.unit),
                    vector: x.vector,
                })
            }
            BinOp::And | BinOp::Or => Val::Error,
        }
    }
}

/// A fix-it for two units that do not match.
pub fn unit_hint(a: Unit, b: Unit) -> String {
    let time = |u: Unit| u == Unit::S;
    let len = |u: Unit| u == Unit::M;
    if (time(a) && len(b)) || (len(a) && time(b)) {
        "one side is a distance (m) and the other a time (s); time positions go in `at`/`during`/`@`".into()
    } else if a == Unit::RAD || b == Unit::RAD {
        "angles (deg/rad) compare with angles; `angle(u, v)` gives one".into()
    } else {
        format!(
            "both sides need the same unit (here {a} and {b}); a bare number takes the other side's unit"
        )
    }
}
