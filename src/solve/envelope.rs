//! Inside the real envelope: a penalty on what no recorded person does, for the late
//! guidance steps beside the foot lock ([`super::feet`]) and the acceleration hold
//! ([`super::accel`]).
//!
//! The late steps move μ directly, with no denoiser after them, so nothing but the
//! program's gradient shapes those frames: a program that cannot be met smoothly is met
//! by a snap (a head rising 0.27 m in one frame to reach an `at end` height) or through
//! the floor (a wrist 13 cm under it while sitting down). The acceleration hold only
//! slows *changes* to the motion over a step's first iterations; this term bounds the
//! motion itself, over every iteration of every late step:
//! * **acceleration**: each joint's `|J[t+1] − 2·J[t] + J[t−1]|` beyond [`ACCEL_LIMITS`],
//!   the largest that joint reaches in the training data (m/frame² at 20 fps), the torso's
//!   at most [`TORSO_ACCEL_LIMIT`];
//! * **floor**: any joint below `y = 0`;
//! * **twist**: the shoulder girdle turned on the hips further than [`MIN_TWIST_COS`];
//! * **people apart**: two people's body capsules (the report's
//!   [`crate::skeleton::capsules::CAPSULES`]) overlapping by more than [`APART_SLACK`]:
//!   a kick met its contact with the kicker's thigh through the other's arm;
//! * **folding**: the torso curled or the shoulders folded in further than any recorded
//!   frame ([`MIN_SPANS`]): the late steps met "hand on the head" by hunching the spine to
//!   0.59 of its length and folding the shoulders to 0.17 m apart, where the training data
//!   keeps the spine above 0.94 and the shoulders above 0.28 m.
//!
//! Both are hinges, so a motion inside the envelope costs nothing and the program's pull
//! is not spread over the clip (as a hold over all iterations did). A sample's penalty is
//! `w · (Σ_{t,j} s(|Δ²J_tj| − a_j) / (N − 2) + Σ_{t,j} s(−y_tj) / N + Σ_{t,(a,b)} s(d_ab − |J_ta − J_tb|) / N)` with
//! `s(e) = √(e² + ε²) − ε` for `e > 0` (0 otherwise), in metres like the program's error.

use super::accel::{add_second_difference_grad, second_difference};
use crate::skeleton::NUM_JOINTS;

/// Smoothing of the hinge at zero (m or m/frame²).
const EPS: f32 = 1e-3;

const J3: usize = NUM_JOINTS * 3;

/// The largest acceleration of each joint the late steps allow (m/frame² at 20 fps, in
/// joint order): the smaller of the training data's largest (the 99.99th percentile over
/// the 617,612 frame triples of the shipped model's training set, `data/combined`, which
/// leaves out about 60 frames where the capture jumps, up to 2.8 m/frame²; `mprog data
/// envelope`, the `accel_p9999` column) and 0.95 × what the plausibility report flags
/// ([`crate::metrics::plausibility::ACCEL_MARGIN`] × the bundle's `accel_peak` p99). With the data's
/// largest alone, knees (0.336), ankles, feet and wrists were held above the report's
/// line: a walk→run seam met its speed with a knee at 0.32 m/frame², inside the guard
/// and flagged by the report (0.25).
pub const ACCEL_LIMITS: [f32; NUM_JOINTS] = [
    0.083, 0.094, 0.096, 0.087, 0.239, 0.237, 0.108, 0.313, 0.308, 0.108, 0.385, 0.381, 0.136,
    0.119, 0.120, 0.146, 0.132, 0.131, 0.239, 0.242, 0.381, 0.393,
];

/// The torso's acceleration limit (m/frame² at 20 fps): pelvis, spine1–3, neck and head are
/// held under the smaller of this and their [`ACCEL_LIMITS`]. 0.08 is above the 99.9th
/// percentile of every torso joint over `data/combined`'s frames (pelvis 0.058, head 0.073)
/// and the largest of pelvis, chest or head in 12,305 frames of Bandai Namco's walks and
/// gestures (0.074–0.079). At the 99.99th percentile the head's limit was 0.147, and the
/// late steps met a lean that starts at a window's first frame by dropping the head 0.16 m
/// in two frames (0.12 m/frame²; the unguided sample's largest is 0.068).
pub const TORSO_ACCEL_LIMIT: f32 = 0.08;

/// The torso joints [`TORSO_ACCEL_LIMIT`] holds (HumanML3D order).
pub const TORSO_JOINTS: [usize; 6] = [0, 3, 6, 9, 12, 15];

/// [`ACCEL_LIMITS`] with the torso held under [`TORSO_ACCEL_LIMIT`].
pub fn accel_limits() -> [f32; NUM_JOINTS] {
    let mut limits = ACCEL_LIMITS;
    for j in TORSO_JOINTS {
        limits[j] = limits[j].min(TORSO_ACCEL_LIMIT);
    }
    limits
}

/// Joint pairs whose distance the training data never takes below a floor (m): the
/// 0.1st percentile over `data/combined`'s frames (`mprog data envelope`, the `rigid`
/// table): pelvis–spine3, pelvis–neck, each hip–spine3, and the shoulders (0.283 in the
/// data, 0.27 here: the skeleton's own rest pose hangs its shoulders 0.281 apart).
pub const MIN_SPANS: [(usize, usize, f32); 5] = [
    (0, 9, 0.311),
    (0, 12, 0.499),
    (1, 9, 0.307),
    (2, 9, 0.307),
    (16, 17, 0.27),
];

/// Overlap (m) of two people's capsules the late steps allow: two thirds of what the report
/// flags ([`crate::metrics::plausibility::OVERLAP_DEPTH`]), so a contact met with the
/// bodies close keeps them short of the report's line. At 1 cm three people gathering
/// close (the sentence bench's s28, seed 1) were pushed into a 0.083 m/frame² torso snap.
pub const APART_SLACK: f32 = 0.02;

/// Smallest cosine of the angle between the hip line and the collar line (60°): the
/// training data twists the torso that far on 0.01 % of its frames (59°; 40° at the
/// 99.9th percentile). A late step once met "arms out sideways" by turning the shoulder
/// girdle 180° on the hips.
pub const MIN_TWIST_COS: f32 = 0.5;

/// The envelope penalty of a batch of motions.
#[derive(Clone, Debug)]
pub struct EnvelopeGuard {
    weight: f32,
    frames: usize,
    people: usize,
    limits: [f32; NUM_JOINTS],
}

fn dot3(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm3(a: [f32; 3]) -> f32 {
    dot3(a, a).sqrt().max(1e-6)
}

/// `s(e)` and `s'(e)` of the smoothed hinge.
fn hinge(e: f32) -> (f32, f32) {
    if e <= 0.0 {
        return (0.0, 0.0);
    }
    let n = (e * e + EPS * EPS).sqrt();
    (n - EPS, e / n)
}

impl EnvelopeGuard {
    /// For motions of `frames` frames; `people` motions make one sample's penalty.
    pub fn new(frames: usize, people: usize, weight: f32) -> Self {
        EnvelopeGuard {
            weight,
            frames,
            people: people.max(1),
            limits: accel_limits(),
        }
    }

    /// The penalty per sample of world joints `[B·P, N, 22, 3]`; adds its gradient with
    /// respect to them to `grad`.
    pub fn eval(&self, joints: &[f32], grad: &mut [f32]) -> Vec<f32> {
        let per = self.frames * J3;
        let motions = joints.len() / per.max(1);
        let mut penalty = vec![0.0f32; motions / self.people];
        if self.frames == 0 {
            return penalty;
        }
        let floor_scale = self.weight / self.frames as f32;
        let accel_scale = self.weight / self.frames.saturating_sub(2).max(1) as f32;
        for m in 0..motions {
            let motion = &joints[m * per..(m + 1) * per];
            let g = &mut grad[m * per..(m + 1) * per];
            let sample = m / self.people;
            for t in 0..self.frames {
                for j in 0..NUM_JOINTS {
                    let k = t * J3 + 3 * j + 1;
                    let (v, d) = hinge(-motion[k]);
                    penalty[sample] += floor_scale * v;
                    g[k] -= floor_scale * d;
                }
            }
            for t in 0..self.frames {
                for &(a, b, least) in &MIN_SPANS {
                    let (ka, kb) = (t * J3 + 3 * a, t * J3 + 3 * b);
                    let r: [f32; 3] = std::array::from_fn(|i| motion[ka + i] - motion[kb + i]);
                    let size = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
                    let (v, d) = hinge(least - size);
                    if v == 0.0 && d == 0.0 {
                        continue;
                    }
                    penalty[sample] += floor_scale * v;
                    // d/dJ_a of s(least − |J_a − J_b|) = −s' · r/|r|.
                    let along = floor_scale * d / size.max(1e-9);
                    for (i, ri) in r.iter().enumerate() {
                        g[ka + i] -= along * ri;
                        g[kb + i] += along * ri;
                    }
                }
            }
            for t in 0..self.frames {
                let k = t * J3;
                let h: [f32; 3] = std::array::from_fn(|i| motion[k + 3 + i] - motion[k + 6 + i]);
                let c: [f32; 3] = std::array::from_fn(|i| motion[k + 39 + i] - motion[k + 42 + i]);
                let (nh, nc) = (norm3(h), norm3(c));
                let cos = dot3(h, c) / (nh * nc);
                let (v, d) = hinge(MIN_TWIST_COS - cos);
                if v == 0.0 && d == 0.0 {
                    continue;
                }
                penalty[sample] += floor_scale * v;
                // ∂cos/∂h = (ĉ − cos·ĥ)/|h|, and the same with h and c swapped; the hinge
                // is of (limit − cos), so descent raises cos.
                for i in 0..3 {
                    let gh = (c[i] / nc - cos * h[i] / nh) / nh;
                    let gc = (h[i] / nh - cos * c[i] / nc) / nc;
                    let s = -floor_scale * d;
                    g[k + 3 + i] += s * gh;
                    g[k + 6 + i] -= s * gh;
                    g[k + 39 + i] += s * gc;
                    g[k + 42 + i] -= s * gc;
                }
            }
            for t in 1..self.frames.saturating_sub(1) {
                for (j, limit) in self.limits.iter().enumerate() {
                    let r: [f32; 3] =
                        std::array::from_fn(|a| second_difference(motion, t, 3 * j + a));
                    let size = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
                    let (v, d) = hinge(size - limit);
                    if v == 0.0 && d == 0.0 {
                        continue;
                    }
                    penalty[sample] += accel_scale * v;
                    let along = accel_scale * d / size.max(1e-9);
                    for (a, ra) in r.iter().enumerate() {
                        add_second_difference_grad(g, t, 3 * j + a, along * ra);
                    }
                }
            }
        }
        for (sample, p) in penalty.iter_mut().enumerate() {
            for a in 0..self.people {
                for b in a + 1..self.people {
                    let (ma, mb) = (sample * self.people + a, sample * self.people + b);
                    let (lo, hi) = grad.split_at_mut(mb * per);
                    *p += apart(
                        [
                            &joints[ma * per..(ma + 1) * per],
                            &joints[mb * per..(mb + 1) * per],
                        ],
                        [&mut lo[ma * per..(ma + 1) * per], &mut hi[..per]],
                        self.frames,
                        floor_scale,
                    );
                }
            }
        }
        penalty
    }
}

/// The people-apart term of two people's joints `[N, 22, 3]` (scaled by `scale` per
/// frame), its gradient added to theirs. The distance between two capsules' closest points
/// moves with their endpoints as the closest points' weights say (the fractions along
/// each segment are a minimum, so their own change adds nothing to first order).
fn apart(people: [&[f32]; 2], grads: [&mut [f32]; 2], frames: usize, scale: f32) -> f32 {
    use crate::skeleton::capsules::{CAPSULES, segment_closest};
    let [a, b] = people;
    let [ga, gb] = grads;
    let at = |m: &[f32], t: usize, j: usize| {
        let k = t * J3 + 3 * j;
        glam::Vec3::new(m[k], m[k + 1], m[k + 2])
    };
    let mut total = 0.0;
    for t in 0..frames {
        for ca in &CAPSULES {
            for cb in &CAPSULES {
                let [a0, a1] = ca.joints.map(|j| at(a, t, j));
                let [b0, b1] = cb.joints.map(|j| at(b, t, j));
                let (s, u) = segment_closest(a0, a1, b0, b1);
                let r = (a0 + (a1 - a0) * s) - (b0 + (b1 - b0) * u);
                let dist = r.length();
                let (v, d) = hinge(ca.radius + cb.radius - APART_SLACK - dist);
                if v == 0.0 && d == 0.0 {
                    continue;
                }
                total += scale * v;
                // d/dp of s(R − |r|) = −s' · r̂ · ∂r/∂p; descent moves the closest points
                // apart along r̂.
                let n = r / dist.max(1e-6) * (scale * d);
                for (j, w) in [(ca.joints[0], 1.0 - s), (ca.joints[1], s)] {
                    let k = t * J3 + 3 * j;
                    for i in 0..3 {
                        ga[k + i] -= w * n[i];
                    }
                }
                for (j, w) in [(cb.joints[0], 1.0 - u), (cb.joints[1], u)] {
                    let k = t * J3 + 3 * j;
                    for i in 0..3 {
                        gb[k + i] += w * n[i];
                    }
                }
            }
        }
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `[1, N, 22, 3]` joints of the rest pose 10 cm up, moved along x by `x(t)`.
    fn motion(x: impl Fn(usize) -> f32, frames: usize) -> Vec<f32> {
        let mut v = Vec::with_capacity(frames * J3);
        for t in 0..frames {
            for p in crate::skeleton::rest_pose() {
                v.extend([p.x + x(t), p.y + 0.1, p.z]);
            }
        }
        v
    }

    #[test]
    fn a_real_motion_is_free_and_a_snap_or_the_floor_is_not() {
        let frames = 12;
        let guard = EnvelopeGuard::new(frames, 1, 1.0);
        // A walk-like drift: 0.07 m per frame, no acceleration.
        let walk = motion(|t| 0.07 * t as f32, frames);
        let mut g = vec![0.0; walk.len()];
        assert_eq!(guard.eval(&walk, &mut g), vec![0.0]);
        assert!(g.iter().all(|&v| v == 0.0));
        // The same with a 0.3 m jump at frame 6: over every joint's limit.
        let snap = motion(|t| 0.07 * t as f32 + if t >= 6 { 0.3 } else { 0.0 }, frames);
        let mut g = vec![0.0; snap.len()];
        assert!(guard.eval(&snap, &mut g)[0] > 0.0);
        // Descent (−gradient) pulls frame 6 back (−x) and frame 5 forward.
        assert!(
            g[6 * J3] > 0.0 && g[5 * J3] < 0.0,
            "{} {}",
            g[6 * J3],
            g[5 * J3]
        );
        // A wrist 10 cm under the floor on one frame: pushed up there only.
        let mut low = walk.clone();
        low[3 * J3 + 3 * 20 + 1] = -0.1;
        let mut g = vec![0.0; low.len()];
        let p = guard.eval(&low, &mut g)[0];
        assert!(p > 0.0);
        assert!(g[3 * J3 + 3 * 20 + 1] < 0.0, "descent raises it");
    }

    #[test]
    fn a_dip_the_limbs_may_make_costs_on_the_torso() {
        let frames = 5;
        let guard = EnvelopeGuard::new(frames, 1, 1.0);
        // Every joint dips 5 cm on the middle frame: 0.1 m/frame² there, inside the head's
        // 99.99th percentile (0.147) and the feet's, over the torso's 0.08.
        let mut dip = motion(|_| 0.0, frames);
        for j in 0..NUM_JOINTS {
            dip[2 * J3 + 3 * j + 1] -= 0.05;
        }
        let mut g = vec![0.0; dip.len()];
        assert!(guard.eval(&dip, &mut g)[0] > 0.0);
        let pushed = |j: usize| g[2 * J3 + 3 * j + 1] != 0.0;
        for j in TORSO_JOINTS {
            assert!(pushed(j), "torso joint {j} held");
        }
        // A foot's limit (0.38) is far above the dip: it costs nothing.
        assert!(!pushed(10) && !pushed(11));
        let limits = accel_limits();
        assert!(TORSO_JOINTS.iter().all(|&j| limits[j] <= TORSO_ACCEL_LIMIT));
        assert_eq!(
            limits[20], ACCEL_LIMITS[20],
            "a wrist keeps the data's limit"
        );
    }

    #[test]
    fn a_hunched_spine_costs_and_is_pushed_open() {
        let frames = 3;
        let guard = EnvelopeGuard::new(frames, 1, 1.0);
        let mut pose = vec![0.0f32; frames * J3];
        for t in 0..frames {
            for (j, p) in crate::skeleton::rest_pose().iter().enumerate() {
                let k = t * J3 + 3 * j;
                pose[k..k + 3].copy_from_slice(&[p.x, p.y + 0.1, p.z]);
            }
        }
        let mut g = vec![0.0; pose.len()];
        assert_eq!(
            guard.eval(&pose, &mut g),
            vec![0.0],
            "the rest pose is inside"
        );
        // Spine3 pulled down to 0.2 m above the pelvis on the middle frame.
        let k = J3 + 3 * 9 + 1;
        pose[k] = pose[J3 + 1] + 0.2;
        let mut g = vec![0.0; pose.len()];
        assert!(guard.eval(&pose, &mut g)[0] > 0.0);
        assert!(g[k] < 0.0, "descent lifts spine3 back up");
    }

    #[test]
    fn two_people_through_each_other_cost_and_are_pushed_apart() {
        let frames = 3;
        let guard = EnvelopeGuard::new(frames, 2, 1.0);
        let a = motion(|_| 0.0, frames);
        // The second person 1 m to the side: free; 10 cm to the side: torsos overlap.
        let far = [a.clone(), motion(|_| 1.0, frames)].concat();
        let mut g = vec![0.0; far.len()];
        assert_eq!(guard.eval(&far, &mut g), vec![0.0]);
        let near = [a, motion(|_| 0.15, frames)].concat();
        let mut g = vec![0.0; near.len()];
        assert!(guard.eval(&near, &mut g)[0] > 0.0);
        // Descent moves the first person to −x and the second to +x (summed over joints:
        // a hip may be pushed across the other's).
        let x_pull = |person: usize| -> f32 {
            let per = frames * J3;
            (0..per).step_by(3).map(|k| g[person * per + k]).sum()
        };
        assert!(
            x_pull(0) > 0.0 && x_pull(1) < 0.0,
            "{} {}",
            x_pull(0),
            x_pull(1)
        );
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let frames = 7;
        let guard = EnvelopeGuard::new(frames, 2, 0.7);
        let mut x: Vec<f32> = (0..2 * frames * J3)
            .map(|i| 0.3 * (0.71 * i as f32).sin())
            .collect();
        // Some joints below the floor, some fast; the second person a little aside, so
        // no two of the people's segments cross exactly (where the distance has a kink).
        for (i, v) in x.iter_mut().enumerate() {
            if i % 3 == 1 {
                *v += 0.2;
            }
            if i >= frames * J3 && i % 3 == 2 {
                *v += 0.05;
            }
        }
        let mut g = vec![0.0; x.len()];
        guard.eval(&x, &mut g);
        let f = |x: &[f32]| -> f64 {
            let mut scratch = vec![0.0; x.len()];
            guard.eval(x, &mut scratch).iter().map(|&v| v as f64).sum()
        };
        let eps = 1e-3;
        for i in (0..x.len()).step_by(5) {
            let (mut a, mut b) = (x.clone(), x.clone());
            a[i] += eps;
            b[i] -= eps;
            let fd = (f(&a) - f(&b)) / (2.0 * eps as f64);
            assert!(
                (fd - g[i] as f64).abs() < 2e-2 * (1.0 + fd.abs()),
                "coordinate {i}: analytic {} vs numeric {fd}",
                g[i]
            );
        }
    }
}
