//! The search: each pose statement's error on every pose of the coverage set, and per
//! [`Ask`] the nearest pose (least summed error), the nearest meeting all but one of its
//! statements, and the longest run of training frames that stays near it.

use super::asks::Ask;
use super::static_eval::{Joints, PoseStatement, error_on, eval_node};
use crate::coverage::search::{Run, nearest};
use crate::coverage::{Coverage, Origin};
use crate::lang::ir::{BinaryOp, Ir, NodeId, Op, UnaryOp};

/// What the data has for one ask.
#[derive(Clone, Debug)]
pub struct Found {
    /// The ask.
    pub ask: Ask,
    /// The nearest pose variant ([`Coverage::variant`]).
    pub nearest: usize,
    /// Its summed error over the ask's statements (m).
    pub distance: f64,
    /// Per statement of the ask (same order), when the ask has two or more: the variant
    /// with the least error on it among those that meet all the others (their summed
    /// error within [`MET`]), with that error.
    pub all_but: Vec<Option<(usize, f64)>>,
    /// The longest run of training frames whose summed error stays within `held`.
    pub run: Option<Run>,
}

/// Summed error (m) under which a pose counts as meeting statements, for the nearest pose
/// with all but one met.
pub const MET: f32 = 0.01;

/// Every pose statement's error on every variant of `cov`.
pub fn errors(ir: &Ir, pose: &[PoseStatement], cov: &Coverage) -> Vec<Vec<f32>> {
    let variants: Vec<Joints> = (0..cov.variants()).map(|v| cov.variant(v)).collect();
    pose.iter()
        .map(|s| variants.iter().map(|p| error_on(ir, s, p) as f32).collect())
        .collect()
}

/// The search for one ask, given [`errors`]; a run of frames holds the ask while their
/// summed error is within `held` (m).
pub fn find(ask: &Ask, errors: &[Vec<f32>], cov: &Coverage, held: f64) -> Found {
    let n = cov.variants();
    let total: Vec<f32> = (0..n)
        .map(|v| ask.statements.iter().map(|&s| errors[s][v]).sum())
        .collect();
    let (best, distance) = nearest(&total).unwrap_or((0, f32::INFINITY));
    let all_but = if ask.statements.len() < 2 {
        Vec::new()
    } else {
        ask.statements
            .iter()
            .map(|&s| {
                let scores: Vec<f32> = (0..n)
                    .map(|v| {
                        let others = total[v] - errors[s][v];
                        if others <= MET {
                            errors[s][v]
                        } else {
                            f32::INFINITY
                        }
                    })
                    .collect();
                nearest(&scores).map(|(v, e)| (v, f64::from(e)))
            })
            .collect()
    };
    let ok: Vec<bool> = total.iter().map(|&t| f64::from(t) <= held).collect();
    Found {
        ask: ask.clone(),
        nearest: best,
        distance: f64::from(distance),
        all_but,
        run: if ask.held > 1 {
            cov.longest_run(&ok)
        } else {
            None
        },
    }
}

/// The two sides of a comparison's error node (`relu(a − b)`, `|a − b|`), when it is one.
fn sides(ir: &Ir, error: NodeId) -> Option<(NodeId, NodeId)> {
    let mut n = error;
    if let Op::SumChannels(a) = ir.nodes[n].op {
        n = a;
    }
    let inner = match ir.nodes[n].op {
        Op::Unary {
            op: UnaryOp::Relu | UnaryOp::Abs,
            arg,
        } => arg,
        _ => return None,
    };
    match ir.nodes[inner].op {
        Op::Binary {
            op: BinaryOp::Sub,
            a,
            b,
        } => Some((a, b)),
        _ => None,
    }
}

/// `text` split at its one top-level comparison: (left, operator, right), trimmed.
fn split_comparison(text: &str) -> Option<(&str, &str, &str)> {
    let mut depth = 0i32;
    let bytes = text.as_bytes();
    for (i, &c) in bytes.iter().enumerate() {
        match c {
            b'(' | b'[' => depth += 1,
            b')' | b']' => depth -= 1,
            b'<' | b'>' | b'=' if depth == 0 => {
                let len = if bytes.get(i + 1) == Some(&b'=') {
                    2
                } else {
                    1
                };
                let (left, right) = (&text[..i], &text[i + len..]);
                return (!right.contains(['<', '>']))
                    .then(|| (left.trim(), &text[i..i + len], right.trim()));
            }
            _ => {}
        }
    }
    None
}

/// What a pose statement reads, on the pose `p`: each side of its comparison that depends
/// on the motion, as (source text, value in m); empty when the statement is no single
/// comparison of scalars.
pub fn quantities(ir: &Ir, s: &PoseStatement, p: &Joints, source: &str) -> Vec<(String, f64)> {
    let st = &ir.statements[s.statement];
    let Some((a, b)) = sides(ir, st.error) else {
        return Vec::new();
    };
    let own = source.get(st.span.start..st.span.end).unwrap_or("");
    // The error is `a − b`: `x < y` and `x == y` give (x, y), `x > y` gives (y, x).
    let (left, right) = match split_comparison(own) {
        Some((l, op, r)) if op.starts_with('>') => (Some((b, l)), Some((a, r))),
        Some((l, _, r)) => (Some((a, l)), Some((b, r))),
        None => (None, None),
    };
    let text = |n: NodeId| {
        let span = ir.nodes[n].span;
        if span.start >= st.span.start && span.end <= st.span.end {
            return source.get(span.start..span.end).map(str::to_string);
        }
        [left, right]
            .into_iter()
            .flatten()
            .find(|(m, _)| *m == n)
            .map(|(_, t)| t.to_string())
    };
    [
        left.map(|x| x.0).unwrap_or(a),
        right.map(|x| x.0).unwrap_or(b),
    ]
    .into_iter()
    .filter(|&n| ir.nodes[n].motion)
    .map(|n| {
        let (v, lanes, channels) = eval_node(ir, &s.nodes, n, p);
        ((lanes == 1 && channels == 1).then(|| v[0]), text(n))
    })
    .map(|(v, t)| Some((t?, v?)))
    .collect::<Option<Vec<_>>>()
    .unwrap_or_default()
}

/// A pose's origin as text: `frame 52 of HDM_bd_lieDown_001_120 ("a person lies down")`.
pub fn origin_text(o: &Origin) -> String {
    if o.caption.is_empty() {
        format!("frame {} of {}", o.frame, o.clip)
    } else {
        format!("frame {} of {} (\"{}\")", o.frame, o.clip, o.caption)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coverage::{Clip, Coverage};

    fn rest() -> Joints {
        crate::skeleton::rest_pose().map(|v| [v.x, v.y, v.z])
    }

    /// A set of two poses: standing, and the same lowered to a pelvis at 0.15 m.
    fn set() -> Coverage {
        let stand = rest();
        let sit = stand.map(|[x, y, z]| [x, y - stand[0][1] + 0.15, z]);
        Coverage::new(
            "t".into(),
            0.04,
            true,
            vec![stand, sit],
            vec![Clip {
                name: "a".into(),
                caption: "sits down".into(),
                frames: vec![0, 0, 1, 1, 1],
            }],
        )
    }

    fn search(body: &str) -> (Vec<Found>, crate::lang::Program) {
        let p = crate::lang::compile(&format!("length 4s\n{body}\n"), "t.mprog", &[]).unwrap();
        let ir = p.ir();
        let pose: Vec<PoseStatement> = ir
            .statements
            .iter()
            .enumerate()
            .filter_map(|(i, s)| super::super::static_eval::pose_statement(ir, i, s))
            .collect();
        let cov = set();
        let e = errors(ir, &pose, &cov);
        let found = super::super::asks::asks(ir, &pose)
            .iter()
            .map(|a| find(a, &e, &cov, 0.01))
            .collect();
        (found, p)
    }

    #[test]
    fn the_nearest_pose_and_the_best_with_all_but_one_met() {
        let sit = set().poses[1];
        assert!((sit[0][1] - 0.15).abs() < 1e-6 && sit[15][1] < 1.2);
        let (found, _) = search("at end { pelvis.y < 20 cm\n head.y > 1.2 m }");
        let f = &found[0];
        // Sitting meets the pelvis bound and misses the head's by 1.2 − head.
        assert_eq!(f.nearest % 2, 1);
        assert!((f.distance - (1.2 - f64::from(sit[15][1]))).abs() < 1e-5);
        // With the head's bound met (standing), the pelvis is 0.637 m too high.
        let (v, e) = f.all_but[0].unwrap();
        assert_eq!(v % 2, 0);
        let stand = rest();
        assert!((e - f64::from(stand[0][1] - 0.2)).abs() < 1e-3, "{e}");
    }

    #[test]
    fn quantities_name_the_sides_and_a_run_is_timed() {
        let (found, p) = search("during 0s..1s { pelvis.y < 20 cm }\nat end { r_hand.y > head.y }");
        let f = &found[0];
        assert!(f.distance < 1e-6);
        // Frames 2..5 of the clip sit, read as stored or mirrored.
        assert_eq!(f.run.as_ref().map(|r| r.frames), Some(3));
        let ir = p.ir();
        let s = super::super::static_eval::pose_statement(ir, 1, &ir.statements[1]).unwrap();
        let q = quantities(ir, &s, &rest(), p.warnings().source.as_str());
        let names: Vec<&str> = q.iter().map(|(t, _)| t.as_str()).collect();
        assert_eq!(names, ["r_hand.y", "head.y"]);
        // A library call's side is named by the program's text, not the library's.
        let (_, p) = search("at end { groundDist(l_foot, r_foot) > 1.5 m }");
        let ir = p.ir();
        let s = super::super::static_eval::pose_statement(ir, 0, &ir.statements[0]).unwrap();
        let q = quantities(ir, &s, &rest(), p.warnings().source.as_str());
        assert_eq!(q.len(), 1);
        assert_eq!(q[0].0, "groundDist(l_foot, r_foot)");
        assert_eq!(super::split_comparison("a < b < c"), None);
        assert_eq!(
            super::split_comparison("f(x, y) >= 2 m"),
            Some(("f(x, y)", ">=", "2 m"))
        );
    }
}
