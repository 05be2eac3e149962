//! A statement's error on one still pose, in f64, without burn: the IR evaluated with
//! every joint read at the pose. Only *pose statements* can be read this way: their error
//! depends on one person's joints on their own frames, through no time, finite
//! difference or support polygon, and it does not change when the body is moved on the
//! floor or turned about the vertical (heights, relative heights, distances between
//! joints; not ground positions or facing).

use crate::lang::ir::{Ir, NodeId, Op, Statement};
use crate::skeleton::NUM_JOINTS;

/// One person's joints (metres, Y up).
pub type Joints = [[f32; 3]; NUM_JOINTS];

/// A value: `lanes × channels`, each axis 1 (broadcast) or its size.
#[derive(Clone, Debug)]
struct Val {
    lanes: usize,
    channels: usize,
    data: Vec<f64>,
}

impl Val {
    fn at(&self, lane: usize, ch: usize) -> f64 {
        let l = if self.lanes == 1 { 0 } else { lane };
        let c = if self.channels == 1 { 0 } else { ch };
        self.data[l * self.channels + c]
    }

    fn map(&self, f: impl Fn(f64) -> f64) -> Val {
        Val {
            data: self.data.iter().map(|&x| f(x)).collect(),
            ..*self
        }
    }

    fn zip(a: &Val, b: &Val, f: impl Fn(f64, f64) -> f64) -> Val {
        let (lanes, channels) = (a.lanes.max(b.lanes), a.channels.max(b.channels));
        let mut data = Vec::with_capacity(lanes * channels);
        for l in 0..lanes {
            for c in 0..channels {
                data.push(f(a.at(l, c), b.at(l, c)));
            }
        }
        Val {
            lanes,
            channels,
            data,
        }
    }

    fn per_lane(&self, channels: usize, f: impl Fn(&[f64]) -> Vec<f64>) -> Val {
        let data = (0..self.lanes)
            .flat_map(|l| f(&self.data[l * self.channels..(l + 1) * self.channels]))
            .collect();
        Val {
            lanes: self.lanes,
            channels,
            data,
        }
    }
}

/// The nodes `root` depends on, ascending (SSA order).
pub fn cone(ir: &Ir, root: NodeId) -> Vec<NodeId> {
    let mut seen = vec![false; root + 1];
    let mut stack = vec![root];
    while let Some(n) = stack.pop() {
        if std::mem::replace(&mut seen[n], true) {
            continue;
        }
        stack.extend(ir.nodes[n].op.args());
    }
    (0..=root).filter(|&n| seen[n]).collect()
}

/// A statement readable on one still pose, with the nodes its error depends on.
#[derive(Clone, Debug)]
pub struct PoseStatement {
    /// Index in [`Ir::statements`].
    pub statement: usize,
    /// The person whose joints it reads.
    pub person: usize,
    /// The nodes of its error, ascending.
    pub nodes: Vec<NodeId>,
}

/// `s` (index `i`) as a pose statement, when its ops allow one (the placement test is
/// [`is_placement_free`]'s).
pub fn pose_statement(ir: &Ir, i: usize, s: &Statement) -> Option<PoseStatement> {
    if s.mask.is_some() || s.weight <= 0.0 || s.objective || s.unit != "m" {
        return None;
    }
    let frames = ir.resolve_domain(s.domain, ir.length);
    if frames.is_empty() {
        return None;
    }
    let nodes = cone(ir, s.error);
    let mut person = None;
    let mut same = |p: usize| person.replace(p).is_none_or(|q| q == p);
    for &n in &nodes {
        let ok = match &ir.nodes[n].op {
            Op::Gather { domain, points } => {
                ir.resolve_domain(*domain, ir.length) == frames
                    && points.iter().all(|&(p, _)| same(p))
            }
            Op::MassCenter {
                domain, persons, ..
            } => {
                ir.resolve_domain(*domain, ir.length) == frames && persons.iter().all(|&p| same(p))
            }
            Op::Time { .. } | Op::Relabel(_) | Op::SupportDist { .. } => false,
            _ => true,
        };
        if !ok {
            return None;
        }
    }
    Some(PoseStatement {
        statement: i,
        person: person?,
        nodes,
    })
}

/// The value of node `root` (one of `nodes`, the cone it needs) on the still pose `p`,
/// as `lanes × channels` (row-major) with its lane and channel counts.
pub fn eval_node(ir: &Ir, nodes: &[NodeId], root: NodeId, p: &Joints) -> (Vec<f64>, usize, usize) {
    let mut vals: Vec<Option<Val>> = vec![None; root + 1];
    for &n in nodes.iter().take_while(|&&n| n <= root) {
        let get = |k: NodeId| vals[k].as_ref().expect("SSA order");
        let v = match &ir.nodes[n].op {
            Op::Const(c) => Val {
                lanes: 1,
                channels: c.len(),
                data: c.iter().map(|&x| f64::from(x)).collect(),
            },
            Op::Gather { points, .. } => Val {
                lanes: points.len(),
                channels: 3,
                data: points
                    .iter()
                    .flat_map(|&(_, j)| p[j].map(f64::from))
                    .collect(),
            },
            Op::MassCenter {
                persons, weights, ..
            } => {
                let mut c = [0.0f64; 3];
                for (j, w) in weights.iter().enumerate() {
                    for (k, ck) in c.iter_mut().enumerate() {
                        *ck += f64::from(*w) * f64::from(p[j][k]);
                    }
                }
                Val {
                    lanes: persons.len(),
                    channels: 3,
                    data: (0..persons.len()).flat_map(|_| c).collect(),
                }
            }
            Op::Component { arg, axis } => get(*arg).per_lane(1, |x| vec![x[*axis]]),
            Op::Compose(args) => {
                let parts: Vec<&Val> = args.iter().map(|&a| get(a)).collect();
                let lanes = parts.iter().map(|v| v.lanes).max().unwrap_or(1);
                Val {
                    lanes,
                    channels: 3,
                    data: (0..lanes)
                        .flat_map(|l| parts.iter().map(move |v| v.at(l, 0)))
                        .collect(),
                }
            }
            Op::Unary { op, arg } => get(*arg).map(|x| op.apply(x)),
            Op::Binary { op, a, b } => Val::zip(get(*a), get(*b), |x, y| op.apply(x, y)),
            Op::SumChannels(a) => get(*a).per_lane(1, |x| vec![x.iter().sum()]),
            Op::Norm(a) => get(*a).per_lane(1, |x| {
                vec![(x.iter().map(|v| v * v).sum::<f64>() + 1e-12).sqrt()]
            }),
            Op::Cross(a, b) => {
                let (x, y) = (get(*a), get(*b));
                let lanes = x.lanes.max(y.lanes);
                let data = (0..lanes)
                    .flat_map(|l| {
                        let (u, v) = (
                            [x.at(l, 0), x.at(l, 1), x.at(l, 2)],
                            [y.at(l, 0), y.at(l, 1), y.at(l, 2)],
                        );
                        [
                            u[1] * v[2] - u[2] * v[1],
                            u[2] * v[0] - u[0] * v[2],
                            u[0] * v[1] - u[1] * v[0],
                        ]
                    })
                    .collect();
                Val {
                    lanes,
                    channels: 3,
                    data,
                }
            }
            Op::Less { a, b } => {
                let m = Val::zip(get(*a), get(*b), |x, y| f64::from(u8::from(x < y)));
                m.per_lane(1, |x| vec![x.iter().copied().fold(1.0, f64::min)])
            }
            // Not in a pose statement's cone.
            Op::Time { .. } | Op::Relabel(_) | Op::SupportDist { .. } => Val {
                lanes: 1,
                channels: 1,
                data: vec![f64::NAN],
            },
        };
        vals[n] = Some(v);
    }
    let v = vals[root].take().expect("root evaluated");
    (v.data, v.lanes, v.channels)
}

/// A pose statement's error on the still pose `p`: its error node summed over lanes.
pub fn error_on(ir: &Ir, s: &PoseStatement, p: &Joints) -> f64 {
    let root = ir.statements[s.statement].error;
    eval_node(ir, &s.nodes, root, p).0.iter().sum()
}

/// The ways a body is moved on the floor and turned that a pose statement must not see.
const MOVES: [(f32, f32, f32); 4] = [
    (0.9, 3.0, -0.6),
    (3.1, -2.5, 1.7),
    (-1.6, 0.4, 3.3),
    (0.0, -3.2, -2.9),
];

/// `p` turned by `yaw` about the vertical and moved by `(dx, dz)`.
fn moved(p: &Joints, (yaw, dx, dz): (f32, f32, f32)) -> Joints {
    let (s, c) = yaw.sin_cos();
    p.map(|[x, y, z]| [x * c + z * s + dx, y, -x * s + z * c + dz])
}

/// Whether `s`'s error is the same on each of `probes` moved and turned on the floor
/// (four moves of metres and turns up to half a circle): a statement on heights and
/// distances between joints is; one on ground positions or facing is not.
pub fn is_placement_free(ir: &Ir, s: &PoseStatement, probes: &[Joints]) -> bool {
    probes.iter().all(|p| {
        let e = error_on(ir, s, p);
        e.is_finite()
            && MOVES.iter().all(|&m| {
                let f = error_on(ir, s, &moved(p, m));
                (f - e).abs() <= 1e-6 * (1.0 + e.abs())
            })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose_statements(body: &str) -> (crate::lang::Program, Vec<Option<PoseStatement>>) {
        let p = crate::lang::compile(&format!("length 4s\n{body}\n"), "t.mprog", &[]).unwrap();
        let ir = p.ir();
        let probes = [crate::skeleton::rest_pose().map(|v| [v.x, v.y, v.z])];
        let found = ir
            .statements
            .iter()
            .enumerate()
            .map(|(i, s)| pose_statement(ir, i, s).filter(|ps| is_placement_free(ir, ps, &probes)))
            .collect();
        (p, found)
    }

    #[test]
    fn heights_and_joint_distances_are_pose_statements() {
        for body in [
            "at 2s { pelvis.y < 20 cm }",
            "head.y > 1.2 m",
            "during 1s..3s { l_foot.y > 20 cm }",
            "at end { dist(l_hand, head) < 10 cm }",
            "at end { r_hand.y > head.y + 10 cm }",
            "at 1s { groundDist(l_foot, r_foot) > 50 cm }",
            "for h in [l_hand, r_hand] { at 2s { h.y > 2 m } }",
        ] {
            let (_, found) = pose_statements(body);
            assert!(found.iter().all(Option::is_some), "{body}");
        }
    }

    #[test]
    fn placements_time_and_speeds_are_not() {
        for body in [
            "at 2s { pelvis.x > 1 m }",
            "at end { l_hand.x > 10 cm }",
            "at 2s { dist(r_hand, [0, 1, 0.5]) < 5 cm }",
            "at 2s { dot(facing(), [0, 0, 1]) > 0.9 }",
            "speed(pelvis) > 1 m/s",
            "at 2s { dist(l_hand, l_hand@1s) > 20 cm }",
            "if head.y > 1 m { l_hand.y > 2 m }",
        ] {
            let (_, found) = pose_statements(body);
            assert!(found.iter().all(Option::is_none), "{body}");
        }
    }

    #[test]
    fn errors_follow_the_language() {
        let (p, found) =
            pose_statements("at 2s { pelvis.y < 20 cm }\nat 2s { dist(l_hand, r_hand) == 0.4 m }");
        let rest = crate::skeleton::rest_pose().map(|v| [v.x, v.y, v.z]);
        let e0 = error_on(p.ir(), found[0].as_ref().unwrap(), &rest);
        assert!((e0 - (f64::from(rest[0][1]) - 0.2)).abs() < 1e-6, "{e0}");
        let d = (0..3)
            .map(|k| f64::from(rest[20][k] - rest[21][k]).powi(2))
            .sum::<f64>()
            .sqrt();
        let e1 = error_on(p.ir(), found[1].as_ref().unwrap(), &rest);
        assert!((e1 - (d - 0.4).abs()).abs() < 1e-5, "{e1} {d}");
    }
}
