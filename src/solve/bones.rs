//! Skeleton projection for the late guidance steps: puts every bone back to the skeleton's
//! length and keeps a foot that is on the floor on the floor.
//!
//! The 263-dim features hold each joint's position independently (the ric block), so an
//! error gradient on those positions moves one joint alone: "head below 0.8 m" pulls the
//! head into the chest. Early in the chain the denoiser repairs such moves; in the last
//! T_s steps (500 iterations each, nothing after them) it cannot. There the guide
//! optimises `E(P(μ))` instead of `E(μ)`, where `P`:
//! 1. rebuilds the body from the pelvis outwards, each bone keeping its direction and
//!    taking its length from [`BONE_LENGTHS`](crate::skeleton::BONE_LENGTHS); the two rigid
//!    parts where three bones leave one joint, the pelvis (hips and spine) and the shoulder
//!    girdle (collars and neck), are rebuilt as one rigid T each ([`HUBS`]): the hips (or
//!    collars) along the line through them, the spine (or neck) square to it. Kept apart,
//!    their bones folded together under the gradient (hip width down to 1 cm in `guide`'s
//!    outputs against the skeleton's 0.21 m), which no skeleton in motion can do and a
//!    BVH cannot carry;
//! 2. on frames where a foot joint touched the floor (below [`CONTACT_HEIGHT`]) when the
//!    projection was set up, shifts the body vertically so that its lowest foot joint is
//!    at that height, or on the floor if it was below it: the body stands on its lowest
//!    foot, whichever that is now;
//! 3. shifts the frames between such frames (a step's swing, a jump) by the shifts of the
//!    planted frames on either side, linearly interpolated over time (the nearest one's
//!    before the first and after the last). Shifting only the planted frames moved the
//!    whole body by the legs' change of length in one frame where a foot landed or left.
//!    (That jump was not what raises `guide`'s peak acceleration on the keyframe tasks:
//!    0.124 m/frame² before, 0.123 after; book, solvers chapter.)
//!
//! The gradient through `P` moves bone *directions*: to lower the head the spine bends or
//! both knees flex, because lowering the pelvis alone lowers the feet and step 2 takes
//! that back. Everything is in the person's own frame (pelvis at
//! `(0, h₃, 0)`, the ric block), where rotation and translation cannot change a length.

use super::host::HEAD;
use crate::features::layout::RIC;
use crate::skeleton::{BONE_LENGTHS, FOOT_LEFT, FOOT_RIGHT, NUM_JOINTS, PARENTS};

/// A foot joint lower than this (metres) is on the floor.
pub const CONTACT_HEIGHT: f32 = 0.05;

/// Column of the root height in a head row.
const ROOT_Y: usize = 3;

/// The rigid T-shaped parts of HumanML3D's skeleton: (hub, left child, right child, up
/// child), whose rest offsets are `+x`, `−x` and `+y` ([`RAW_OFFSETS`](crate::skeleton::RAW_OFFSETS)):
/// the pelvis with its hips and spine, the chest (spine3) with its collars and neck.
pub const HUBS: [(usize, usize, usize, usize); 2] = [(0, 1, 2, 3), (9, 13, 14, 12)];

/// The unit directions of every bone after the projection: each bone's own, but for the
/// children of a [`HUBS`] entry, which share one rigid frame.
fn bone_directions(u: &[f32]) -> [V3; NUM_JOINTS] {
    let mut dirs: [V3; NUM_JOINTS] = std::array::from_fn(|j| scaled(bone(u, j), 1.0));
    for (_, l, r, up) in HUBS {
        let x = scaled(sub(bone(u, l), bone(u, r)), 1.0);
        let y = scaled(reject(bone(u, up), x), 1.0);
        dirs[l] = x;
        dirs[r] = x.map(|v| -v);
        dirs[up] = y;
    }
    dirs
}

/// `v` without its component along the unit vector `x`.
fn reject(v: V3, x: V3) -> V3 {
    let d = dot(v, x);
    std::array::from_fn(|i| v[i] - d * x[i])
}

fn dot(a: V3, b: V3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `P` and its backward on de-normalised heads `[M, N, 67]`.
#[derive(Clone, Debug)]
pub struct SkeletonProjection {
    /// Per row (motion, frame): the height of the lowest foot joint, if it was planted.
    anchors: Vec<Option<f32>>,
    /// Per row: the planted rows of its motion whose shifts it takes, with weights that
    /// sum to 1 (both weights 0 in a motion with no planted frame).
    shift_from: Vec<[(usize, f32); 2]>,
    /// Per row: the lowest foot joint of the last forward (the one the shift used).
    lowest: Vec<usize>,
    /// Per row: its own vertical shift at the last forward (0 where not planted).
    shifts: Vec<f32>,
    /// Bone vectors of the last forward, `[rows, 22, 3]` (index = child joint).
    bones: Vec<f32>,
    /// Joints of the last forward before the shift, `[rows, 22, 3]`.
    unshifted: Vec<[f32; 3]>,
}

/// Position of joint `j` in a head row (the pelvis is `(0, h₃, 0)`).
fn joint(row: &[f32], j: usize) -> [f32; 3] {
    if j == 0 {
        [0.0, row[ROOT_Y], 0.0]
    } else {
        let b = RIC.start + 3 * (j - 1);
        [row[b], row[b + 1], row[b + 2]]
    }
}

impl SkeletonProjection {
    /// Set up on de-normalised heads of motions of `frames` frames: records, per frame,
    /// the height of the lowest foot joint if it is on the floor.
    pub fn new(head: &[f32], frames: usize) -> Self {
        let anchors: Vec<Option<f32>> = head
            .chunks_exact(HEAD)
            .map(|row| {
                let (_, y) = lowest_foot(|j| joint(row, j)[1]);
                // A planted foot stands on the floor, not in it: an anchor below y = 0 would
                // hold it there against the envelope's floor term (an ankle 5 cm under the
                // floor on 12 to 31 frames of the trial's standing tasks).
                (y < CONTACT_HEIGHT).then_some(y.max(0.0))
            })
            .collect();
        let rows = anchors.len();
        let frames = frames.max(1);
        assert_eq!(rows % frames, 0, "head rows are whole motions");
        let shift_from = (0..rows)
            .map(|r| {
                let (start, end) = (r - r % frames, r - r % frames + frames);
                let prev = (start..=r).rev().find(|&k| anchors[k].is_some());
                let next = (r..end).find(|&k| anchors[k].is_some());
                match (prev, next) {
                    (Some(a), Some(b)) if a == b => [(a, 1.0), (a, 0.0)],
                    (Some(a), Some(b)) => {
                        let w = (r - a) as f32 / (b - a) as f32;
                        [(a, 1.0 - w), (b, w)]
                    }
                    (Some(k), None) | (None, Some(k)) => [(k, 1.0), (k, 0.0)],
                    (None, None) => [(r, 0.0), (r, 0.0)],
                }
            })
            .collect();
        SkeletonProjection {
            lowest: vec![0; rows],
            shifts: vec![0.0; rows],
            shift_from,
            anchors,
            bones: Vec::new(),
            unshifted: Vec::new(),
        }
    }

    /// Frames (rows) with a planted foot.
    pub fn anchored(&self) -> usize {
        self.anchors.iter().filter(|a| a.is_some()).count()
    }

    /// `out ← P(head)`; both `[rows, 67]`, rows as at [`new`](Self::new).
    pub fn forward(&mut self, head: &[f32], out: &mut [f32]) {
        let rows = self.anchors.len();
        assert_eq!(head.len(), rows * HEAD, "head rows");
        assert_eq!(out.len(), head.len(), "output length");
        self.bones.resize(rows * NUM_JOINTS * 3, 0.0);
        self.unshifted.resize(rows * NUM_JOINTS, [0.0; 3]);
        // Bones back to length, and each planted row's own shift.
        for (r, h) in head.chunks_exact(HEAD).enumerate() {
            let u = &mut self.bones[r * NUM_JOINTS * 3..(r + 1) * NUM_JOINTS * 3];
            let q = &mut self.unshifted[r * NUM_JOINTS..(r + 1) * NUM_JOINTS];
            for j in 1..NUM_JOINTS {
                let b = sub(joint(h, j), joint(h, PARENTS[j]));
                u[3 * j..3 * j + 3].copy_from_slice(&b);
            }
            q[0] = joint(h, 0);
            let dirs = bone_directions(u);
            for j in 1..NUM_JOINTS {
                q[j] = add(q[PARENTS[j]], dirs[j].map(|v| v * BONE_LENGTHS[j]));
            }
            if let Some(y) = self.anchors[r] {
                let (k, lowest) = lowest_foot(|j| q[j][1]);
                self.lowest[r] = k;
                self.shifts[r] = y - lowest;
            }
        }
        // Every row shifted by its planted neighbours' shifts.
        for (r, o) in out.chunks_exact_mut(HEAD).enumerate() {
            let dy: f32 = self.shift_from[r]
                .iter()
                .map(|&(k, w)| w * self.shifts[k])
                .sum();
            let q = &self.unshifted[r * NUM_JOINTS..(r + 1) * NUM_JOINTS];
            let h = &head[r * HEAD..(r + 1) * HEAD];
            o[..ROOT_Y].copy_from_slice(&h[..ROOT_Y]);
            o[ROOT_Y] = q[0][1] + dy;
            for (j, qj) in q.iter().enumerate().skip(1) {
                let b = RIC.start + 3 * (j - 1);
                o[b..b + 3].copy_from_slice(&[qj[0], qj[1] + dy, qj[2]]);
            }
        }
    }

    /// `g_head ← (∂P/∂head)ᵀ g_out` at the last [`forward`](Self::forward).
    pub fn backward(&self, g_out: &[f32], g_head: &mut [f32]) {
        assert_eq!(g_out.len(), self.anchors.len() * HEAD, "gradient rows");
        assert_eq!(g_head.len(), g_out.len(), "gradient length");
        // Each planted row's shift moves every joint of the rows that take it: gather the
        // vertical gradient those rows send it.
        let mut g_shift = vec![0.0f32; self.anchors.len()];
        for (r, go) in g_out.chunks_exact(HEAD).enumerate() {
            let total = go[ROOT_Y]
                + (1..NUM_JOINTS)
                    .map(|j| go[RIC.start + 3 * (j - 1) + 1])
                    .sum::<f32>();
            for &(k, w) in &self.shift_from[r] {
                g_shift[k] += w * total;
            }
        }
        let rows = g_out.chunks_exact(HEAD).zip(g_head.chunks_exact_mut(HEAD));
        for (r, (go, gh)) in rows.enumerate() {
            let u = &self.bones[r * NUM_JOINTS * 3..(r + 1) * NUM_JOINTS * 3];
            // Gradient with respect to the unshifted joints: their own, and through this
            // row's shift (y − its lowest foot joint) the gradient gathered above.
            let mut gq: [[f32; 3]; NUM_JOINTS] = std::array::from_fn(|j| joint(go, j));
            gq[0] = [0.0, go[ROOT_Y], 0.0];
            if self.anchors[r].is_some() {
                gq[self.lowest[r]][1] -= g_shift[r];
            }
            // Children before parents: q_j = q_parent + L·b/|b|, b = p_j − p_parent, but
            // for a hub's children, whose directions come from all three bones (once the
            // lowest-numbered of them is reached, all three gradients are complete).
            let mut gp = [[0.0f32; 3]; NUM_JOINTS];
            for j in (1..NUM_JOINTS).rev() {
                let par = PARENTS[j];
                let g = gq[j];
                gq[par] = add(gq[par], g);
                match HUBS.iter().find(|h| [h.1, h.2, h.3].contains(&j)) {
                    None => {
                        let gb = scaled_vjp(bone(u, j), BONE_LENGTHS[j], g);
                        gp[j] = add(gp[j], gb);
                        gp[par] = sub(gp[par], gb);
                    }
                    Some(&(_, l, r, up)) if j == l.min(r).min(up) => {
                        for (k, gb) in hub_vjp(u, (l, r, up), &gq) {
                            gp[k] = add(gp[k], gb);
                            gp[par] = sub(gp[par], gb);
                        }
                    }
                    Some(_) => {}
                }
            }
            gh[..ROOT_Y].copy_from_slice(&go[..ROOT_Y]);
            // Only the pelvis height is a feature; its x and z are the root's (fixed at 0).
            gh[ROOT_Y] = gp[0][1] + gq[0][1];
            for (j, g) in gp.iter().enumerate().skip(1) {
                let b = RIC.start + 3 * (j - 1);
                gh[b..b + 3].copy_from_slice(g);
            }
        }
    }
}

/// The gradient of a hub's three bone vectors (left, right, up child) given the gradients
/// `gq` of their rebuilt joints: `q_l = q_h + L_l·x`, `q_r = q_h − L_r·x`, `q_up = q_h + L_up·y`
/// with `x = n(b_l − b_r)`, `y = n(b_up − (b_up·x)·x)`.
fn hub_vjp(
    u: &[f32],
    (l, r, up): (usize, usize, usize),
    gq: &[V3; NUM_JOINTS],
) -> [(usize, V3); 3] {
    let d = sub(bone(u, l), bone(u, r));
    let x = scaled(d, 1.0);
    let b_up = bone(u, up);
    let w = reject(b_up, x);
    let y = gq[up].map(|v| v * BONE_LENGTHS[up]);
    let g_w = scaled_vjp(w, 1.0, y);
    let g_up = reject(g_w, x);
    let (bx, gx) = (dot(b_up, x), dot(x, g_w));
    let g_x: V3 = std::array::from_fn(|i| {
        BONE_LENGTHS[l] * gq[l][i] - BONE_LENGTHS[r] * gq[r][i] - bx * g_w[i] - gx * b_up[i]
    });
    let g_d = scaled_vjp(d, 1.0, g_x);
    [(l, g_d), (r, g_d.map(|v| -v)), (up, g_up)]
}

/// The lowest foot joint (ankles and toes) and its height, given each joint's height.
fn lowest_foot(height: impl Fn(usize) -> f32) -> (usize, f32) {
    [FOOT_LEFT, FOOT_RIGHT]
        .concat()
        .into_iter()
        .map(|j| (j, height(j)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("four foot joints")
}

/// Length of a bone vector, kept away from 0 (a collapsed bone keeps its zero direction).
fn norm(b: [f32; 3]) -> f32 {
    (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt().max(1e-6)
}

type V3 = [f32; 3];

fn add(a: V3, b: V3) -> V3 {
    std::array::from_fn(|i| a[i] + b[i])
}

fn sub(a: V3, b: V3) -> V3 {
    std::array::from_fn(|i| a[i] - b[i])
}

/// `v` scaled to length `l`.
fn scaled(v: V3, l: f32) -> V3 {
    let s = l / norm(v);
    v.map(|x| s * x)
}

/// `(∂ scaled(v, l) / ∂v)ᵀ g`: `l/|v|` times `g` without its component along `v`.
fn scaled_vjp(v: V3, l: f32, g: V3) -> V3 {
    let n = norm(v);
    let dot = (v[0] * g[0] + v[1] * g[1] + v[2] * g[2]) / (n * n);
    let s = l / n;
    std::array::from_fn(|i| s * (g[i] - v[i] * dot))
}

/// Bone vector of child joint `j` (the raw `p_j − p_parent`) in a row's `[22 × 3]` bones.
fn bone(u: &[f32], j: usize) -> V3 {
    [u[3 * j], u[3 * j + 1], u[3 * j + 2]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::rest_pose;

    /// A head row of a pose (yaw and root velocity columns set to something non-zero).
    fn row_of(pose: &[[f32; 3]; NUM_JOINTS]) -> Vec<f32> {
        let mut row = vec![0.1, 0.02, 0.03, pose[0][1]];
        for p in &pose[1..] {
            row.extend_from_slice(p);
        }
        assert_eq!(row.len(), HEAD);
        row
    }

    fn rest() -> [[f32; 3]; NUM_JOINTS] {
        rest_pose().map(|p| p.to_array())
    }

    fn bone_length(row: &[f32], j: usize) -> f32 {
        let (p, q) = (joint(row, j), joint(row, PARENTS[j]));
        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
    }

    #[test]
    fn the_rest_pose_is_a_fixed_point() {
        let row = row_of(&rest());
        let mut p = SkeletonProjection::new(&row, 1);
        let mut out = vec![0.0; HEAD];
        p.forward(&row, &mut out);
        for (a, b) in row.iter().zip(&out) {
            assert!((a - b).abs() < 1e-5, "{a} vs {b}");
        }
    }

    #[test]
    fn a_head_pulled_into_the_chest_gets_its_neck_back_and_a_planted_foot_stays() {
        let mut pose = rest();
        pose[15][1] -= 0.3; // head below the neck's length
        pose[0][1] -= 0.2; // pelvis sunk: the legs would push the feet through the floor
        let row = row_of(&pose);
        let mut p = SkeletonProjection::new(&row_of(&rest()), 1);
        assert_eq!(p.anchored(), 1, "the rest pose stands on the floor");
        let mut out = vec![0.0; HEAD];
        p.forward(&row, &mut out);
        for (j, length) in BONE_LENGTHS.iter().enumerate().skip(1) {
            assert!((bone_length(&out, j) - length).abs() < 1e-5, "bone {j}");
        }
        let foot_y = |r: &[f32]| [7, 8, 10, 11].map(|j| joint(r, j)[1]);
        let lowest = foot_y(&out).into_iter().fold(f32::INFINITY, f32::min);
        let rest_lowest = foot_y(&row_of(&rest()))
            .into_iter()
            .fold(f32::INFINITY, f32::min);
        assert!(
            (lowest - rest_lowest).abs() < 1e-5,
            "{lowest} vs {rest_lowest}"
        );
    }

    /// A bent, uneven pose so no bone is axis-aligned and lengths are off; `phase`
    /// varies it.
    fn bent(phase: f32) -> [[f32; 3]; NUM_JOINTS] {
        let mut pose = rest();
        for (j, p) in pose.iter_mut().enumerate() {
            let f = j as f32 + phase;
            p[0] += 0.03 * (1.7 * f).sin();
            p[1] += 0.04 * (0.9 * f).cos();
            p[2] += 0.05 * (1.3 * f).sin();
        }
        pose
    }

    /// `p.backward` against central differences of `Σ w·P(head)` with fixed pseudo-random
    /// weights, on every column of `head`.
    fn assert_backward_matches_finite_differences(
        p: &mut SkeletonProjection,
        head: &[f32],
        case: &str,
    ) {
        let w: Vec<f32> = (0..head.len()).map(|i| (0.37 * i as f32).sin()).collect();
        let mut out = vec![0.0; head.len()];
        let mut loss = |h: &[f32], p: &mut SkeletonProjection| -> f64 {
            p.forward(h, &mut out);
            out.iter().zip(&w).map(|(o, w)| (o * w) as f64).sum()
        };
        loss(head, p);
        let mut g = vec![0.0; head.len()];
        p.backward(&w, &mut g);
        // Small: with the rigid hubs a hip's move tilts both legs, and 1 mm can swap which
        // foot is lowest (a kink of the shift) in the three-frame case.
        let eps = 2e-4;
        for i in 0..head.len() {
            let (mut a, mut b) = (head.to_vec(), head.to_vec());
            a[i] += eps;
            b[i] -= eps;
            let fd = (loss(&a, p) - loss(&b, p)) / (2.0 * eps as f64);
            assert!(
                (fd - g[i] as f64).abs() < 2e-2 * (1.0 + fd.abs()),
                "{case}: column {} of frame {}: analytic {} vs numeric {fd}",
                i % HEAD,
                i / HEAD,
                g[i]
            );
        }
    }

    #[test]
    fn a_foot_planted_under_the_floor_is_stood_on_the_floor() {
        let sunk = lifted(rest(), -0.05);
        let mut p = SkeletonProjection::new(&sunk, 1);
        assert_eq!(p.anchored(), 1);
        let mut out = vec![0.0; HEAD];
        p.forward(&sunk, &mut out);
        let lowest = [7, 8, 10, 11]
            .map(|j| joint(&out, j)[1])
            .into_iter()
            .fold(f32::INFINITY, f32::min);
        assert!(lowest.abs() < 1e-5, "lowest foot joint at {lowest}");
    }

    #[test]
    fn hips_folded_together_come_back_as_a_rigid_pelvis() {
        // The gradient's fold: both hips pulled in towards the pelvis's midline and down.
        let mut pose = bent(0.3);
        pose[1][0] = pose[0][0] + 0.005;
        pose[2][0] = pose[0][0] - 0.004;
        pose[13][0] = pose[9][0] + 0.01;
        let row = row_of(&pose);
        let mut p = SkeletonProjection::new(&row_of(&rest()), 1);
        let mut out = vec![0.0; HEAD];
        p.forward(&row, &mut out);
        let dist = |a: usize, b: usize| {
            let (p, q) = (joint(&out, a), joint(&out, b));
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
        };
        let rest_row = row_of(&rest());
        let rest_dist = |a: usize, b: usize| {
            let (p, q) = (joint(&rest_row, a), joint(&rest_row, b));
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
        };
        // Every distance inside each rigid part is the rest skeleton's.
        for (h, l, r, up) in HUBS {
            for (a, b) in [(h, l), (h, r), (h, up), (l, r), (l, up), (r, up)] {
                assert!(
                    (dist(a, b) - rest_dist(a, b)).abs() < 1e-5,
                    "{a}–{b}: {} vs rest {}",
                    dist(a, b),
                    rest_dist(a, b)
                );
            }
        }
    }

    #[test]
    fn backward_matches_finite_differences() {
        let row = row_of(&bent(0.0));
        for anchored in [false, true] {
            let setup = if anchored {
                row_of(&rest())
            } else {
                lifted(rest(), 0.5)
            };
            let mut p = SkeletonProjection::new(&setup, 1);
            assert_eq!(p.anchored(), anchored as usize);
            assert_backward_matches_finite_differences(
                &mut p,
                &row,
                &format!("anchored {anchored}"),
            );
        }
    }

    /// `pose` moved by `dy` vertically, as a head row.
    fn lifted(pose: [[f32; 3]; NUM_JOINTS], dy: f32) -> Vec<f32> {
        row_of(&pose.map(|p| [p[0], p[1] + dy, p[2]]))
    }

    #[test]
    fn frames_between_planted_ones_take_their_shifts_interpolated() {
        // A jump of four frames: planted, in the air, in the air, planted.
        let setup: Vec<f32> = [0.0, 0.5, 0.5, 0.0]
            .into_iter()
            .flat_map(|dy| lifted(rest(), dy))
            .collect();
        let mut p = SkeletonProjection::new(&setup, 4);
        assert_eq!(p.anchored(), 2);
        // The body sunk 0.1 m into the floor at take-off and 0.4 m at landing: those frames
        // are lifted back by 0.1 and 0.4, the frames between by 0.2 and 0.3.
        let sunk: Vec<f32> = [-0.1, 0.5, 0.5, -0.4]
            .into_iter()
            .flat_map(|dy| lifted(rest(), dy))
            .collect();
        let mut out = vec![0.0; sunk.len()];
        p.forward(&sunk, &mut out);
        let pelvis = |rows: &[f32], r: usize| rows[r * HEAD + ROOT_Y];
        for (r, lift) in [0.1, 0.2, 0.3, 0.4].into_iter().enumerate() {
            let got = pelvis(&out, r) - pelvis(&sunk, r);
            assert!(
                (got - lift).abs() < 1e-5,
                "frame {r}: lifted {got}, not {lift}"
            );
        }
        // A second motion of the batch, with no planted frame, is not shifted.
        let mut two = setup.clone();
        two.extend([0.5; 4].into_iter().flat_map(|dy| lifted(rest(), dy)));
        let mut p = SkeletonProjection::new(&two, 4);
        let mut both = sunk.clone();
        both.extend(sunk.iter().copied());
        let mut out = vec![0.0; both.len()];
        p.forward(&both, &mut out);
        for r in 4..8 {
            assert!((pelvis(&out, r) - pelvis(&both, r)).abs() < 1e-5, "row {r}");
        }
    }

    #[test]
    fn backward_matches_finite_differences_across_frames() {
        // Three bent frames, the middle one in the air: its shift comes from the other two.
        let head: Vec<f32> = [(0.0, 0.0), (1.0, 0.3), (2.0, 0.0)]
            .into_iter()
            .flat_map(|(phase, dy)| lifted(bent(phase), dy))
            .collect();
        let setup: Vec<f32> = [0.0, 0.5, 0.0]
            .into_iter()
            .flat_map(|dy| lifted(rest(), dy))
            .collect();
        let mut p = SkeletonProjection::new(&setup, 3);
        assert_eq!(p.anchored(), 2);
        assert_backward_matches_finite_differences(&mut p, &head, "three frames");
    }
}
