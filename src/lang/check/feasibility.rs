//! Constraints no motion can meet, found before anything runs by interval arithmetic
//! over the IR.
//!
//! Every joint coordinate a statement reads is bounded: heights by what a human body
//! reaches, ground positions by where the person starts (the solvers pin each person's
//! pelvis at frame 0 to its start placement) plus how far a body reaches from its pelvis
//! and how far a person can run by that frame. Propagating those intervals through the
//! statement's ops bounds its error from below; a constraint whose error is bounded away
//! from zero on every frame it applies to can never be met (`at start { pelvis.x > 1 m }`,
//! `head.y > 3 m`, `at 1s { pelvis.z > 20 m }`). The bounds are generous, so a warning is
//! certain; many impossible constraints (limb lengths between two joints) go unnoticed.

use crate::lang::ir::{BinaryOp, Ir, NodeId, Op, UnaryOp};
use crate::scene::Placement;

/// Ground distance a joint other than the pelvis reaches from the pelvis (m).
const REACH: f64 = 1.4;
/// Slack on the pinned pelvis position at frame 0 (m).
const PINNED: f64 = 0.02;
/// Fastest horizontal travel (m per frame at 20 fps: 10 m/s).
const TRAVEL_PER_FRAME: f64 = 0.5;
/// Heights any joint can take (m): a little under the floor to a jump with arms up.
const HEIGHT: (f64, f64) = (-0.3, 3.0);
/// Errors below this are "met" (the smooth norms leave ~1e-6).
const TOLERANCE: f64 = 1e-3;

#[derive(Clone, Copy, Debug, PartialEq)]
struct Iv {
    lo: f64,
    hi: f64,
}

impl Iv {
    const ANY: Iv = Iv {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };

    fn new(lo: f64, hi: f64) -> Iv {
        if lo.is_nan() || hi.is_nan() {
            Iv::ANY
        } else {
            Iv { lo, hi }
        }
    }

    fn point(x: f64) -> Iv {
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
type Bounds = Vec<Iv>;

fn broadcast(v: &Bounds, c: usize) -> Iv {
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
/// `last` (None: the domain is empty).
fn joint_bounds(points: &[(usize, usize)], last: usize, starts: &[Placement]) -> Bounds {
    let travel = TRAVEL_PER_FRAME * last as f64;
    let mut out: Option<Bounds> = None;
    for &(person, joint) in points {
        let start = starts.get(person).copied().unwrap_or(Placement::IDENTITY);
        let r = travel + if joint == 0 { PINNED } else { REACH };
        let b = vec![
            Iv::new(f64::from(start.x) - r, f64::from(start.x) + r),
            Iv::new(HEIGHT.0, HEIGHT.1),
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
enum Pick {
    /// The latest: bounds that hold on every frame.
    Latest,
    /// The earliest: bounds on the first frame each statement applies to.
    Earliest,
}

/// Bounds of every node of `ir`.
fn node_bounds(ir: &Ir, starts: &[Placement], pick: Pick) -> Vec<Bounds> {
    let mut out: Vec<Bounds> = Vec::with_capacity(ir.nodes.len());
    let last_frame = |d| {
        let frames = ir.resolve_domain(d, ir.length).into_iter();
        match pick {
            Pick::Latest => frames.max(),
            Pick::Earliest => frames.min(),
        }
        .unwrap_or(ir.length.saturating_sub(1))
    };
    for node in &ir.nodes {
        let get = |i: NodeId| &out[i];
        let b: Bounds = match &node.op {
            Op::Const(v) => v.iter().map(|&x| Iv::point(f64::from(x))).collect(),
            Op::Gather { domain, points } => joint_bounds(points, last_frame(*domain), starts),
            Op::MassCenter {
                domain, persons, ..
            } => {
                let points: Vec<(usize, usize)> = persons.iter().map(|&p| (p, 1)).collect();
                joint_bounds(&points, last_frame(*domain), starts)
            }
            Op::Component { arg, axis } => vec![broadcast(get(*arg), *axis)],
            Op::Compose(a) => a.iter().map(|&i| broadcast(get(i), 0)).collect(),
            Op::Unary { op, arg } => unary(*op, get(*arg)),
            Op::Binary { op, a, b } => binary(*op, get(*a), get(*b)),
            Op::SumChannels(a) => vec![get(*a).iter().fold(Iv::point(0.0), |s, x| s.add(*x))],
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

/// `(statement index, lowest possible error)` of every constraint no motion can meet.
/// Objectives (`minimize`), statements under an `if` and weight-0 statements are skipped.
///
/// A statement's error is the mean over its frames. With bounds valid on every frame, a
/// positive lower bound is the answer. Joints read on the statement's earliest frame are
/// bounded tighter (less time to travel); when the error can never be negative, a positive
/// bound on that one frame alone makes the mean positive too.
pub fn never_met(ir: &Ir) -> Vec<(usize, f64)> {
    let starts = ir.start_placements();
    let every = node_bounds(ir, &starts, Pick::Latest);
    let first = node_bounds(ir, &starts, Pick::Earliest);
    let lowest = |b: &Bounds| b.iter().map(|x| x.lo).fold(f64::INFINITY, f64::min);
    ir.statements
        .iter()
        .enumerate()
        .filter(|(_, s)| s.mask.is_none() && s.weight > 0.0 && !s.objective)
        .filter_map(|(i, s)| {
            let anywhere = lowest(&every[s.error]);
            if anywhere.is_finite() && anywhere > TOLERANCE {
                return Some((i, anywhere));
            }
            let frames = ir.resolve_domain(s.domain, ir.length).len().max(1);
            let mean = lowest(&first[s.error]) / frames as f64;
            (anywhere >= 0.0 && mean.is_finite() && mean > TOLERANCE).then_some((i, mean))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use crate::lang::check_source;

    fn flagged(source: &str) -> usize {
        let d = check_source(source, "t.mprog", &[]);
        assert_eq!(d.error_count(), 0, "{}", d.render_plain());
        d.warnings()
            .filter(|w| w.code == "mprog::never_met")
            .count()
    }

    #[test]
    fn impossible_constraints_are_flagged() {
        for body in [
            "at start { pelvis.x > 1 m }",
            "head.y > 3.5 m",
            "at 1s { pelvis.z > 20 m }",
            "at start { groundDist(pelvis, [-1.5, 0, 0]) < 30 cm }",
            "l_foot.y < -1 m",
            "at start, end { groundDist(pelvis, [-1.5, 0, 0]) < 30 cm }",
        ] {
            assert_eq!(flagged(&format!("length 4s\n{body}\n")), 1, "{body}");
        }
        let two = "length 4s\npeople a \"x\", b \"y\"\nat start { groundDist(a.pelvis, b.pelvis) < 1 m }\n";
        assert_eq!(flagged(two), 1);
        // Placed 0.8 m apart by `spacing`, the same start is possible.
        let close = two.replace("length 4s", "length 4s\nspacing 80 cm");
        assert_eq!(flagged(&close), 0);
    }

    #[test]
    fn possible_ones_objectives_and_conditionals_are_not() {
        for body in [
            "at 1s { pelvis.z > 5 m }",
            "at end { pelvis.x > 3 m }",
            "head.y > 1.5 m",
            "at start { r_hand.x < -0.5 m }",
            "minimize head.y + 10 m",
            "if head.y > 1 m { head.y > 5 m }",
            "weight 0 { head.y > 5 m }",
            "not (head.y > 5 m)",
            "head.y > 5 m or head.y < 1 m",
            "during 1s..end { groundDist(pelvis, [-1.5, 0, 0]) < 30 cm }",
            "at start { not (pelvis.x > 1 m) }",
        ] {
            assert_eq!(flagged(&format!("length 4s\n{body}\n")), 0, "{body}");
        }
    }

    #[test]
    fn no_shipped_program_is_flagged() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/programs");
        let mut n = 0;
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "mprog") {
                let source = std::fs::read_to_string(&path).unwrap();
                assert_eq!(flagged(&source), 0, "{}", path.display());
                n += 1;
            }
        }
        assert!(n >= 12);
    }
}
