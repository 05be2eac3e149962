//! Feature extraction (HumanML3D `process_file`): in, a motion of F frames; out, F − 1
//! feature frames in the layout of [`super::layout`].
//!
//! Steps: optional retarget to the uniform skeleton ([`super::uniform_skeleton`]),
//! [`super::canonicalize`], foot contacts, the smoothed per-frame root rotation `r[t]`
//! ([`kinematics::root_rotations`], quirk included), IK for the 6-D block, then per frame t < F − 1:
//! * yaw velocity = arcsin of the y component of `r[t+1]·r[t]⁻¹` (a half-angle);
//! * root velocity = `r[t+1]·(p₀[t+1] − p₀[t])`, x and z;
//! * root height = `p₀[t].y`;
//! * ric = `r[t]·(p_j[t] − (p₀[t].x, 0, p₀[t].z))` for joints 1..21;
//! * rot = 6-D of the local rotations of joints 1..21;
//! * local velocity = `r[t]·(p_j[t+1] − p_j[t])` for all 22 joints;
//! * contacts = `‖p_j[t+1] − p_j[t]‖² < 0.002` for joints 7, 10, 8, 11.

use super::FeatureError;
use super::canonical::canonicalize_f64;
use super::kinematics::{self, Pose64};
use super::layout::{FEATURE_DIM, Features};
use super::retarget::uniform_skeleton_f64;
use crate::motion::Motion;
use crate::skeleton::{FOOT_LEFT, FOOT_RIGHT, FPS, NUM_JOINTS};
use glam::{DQuat, DVec3};

/// Squared per-frame displacement (m²) below which a foot joint is in contact.
pub const FOOT_CONTACT_THRESHOLD: f64 = 0.002;

/// Options of [`extract`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ExtractOptions {
    /// Retarget to HumanML3D's bone lengths first ([`super::uniform_skeleton`]). Use it for
    /// clips from another skeleton (e.g. imported mocap), so every clip has the same body;
    /// leave it off for motions already on HumanML3D's skeleton.
    pub uniform_skeleton: bool,
}

/// Extracts HumanML3D features: F frames in, F − 1 feature frames out.
///
/// Errors: fewer than 2 frames, a frame rate other than 20 fps, non-finite coordinates,
/// zero-length bones, or hips and shoulders that give no facing direction.
pub fn extract(m: &Motion, opts: &ExtractOptions) -> Result<Features, FeatureError> {
    if m.len() < 2 {
        return Err(FeatureError::TooFewFrames {
            frames: m.len(),
            needed: 2,
        });
    }
    if (m.fps - FPS).abs() > 1e-3 {
        return Err(FeatureError::WrongFps { fps: m.fps });
    }
    let mut poses = kinematics::poses_f64(m)?;
    if opts.uniform_skeleton {
        poses = uniform_skeleton_f64(&poses)?;
    }
    let poses = canonicalize_f64(poses)?;
    let roots = kinematics::root_rotations(&poses, true)?;
    let locals = kinematics::inverse_kinematics(&poses, &roots)?;
    let mut data = Vec::with_capacity((poses.len() - 1) * FEATURE_DIM);
    for t in 0..poses.len() - 1 {
        let frame = Frame {
            now: &poses[t],
            next: &poses[t + 1],
            r: roots[t],
            r_next: roots[t + 1],
        };
        frame.push_row(&locals[t], &mut data);
    }
    Features::from_vec(data)
}

/// Foot contacts of one frame pair: left ankle, left foot, right ankle, right foot.
pub fn foot_contacts(now: &[DVec3; NUM_JOINTS], next: &[DVec3; NUM_JOINTS]) -> [f32; 4] {
    let [la, lf] = FOOT_LEFT;
    let [ra, rf] = FOOT_RIGHT;
    [la, lf, ra, rf].map(|j| {
        f32::from(u8::from(
            (next[j] - now[j]).length_squared() < FOOT_CONTACT_THRESHOLD,
        ))
    })
}

/// One frame t with its successor and their root rotations.
struct Frame<'a> {
    now: &'a Pose64,
    next: &'a Pose64,
    r: DQuat,
    r_next: DQuat,
}

impl Frame<'_> {
    /// Appends the 263 values of this frame to `out`.
    fn push_row(&self, locals: &[DQuat; NUM_JOINTS], out: &mut Vec<f32>) {
        let start = out.len();
        let push3 = |out: &mut Vec<f32>, v: DVec3| out.extend([v.x as f32, v.y as f32, v.z as f32]);
        let root = self.now[0];
        // Root: yaw velocity (half-angle), velocity in the next frame's facing, height.
        let yaw_step = self.r_next * self.r.inverse();
        let vel = self.r_next * (self.next[0] - root);
        out.extend([
            yaw_step.y.clamp(-1.0, 1.0).asin() as f32,
            vel.x as f32,
            vel.z as f32,
            root.y as f32,
        ]);
        // ric: root-relative in XZ only (absolute height), in this frame's facing.
        let ground = DVec3::new(root.x, 0.0, root.z);
        for p in &self.now[1..] {
            push3(out, self.r * (*p - ground));
        }
        for q in &locals[1..] {
            out.extend(kinematics::rotation_6d(*q).map(|x| x as f32));
        }
        for (p, n) in self.now.iter().zip(self.next) {
            push3(out, self.r * (*n - *p));
        }
        out.extend(foot_contacts(self.now, self.next));
        debug_assert_eq!(out.len() - start, FEATURE_DIM);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::layout::{CONTACT, RIC, ROOT_Y};
    use crate::skeleton::rest_pose;
    use glam::Vec3;

    #[test]
    fn standing_still_gives_zero_velocities_and_full_contact() {
        let m = Motion::new(vec![rest_pose(); 5]);
        let f = extract(&m, &ExtractOptions::default()).unwrap();
        assert_eq!(f.frames(), 4);
        let floor = rest_pose()
            .iter()
            .map(|p| p.y)
            .fold(f32::INFINITY, f32::min);
        for row in f.rows() {
            assert!(row[..3].iter().all(|x| x.abs() < 1e-6));
            assert!((row[ROOT_Y.start] - (rest_pose()[0].y - floor)).abs() < 1e-6);
            assert_eq!(&row[CONTACT], &[1.0; 4]);
            // ric of the left hip: +X of the root by its bone length.
            assert!((row[RIC.start] - 0.10307).abs() < 1e-5);
        }
    }

    #[test]
    fn too_short_or_broken_motions_are_errors() {
        let one = Motion::new(vec![rest_pose()]);
        assert!(matches!(
            extract(&one, &ExtractOptions::default()),
            Err(FeatureError::TooFewFrames {
                frames: 1,
                needed: 2
            })
        ));
        let mut bad = vec![rest_pose(); 3];
        bad[2][7] = Vec3::new(f32::INFINITY, 0.0, 0.0);
        assert!(matches!(
            extract(&Motion::new(bad), &ExtractOptions::default()),
            Err(FeatureError::NonFinite {
                frame: 2,
                joint: 7,
                ..
            })
        ));
    }
}
