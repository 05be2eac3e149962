//! Interval bounds of IR nodes under [`Limits`] on where joints can be: the arithmetic
//! under the checker's motion-independent warnings (`feasibility.rs`, `reach.rs`).
//!
//! Every joint coordinate a node reads is bounded: heights by what a human body reaches,
//! ground positions by where the person starts (the solvers pin each person's pelvis at
//! frame 0 to its start placement) plus how far a body reaches from its pelvis and how far
//! a person can run by that frame. The bounds propagate through the ops; a node's bounds
//! hold on every frame and lane it has.

use crate::lang::ir::{BinaryOp, Ir, NodeId, Op, Statement, UnaryOp};
use crate::scene::Placement;
use std::collections::HashMap;

/// Errors below this are "met" (the smooth norms leave ~1e-6).
pub(super) const TOLERANCE: f64 = 1e-3;

/// Where the joints of a body can be: the assumptions behind a bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Limits {
    /// Ground distance a joint other than the pelvis reaches from the pelvis (m).
    pub reach: f64,
    /// Slack on the pinned pelvis position at frame 0 (m).
    pub pinned: f64,
    /// Fastest horizontal travel (m per frame).
    pub travel_per_frame: f64,
    /// Heights any joint can take (m).
    pub height: (f64, f64),
}

impl Limits {
    /// Generous limits no motion escapes: a warning under them is certain.
    pub const BODY: Limits = Limits {
        reach: 1.4,
        pinned: 0.02,
        // 10 m/s at 20 fps.
        travel_per_frame: 0.5,
        // A little under the floor to a jump with arms up.
        height: (-0.3, 3.0),
    };
}

/// A closed interval; NaN bounds widen to the whole line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Iv {
    pub lo: f64,
    pub hi: f64,
}

impl Iv {
    pub const ANY: Iv = Iv {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };

    pub fn new(lo: f64, hi: f64) -> Iv {
        if lo.is_nan() || hi.is_nan() {
            Iv::ANY
        } else {
            Iv { lo, hi }
        }
    }

    pub fn point(x: f64) -> Iv {
        Iv::new(x, x)
    }

    fn union(self, o: Iv) -> Iv {
        Iv::new(self.lo.min(o.lo), self.hi.max(o.hi))
    }

    fn add(self, o: Iv) -> Iv {
        Iv::new(self.lo + o.lo, self.hi + o.hi)
    }

    fn neg(self) -> Iv {
        Iv::new(-self.hi, -self.lo)
    }

    fn mul(self, o: Iv) -> Iv {
        let p = [
            self.lo * o.lo,
            self.lo * o.hi,
            self.hi * o.lo,
            self.hi * o.hi,
        ];
        // 0 · ∞ is NaN: an infinite bound times zero stays unbounded.
        if p.iter().any(|x| x.is_nan()) {
            return Iv::ANY;
        }
        Iv::new(
            p.iter().copied().fold(f64::INFINITY, f64::min),
            p.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    }

    fn div(self, o: Iv) -> Iv {
        if o.lo <= 0.0 && o.hi >= 0.0 {
            return Iv::ANY;
        }
        self.mul(Iv::new(1.0 / o.hi, 1.0 / o.lo))
    }

    fn abs(self) -> Iv {
        if self.lo >= 0.0 {
            self
        } else if self.hi <= 0.0 {
            self.neg()
        } else {
            Iv::new(0.0, self.hi.max(-self.lo))
        }
    }

    fn square(self) -> Iv {
        let a = self.abs();
        Iv::new(a.lo * a.lo, a.hi * a.hi)
    }

    fn relu(self) -> Iv {
        Iv::new(self.lo.max(0.0), self.hi.max(0.0))
    }

    fn sqrt(self) -> Iv {
        let r = self.relu();
        Iv::new((r.lo + 1e-12).sqrt(), (r.hi + 1e-12).sqrt())
    }
}

/// Per-channel bounds of one node, over all its frames and lanes.
pub(super) type Bounds = Vec<Iv>;

pub(super) fn broadcast(v: &Bounds, c: usize) -> Iv {
    if v.len() == 1 { v[0] } else { v[c] }
}

fn binary(op: BinaryOp, a: &Bounds, b: &Bounds) -> Bounds {
    let n = a.len().max(b.len());
    (0..n)
        .map(|c| {
            let (x, y) = (broadcast(a, c), broadcast(b, c));
            match op {
                BinaryOp::Add => x.add(y),
                BinaryOp::Sub => x.add(y.neg()),
                BinaryOp::Mul => x.mul(y),
                BinaryOp::Div => x.div(y),
                BinaryOp::Min => Iv::new(x.lo.min(y.lo), x.hi.min(y.hi)),
                BinaryOp::Max => Iv::new(x.lo.max(y.lo), x.hi.max(y.hi)),
                BinaryOp::Atan2 => Iv::new(-std::f64::consts::PI, std::f64::consts::PI),
            }
        })
        .collect()
}

fn unary(op: UnaryOp, a: &Bounds) -> Bounds {
    a.iter()
        .map(|&x| match op {
            UnaryOp::Neg => x.neg(),
            UnaryOp::Abs => x.abs(),
            UnaryOp::Sqrt => x.sqrt(),
            UnaryOp::Relu => x.relu(),
            UnaryOp::Sin | UnaryOp::Cos => Iv::new(-1.0, 1.0),
            UnaryOp::Square => x.square(),
            UnaryOp::OneMinus => Iv::point(1.0).add(x.neg()),
        })
        .collect()
}

/// Where the joints of `points` can be on the frames of a domain whose last frame is
/// `last`.
pub(super) fn joint_bounds(
    points: &[(usize, usize)],
    last: usize,
    starts: &[Placement],
    lim: &Limits,
) -> Bounds {
    let travel = lim.travel_per_frame * last as f64;
    let mut out: Option<Bounds> = None;
    for &(person, joint) in points {
        let start = starts.get(person).copied().unwrap_or(Placement::IDENTITY);
        let r = travel + if joint == 0 { lim.pinned } else { lim.reach };
        let b = vec![
            Iv::new(f64::from(start.x) - r, f64::from(start.x) + r),
            Iv::new(lim.height.0, lim.height.1),
            Iv::new(f64::from(start.z) - r, f64::from(start.z) + r),
        ];
        out = Some(match out {
            None => b,
            Some(o) => o.iter().zip(&b).map(|(x, y)| x.union(*y)).collect(),
        });
    }
    out.unwrap_or_else(|| vec![Iv::ANY; 3])
}

/// Which frame of each joint read's domain the bounds are for.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum Pick {
    /// The latest: bounds that hold on every frame.
    Latest,
    /// The earliest: bounds on the first frame each statement applies to.
    Earliest,
}

/// What one bounds pass assumes.
pub(super) struct Pass<'a> {
    pub starts: &'a [Placement],
    pub limits: Limits,
    pub pick: Pick,
    /// Nodes whose bounds are given instead of computed.
    pub fixed: &'a [(NodeId, Bounds)],
}

impl Pass<'_> {
    /// Bounds of the nodes `ids` (ascending, closed under op arguments: a [`cone`]), in
    /// that order.
    pub fn run(&self, ir: &Ir, ids: &[NodeId]) -> Vec<Bounds> {
        let at: HashMap<NodeId, usize> = ids.iter().enumerate().map(|(k, &i)| (i, k)).collect();
        let mut out: Vec<Bounds> = Vec::with_capacity(ids.len());
        let last_frame = |d| {
            let frames = ir.resolve_domain(d, ir.length).into_iter();
            match self.pick {
                Pick::Latest => frames.max(),
                Pick::Earliest => frames.min(),
            }
            .unwrap_or(ir.length.saturating_sub(1))
        };
        let lim = &self.limits;
        for &id in ids {
            if let Some((_, b)) = self.fixed.iter().find(|(n, _)| *n == id) {
                out.push(b.clone());
                continue;
            }
            let node = &ir.nodes[id];
            let get = |i: NodeId| &out[at[&i]];
            let b: Bounds = match &node.op {
                Op::Const(v) => v.iter().map(|&x| Iv::point(f64::from(x))).collect(),
                Op::Gather { domain, points } => {
                    joint_bounds(points, last_frame(*domain), self.starts, lim)
                }
                Op::MassCenter {
                    domain, persons, ..
                } => {
                    let points: Vec<(usize, usize)> = persons.iter().map(|&p| (p, 1)).collect();
                    joint_bounds(&points, last_frame(*domain), self.starts, lim)
                }
                Op::Time { domain } => {
                    let frames = ir.resolve_domain(*domain, ir.length);
                    let fps = f64::from(crate::skeleton::FPS);
                    let lo = frames.iter().min().map_or(0.0, |&f| f as f64 / fps);
                    let hi = frames.iter().max().map_or(0.0, |&f| f as f64 / fps);
                    vec![Iv::new(lo, hi)]
                }
                Op::Component { arg, axis } => vec![broadcast(get(*arg), *axis)],
                Op::Compose(a) => a.iter().map(|&i| broadcast(get(i), 0)).collect(),
                Op::Unary { op, arg } => unary(*op, get(*arg)),
                Op::Binary { op, a, b } => binary(*op, get(*a), get(*b)),
                Op::SumChannels(a) => {
                    vec![get(*a).iter().fold(Iv::point(0.0), |s, x| s.add(*x))]
                }
                Op::Norm(a) => {
                    let s = get(*a)
                        .iter()
                        .fold(Iv::point(0.0), |s, x| s.add(x.square()));
                    vec![s.sqrt()]
                }
                Op::Cross(a, b) => {
                    let (a, b) = (get(*a), get(*b));
                    let c = |i: usize| broadcast(a, i);
                    let d = |i: usize| broadcast(b, i);
                    vec![
                        c(1).mul(d(2)).add(c(2).mul(d(1)).neg()),
                        c(2).mul(d(0)).add(c(0).mul(d(2)).neg()),
                        c(0).mul(d(1)).add(c(1).mul(d(0)).neg()),
                    ]
                }
                Op::Relabel(a) => get(*a).clone(),
                Op::SupportDist { .. } => vec![Iv::ANY],
                Op::Less { .. } => vec![Iv::new(0.0, 1.0); node.channels.max(1)],
            };
            out.push(b);
        }
        out
    }
}

/// The nodes a statement's error reads, itself included, ascending (its error last).
pub(super) fn cone(ir: &Ir, s: &Statement) -> Vec<NodeId> {
    let mut live = vec![false; s.error + 1];
    live[s.error] = true;
    for i in (0..=s.error).rev() {
        if live[i] {
            for a in ir.nodes[i].op.args() {
                live[a] = true;
            }
        }
    }
    (0..=s.error).filter(|&i| live[i]).collect()
}

/// The lowest value of any channel.
pub(super) fn lowest(b: &Bounds) -> f64 {
    b.iter().map(|x| x.lo).fold(f64::INFINITY, f64::min)
}
