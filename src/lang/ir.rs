//! The checked, backend-free IR: a serialisable list of tensor ops in SSA order, the
//! frame domains they are evaluated over, and the statements whose errors make up the
//! total. Produced by [`crate::lang::check`], consumed by [`crate::lang::eval`].
//!
//! Every value is a 4-d tensor `[batch, frames, lanes, channels]`:
//! * `frames` is the size of the node's frame domain, or 1 (broadcast) for values that are
//!   the same at every frame (constants, `x@t`);
//! * `lanes` is 1, or the number of unrolled loop iterations (`for j in …` runs all
//!   iterations side by side as lanes instead of repeating the ops);
//! * `channels` is 1 for scalars and masks, 3 for vectors.

use super::syntax::ast::Span;
use serde::{Deserialize, Serialize};

/// Index of a node in [`Ir::nodes`].
pub type NodeId = usize;
/// Index of a domain in [`Ir::domains`].
pub type DomainId = usize;

/// A frame position `round(frames + fraction · (F − 1))`, clamped to the motion, where F
/// is the number of frames evaluated: `2s` is `{40, 0}`, `end` is `{0, 1}`, `50%` is
/// `{0, 0.5}`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TimePoint {
    /// Absolute part, in frames.
    pub frames: f64,
    /// Part relative to the last frame.
    pub fraction: f64,
}

impl TimePoint {
    /// The frame index in a motion of `f` frames (unclamped).
    pub fn frame_unclamped(&self, f: usize) -> f64 {
        (self.frames + self.fraction * (f.max(1) - 1) as f64).round()
    }

    /// The frame index in a motion of `f` frames, clamped to `[0, f - 1]`.
    pub fn frame(&self, f: usize) -> usize {
        self.frame_unclamped(f).clamp(0.0, (f.max(1) - 1) as f64) as usize
    }
}

/// Which neighbour a finite difference reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Shift {
    /// `min(t + 1, F − 1)`: the later frame of a first difference.
    VelHi,
    /// `min(t + 1, F − 1) − 1`: the earlier frame of a first difference.
    VelLo,
    /// `min(t, F − 3) + k`: frame k of a second difference.
    Acc(u8),
}

/// A set of frames, resolved to a list of indices once the frame count is known.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Domain {
    /// Every frame, in order.
    All,
    /// The listed keyframes (duplicates removed, in the order given).
    At(Vec<TimePoint>),
    /// Frames in `[from, to)`.
    During(TimePoint, TimePoint),
    /// Frames of the first domain that are also in the second.
    Intersect(DomainId, DomainId),
    /// Each frame of `base` mapped to a neighbour (velocities, accelerations).
    Shift(DomainId, Shift),
}

/// Whether a node varies along the frame axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Frames {
    /// Size 1: the same at every frame.
    Const,
    /// One entry per frame of the domain.
    Domain(DomainId),
}

/// Elementwise one-argument ops.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum UnaryOp {
    Neg,
    Abs,
    /// `sqrt(max(x, 0) + 1e-12)`: finite gradient at 0.
    Sqrt,
    /// `max(x, 0)`.
    Relu,
    Sin,
    Cos,
    Square,
    /// `1 − x` (mask complement).
    OneMinus,
}

/// Elementwise two-argument ops (with broadcasting).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum BinaryOp {
    Add,
    Sub,
    Mul,
    Div,
    Min,
    Max,
    Atan2,
}

impl UnaryOp {
    /// The op on one number (constant folding, still-pose evaluation).
    pub fn apply(self, x: f64) -> f64 {
        match self {
            UnaryOp::Neg => -x,
            UnaryOp::Abs => x.abs(),
            UnaryOp::Sqrt => (x.max(0.0) + 1e-12).sqrt(),
            UnaryOp::Relu => x.max(0.0),
            UnaryOp::Sin => x.sin(),
            UnaryOp::Cos => x.cos(),
            UnaryOp::Square => x * x,
            UnaryOp::OneMinus => 1.0 - x,
        }
    }
}

impl BinaryOp {
    /// The op on two numbers (constant folding, still-pose evaluation).
    pub fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            BinaryOp::Add => a + b,
            BinaryOp::Sub => a - b,
            BinaryOp::Mul => a * b,
            BinaryOp::Div => a / b,
            BinaryOp::Min => a.min(b),
            BinaryOp::Max => a.max(b),
            BinaryOp::Atan2 => a.atan2(b),
        }
    }
}

/// One tensor op.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Op {
    /// A constant `[1, 1, 1, len]`.
    Const(Vec<f32>),
    /// Joint positions `[B, |D|, K, 3]`: lane k reads `(person, joint)` = `points[k]`.
    Gather {
        domain: DomainId,
        points: Vec<(usize, usize)>,
    },
    /// Weighted sum over all 22 joints of each lane's person `[B, |D|, K, 3]`.
    MassCenter {
        domain: DomainId,
        persons: Vec<usize>,
        weights: Vec<f32>,
    },
    /// Seconds since the start (`time`) at each frame of the domain `[1, |D|, 1, 1]`:
    /// frame index / fps, a constant of the frame (no gradient, the same for every sample).
    Time { domain: DomainId },
    /// Channel `axis` of a vector.
    Component { arg: NodeId, axis: usize },
    /// Three scalars stacked into a vector.
    Compose([NodeId; 3]),
    /// Elementwise op.
    Unary { op: UnaryOp, arg: NodeId },
    /// Elementwise op.
    Binary { op: BinaryOp, a: NodeId, b: NodeId },
    /// Sum over channels.
    SumChannels(NodeId),
    /// `sqrt(Σ x² + 1e-12)` over channels.
    Norm(NodeId),
    /// Cross product of two vectors.
    Cross(NodeId, NodeId),
    /// The argument re-labelled onto another frame domain of the same size (finite
    /// differences read shifted domains and are labelled with the statement's domain).
    Relabel(NodeId),
    /// Signed ground distance of `point` to the support polygon of the 4 foot joints in
    /// `feet` (a gather with 4 lanes per lane): positive outside, negative inside.
    SupportDist { point: NodeId, feet: NodeId },
    /// Mask `a < b` as 0/1, all channels (no gradient).
    Less { a: NodeId, b: NodeId },
}

impl Op {
    /// The nodes this op reads.
    pub fn args(&self) -> Vec<NodeId> {
        match self {
            Op::Const(_) | Op::Gather { .. } | Op::MassCenter { .. } | Op::Time { .. } => vec![],
            Op::Component { arg, .. } | Op::Unary { arg, .. } => vec![*arg],
            Op::SumChannels(a) | Op::Norm(a) | Op::Relabel(a) => vec![*a],
            Op::Compose(a) => a.to_vec(),
            Op::Binary { a, b, .. } | Op::Cross(a, b) | Op::Less { a, b } => vec![*a, *b],
            Op::SupportDist { point, feet } => vec![*point, *feet],
        }
    }

    /// Remaps the nodes this op reads.
    pub fn map_args(&mut self, f: impl Fn(NodeId) -> NodeId) {
        match self {
            Op::Const(_) | Op::Gather { .. } | Op::MassCenter { .. } | Op::Time { .. } => {}
            Op::Component { arg, .. } | Op::Unary { arg, .. } => *arg = f(*arg),
            Op::SumChannels(a) | Op::Norm(a) | Op::Relabel(a) => *a = f(*a),
            Op::Compose(a) => a.iter_mut().for_each(|x| *x = f(*x)),
            Op::Binary { a, b, .. } | Op::Cross(a, b) | Op::Less { a, b } => {
                *a = f(*a);
                *b = f(*b);
            }
            Op::SupportDist { point, feet } => {
                *point = f(*point);
                *feet = f(*feet);
            }
        }
    }
}

/// A node: an op, the source it came from, and its shape.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Node {
    /// What to compute.
    pub op: Op,
    /// The source that asked for it (for runtime messages).
    pub span: Span,
    /// Frame axis.
    pub frames: Frames,
    /// Lane count (1 or the statement's lane count).
    pub lanes: usize,
    /// 1 or 3.
    pub channels: usize,
    /// True when the value depends on the motion.
    pub motion: bool,
}

/// One statement: its error per (sample, frame, lane), where it applies, and its weight.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Statement {
    /// Error `[B, |D| or 1, K or 1, 1]`.
    pub error: NodeId,
    /// Optional 0/1 mask of the frames it applies to (from `if`), same layout.
    pub mask: Option<NodeId>,
    /// Frames it applies to.
    pub domain: DomainId,
    /// Number of unrolled loop iterations it stands for.
    pub lanes: usize,
    /// Multiplier of its mean error.
    pub weight: f64,
    /// The constraint's source.
    pub span: Span,
    /// 1-based source line.
    pub line: usize,
    /// `line N: <source text>`.
    pub label: String,
    /// Unit of the error (`m`, `m/s`, `rad`, …).
    pub unit: String,
    /// `minimize`/`maximize`: a value to push, not a constraint to meet.
    #[serde(default)]
    pub objective: bool,
}

/// A whole checked program, ready to evaluate.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Ir {
    /// Ops in evaluation order.
    pub nodes: Vec<Node>,
    /// Frame domains.
    pub domains: Vec<Domain>,
    /// Statements, in source order.
    pub statements: Vec<Statement>,
    /// Number of people (tensor axis 1).
    pub people: usize,
    /// Declared length in frames.
    pub length: usize,
    /// Declared spacing of the people's start placements in metres (`None`: the default).
    #[serde(default)]
    pub spacing: Option<f64>,
    /// Declared starts (`at`/`facing`), one per person (or empty): they override the
    /// default placement's position, its facing, or both.
    #[serde(default)]
    pub starts: Vec<StartOverride>,
}

/// A person's declared start: where they stand on frame 0 and which way they face.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StartOverride {
    /// Ground position `(x, z)` in metres.
    pub at: Option<[f64; 2]>,
    /// Facing as a yaw about +Y in radians (`(sin yaw, 0, cos yaw)`; 0 faces +Z).
    pub yaw: Option<f64>,
}

/// What evaluating a program costs, estimated at the declared length.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CostEstimate {
    /// Tensor ops of one evaluation (forward), statement reductions included.
    pub ops: usize,
    /// Tensor elements produced per sample in one forward pass.
    pub elements_per_sample: usize,
}

impl CostEstimate {
    /// Rough element work of forward + backward for a batch (backward ≈ 2× forward).
    pub fn work(&self, batch: usize) -> f64 {
        3.0 * self.elements_per_sample as f64 * batch as f64
    }

    /// Tensor elements one forward pass produces for a batch of `batch` motions.
    pub fn elements(&self, batch: usize) -> usize {
        self.elements_per_sample.saturating_mul(batch)
    }
}

impl Ir {
    /// Where each person starts: the default placements, `spacing` metres apart when the
    /// program declares one, with each declared `at`/`facing` put in.
    pub fn start_placements(&self) -> Vec<crate::scene::Placement> {
        let spacing = self
            .spacing
            .map_or(crate::scene::DEFAULT_SPACING, |s| s as f32);
        let mut places = crate::scene::Placement::defaults(self.people, spacing);
        for (place, start) in places.iter_mut().zip(&self.starts) {
            if let Some([x, z]) = start.at {
                place.x = x as f32;
                place.z = z as f32;
            }
            if let Some(yaw) = start.yaw {
                place.yaw = yaw as f32;
            }
        }
        places
    }

    /// Frame indices of a domain for a motion of `f` frames.
    pub fn resolve_domain(&self, d: DomainId, f: usize) -> Vec<usize> {
        let last = f.max(1) - 1;
        match &self.domains[d] {
            Domain::All => (0..f).collect(),
            Domain::At(points) => {
                let mut out: Vec<usize> = Vec::with_capacity(points.len());
                for p in points {
                    let t = p.frame(f);
                    if !out.contains(&t) {
                        out.push(t);
                    }
                }
                out
            }
            Domain::During(a, b) => {
                let a = a.frame_unclamped(f).clamp(0.0, f as f64) as usize;
                let b = b.frame_unclamped(f).clamp(0.0, f as f64) as usize;
                (a..b.max(a)).collect()
            }
            Domain::Intersect(a, b) => {
                let inner = self.resolve_domain(*b, f);
                self.resolve_domain(*a, f)
                    .into_iter()
                    .filter(|t| inner.contains(t))
                    .collect()
            }
            Domain::Shift(base, shift) => self
                .resolve_domain(*base, f)
                .into_iter()
                .map(|t| match shift {
                    Shift::VelHi => (t + 1).min(last),
                    Shift::VelLo => (t + 1).min(last).saturating_sub(1),
                    Shift::Acc(k) => (t.min(last.saturating_sub(2)) + *k as usize).min(last),
                })
                .collect(),
        }
    }

    /// Per frame of a motion of `f` frames, whether some statement's error reads it: the
    /// frames of every joint read (`Gather`, `MassCenter`) its error or its `if` mask
    /// depends on, so a velocity's or an acceleration's neighbours count and a read at a
    /// keyframe (`hand@2s`) counts only there. A statement of weight 0 reads nothing.
    /// Whether the statement is met does not matter: a met frame is still constrained.
    pub fn active_frames(&self, f: usize) -> Vec<bool> {
        let mut live = vec![false; self.nodes.len()];
        for s in self.statements.iter().filter(|s| s.weight != 0.0) {
            live[s.error] = true;
            if let Some(m) = s.mask {
                live[m] = true;
            }
        }
        let mut active = vec![false; f];
        for i in (0..self.nodes.len()).rev() {
            if !live[i] {
                continue;
            }
            let op = &self.nodes[i].op;
            op.args().into_iter().for_each(|a| live[a] = true);
            if let Op::Gather { domain, .. } | Op::MassCenter { domain, .. } = op {
                for t in self.resolve_domain(*domain, f) {
                    if let Some(a) = active.get_mut(t) {
                        *a = true;
                    }
                }
            }
        }
        active
    }

    /// Number of frames a node spans for a motion of `f` frames.
    pub fn frames_of(&self, n: NodeId, f: usize) -> usize {
        match self.nodes[n].frames {
            Frames::Const => 1,
            Frames::Domain(d) => self.resolve_domain(d, f).len(),
        }
    }

    /// Estimated cost of one evaluation at the declared length.
    pub fn cost_estimate(&self) -> CostEstimate {
        self.cost_estimate_at(self.length)
    }

    /// Estimated cost of one evaluation on motions of `frames` frames.
    pub fn cost_estimate_at(&self, frames: usize) -> CostEstimate {
        let f = frames.max(1);
        let mut domain_len = vec![None; self.domains.len()];
        let mut len_of = |d: DomainId| -> usize {
            *domain_len[d].get_or_insert_with(|| self.resolve_domain(d, f).len())
        };
        let mut elements = 0usize;
        let mut ops = 0usize;
        for node in &self.nodes {
            let frames = match node.frames {
                Frames::Const => 1,
                Frames::Domain(d) => len_of(d),
            };
            let per_op = match &node.op {
                Op::SupportDist { .. } => 30,
                Op::MassCenter { .. } => 3,
                Op::Less { .. } => 3,
                _ => 1,
            };
            ops += per_op;
            let node_elements = (per_op * frames)
                .saturating_mul(node.lanes)
                .saturating_mul(node.channels);
            elements = elements.saturating_add(node_elements);
        }
        for s in &self.statements {
            ops += if s.mask.is_some() { 6 } else { 3 };
            elements = elements.saturating_add(len_of(s.domain).saturating_mul(s.lanes * 2));
        }
        CostEstimate {
            ops: ops + 2,
            elements_per_sample: elements,
        }
    }
}

#[cfg(test)]
mod tests {
    /// The frames of a 60-frame motion that `body` (a program of 60 frames) reads.
    fn active(body: &str) -> Vec<usize> {
        let source = format!("prompt \"a person walks\"\nlength 60 frames\n{body}\n");
        let p = crate::lang::compile(&source, "t.mprog", &[]).unwrap_or_else(|d| panic!("{d:?}"));
        let a = p.ir().active_frames(60);
        (0..60).filter(|&t| a[t]).collect()
    }

    #[test]
    fn active_frames_are_the_frames_statements_read() {
        // A window: its frames, met or not.
        let second_half = active("during 50%..end + 1 { dist(l_hand, head) < 15 cm }");
        assert_eq!(second_half, (30..60).collect::<Vec<_>>());
        assert_eq!(
            active("during 50%..100% { dist(l_hand, head) < 15 cm }"),
            (30..59).collect::<Vec<_>>()
        );
        // Every frame, at top level or in `always`.
        assert_eq!(active("head.y > 0 m").len(), 60);
        assert_eq!(active("always { head.y > 0 m }").len(), 60);
        // A velocity reads the next frame too; an acceleration the next two.
        assert_eq!(
            active("during 1s..2s { vel(pelvis).y < 1 m/s }"),
            (20..41).collect::<Vec<_>>()
        );
        assert_eq!(active("at 1s { norm(acc(pelvis)) < 1 }"), [20, 21, 22]);
        // A keyframe read inside another keyframe: both frames, nothing between.
        assert_eq!(active("at 2s { dist(l_hand, head@1s) < 10 cm }"), [20, 40]);
        // A statement of weight 0 counts for nothing.
        assert_eq!(
            active("weight 0 { head.y > 0 m }\nat end { head.y > 0 m }"),
            [59]
        );
    }
}
