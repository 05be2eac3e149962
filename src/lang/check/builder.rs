//! Builds IR nodes: shape inference (frames, lanes, channels), common-subexpression
//! sharing (identical ops become one node) and constant folding (ops on constants are
//! computed at check time, so static `if`s and weights cost nothing at run time).

use crate::lang::ir::*;
use crate::lang::syntax::ast::Span;
use std::collections::HashMap;

/// Largest number of IR nodes a program may produce (guards inlining blow-ups).
pub const MAX_NODES: usize = 50_000;

/// Accumulates nodes and domains.
#[derive(Default)]
pub struct Builder {
    pub nodes: Vec<Node>,
    pub domains: Vec<Domain>,
    cse: HashMap<String, NodeId>,
    domain_cse: HashMap<String, DomainId>,
    /// Set once [`MAX_NODES`] is reached; later nodes are dropped onto node 0.
    pub overflow: bool,
}

impl Builder {
    /// A builder whose domain 0 is `All`.
    pub fn new() -> Self {
        let mut b = Builder::default();
        b.domain(Domain::All);
        b.konst(&[0.0], Span::default());
        b
    }

    /// Interns a domain.
    pub fn domain(&mut self, d: Domain) -> DomainId {
        let key = format!("{d:?}");
        if let Some(&id) = self.domain_cse.get(&key) {
            return id;
        }
        self.domains.push(d);
        self.domain_cse.insert(key, self.domains.len() - 1);
        self.domains.len() - 1
    }

    /// True when domain `d` is a single keyframe.
    pub fn is_single(&self, d: DomainId) -> bool {
        matches!(&self.domains[d], Domain::At(p) if p.len() == 1)
    }

    fn push(&mut self, node: Node) -> NodeId {
        let key = format!(
            "{:?}|{:?}|{}|{}",
            node.op, node.frames, node.lanes, node.channels
        );
        if let Some(&id) = self.cse.get(&key) {
            return id;
        }
        if self.nodes.len() >= MAX_NODES {
            self.overflow = true;
            return 0;
        }
        self.nodes.push(node);
        self.cse.insert(key, self.nodes.len() - 1);
        self.nodes.len() - 1
    }

    /// The constant values of a node, if it is a constant.
    pub fn const_of(&self, n: NodeId) -> Option<&[f32]> {
        match &self.nodes[n].op {
            Op::Const(v) => Some(v),
            _ => None,
        }
    }

    /// A constant scalar or vector.
    pub fn konst(&mut self, values: &[f64], span: Span) -> NodeId {
        let values: Vec<f32> = values.iter().map(|&v| v as f32).collect();
        let channels = values.len();
        self.push(Node {
            op: Op::Const(values),
            span,
            frames: Frames::Const,
            lanes: 1,
            channels,
            motion: false,
        })
    }

    /// Joint positions.
    pub fn gather(&mut self, domain: DomainId, points: Vec<(usize, usize)>, span: Span) -> NodeId {
        let lanes = points.len();
        self.push(Node {
            op: Op::Gather { domain, points },
            span,
            frames: Frames::Domain(domain),
            lanes,
            channels: 3,
            motion: true,
        })
    }

    /// Centre of mass of each lane's person.
    pub fn mass_center(
        &mut self,
        domain: DomainId,
        persons: Vec<usize>,
        weights: Vec<f32>,
        span: Span,
    ) -> NodeId {
        let lanes = persons.len();
        self.push(Node {
            op: Op::MassCenter {
                domain,
                persons,
                weights,
            },
            span,
            frames: Frames::Domain(domain),
            lanes,
            channels: 3,
            motion: true,
        })
    }

    /// Seconds since the start at each frame of `domain` (`time`): per frame, not motion.
    pub fn time(&mut self, domain: DomainId, span: Span) -> NodeId {
        self.push(Node {
            op: Op::Time { domain },
            span,
            frames: Frames::Domain(domain),
            lanes: 1,
            channels: 1,
            motion: false,
        })
    }

    fn merge_frames(&self, a: Frames, b: Frames) -> Frames {
        match (a, b) {
            (Frames::Const, x) | (x, Frames::Const) => x,
            (Frames::Domain(x), Frames::Domain(y)) if x == y => a,
            (Frames::Domain(x), _) if self.is_single(x) => b,
            _ => a,
        }
    }

    fn node_like(&mut self, op: Op, span: Span, args: &[NodeId], channels: usize) -> NodeId {
        let mut frames = Frames::Const;
        let mut lanes = 1;
        let mut motion = false;
        for &a in args {
            let n = &self.nodes[a];
            frames = self.merge_frames(frames, n.frames);
            lanes = lanes.max(n.lanes);
            motion |= n.motion;
        }
        self.push(Node {
            op,
            span,
            frames,
            lanes,
            channels,
            motion,
        })
    }

    /// Channel `axis` of `arg`.
    pub fn component(&mut self, arg: NodeId, axis: usize, span: Span) -> NodeId {
        if let Some(v) = self.const_of(arg) {
            let x = f64::from(v[axis.min(v.len() - 1)]);
            return self.konst(&[x], span);
        }
        self.node_like(Op::Component { arg, axis }, span, &[arg], 1)
    }

    /// A vector from three scalars.
    pub fn compose(&mut self, xyz: [NodeId; 3], span: Span) -> NodeId {
        if let (Some(x), Some(y), Some(z)) = (
            self.const_of(xyz[0]),
            self.const_of(xyz[1]),
            self.const_of(xyz[2]),
        ) {
            let v = [f64::from(x[0]), f64::from(y[0]), f64::from(z[0])];
            return self.konst(&v, span);
        }
        self.node_like(Op::Compose(xyz), span, &xyz, 3)
    }

    /// Elementwise unary op.
    pub fn unary(&mut self, op: UnaryOp, arg: NodeId, span: Span) -> NodeId {
        if let Some(v) = self.const_of(arg) {
            let out: Vec<f64> = v.iter().map(|&x| op.apply(f64::from(x))).collect();
            return self.konst(&out, span);
        }
        let channels = self.nodes[arg].channels;
        self.node_like(Op::Unary { op, arg }, span, &[arg], channels)
    }

    /// Elementwise binary op with broadcasting.
    pub fn binary(&mut self, op: BinaryOp, a: NodeId, b: NodeId, span: Span) -> NodeId {
        let channels = self.nodes[a].channels.max(self.nodes[b].channels);
        if let (Some(x), Some(y)) = (self.const_of(a), self.const_of(b)) {
            let out: Vec<f64> = (0..channels)
                .map(|i| {
                    let xa = f64::from(x[i.min(x.len() - 1)]);
                    let yb = f64::from(y[i.min(y.len() - 1)]);
                    op.apply(xa, yb)
                })
                .collect();
            return self.konst(&out, span);
        }
        // x + 0, x * 1: skip the op (common after inlining library functions).
        let is = |n: NodeId, v: f32, s: &Self| {
            s.const_of(n).is_some_and(|c| c.iter().all(|&e| e == v))
                && s.nodes[n].channels <= channels
        };
        match op {
            BinaryOp::Add if is(b, 0.0, self) && self.nodes[a].channels == channels => return a,
            BinaryOp::Add if is(a, 0.0, self) && self.nodes[b].channels == channels => return b,
            BinaryOp::Sub if is(b, 0.0, self) && self.nodes[a].channels == channels => return a,
            BinaryOp::Mul | BinaryOp::Div
                if is(b, 1.0, self) && self.nodes[a].channels == channels =>
            {
                return a;
            }
            BinaryOp::Mul if is(a, 1.0, self) && self.nodes[b].channels == channels => return b,
            _ => {}
        }
        self.node_like(Op::Binary { op, a, b }, span, &[a, b], channels)
    }

    /// Sum over channels.
    pub fn sum_channels(&mut self, arg: NodeId, span: Span) -> NodeId {
        if self.nodes[arg].channels == 1 {
            return arg;
        }
        if let Some(v) = self.const_of(arg) {
            let s: f64 = v.iter().map(|&x| f64::from(x)).sum();
            return self.konst(&[s], span);
        }
        self.node_like(Op::SumChannels(arg), span, &[arg], 1)
    }

    /// Euclidean norm over channels.
    pub fn norm(&mut self, arg: NodeId, span: Span) -> NodeId {
        if let Some(v) = self.const_of(arg) {
            let s: f64 = v.iter().map(|&x| f64::from(x).powi(2)).sum::<f64>() + 1e-12;
            return self.konst(&[s.sqrt()], span);
        }
        self.node_like(Op::Norm(arg), span, &[arg], 1)
    }

    /// Cross product.
    pub fn cross(&mut self, a: NodeId, b: NodeId, span: Span) -> NodeId {
        if let (Some(x), Some(y)) = (self.const_of(a), self.const_of(b)) {
            let (x, y): (Vec<f64>, Vec<f64>) = (
                x.iter().map(|&v| v.into()).collect(),
                y.iter().map(|&v| v.into()).collect(),
            );
            let c = [
                x[1] * y[2] - x[2] * y[1],
                x[2] * y[0] - x[0] * y[2],
                x[0] * y[1] - x[1] * y[0],
            ];
            return self.konst(&c, span);
        }
        self.node_like(Op::Cross(a, b), span, &[a, b], 3)
    }

    /// `arg` re-labelled onto `domain`.
    pub fn relabel(&mut self, arg: NodeId, domain: DomainId, span: Span) -> NodeId {
        let n = &self.nodes[arg];
        if n.frames == Frames::Const {
            return arg;
        }
        let (lanes, channels, motion) = (n.lanes, n.channels, n.motion);
        self.push(Node {
            op: Op::Relabel(arg),
            span,
            frames: Frames::Domain(domain),
            lanes,
            channels,
            motion,
        })
    }

    /// Support-polygon distance.
    pub fn support_dist(
        &mut self,
        point: NodeId,
        feet: NodeId,
        lanes: usize,
        span: Span,
    ) -> NodeId {
        let frames = self.merge_frames(self.nodes[point].frames, self.nodes[feet].frames);
        self.push(Node {
            op: Op::SupportDist { point, feet },
            span,
            frames,
            lanes,
            channels: 1,
            motion: true,
        })
    }

    /// Mask `a < b` (all channels).
    pub fn less(&mut self, a: NodeId, b: NodeId, span: Span) -> NodeId {
        if let (Some(x), Some(y)) = (self.const_of(a), self.const_of(b)) {
            let n = x.len().max(y.len());
            let all = (0..n).all(|i| x[i.min(x.len() - 1)] < y[i.min(y.len() - 1)]);
            return self.konst(&[f64::from(u8::from(all))], span);
        }
        self.node_like(Op::Less { a, b }, span, &[a, b], 1)
    }
}
