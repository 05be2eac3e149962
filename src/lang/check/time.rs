//! Time positions: constant expressions such as `0`, `2s`, `40 frames`, `50%`, `start`,
//! `mid`, `end`, `end - 1`, or a parameter, turned into a [`TimePoint`] and checked
//! against the declared length. A bare number is a frame index.

use super::Checker;
use super::units::Unit;
use super::values::*;
use crate::lang::ir::TimePoint;
use crate::lang::syntax::ast::*;
use crate::skeleton::FPS;

const fn tp(frames: f64, fraction: f64) -> TimePoint {
    TimePoint { frames, fraction }
}

impl<'a> Checker<'a> {
    /// Evaluates a time position.
    pub fn time_point(&mut self, e: &'a Expr, env: &Env<'a>, cx: &Cx) -> Option<TimePoint> {
        let fps = f64::from(FPS);
        match &e.kind {
            ExprKind::Number(v, u) => match u {
                None | Some(UnitLit::Frames) => Some(tp(*v, 0.0)),
                Some(UnitLit::S) => Some(tp(v * fps, 0.0)),
                Some(UnitLit::Ms) => Some(tp(v * fps / 1000.0, 0.0)),
                Some(UnitLit::Percent) => Some(tp(0.0, v / 100.0)),
                Some(_) => {
                    self.not_a_time(e, cx, "a distance or angle");
                    None
                }
            },
            ExprKind::Name(n) if matches!(n.as_str(), "start" | "mid" | "end") => Some(tp(
                0.0,
                match n.as_str() {
                    "start" => 0.0,
                    "mid" => 0.5,
                    _ => 1.0,
                },
            )),
            ExprKind::Name(n) => {
                if let Some(Binding::Thunk {
                    expr,
                    env: tenv,
                    site,
                }) = lookup(env, n)
                {
                    let inner = Cx { site, ..cx.clone() };
                    return self.time_point(expr, &tenv, &inner);
                }
                if n == "time" {
                    self.not_a_time(e, cx, "`time`, the time of each frame (a value)");
                    return None;
                }
                let param = self.header.params.iter().find(|p| &p.name == n).cloned();
                match param {
                    Some(p) if p.value.len() == 1 && p.unit_value == Unit::S => {
                        Some(tp(p.value[0] * fps, 0.0))
                    }
                    Some(p) if p.value.len() == 1 && p.unit_value == Unit::FREE => {
                        Some(tp(p.value[0], 0.0))
                    }
                    Some(_) => {
                        self.not_a_time(e, cx, "a parameter that is not a time");
                        None
                    }
                    None => {
                        self.not_a_time(e, cx, "a name that is not a time");
                        None
                    }
                }
            }
            ExprKind::Unary(UnOp::Neg, a) => self
                .time_point(a, env, cx)
                .map(|t| tp(-t.frames, -t.fraction)),
            ExprKind::Binary(op @ (BinOp::Add | BinOp::Sub), a, b) => {
                let (x, y) = (self.time_point(a, env, cx), self.time_point(b, env, cx));
                let s = if *op == BinOp::Add { 1.0 } else { -1.0 };
                Some(tp(x?.frames + s * y?.frames, x?.fraction + s * y?.fraction))
            }
            ExprKind::Binary(op @ (BinOp::Mul | BinOp::Div), a, b) => {
                let (time, factor) = if *op == BinOp::Mul && self.plain_const(a, env).is_some() {
                    (b, self.plain_const(a, env))
                } else {
                    (a, self.plain_const(b, env))
                };
                let Some(k) = factor else {
                    self.not_a_time(e, cx, "a product of two times");
                    return None;
                };
                let k = if *op == BinOp::Div {
                    if k == 0.0 {
                        self.error(
                            cx,
                            crate::lang::codes::DIVISION_BY_ZERO,
                            e.span,
                            "division by zero",
                        )
                        .help("divide by a non-zero number");
                        return None;
                    }
                    1.0 / k
                } else {
                    k
                };
                self.time_point(time, env, cx)
                    .map(|t| tp(t.frames * k, t.fraction * k))
            }
            ExprKind::Error => None,
            _ => {
                self.not_a_time(e, cx, "not a constant time");
                None
            }
        }
    }

    /// A constant plain number (no unit), if `e` is one; reports nothing.
    fn plain_const(&self, e: &'a Expr, env: &Env<'a>) -> Option<f64> {
        match &e.kind {
            ExprKind::Number(v, None) => Some(*v),
            ExprKind::Name(n) if lookup(env, n).is_none() => {
                let p = self.header.params.iter().find(|p| &p.name == n)?;
                (p.value.len() == 1 && p.unit_value.is_plain()).then(|| p.value[0])
            }
            ExprKind::Unary(UnOp::Neg, a) => self.plain_const(a, env).map(|v| -v),
            _ => None,
        }
    }

    fn not_a_time(&mut self, e: &Expr, cx: &Cx, what: &str) {
        self.error(
            cx,
            crate::lang::codes::NOT_A_TIME,
            e.span,
            format!("expected a time position, found {what}"),
        )
        .label("not a time")
        .help(
            "times are frame numbers (`40`), seconds (`2s`), `40 frames`, percentages (`50%`), \
                   `start`, `mid`, `end`, or sums like `end - 1`",
        );
    }

    /// Reports a time outside `[0, length - 1]`; true when it is inside.
    pub fn check_time(&mut self, t: TimePoint, span: Span, cx: &Cx) -> bool {
        let len = self.header.length;
        let f = t.frame_unclamped(len);
        if (0.0..=(len - 1) as f64).contains(&f) {
            return true;
        }
        self.error(
            cx,
            crate::lang::codes::TIME_OUT_OF_RANGE,
            span,
            format!("frame {f} is outside the motion"),
        )
        .label(format!("frame {f}"))
        .help(format!(
            "the motion has {len} frames ({:.2} s), numbered 0 to {}; use `end` for the last frame",
            len as f64 / f64::from(FPS),
            len - 1
        ));
        false
    }

    /// Reports a `during a..b` range that is empty or leaves the motion.
    pub fn check_range(&mut self, a: TimePoint, b: TimePoint, span: Span, cx: &Cx) -> bool {
        let len = self.header.length;
        let (fa, fb) = (a.frame_unclamped(len), b.frame_unclamped(len));
        if fa < 0.0 || fb > len as f64 || fa >= fb {
            let why = if fa >= fb {
                format!("from frame {fa} to {fb} is empty")
            } else {
                format!("frames {fa}..{fb} leave the motion")
            };
            self.error(cx, crate::lang::codes::TIME_OUT_OF_RANGE, span, format!("the range {why}"))
                .label("bad range")
                .help(format!(
                    "`during a..b` covers frames a ≤ t < b with 0 ≤ a < b ≤ {len} (the length); `during 0%..100%` is all of it"
                ));
            return false;
        }
        true
    }
}
