//! Motion metrics on joint positions (`[frames, 22, 3]`, metres, Y up, 20 fps).
//!
//! Physical plausibility (lower is better, real data is the reference):
//! * [`foot_skating_ratio`]: PMG/OmniControl's `calculate_skating_ratio`
//!   (reference-algorithms §1.6): feet 10 and 11, both frames of a step below 5 cm, horizontal
//!   speed above 0.5 m/s both raw and after a centred 5-frame moving average (zero padded);
//!   fraction of the `T − 1` steps where either foot skates.
//! * [`max_acceleration`]: max over joints and frames of ‖p[t+1] − 2p[t] + p[t−1]‖ (m/frame²).
//! * [`bone_length_variation`]: std / mean of each bone's length over time, averaged over the
//!   21 bones (0 for a rigid skeleton).
//! * [`max_bone_error`]: the largest difference of any bone's length from the skeleton's
//!   (m): how far a solver stretched the body to meet its constraints.
//! * [`floor_penetration`]: per frame, how far the lowest joint is below y = 0.
//!
//! Descriptors of the training-baseline table (`notes/training-baseline.md`):
//! * [`mean_root_speed`]: mean horizontal pelvis speed (m/s).
//! * [`total_turn`]: unwrapped heading change of the pelvis path (degrees, + = left turn).
//! * [`wrists_above_head`]: max over frames of (highest wrist y − head y) (m).
//! * [`right_minus_left_wrist`]: peak height of the right wrist minus that of the left (m),
//!   telling which hand a one-handed gesture used.

use crate::motion::Motion;
use crate::skeleton::{BONE_LENGTHS, NUM_JOINTS, PARENTS};
use glam::Vec3;

/// Feet used by the skating ratio (left foot, right foot).
pub const SKATING_FEET: [usize; 2] = crate::skeleton::FEET;
/// Height (m) below which a foot counts as touching the floor.
pub const SKATING_HEIGHT: f32 = 0.05;
/// Horizontal foot speed (m/s) above which a foot in contact skates.
pub const SKATING_SPEED: f32 = 0.5;
/// Width of the centred moving average of the foot speed.
pub const SKATING_WINDOW: usize = 5;
/// Depth (m) below the floor from which a frame counts as penetrating.
pub const PENETRATION_TOLERANCE: f32 = 0.01;
/// Frames over which the pelvis displacement defines the path heading (0.25 s).
pub const HEADING_WINDOW: usize = 5;
/// Pelvis speed (m/s, over [`HEADING_WINDOW`]) below which the path has no heading.
pub const HEADING_MIN_SPEED: f32 = 0.1;

const PELVIS: usize = 0;
const HEAD: usize = 15;
const WRISTS: [usize; 2] = [20, 21];

/// Centred moving average of width `w` with zeros outside (SciPy `uniform_filter1d`,
/// `mode="constant"`).
fn moving_average_zero_padded(v: &[f32], w: usize) -> Vec<f32> {
    let half = w / 2;
    (0..v.len())
        .map(|t| {
            let lo = t.saturating_sub(half);
            let hi = (t + w - half).min(v.len());
            v[lo..hi].iter().sum::<f32>() / w as f32
        })
        .collect()
}

/// Fraction of frame steps in which a foot in floor contact slides (§1.6).
///
/// 0 for motions shorter than two frames.
pub fn foot_skating_ratio(m: &Motion) -> f32 {
    let t = m.len();
    if t < 2 {
        return 0.0;
    }
    let skating = skating_steps(m);
    skating.iter().filter(|&&s| s).count() as f32 / (t - 1) as f32
}

/// For each of the `T − 1` frame steps, whether a foot in floor contact slides there (the
/// steps [`foot_skating_ratio`] counts); empty for motions shorter than two frames.
pub fn skating_steps(m: &Motion) -> Vec<bool> {
    let t = m.len();
    if t < 2 {
        return Vec::new();
    }
    let fps = m.fps;
    let mut skating = vec![false; t - 1];
    for &foot in &SKATING_FEET {
        let speed: Vec<f32> = m
            .frames
            .windows(2)
            .map(|w| {
                let d = w[1][foot] - w[0][foot];
                (d.x * d.x + d.z * d.z).sqrt() * fps
            })
            .collect();
        let avg = moving_average_zero_padded(&speed, SKATING_WINDOW);
        for (i, s) in skating.iter_mut().enumerate() {
            let contact =
                m.frames[i][foot].y < SKATING_HEIGHT && m.frames[i + 1][foot].y < SKATING_HEIGHT;
            *s |= contact && speed[i] > SKATING_SPEED && avg[i] > SKATING_SPEED;
        }
    }
    skating
}

/// Largest second difference of any joint position (m/frame², no fps scaling).
pub fn max_acceleration(m: &Motion) -> f32 {
    peak_acceleration(m).value
}

/// Where a motion's largest second difference is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PeakAcceleration {
    /// Its length (m/frame²); 0 for a motion of fewer than 3 frames.
    pub value: f32,
    /// The joint.
    pub joint: usize,
    /// The middle frame of the three.
    pub frame: usize,
}

/// The largest second difference of any joint position, with its joint and frame (the
/// first one on ties).
pub fn peak_acceleration(m: &Motion) -> PeakAcceleration {
    let mut peak = PeakAcceleration {
        value: 0.0,
        joint: 0,
        frame: 0,
    };
    for (i, w) in m.frames.windows(3).enumerate() {
        let (before, at, after) = (&w[0], &w[1], &w[2]);
        for j in 0..NUM_JOINTS {
            let a = (after[j] - 2.0 * at[j] + before[j]).length();
            if a > peak.value {
                peak = PeakAcceleration {
                    value: a,
                    joint: j,
                    frame: i + 1,
                };
            }
        }
    }
    peak
}

/// Mean over the 21 bones of (std / mean) of the bone's length over time.
///
/// 0 for an empty motion; bones of zero mean length are skipped.
pub fn bone_length_variation(m: &Motion) -> f32 {
    if m.is_empty() {
        return 0.0;
    }
    let n = m.len() as f64;
    let mut total = 0.0f64;
    let mut bones = 0usize;
    for j in 1..NUM_JOINTS {
        let p = PARENTS[j];
        let lengths: Vec<f64> = m
            .frames
            .iter()
            .map(|f| (f[j] - f[p]).length() as f64)
            .collect();
        let mean = lengths.iter().sum::<f64>() / n;
        if mean <= 1e-9 {
            continue;
        }
        let var = lengths.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / n;
        total += var.sqrt() / mean;
        bones += 1;
    }
    if bones == 0 {
        0.0
    } else {
        (total / bones as f64) as f32
    }
}

/// Largest |bone length − the HumanML3D skeleton's| over bones and frames (m); 0 when empty.
pub fn max_bone_error(m: &Motion) -> f32 {
    m.frames
        .iter()
        .flat_map(|f| {
            (1..NUM_JOINTS).map(move |j| ((f[j] - f[PARENTS[j]]).length() - BONE_LENGTHS[j]).abs())
        })
        .fold(0.0, f32::max)
}

/// Floor penetration of a motion.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Penetration {
    /// Mean over frames of max(0, −lowest joint y) (m).
    pub mean_depth: f32,
    /// Fraction of frames whose lowest joint is more than [`PENETRATION_TOLERANCE`] below 0.
    pub frame_fraction: f32,
}

/// How far the body goes below the floor (y = 0).
pub fn floor_penetration(m: &Motion) -> Penetration {
    if m.is_empty() {
        return Penetration::default();
    }
    let depths: Vec<f32> = m
        .frames
        .iter()
        .map(|f| (-f.iter().map(|p| p.y).fold(f32::INFINITY, f32::min)).max(0.0))
        .collect();
    let n = depths.len() as f32;
    Penetration {
        mean_depth: depths.iter().sum::<f32>() / n,
        frame_fraction: depths
            .iter()
            .filter(|&&d| d > PENETRATION_TOLERANCE)
            .count() as f32
            / n,
    }
}

/// Mean horizontal speed of the pelvis (m/s); 0 for fewer than two frames.
pub fn mean_root_speed(m: &Motion) -> f32 {
    if m.len() < 2 {
        return 0.0;
    }
    let dist: f32 = m
        .frames
        .windows(2)
        .map(|w| horizontal(w[1][PELVIS] - w[0][PELVIS]).length())
        .sum();
    dist * m.fps / (m.len() - 1) as f32
}

fn horizontal(v: Vec3) -> Vec3 {
    Vec3::new(v.x, 0.0, v.z)
}

/// Heading of a horizontal direction in radians: 0 along +Z, +π/2 along +X.
///
/// With Y up, a body facing +Z has its left side at +X, so a growing heading is a left turn.
pub fn heading(v: Vec3) -> f32 {
    v.x.atan2(v.z)
}

/// Net heading change of the pelvis path in degrees (+ = left turn, Y up).
///
/// The path heading at frame t is the direction of the pelvis displacement over the next
/// [`HEADING_WINDOW`] frames, defined only where that displacement is faster than
/// [`HEADING_MIN_SPEED`] (standing has no path direction). Consecutive defined headings
/// are unwrapped (each step taken in (−180°, 180°]) and summed. 0 when fewer than two
/// frames have a heading.
pub fn total_turn(m: &Motion) -> f32 {
    let w = HEADING_WINDOW;
    if m.len() <= w {
        return 0.0;
    }
    let min_step = HEADING_MIN_SPEED * w as f32 / m.fps;
    let headings: Vec<f32> = (0..m.len() - w)
        .filter_map(|t| {
            let d = horizontal(m.frames[t + w][PELVIS] - m.frames[t][PELVIS]);
            (d.length() > min_step).then(|| heading(d))
        })
        .collect();
    let turn: f32 = headings.windows(2).map(|h| wrap_angle(h[1] - h[0])).sum();
    turn.to_degrees()
}

/// Wraps an angle to (−π, π].
fn wrap_angle(a: f32) -> f32 {
    use std::f32::consts::{PI, TAU};
    let r = a.rem_euclid(TAU);
    if r > PI { r - TAU } else { r }
}

/// Max over frames of (highest wrist y − head y) in metres; negative when the hands stay
/// below the head. 0 for an empty motion.
pub fn wrists_above_head(m: &Motion) -> f32 {
    m.frames
        .iter()
        .map(|f| f[WRISTS[0]].y.max(f[WRISTS[1]].y) - f[HEAD].y)
        .reduce(f32::max)
        .unwrap_or(0.0)
}

/// max over frames of the right wrist's height minus max over frames of the left wrist's
/// (m): positive when the right hand went higher. 0 for an empty motion.
pub fn right_minus_left_wrist(m: &Motion) -> f32 {
    let peak = |j: usize| {
        m.frames
            .iter()
            .map(|f| f[j].y)
            .reduce(f32::max)
            .unwrap_or(0.0)
    };
    peak(WRISTS[1]) - peak(WRISTS[0])
}

/// Every per-motion metric at once.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MotionMetrics {
    /// [`foot_skating_ratio`].
    pub skating: f32,
    /// [`max_acceleration`].
    pub max_accel: f32,
    /// [`bone_length_variation`].
    pub bone_variation: f32,
    /// [`floor_penetration`].
    pub penetration: Penetration,
    /// [`mean_root_speed`].
    pub speed: f32,
    /// [`total_turn`].
    pub turn_deg: f32,
    /// [`wrists_above_head`].
    pub wrists_above_head: f32,
    /// [`right_minus_left_wrist`].
    pub wrist_side: f32,
}

impl MotionMetrics {
    /// Measures a motion.
    pub fn of(m: &Motion) -> Self {
        MotionMetrics {
            skating: foot_skating_ratio(m),
            max_accel: max_acceleration(m),
            bone_variation: bone_length_variation(m),
            penetration: floor_penetration(m),
            speed: mean_root_speed(m),
            turn_deg: total_turn(m),
            wrists_above_head: wrists_above_head(m),
            wrist_side: right_minus_left_wrist(m),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::Pose;
    use crate::skeleton::rest_pose;

    /// The rest pose translated by `offset` in every frame.
    fn shifted(offsets: &[Vec3]) -> Motion {
        let rest = rest_pose();
        Motion::new(
            offsets
                .iter()
                .map(|&o| std::array::from_fn(|j| rest[j] + o))
                .collect(),
        )
    }

    fn approx(a: f32, b: f32, tol: f32) {
        assert!((a - b).abs() <= tol, "{a} != {b} (tol {tol})");
    }

    #[test]
    fn moving_average_pads_with_zeros() {
        let avg = moving_average_zero_padded(&[5.0, 5.0, 5.0, 5.0, 5.0, 5.0], 5);
        assert_eq!(avg, vec![3.0, 4.0, 5.0, 5.0, 4.0, 3.0]);
    }

    #[test]
    fn skating_counts_sliding_feet_on_the_floor() {
        // Feet at y = 0.03 (on the floor) for all frames; the whole body slides along +X
        // at 3 cm/frame (0.6 m/s) during steps 0..6, then stands still for steps 6..9.
        let mut pos = vec![Vec3::ZERO];
        for t in 0..9 {
            let step = if t < 6 { 0.03 } else { 0.0 };
            pos.push(pos[t] + Vec3::new(step, 0.0, 0.0));
        }
        let mut m = shifted(&pos);
        for f in &mut m.frames {
            f[10].y = 0.03;
            f[11].y = 0.03;
        }
        // Raw speeds: 0.6 for steps 0..=5, 0 for 6..=8. Centred 5-step sums ÷ 5 (zero
        // padded): 0.36, 0.48, 0.6, 0.6, 0.48, 0.36, 0.24, 0.12, 0. Skating needs both
        // > 0.5: steps 2 and 3 → 2 of 9.
        approx(foot_skating_ratio(&m), 2.0 / 9.0, 1e-6);
        // Lift the feet above 5 cm: no contact, no skating.
        for f in &mut m.frames {
            f[10].y = 0.2;
            f[11].y = 0.2;
        }
        assert_eq!(foot_skating_ratio(&m), 0.0);
    }

    #[test]
    fn skating_needs_both_frames_of_a_step_in_contact() {
        let pos: Vec<Vec3> = (0..8)
            .map(|t| Vec3::new(0.05 * t as f32, 0.0, 0.0))
            .collect();
        let mut m = shifted(&pos);
        for (t, f) in m.frames.iter_mut().enumerate() {
            f[10].y = 0.0;
            f[11].y = if t % 2 == 0 { 0.0 } else { 0.3 };
        }
        // 1 m/s everywhere; the left foot is always down. Averages of steps 0, 1, 5, 6
        // are 0.6, 0.8, 0.8, 0.6 (> 0.5): all 7 steps skate.
        approx(foot_skating_ratio(&m), 1.0, 1e-6);
        for f in &mut m.frames {
            f[10].y = 0.3;
        }
        // Only the right foot now, up every other frame: no step has both ends down.
        assert_eq!(foot_skating_ratio(&m), 0.0);
    }

    #[test]
    fn max_acceleration_of_a_jerk() {
        // Positions along x: 0, 0, 0, 0.1, 0.2 → second differences 0, 0.1, 0.
        let pos: Vec<Vec3> = [0.0, 0.0, 0.0, 0.1, 0.2]
            .iter()
            .map(|&x| Vec3::new(x, 0.0, 0.0))
            .collect();
        let mut m = shifted(&pos);
        approx(max_acceleration(&m), 0.1, 1e-6);
        // Kick the wrist by k = (0, 0.3, 0.4) at frame 2: its second difference is k
        // (length 0.5) at frames 1 and 3 and (0.1, 0, 0) − 2k at frame 2, of length
        // √(0.01 + 0.36 + 0.64) = √1.01.
        m.frames[2][20] += Vec3::new(0.0, 0.3, 0.4);
        approx(max_acceleration(&m), 1.01f32.sqrt(), 1e-5);
        let peak = peak_acceleration(&m);
        assert_eq!((peak.joint, peak.frame), (20, 2));
        assert_eq!(max_acceleration(&shifted(&[Vec3::ZERO; 2])), 0.0);
    }

    #[test]
    fn bone_variation_of_a_stretching_forearm() {
        let rest = rest_pose();
        let frames: Vec<Pose> = [1.0f32, 3.0]
            .iter()
            .map(|&s| {
                let mut p = rest;
                // Wrist 20 placed s × 0.1 m from the elbow: lengths 0.1 and 0.3.
                p[20] = p[18] + Vec3::new(0.0, -0.1 * s, 0.0);
                p
            })
            .collect();
        let m = Motion::new(frames);
        // That bone: mean 0.2, std 0.1 → 0.5; the other 20 bones: 0. Mean 0.5 / 21.
        approx(bone_length_variation(&m), 0.5 / 21.0, 1e-6);
        assert_eq!(bone_length_variation(&shifted(&[Vec3::ZERO; 4])), 0.0);
        // The left forearm is 0.26601 m in the skeleton: 0.1 and 0.3 are 0.16601 and 0.03399 off.
        approx(max_bone_error(&m), 0.26601 - 0.1, 1e-5);
        approx(max_bone_error(&shifted(&[Vec3::ZERO; 4])), 0.0, 1e-5);
    }

    #[test]
    fn penetration_depth_and_fraction() {
        let mut m = shifted(&[Vec3::ZERO; 4]);
        let lowest = m.frames[0]
            .iter()
            .map(|p| p.y)
            .fold(f32::INFINITY, f32::min);
        for f in &mut m.frames {
            for p in f.iter_mut() {
                p.y -= lowest; // lowest joint exactly on the floor
            }
        }
        m.frames[1][10].y = -0.04;
        m.frames[3][11].y = -0.005; // within the tolerance
        let p = floor_penetration(&m);
        approx(p.mean_depth, (0.04 + 0.005) / 4.0, 1e-6);
        approx(p.frame_fraction, 0.25, 1e-6);
    }

    #[test]
    fn speed_of_a_steady_walk() {
        // 5 cm per frame along +Z plus a vertical bob that must not count.
        let pos: Vec<Vec3> = (0..21)
            .map(|t| Vec3::new(0.0, 0.02 * (t % 2) as f32, 0.05 * t as f32))
            .collect();
        approx(mean_root_speed(&shifted(&pos)), 1.0, 1e-5);
    }

    /// Walk a circle arc at 1 m/s starting along +Z and bending towards `side`.x.
    fn arc(degrees: f32, side: f32) -> Motion {
        let frames = 81;
        let radius = 2.0f32;
        let total = degrees.to_radians();
        let pos: Vec<Vec3> = (0..frames)
            .map(|t| {
                let a = total * t as f32 / (frames - 1) as f32;
                // Centre at (side·r, 0, 0); start at the origin heading +Z.
                Vec3::new(side * radius * (1.0 - a.cos()), 0.0, radius * a.sin())
            })
            .collect();
        shifted(&pos)
    }

    #[test]
    fn turning_towards_plus_x_is_a_left_turn() {
        // Facing +Z with Y up, the body's left is +X (left = up × forward).
        let left = Vec3::Y.cross(Vec3::Z);
        assert_eq!(left, Vec3::X);
        let turn = total_turn(&arc(90.0, 1.0));
        // The window heading at the ends lags by half a window: 90° × (1 − 5/80).
        approx(turn, 90.0 * 75.0 / 80.0, 0.5);
        approx(total_turn(&arc(90.0, -1.0)), -90.0 * 75.0 / 80.0, 0.5);
        // More than a full circle unwraps instead of wrapping back.
        assert!(total_turn(&arc(400.0, 1.0)) > 360.0);
        // Standing still (a little sway) has no turn at all.
        let sway: Vec<Vec3> = (0..40)
            .map(|t| Vec3::new(0.003 * (t as f32).sin(), 0.0, 0.0))
            .collect();
        assert_eq!(total_turn(&shifted(&sway)), 0.0);
    }

    #[test]
    fn wrists_relative_to_head() {
        let mut m = shifted(&[Vec3::ZERO; 3]);
        let head = m.frames[0][HEAD].y;
        let below = m.frames[0][20].y.max(m.frames[0][21].y) - head;
        assert!(below < 0.0);
        approx(wrists_above_head(&m), below, 1e-6);
        m.frames[1][21].y = head + 0.25;
        approx(wrists_above_head(&m), 0.25, 1e-6);
        // Right wrist 21 peaks at head + 0.25, the left one stays at its rest height.
        let left_rest = m.frames[0][20].y;
        approx(right_minus_left_wrist(&m), head + 0.25 - left_rest, 1e-6);
        m.frames[2][20].y = head + 0.5;
        approx(right_minus_left_wrist(&m), -0.25, 1e-6);
    }
}
