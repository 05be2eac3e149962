//! The poses a program asks for: per person, the pose statements
//! ([`super::static_eval::pose_statement`]) active together on some frame, and how long
//! they are held together.

use super::static_eval::PoseStatement;
use crate::lang::ir::Ir;

/// Longest hold that counts (frames): a motion is made in windows of at most 9.8 s, so
/// the model never has to hold a pose longer within one.
pub const MAX_HELD: usize = 196;

/// One pose a program asks for.
#[derive(Clone, Debug, PartialEq)]
pub struct Ask {
    /// The person.
    pub person: usize,
    /// Indices into the pose statements, ascending: all active on some frame.
    pub statements: Vec<usize>,
    /// The first frame on which exactly these are active.
    pub frame: usize,
    /// The longest run of consecutive frames on which all of them are active, at most
    /// [`MAX_HELD`].
    pub held: usize,
}

/// Every distinct set of pose statements active together on a frame, per person, smallest
/// sets first.
pub fn asks(ir: &Ir, pose: &[PoseStatement]) -> Vec<Ask> {
    let f = ir.length.max(1);
    let on: Vec<Vec<bool>> = pose
        .iter()
        .map(|p| {
            let mut v = vec![false; f];
            for t in ir.resolve_domain(ir.statements[p.statement].domain, f) {
                if let Some(x) = v.get_mut(t) {
                    *x = true;
                }
            }
            v
        })
        .collect();
    let people = pose.iter().map(|p| p.person).max().map_or(0, |m| m + 1);
    let mut out: Vec<Ask> = Vec::new();
    for person in 0..people {
        let mine: Vec<usize> = (0..pose.len())
            .filter(|&i| pose[i].person == person)
            .collect();
        for t in 0..f {
            let set: Vec<usize> = mine.iter().copied().filter(|&i| on[i][t]).collect();
            if set.is_empty()
                || out
                    .iter()
                    .any(|a| a.person == person && a.statements == set)
            {
                continue;
            }
            let (mut held, mut run) = (0, 0);
            for u in 0..f {
                if set.iter().all(|&i| on[i].get(u) == Some(&true)) {
                    run += 1;
                    held = held.max(run);
                } else {
                    run = 0;
                }
            }
            out.push(Ask {
                person,
                statements: set,
                frame: t,
                held: held.min(MAX_HELD),
            });
        }
    }
    out.sort_by_key(|a| (a.statements.len(), a.frame));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn asks_of(body: &str) -> Vec<Ask> {
        let p = crate::lang::compile(&format!("length 4s\n{body}\n"), "t.mprog", &[]).unwrap();
        let ir = p.ir();
        let pose: Vec<PoseStatement> = ir
            .statements
            .iter()
            .enumerate()
            .filter_map(|(i, s)| super::super::static_eval::pose_statement(ir, i, s))
            .collect();
        asks(ir, &pose)
    }

    #[test]
    fn statements_on_the_same_frames_make_one_ask() {
        let a = asks_of("at end { pelvis.y < 20 cm\n head.y > 65 cm }");
        assert_eq!(a.len(), 1);
        assert_eq!(
            (a[0].statements.clone(), a[0].frame, a[0].held),
            (vec![0, 1], 79, 1)
        );
    }

    #[test]
    fn an_always_joins_each_keyframe_and_a_window_is_held() {
        let a =
            asks_of("head.y > 1 m\nat 2s { pelvis.y < 50 cm }\nduring 1s..3s { l_foot.y > 20 cm }");
        let sets: Vec<(Vec<usize>, usize)> =
            a.iter().map(|a| (a.statements.clone(), a.held)).collect();
        // `always` alone (80 frames), with the window (40), with the window and the keyframe (1).
        assert_eq!(sets, [(vec![0], 80), (vec![0, 2], 40), (vec![0, 1, 2], 1)]);
    }
}
