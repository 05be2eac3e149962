//! Numeric built-ins: vector maths (`norm`, `normalize`, `dot`, `cross`), one-argument
//! functions (`abs`, `sq`, `sqrt`, `sin`, `cos`), `min`/`max`/`atan2`, `clamp` and `vec`.
//! In: the arguments' values ([`Num`], already elaborated). Out: the result's node, with
//! its unit and shape checked, or [`Val::Error`] after a diagnostic.

use super::Checker;
use super::builtins::BuiltinDoc;
use super::units::Unit;
use super::values::*;
use crate::lang::codes::{TYPE_MISMATCH, UNIT_MISMATCH};
use crate::lang::ir::{BinaryOp, NodeId, UnaryOp};
use crate::lang::syntax::ast::*;

/// One call of a numeric built-in: its name, its arguments' values and expressions.
struct NumCall<'c, 'a> {
    name: &'static str,
    v: &'c [Num],
    args: &'a [Expr],
    span: Span,
    cx: &'c Cx,
}

/// A number held by `node`.
fn num(node: NodeId, unit: Unit, vector: bool) -> Val {
    Val::Num(Num { node, unit, vector })
}

impl<'a> Checker<'a> {
    /// Elaborates the numeric built-in `b` on the arguments' values `v`.
    pub(super) fn numeric_builtin(
        &mut self,
        b: &BuiltinDoc,
        v: &[Num],
        args: &'a [Expr],
        span: Span,
        cx: &Cx,
    ) -> Val {
        let call = NumCall {
            name: b.name,
            v,
            args,
            span,
            cx,
        };
        match b.name {
            "norm" | "normalize" => self.norm_call(&call),
            "dot" | "cross" => self.product_call(&call),
            "abs" | "sq" | "sqrt" => self.power_call(&call),
            "sin" | "cos" => self.trig_call(&call),
            "min" | "max" | "atan2" => self.pairwise_call(&call),
            "clamp" => self.clamp_call(&call),
            "vec" => self.vec_call(&call),
            _ => Val::Error,
        }
    }

    /// The unit `x` and `y` share, or `None` after reporting that they mix units.
    fn unify_units(&mut self, c: &NumCall, x: &Num, y: &Num) -> Option<Unit> {
        let u = x.unit.unify(y.unit);
        if u.is_none() {
            let name = c.name;
            self.error(
                c.cx,
                UNIT_MISMATCH,
                c.span,
                format!("`{name}` mixes {} and {}", x.unit, y.unit),
            )
            .label(format!("{} vs {}", x.unit, y.unit))
            .help(super::ops::unit_hint(x.unit, y.unit));
        }
        u
    }

    /// `norm(v)`, in `v`'s unit, or `normalize(v)`, unitless.
    fn norm_call(&mut self, c: &NumCall) -> Val {
        let (v, span) = (c.v, c.span);
        if !self.want(&v[0], true, &c.args[0], c.name, c.cx) {
            return Val::Error;
        }
        if c.name == "norm" {
            num(self.b.norm(v[0].node, span), v[0].unit, false)
        } else {
            num(self.normalize(v[0].node, span), Unit::ONE, true)
        }
    }

    /// `dot(a, b)` or `cross(a, b)` of two vectors, in the product of their units.
    fn product_call(&mut self, c: &NumCall) -> Val {
        let (v, span) = (c.v, c.span);
        if !self.want(&v[0], true, &c.args[0], c.name, c.cx)
            || !self.want(&v[1], true, &c.args[1], c.name, c.cx)
        {
            return Val::Error;
        }
        let unit = v[0].unit.times(v[1].unit);
        if c.name == "cross" {
            num(self.b.cross(v[0].node, v[1].node, span), unit, true)
        } else {
            let m = self.b.binary(BinaryOp::Mul, v[0].node, v[1].node, span);
            num(self.b.sum_channels(m, span), unit, false)
        }
    }

    /// `abs`, `sq` or `sqrt`, element-wise; `sqrt` needs a unit with a square root.
    fn power_call(&mut self, c: &NumCall) -> Val {
        let v = c.v;
        let (op, unit) = match c.name {
            "abs" => (UnaryOp::Abs, Some(v[0].unit)),
            "sq" => (UnaryOp::Square, Some(v[0].unit.pow(2))),
            _ => (UnaryOp::Sqrt, v[0].unit.sqrt()),
        };
        let Some(unit) = unit else {
            self.error(
                c.cx,
                UNIT_MISMATCH,
                c.args[0].span,
                format!("`sqrt` of {} has no unit", v[0].unit),
            )
            .help("take square roots of squared quantities such as m²");
            return Val::Error;
        };
        num(self.b.unary(op, v[0].node, c.span), unit, v[0].vector)
    }

    /// `sin` or `cos` of a scalar angle.
    fn trig_call(&mut self, c: &NumCall) -> Val {
        let (v, name) = (c.v, c.name);
        if !self.want(&v[0], false, &c.args[0], name, c.cx) {
            return Val::Error;
        }
        if !v[0].unit.is_angle_like() {
            self.error(
                c.cx,
                UNIT_MISMATCH,
                c.args[0].span,
                format!("`{name}` needs an angle, found {}", v[0].unit),
            )
            .help(if v[0].unit == Unit::S {
                format!(
                    "a time is not an angle: multiply it by an angular rate, e.g. \
                     `{name}(180 deg/s * time)` (half a turn per second)"
                )
            } else {
                "write angles with `deg` or `rad`, e.g. `sin(30 deg)`".to_string()
            });
            return Val::Error;
        }
        let op = if name == "sin" {
            UnaryOp::Sin
        } else {
            UnaryOp::Cos
        };
        // A plain number, like a literal: `0.3 * cos(a)` takes the unit of what it meets
        // (`[0.3 * cos(a), 1.2, 0.3 * sin(a)]` is a point in metres).
        num(self.b.unary(op, v[0].node, c.span), Unit::FREE, false)
    }

    /// `min`, `max` or `atan2` of two scalars or two vectors in one unit.
    fn pairwise_call(&mut self, c: &NumCall) -> Val {
        let (v, name, span) = (c.v, c.name, c.span);
        if v[0].vector != v[1].vector {
            self.error(
                c.cx,
                TYPE_MISMATCH,
                span,
                format!("`{name}` of a scalar and a vector"),
            )
            .help("both arguments must be scalars, or both vectors");
            return Val::Error;
        }
        let Some(unit) = self.unify_units(c, &v[0], &v[1]) else {
            return Val::Error;
        };
        let (op, unit) = match name {
            "min" => (BinaryOp::Min, unit),
            "max" => (BinaryOp::Max, unit),
            _ => (BinaryOp::Atan2, Unit::RAD),
        };
        num(
            self.b.binary(op, v[0].node, v[1].node, span),
            unit,
            v[0].vector,
        )
    }

    /// `clamp(x, lo, hi)`: `min(max(x, lo), hi)`, the bounds scalars in `x`'s unit.
    fn clamp_call(&mut self, c: &NumCall) -> Val {
        let (v, span) = (c.v, c.span);
        let Some(u1) = self.unify_units(c, &v[0], &v[1]) else {
            return Val::Error;
        };
        let Some(unit) = self.unify_units(c, &Num { unit: u1, ..v[0] }, &v[2]) else {
            return Val::Error;
        };
        if v[1].vector || v[2].vector {
            self.error(c.cx, TYPE_MISMATCH, span, "`clamp` bounds must be scalars")
                .help("e.g. `clamp(t, 0, 1)`");
            return Val::Error;
        }
        let lo = self.b.binary(BinaryOp::Max, v[0].node, v[1].node, span);
        num(
            self.b.binary(BinaryOp::Min, lo, v[2].node, span),
            unit,
            v[0].vector,
        )
    }

    /// `vec(x, y, z)` of three scalars in one unit.
    fn vec_call(&mut self, c: &NumCall) -> Val {
        let v = c.v;
        for (n, e) in v.iter().zip(c.args) {
            if !self.want(n, false, e, c.name, c.cx) {
                return Val::Error;
            }
        }
        let Some(u1) = self.unify_units(c, &v[0], &v[1]) else {
            return Val::Error;
        };
        let Some(unit) = self.unify_units(c, &Num { unit: u1, ..v[0] }, &v[2]) else {
            return Val::Error;
        };
        num(
            self.b.compose([v[0].node, v[1].node, v[2].node], c.span),
            unit,
            true,
        )
    }
}
