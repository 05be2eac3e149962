//! A take: motion the user already has, as the solvers see it. In: world joint positions,
//! one motion per person (any body, 20 fps). Out: [`Take`], each person's HumanML3D
//! features (retargeted to the model's skeleton, canonical frame) and the [`Placement`]
//! that puts them back where the take stands, so an edit keeps the take's start position
//! and facing.
//!
//! [`Take::splice`] builds the take of an in-between: the end of one take, a gap for the
//! model to fill, the start of another.

use crate::features::kinematics::{body_facing, poses_f64};
use crate::features::{ExtractOptions, FEATURE_DIM, FeatureError, extract, recover_from_ric};
use crate::motion::Motion;
use crate::scene::Placement;
use glam::DVec3;

/// Features and world placement of a take, one entry per person.
#[derive(Clone, Debug, PartialEq)]
pub struct Take {
    /// `[person][frames · 263]` de-normalised features in the model's canonical frame.
    pub features: Vec<Vec<f32>>,
    /// Where each person's canonical motion stands in the world.
    pub placements: Vec<Placement>,
    /// Feature frames (a take of F frames gives F − 1, as HumanML3D's extraction does).
    pub frames: usize,
}

/// The placement of a motion's frame 0: its root's XZ and its facing (the canonical rule
/// of [`crate::features::canonicalize`]), the transform from the canonical frame back to it.
fn start_placement(m: &Motion) -> Result<Placement, FeatureError> {
    let poses = poses_f64(m)?;
    let first = poses.first().ok_or(FeatureError::TooFewFrames {
        frames: 0,
        needed: 2,
    })?;
    let forward = body_facing(first, 0)? * DVec3::Z;
    Ok(Placement {
        yaw: forward.x.atan2(forward.z) as f32,
        x: first[0].x as f32,
        z: first[0].z as f32,
    })
}

impl Take {
    /// Encodes each person's motion: retargeted to HumanML3D's bone lengths, put in the
    /// canonical frame, turned into features (F frames give F − 1); the placement keeps
    /// frame 0's root position and facing. All people must have the same frame count.
    pub fn encode(people: &[Motion]) -> Result<Take, FeatureError> {
        let opts = ExtractOptions {
            uniform_skeleton: true,
        };
        let mut features = Vec::with_capacity(people.len());
        let mut placements = Vec::with_capacity(people.len());
        for m in people {
            features.push(extract(m, &opts)?.into_vec());
            placements.push(start_placement(m)?);
        }
        let frames = features.first().map_or(0, |f| f.len() / FEATURE_DIM);
        Ok(Take {
            features,
            placements,
            frames,
        })
    }

    /// The take of an in-between `frames` long: every frame of `before`, a gap of mean
    /// features (`mean`, de-normalised) for the model to fill, every frame of `after`. It
    /// stands where `before` starts; `after`'s part follows on from wherever the gap leaves
    /// the body (the root is stored as velocities, as in MDM's in-betweening). `None` when
    /// the people differ or the two leave no gap.
    pub fn splice(before: &Take, after: &Take, frames: usize, mean: &[f32]) -> Option<Take> {
        let gap = frames.checked_sub(before.frames + after.frames)?;
        if gap == 0 || before.features.len() != after.features.len() {
            return None;
        }
        let features = before
            .features
            .iter()
            .zip(&after.features)
            .map(|(a, b)| {
                let mut rows = Vec::with_capacity(frames * FEATURE_DIM);
                rows.extend_from_slice(a);
                for _ in 0..gap {
                    rows.extend_from_slice(mean);
                }
                rows.extend_from_slice(b);
                rows
            })
            .collect();
        Some(Take {
            features,
            placements: before.placements.clone(),
            frames,
        })
    }

    /// The people of the take as the model's skeleton draws them, placed in the world:
    /// what an edit at strength 0 returns.
    pub fn motions(&self) -> Result<Vec<Motion>, FeatureError> {
        self.features
            .iter()
            .zip(&self.placements)
            .map(|(f, place)| {
                let mut m = recover_from_ric(f)?;
                for pose in &mut m.frames {
                    for j in pose.iter_mut() {
                        *j = place.apply(*j);
                    }
                }
                Ok(m)
            })
            .collect()
    }
}

/// Frames `lo..hi` of a motion (a part of a take); `None` when the range leaves it.
pub fn frames_of(m: &Motion, lo: usize, hi: usize) -> Option<Motion> {
    (lo < hi && hi <= m.len()).then(|| Motion {
        frames: m.frames[lo..hi].to_vec(),
        fps: m.fps,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::{BONE_LENGTHS, PARENTS, rest_pose};
    use glam::{Quat, Vec3};

    /// A rest pose walking 4 cm a frame along its facing, turned by `yaw` and moved to
    /// `(x, z)`, with the arms swinging so the pose changes.
    fn walk(frames: usize, yaw: f32, x: f32, z: f32) -> Motion {
        let turn = Quat::from_rotation_y(yaw);
        Motion::new(
            (0..frames)
                .map(|t| {
                    let mut p = rest_pose();
                    // Forearms swing about the elbows (bone lengths kept).
                    let swing = Quat::from_rotation_x(0.5 * (t as f32 * 0.3).sin());
                    for (elbow, wrist) in [(18, 20), (19, 21)] {
                        p[wrist] = p[elbow] + swing * (p[wrist] - p[elbow]);
                    }
                    p.map(|v| {
                        turn * (v + Vec3::new(0.0, 0.0, 0.04 * t as f32)) + Vec3::new(x, 0.0, z)
                    })
                })
                .collect(),
        )
    }

    #[test]
    fn a_take_comes_back_where_it_stood() {
        let m = walk(30, 2.0, 3.0, -1.5);
        let take = Take::encode(std::slice::from_ref(&m)).unwrap();
        assert_eq!(take.frames, 29);
        let back = &take.motions().unwrap()[0];
        assert_eq!(back.len(), 29);
        let floor = m.bounds().0.y;
        for (t, (a, b)) in back.frames.iter().zip(&m.frames).enumerate() {
            // The rest pose is HumanML3D's skeleton, so retargeting changes nothing.
            for j in 0..22 {
                let want = b[j] - Vec3::new(0.0, floor, 0.0);
                assert!(
                    (a[j] - want).length() < 2e-3,
                    "frame {t} joint {j}: {} vs {want}",
                    a[j]
                );
            }
        }
    }

    #[test]
    fn a_larger_body_is_retargeted_and_keeps_its_start() {
        let m = walk(12, -0.7, 1.0, 2.0);
        let big = Motion::new(m.frames.iter().map(|p| p.map(|v| v * 1.3)).collect());
        let take = Take::encode(std::slice::from_ref(&big)).unwrap();
        let back = &take.motions().unwrap()[0];
        let root = back.frames[0][0];
        assert!(
            (root.x - 1.3).abs() < 1e-3 && (root.z - 2.6).abs() < 1e-3,
            "{root}"
        );
        for pose in &back.frames {
            for j in 1..22 {
                let bone = (pose[j] - pose[PARENTS[j]]).length();
                assert!((bone - BONE_LENGTHS[j]).abs() < 1e-3, "joint {j}: {bone}");
            }
        }
    }

    #[test]
    fn a_splice_holds_both_ends() {
        let a = Take::encode(&[walk(6, 0.0, 0.0, 0.0)]).unwrap();
        let b = Take::encode(&[walk(6, 1.0, 0.0, 0.0)]).unwrap();
        let mean = vec![0.5; FEATURE_DIM];
        let s = Take::splice(&a, &b, 30, &mean).unwrap();
        let f = &s.features[0];
        assert_eq!(f.len(), 30 * FEATURE_DIM);
        assert_eq!(&f[..5 * FEATURE_DIM], &a.features[0][..]);
        assert_eq!(&f[25 * FEATURE_DIM..], &b.features[0][..]);
        assert!(
            f[5 * FEATURE_DIM..25 * FEATURE_DIM]
                .iter()
                .all(|v| *v == 0.5)
        );
        assert!(Take::splice(&a, &b, 10, &mean).is_none(), "no gap");
        assert!(frames_of(&walk(5, 0.0, 0.0, 0.0), 2, 6).is_none());
        assert_eq!(frames_of(&walk(5, 0.0, 0.0, 0.0), 1, 3).unwrap().len(), 2);
    }
}
