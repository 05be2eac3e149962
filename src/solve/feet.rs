//! Planted feet stay put: a penalty on the horizontal slide of feet that are on the floor,
//! for the late guidance steps.
//!
//! The late steps meet a program by moving μ directly, hundreds of iterations with no
//! denoiser in between. A gradient that moves the root (walk to a target, avoid a wall)
//! carries a planted foot with it, and the result skates: in the benchmark `guide` skated
//! more than the unguided model it steers (0.76 against 0.69). This term lets the
//! optimiser meet the program with the legs instead.
//!
//! When set up on world joints it records, per motion and toe, the frame pairs `(t, t+1)`
//! where the toe is planted: below [`CONTACT_HEIGHT`](super::bones::CONTACT_HEIGHT) on
//! both frames and sliding slower than [`PLANTED_SPEED`]. A toe that is low but fast is a
//! swing skimming the floor, not a contact; locking it would stop the step. The penalty
//! of a sample is the mean horizontal slide over its planted pairs beyond a tolerance
//! (metres per frame, smoothed so it has a gradient everywhere), times a weight:
//! `w · Σ (√(r² + ε²) − ε) / max(1, pairs)` with `r = max(0, |Δxz| − tol)`.
//!
//! The guide's lock tolerates [`LOCK_TOLERANCE`] (5 mm per frame, 0.1 m/s, a fifth of the
//! skating ratio's threshold): without it every planted pair resisted any slide at all,
//! and a person standing 0.3 m beside a balance beam could not be moved onto it (GEO-2,
//! 0.15 m² with the lock against 0.015 without). The foot cleanup of finished motions
//! ([`super::cleanup`]) tolerates nothing.
//! The contacts are fixed between set-ups, so the penalty is a smooth function of the
//! joints.

use super::bones::CONTACT_HEIGHT;
use crate::skeleton::FEET as SKATING_FEET;
use crate::skeleton::{FPS, NUM_JOINTS};

/// A toe sliding faster than this (m/s) at set-up is swinging, not planted.
pub const PLANTED_SPEED: f32 = 1.0;

/// Smoothing of the slide's norm at zero (metres).
const EPS: f32 = 1e-3;

/// Slide per frame (metres) a planted toe may make at no cost in the guide's lock.
pub const LOCK_TOLERANCE: f32 = 0.005;

const J3: usize = NUM_JOINTS * 3;

/// Planted toe contacts of a batch of motions and the slide penalty on them.
#[derive(Clone, Debug)]
pub struct FootLock {
    weight: f32,
    /// Slide per frame that costs nothing (metres).
    tolerance: f32,
    frames: usize,
    people: usize,
    /// `(motion, toe joint, frame t)`: the toe is planted from `t` to `t + 1`.
    pairs: Vec<(usize, usize, usize)>,
}

impl FootLock {
    /// Contacts of world joints `[B·P, N, 22, 3]` (flat); `people` motions make one
    /// sample's penalty.
    /// The slide tolerance is [`LOCK_TOLERANCE`].
    pub fn new(joints: &[f32], frames: usize, people: usize, weight: f32) -> Self {
        Self::with_speed(
            joints,
            frames,
            people,
            weight,
            PLANTED_SPEED,
            LOCK_TOLERANCE,
        )
    }

    /// [`new`](Self::new) with toes slower than `planted_speed` (m/s) counted as planted and
    /// slides up to `tolerance` metres per frame free.
    pub fn with_speed(
        joints: &[f32],
        frames: usize,
        people: usize,
        weight: f32,
        planted_speed: f32,
        tolerance: f32,
    ) -> Self {
        let motions = joints.len() / (frames * J3);
        let limit = planted_speed / FPS;
        let mut pairs = Vec::new();
        for m in 0..motions {
            for &toe in &SKATING_FEET {
                for t in 0..frames.saturating_sub(1) {
                    let (a, b) = (
                        at(joints, frames, m, t, toe),
                        at(joints, frames, m, t + 1, toe),
                    );
                    let low = a[1] < CONTACT_HEIGHT && b[1] < CONTACT_HEIGHT;
                    if low && (b[0] - a[0]).hypot(b[2] - a[2]) < limit {
                        pairs.push((m, toe, t));
                    }
                }
            }
        }
        FootLock {
            weight,
            tolerance: tolerance.max(0.0),
            frames,
            people: people.max(1),
            pairs,
        }
    }

    /// Planted toe-frame pairs found at set-up.
    pub fn planted(&self) -> usize {
        self.pairs.len()
    }

    /// Penalty per sample `[B]`; adds its gradient with respect to the joints into `grad`
    /// (same layout as `joints`).
    pub fn eval(&self, joints: &[f32], grad: &mut [f32]) -> Vec<f32> {
        let motions = joints.len() / (self.frames * J3);
        let samples = motions / self.people;
        let mut count = vec![0usize; samples];
        for &(m, _, _) in &self.pairs {
            count[m / self.people] += 1;
        }
        let mut penalty = vec![0.0f32; samples];
        for &(m, toe, t) in &self.pairs {
            let b = m / self.people;
            let scale = self.weight / count[b] as f32;
            let (ia, ib) = (
                index(self.frames, m, t, toe),
                index(self.frames, m, t + 1, toe),
            );
            let (dx, dz) = (joints[ib] - joints[ia], joints[ib + 2] - joints[ia + 2]);
            let slide = dx.hypot(dz);
            let excess = slide - self.tolerance;
            if excess <= 0.0 || slide == 0.0 {
                continue;
            }
            let norm = (excess * excess + EPS * EPS).sqrt();
            penalty[b] += scale * (norm - EPS);
            // d/dΔ of √(r² + ε²) with r = |Δ| − tol: r/√(r² + ε²) · Δ/|Δ|.
            let along = scale * excess / (norm * slide);
            let (gx, gz) = (along * dx, along * dz);
            grad[ib] += gx;
            grad[ib + 2] += gz;
            grad[ia] -= gx;
            grad[ia + 2] -= gz;
        }
        penalty
    }
}

/// Flat index of joint `j`'s x in motion `m`, frame `t`.
fn index(frames: usize, m: usize, t: usize, j: usize) -> usize {
    (m * frames + t) * J3 + 3 * j
}

fn at(joints: &[f32], frames: usize, m: usize, t: usize, j: usize) -> [f32; 3] {
    let i = index(frames, m, t, j);
    [joints[i], joints[i + 1], joints[i + 2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One motion of `n` frames, every joint at 1 m height except the toes, which follow
    /// `toe(t)`.
    fn motion(n: usize, toe: impl Fn(usize) -> [f32; 3]) -> Vec<f32> {
        let mut j = vec![0.0; n * J3];
        for t in 0..n {
            for k in 0..NUM_JOINTS {
                let p = if SKATING_FEET.contains(&k) {
                    toe(t)
                } else {
                    [0.0, 1.0, 0.0]
                };
                j[index(n, 0, t, k)..index(n, 0, t, k) + 3].copy_from_slice(&p);
            }
        }
        j
    }

    #[test]
    fn slow_low_toes_are_planted_and_fast_or_lifted_ones_are_not() {
        // Creeping 1 cm per frame (0.2 m/s) on the floor: planted on every pair.
        let creep = motion(5, |t| [0.01 * t as f32, 0.02, 0.0]);
        assert_eq!(FootLock::new(&creep, 5, 1, 1.0).planted(), 2 * 4);
        // 10 cm per frame (2 m/s): a swing skimming the floor.
        let swing = motion(5, |t| [0.1 * t as f32, 0.02, 0.0]);
        assert_eq!(FootLock::new(&swing, 5, 1, 1.0).planted(), 0);
        // Slow but 20 cm up.
        let lifted = motion(5, |t| [0.01 * t as f32, 0.2, 0.0]);
        assert_eq!(FootLock::new(&lifted, 5, 1, 1.0).planted(), 0);
    }

    #[test]
    fn penalty_is_the_mean_slide_and_its_gradient_matches_finite_differences() {
        let joints = motion(6, |t| [0.01 * t as f32, 0.02, 0.005 * (t * t) as f32]);
        let lock = FootLock::with_speed(&joints, 6, 1, 2.0, PLANTED_SPEED, 0.0);
        let mut g = vec![0.0; joints.len()];
        let p = lock.eval(&joints, &mut g)[0];
        // Both toes slide the same; the mean slide over the pairs, times 2.
        let slides: Vec<f32> = (0..5)
            .map(|t| (0.01f32).hypot(0.005 * (2 * t + 1) as f32))
            .collect();
        let expected = 2.0 * slides.iter().map(|s| s.hypot(EPS) - EPS).sum::<f32>() / 5.0;
        assert!((p - expected).abs() < 1e-6, "{p} vs {expected}");
        let indices = [
            index(6, 0, 2, 10),
            index(6, 0, 3, 11) + 2,
            index(6, 0, 0, 10) + 1,
        ];
        assert_gradient(&lock, &joints, &g, &indices, 1e-3, 1e-3);
    }

    /// The analytic gradient `g` of sample 0's penalty matches central differences (step
    /// `eps`) at `indices`, within `tol`.
    fn assert_gradient(
        lock: &FootLock,
        joints: &[f32],
        g: &[f32],
        indices: &[usize],
        eps: f32,
        tol: f32,
    ) {
        let mut scratch = vec![0.0; joints.len()];
        for &i in indices {
            let (mut a, mut b) = (joints.to_vec(), joints.to_vec());
            a[i] += eps;
            b[i] -= eps;
            let fd =
                (lock.eval(&a, &mut scratch)[0] - lock.eval(&b, &mut scratch)[0]) / (2.0 * eps);
            assert!(
                (fd - g[i]).abs() < tol,
                "index {i}: analytic {} vs numeric {fd}",
                g[i]
            );
        }
    }

    #[test]
    fn a_standing_foot_costs_nothing_and_people_share_their_sample() {
        let still = motion(4, |_| [0.3, 0.0, 0.1]);
        let creep = motion(4, |t| [0.02 * t as f32, 0.0, 0.0]);
        let two = [still.clone(), creep].concat();
        let lock = FootLock::with_speed(&two, 4, 2, 1.0, PLANTED_SPEED, 0.0);
        let mut g = vec![0.0; two.len()];
        let p = lock.eval(&two, &mut g);
        assert_eq!(p.len(), 1, "two people, one sample");
        // Half the pairs slide 2 cm, half not at all.
        assert!(
            (p[0] - 0.5 * (0.02f32.hypot(EPS) - EPS)).abs() < 1e-6,
            "{}",
            p[0]
        );
        assert!(g[..still.len()].iter().all(|&v| v == 0.0));
    }

    #[test]
    fn slides_within_the_tolerance_are_free_and_the_excess_has_the_right_gradient() {
        // 3 mm per frame: under the guide's 5 mm tolerance.
        let drift = motion(6, |t| [0.003 * t as f32, 0.02, 0.0]);
        let lock = FootLock::new(&drift, 6, 1, 1.0);
        assert_eq!(lock.planted(), 2 * 5);
        let mut g = vec![0.0; drift.len()];
        assert_eq!(lock.eval(&drift, &mut g)[0], 0.0);
        assert!(g.iter().all(|&v| v == 0.0));
        // 2 cm per frame: only the 1.5 cm beyond the tolerance costs.
        let creep = motion(6, |t| [0.02 * t as f32, 0.02, 0.001 * (t * t) as f32]);
        let lock = FootLock::new(&creep, 6, 1, 1.0);
        let mut g = vec![0.0; creep.len()];
        let p = lock.eval(&creep, &mut g)[0];
        let expected = (0..5)
            .map(|t| {
                let r = (0.02f32).hypot(0.001 * (2 * t + 1) as f32) - LOCK_TOLERANCE;
                r.hypot(EPS) - EPS
            })
            .sum::<f32>()
            / 5.0;
        assert!((p - expected).abs() < 1e-6, "{p} vs {expected}");
        let indices = [index(6, 0, 2, 10), index(6, 0, 3, 11) + 2];
        assert_gradient(&lock, &creep, &g, &indices, 1e-4, 2e-3);
    }
}
