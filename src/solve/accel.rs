//! No new jerks: a penalty on the joint acceleration the late guidance steps add, for the
//! late steps beside the foot lock ([`super::feet`]).
//!
//! The late steps move μ directly, with no denoiser after them. Keyframes on scattered
//! frames (OmniControl's 25 % density) are met frame by frame, and the frames between
//! follow only as far as the step's smoothing over time carries them: the path comes out
//! jagged. `guide`'s peak joint acceleration on the keyframe tasks was 0.124 m/frame²
//! against 0.093 unguided, 0.147 at 25 % density (book, solvers chapter).
//!
//! Set up on world joints, it records every joint's second difference over time. The
//! penalty of a sample is what the steps add to it, beyond a small tolerance, summed over
//! joints and averaged over frames (m/frame², smoothed so it has a gradient everywhere),
//! times a weight: `w · Σ_{t,j} (√(r² + ε²) − ε) / (N − 2)` with
//! `r = max(0, |Δ²J_tj − Δ²J⁰_tj| − tol)`. The motion's own acceleration costs nothing;
//! a change that is smooth over time costs little, a change of one frame a lot.
//!
//! `guide` sets it up at the start of each late step on the joints before the skeleton
//! projection, but for the ankles and toes, which keep the projection's planted contacts
//! ([`HostObjective::hold_accel`](super::host::HostObjective::hold_accel)): so the jerk the
//! projection itself adds is held back too. It acts over the first
//! [`ACCEL_HOLD_ITERATIONS`](super::guide::ACCEL_HOLD_ITERATIONS) iterations of each late
//! step only: held over all 500 of the CLI's, a program that cannot be met spread its pull
//! over the whole clip (book, solvers chapter).

use crate::skeleton::NUM_JOINTS;

/// Smoothing of the norm at zero (m/frame²).
const EPS: f32 = 1e-3;

/// Added acceleration (m/frame²) that costs nothing.
pub const ACCEL_TOLERANCE: f32 = 0.002;

const J3: usize = NUM_JOINTS * 3;

/// The second differences of a batch of motions at set-up, and the penalty on changing
/// them.
#[derive(Clone, Debug)]
pub struct AccelHold {
    weight: f32,
    frames: usize,
    people: usize,
    /// `[motions, N − 2, 22, 3]`: `J[t+1] − 2·J[t] + J[t−1]` at set-up, for t = 1..N−1.
    reference: Vec<f32>,
}

/// `J[t+1] − 2·J[t] + J[t−1]` of coordinate `k` of a `[N, 22, 3]` motion, `t` the middle.
pub(super) fn second_difference(motion: &[f32], t: usize, k: usize) -> f32 {
    motion[(t + 1) * J3 + k] - 2.0 * motion[t * J3 + k] + motion[(t - 1) * J3 + k]
}

/// Adds `d` times the gradient of [`second_difference`]`(·, t, k)` to `grad`.
pub(super) fn add_second_difference_grad(grad: &mut [f32], t: usize, k: usize, d: f32) {
    grad[(t + 1) * J3 + k] += d;
    grad[t * J3 + k] -= 2.0 * d;
    grad[(t - 1) * J3 + k] += d;
}

impl AccelHold {
    /// On world joints `[B·P, N, 22, 3]` (flat); `people` motions make one sample's penalty.
    pub fn new(joints: &[f32], frames: usize, people: usize, weight: f32) -> Self {
        let mut reference = Vec::new();
        if frames >= 3 {
            for motion in joints.chunks_exact(frames * J3) {
                for t in 1..frames - 1 {
                    reference.extend((0..J3).map(|k| second_difference(motion, t, k)));
                }
            }
        }
        AccelHold {
            weight,
            frames,
            people: people.max(1),
            reference,
        }
    }

    /// The penalty per sample `[B]`; adds its gradient with respect to the joints to `grad`.
    pub fn eval(&self, joints: &[f32], grad: &mut [f32]) -> Vec<f32> {
        let motions = joints.len() / (self.frames * J3).max(1);
        let mut penalty = vec![0.0f32; motions / self.people];
        if self.frames < 3 {
            return penalty;
        }
        let scale = self.weight / (self.frames - 2) as f32;
        let per = self.frames * J3;
        let inner = (self.frames - 2) * J3;
        for m in 0..motions {
            let motion = &joints[m * per..(m + 1) * per];
            let g = &mut grad[m * per..(m + 1) * per];
            let reference = &self.reference[m * inner..(m + 1) * inner];
            for t in 1..self.frames - 1 {
                for j in 0..NUM_JOINTS {
                    let r: [f32; 3] = std::array::from_fn(|a| {
                        let k = 3 * j + a;
                        second_difference(motion, t, k) - reference[(t - 1) * J3 + k]
                    });
                    let size = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
                    let excess = size - ACCEL_TOLERANCE;
                    if excess <= 0.0 {
                        continue;
                    }
                    let norm = (excess * excess + EPS * EPS).sqrt();
                    penalty[m / self.people] += scale * (norm - EPS);
                    // d/dr of √(e² + ε²) with e = |r| − tol: e/√(e² + ε²) · r/|r|.
                    let along = scale * excess / (norm * size);
                    for (a, ra) in r.iter().enumerate() {
                        add_second_difference_grad(g, t, 3 * j + a, along * ra);
                    }
                }
            }
        }
        penalty
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `[1, N, 22, 3]` joints: every joint at `x(t)` on the x axis, its index on y.
    fn motion(x: impl Fn(usize) -> f32, frames: usize) -> Vec<f32> {
        let mut v = Vec::with_capacity(frames * J3);
        for t in 0..frames {
            for j in 0..NUM_JOINTS {
                v.extend([x(t), j as f32, 0.0]);
            }
        }
        v
    }

    #[test]
    fn the_motions_own_acceleration_is_free_and_a_one_frame_kick_is_not() {
        let frames = 10;
        // A swing: accelerating along x.
        let swing = motion(|t| 0.01 * (t * t) as f32, frames);
        let hold = AccelHold::new(&swing, frames, 1, 1.0);
        let mut g = vec![0.0; swing.len()];
        assert_eq!(hold.eval(&swing, &mut g), vec![0.0]);
        assert!(g.iter().all(|&v| v == 0.0));
        // The same swing moved 1 cm further along x from frame 4 on: one frame's kick.
        let kicked = motion(
            |t| 0.01 * (t * t) as f32 + if t >= 4 { 0.01 } else { 0.0 },
            frames,
        );
        let mut g = vec![0.0; swing.len()];
        let p = hold.eval(&kicked, &mut g)[0];
        // Second differences of +0.01 at t = 3 and −0.01 at t = 4, on each of 22 joints.
        let each = ((0.01 - ACCEL_TOLERANCE).powi(2) + EPS * EPS).sqrt() - EPS;
        let expected = 2.0 * NUM_JOINTS as f32 * each / (frames - 2) as f32;
        assert!((p - expected).abs() < 1e-5, "{p} vs {expected}");
        // The gradient pulls frame 4 back (its x gradient is positive) and frame 3 forward.
        assert!(
            g[4 * J3] > 0.0 && g[3 * J3] < 0.0,
            "{} {}",
            g[4 * J3],
            g[3 * J3]
        );
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let frames = 6;
        let base = motion(|t| 0.02 * t as f32, frames);
        let hold = AccelHold::new(&base, frames, 1, 2.0);
        let moved: Vec<f32> = base
            .iter()
            .enumerate()
            .map(|(i, v)| v + 0.03 * (0.7 * i as f32).sin())
            .collect();
        let mut g = vec![0.0; moved.len()];
        hold.eval(&moved, &mut g);
        let eps = 1e-3;
        for i in (0..moved.len()).step_by(7) {
            let (mut a, mut b) = (moved.clone(), moved.clone());
            a[i] += eps;
            b[i] -= eps;
            let mut scratch = vec![0.0; moved.len()];
            let fd =
                (hold.eval(&a, &mut scratch)[0] - hold.eval(&b, &mut scratch)[0]) / (2.0 * eps);
            assert!(
                (fd - g[i]).abs() < 2e-2 * (1.0 + fd.abs()),
                "coordinate {i}: {} vs {fd}",
                g[i]
            );
        }
    }

    #[test]
    fn people_of_a_sample_add_up_and_short_motions_cost_nothing() {
        let frames = 5;
        let a = motion(|t| 0.0 * t as f32, frames);
        let mut b = a.clone();
        b[2 * J3] += 0.05; // joint 0 of frame 2 kicked along x
        let two: Vec<f32> = [a.clone(), a.clone()].concat();
        let hold = AccelHold::new(&two, frames, 2, 1.0);
        let mut g = vec![0.0; two.len()];
        let kicked: Vec<f32> = [a.clone(), b].concat();
        let p = hold.eval(&kicked, &mut g);
        assert_eq!(p.len(), 1);
        assert!(p[0] > 0.0);
        let short = motion(|_| 0.0, 2);
        let hold = AccelHold::new(&short, 2, 1, 1.0);
        assert_eq!(hold.eval(&short, &mut vec![0.0; short.len()]), vec![0.0]);
    }
}
