//! Measurements of a coverage set, printed by `mprog data coverage`: how long the data
//! holds one-leg support, and how near a set built without some clips comes to those
//! clips' own poses (what the `mprog::unseen_pose` threshold is chosen against).

use super::Coverage;
use super::pose::Pose;
use super::search::Run;
use rand::{Rng, SeedableRng};

/// Joints whose heights held-out queries bound: pelvis, head, wrists, ankles, toes.
pub const QUERY_JOINTS: [usize; 8] = [0, 15, 20, 21, 7, 8, 10, 11];

/// Height of a foot's lowest joint (ankle or toes), left (0) or right (1).
pub fn foot_low(p: &Pose, side: usize) -> f32 {
    let (a, f) = if side == 0 { (7, 10) } else { (8, 11) };
    p[a][1].min(p[f][1])
}

/// A foot is on the floor below this height (m).
pub const ON_FLOOR: f32 = 0.05;

/// Per lift height: the longest run of frames with one foot on the floor and the other's
/// lowest joint higher than the lift (standing on one leg).
pub fn one_leg_runs(c: &Coverage, lifts: &[f32]) -> Vec<(f32, Option<Run>)> {
    lifts
        .iter()
        .map(|&h| {
            let ok: Vec<bool> = (0..c.variants())
                .map(|v| {
                    let p = c.variant(v);
                    let (l, r) = (foot_low(&p, 0), foot_low(&p, 1));
                    (l < ON_FLOOR && r > h) || (r < ON_FLOOR && l > h)
                })
                .collect();
            (h, c.longest_run(&ok))
        })
        .collect()
}

/// Percentiles of a list (sorted in place): p50, p90, p99, p99.9, max.
pub fn percentiles(v: &mut [f32]) -> [f32; 5] {
    v.sort_by(f32::total_cmp);
    let at = |q: f64| {
        v.get(((q * (v.len().max(1) - 1) as f64).round()) as usize)
            .copied()
            .unwrap_or(0.0)
    };
    [at(0.5), at(0.9), at(0.99), at(0.999), at(1.0)]
}

/// What held-out queries bound: joint heights, or distances between two joints.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Query {
    /// The heights of [`QUERY_JOINTS`] (`head.y > 65 cm`).
    Heights,
    /// The distances between pairs of [`QUERY_JOINTS`] (`dist(l_hand, head) < 10 cm`).
    Distances,
}

/// The quantities `q` reads on a pose.
fn quantities(q: Query, p: &Pose) -> Vec<f32> {
    match q {
        Query::Heights => QUERY_JOINTS.iter().map(|&j| p[j][1]).collect(),
        Query::Distances => {
            let mut v = Vec::new();
            for (i, &a) in QUERY_JOINTS.iter().enumerate() {
                for &b in &QUERY_JOINTS[i + 1..] {
                    let d = (0..3).map(|k| (p[a][k] - p[b][k]).powi(2)).sum::<f32>();
                    v.push(d.sqrt());
                }
            }
            v
        }
    }
}

/// How near `set` comes to each held-out pose: the least violation, over the set's poses
/// read as stored and mirrored, of `k` bounds the held-out pose meets exactly, each on
/// one of `q`'s quantities chosen at random and on the side away from its median in `set`
/// (the pelvis low, the head high: `pelvis.y < 20 cm`, `head.y > 65 cm`): the sum of how
/// far each bound is broken (m), as the warning measures it. One value per held-out pose.
pub fn held_out_violations(
    set: &Coverage,
    held_out: &[Pose],
    q: Query,
    k: usize,
    seed: u64,
) -> Vec<f32> {
    let values: Vec<Vec<f32>> = (0..set.variants())
        .map(|v| quantities(q, &set.variant(v)))
        .collect();
    let n = values.first().map_or(0, Vec::len);
    let median: Vec<f32> = (0..n)
        .map(|i| {
            let mut h: Vec<f32> = values.iter().map(|h| h[i]).collect();
            percentiles(&mut h)[0]
        })
        .collect();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    held_out
        .iter()
        .map(|p| {
            let own = quantities(q, p);
            let mut picks: Vec<usize> = (0..n).collect();
            for i in 0..k.min(n) {
                let j = rng.random_range(i..n);
                picks.swap(i, j);
            }
            let query: Vec<(usize, f32, bool)> = picks[..k.min(n)]
                .iter()
                .map(|&i| (i, own[i], own[i] < median[i]))
                .collect();
            values
                .iter()
                .map(|h| {
                    query
                        .iter()
                        .map(|&(i, v, below)| {
                            if below {
                                (h[i] - v).max(0.0)
                            } else {
                                (v - h[i]).max(0.0)
                            }
                        })
                        .sum::<f32>()
                })
                .fold(f32::INFINITY, f32::min)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::{Clip, Coverage};
    use super::*;

    fn rest() -> Pose {
        crate::skeleton::rest_pose().map(|v| [v.x, v.y, v.z])
    }

    #[test]
    fn one_leg_support_is_timed() {
        let stand = rest();
        let mut lift = rest();
        for j in [7, 10] {
            lift[j][1] += 0.3;
        }
        // The rest pose's feet are at the floor's height.
        assert!(foot_low(&stand, 0) < ON_FLOOR, "{}", foot_low(&stand, 0));
        let c = Coverage::new(
            "t".into(),
            0.04,
            true,
            vec![stand, lift],
            vec![Clip {
                name: "a".into(),
                caption: String::new(),
                frames: vec![0, 1, 1, 1, 1, 0],
            }],
        );
        let runs = one_leg_runs(&c, &[0.2, 0.4]);
        assert_eq!(runs[0].1.as_ref().unwrap().frames, 4);
        assert!(runs[1].1.is_none());
    }

    #[test]
    fn a_pose_of_the_set_is_met_exactly_and_others_are_not() {
        let stand = rest();
        let c = Coverage::new(
            "t".into(),
            0.04,
            true,
            vec![stand],
            vec![Clip {
                name: "a".into(),
                caption: String::new(),
                frames: vec![0],
            }],
        );
        let v = held_out_violations(&c, &[stand], Query::Heights, 8, 1);
        assert!(v[0] < 1e-6);
        let mut low = stand;
        low.iter_mut().for_each(|j| j[1] -= 0.5);
        // Lower than the median everywhere: each of the 8 bounds asks for 0.5 m lower.
        let v = held_out_violations(&c, &[low], Query::Heights, 8, 1);
        assert!((v[0] - 4.0).abs() < 1e-3, "{}", v[0]);
        assert_eq!(percentiles(&mut [3.0, 1.0, 2.0])[0], 2.0);
    }
}
