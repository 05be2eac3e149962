//! Forward kinematics: channel values → global joint positions.
//!
//! In: a parsed [`Bvh`]. Out: `[frames, joints]` global positions in file units (End
//! Sites included), read the way Blender's importer reads them:
//! * a position channel replaces that axis of the joint's OFFSET (the Bandai files put
//!   `Xposition Yposition Zposition` on every joint);
//! * rotation channels compose in the order listed, intrinsically:
//!   `R = R_first · R_second · R_third`, angles in degrees;
//! * local transform = translate(offset or position) · R; global = parent global · local.
//!
//! Resampling happens here, on the channels (positions lerped, local rotations slerped),
//! not on the global positions: interpolating positions would shorten fast-turning bones
//! (by up to 10 % on Bandai dance clips at 30 → 20 fps); this keeps every bone rigid.

use super::parse::{Axis, Bvh, Channel};
use glam::{Quat, Vec3};

/// Where an output frame lies in the source: between frames `i0` and `i1` at `t`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SamplePoint {
    pub i0: usize,
    pub i1: usize,
    pub t: f32,
}

/// Output frames at `fps` covering the source's duration, the rule of
/// [`crate::motion::Motion::resample`]: `floor((frames − 1) · fps / source_fps) + 1` frames.
pub fn sample_points(frame_count: usize, source_fps: f32, fps: f32) -> Vec<SamplePoint> {
    if frame_count < 2 || (fps - source_fps).abs() < 1e-6 {
        return (0..frame_count)
            .map(|i| SamplePoint {
                i0: i,
                i1: i,
                t: 0.0,
            })
            .collect();
    }
    let ratio = f64::from(source_fps) / f64::from(fps);
    let count = sample_count(frame_count, source_fps, fps) as usize;
    (0..count)
        .map(|k| {
            let src = k as f64 * ratio;
            let i0 = (src.floor() as usize).min(frame_count - 1);
            let i1 = (i0 + 1).min(frame_count - 1);
            SamplePoint {
                i0,
                i1,
                t: (src - i0 as f64) as f32,
            }
        })
        .collect()
}

/// Number of output frames [`sample_points`] makes (as `f64`, so absurd frame rates can be
/// refused before anything is allocated).
pub fn sample_count(frame_count: usize, source_fps: f32, fps: f32) -> f64 {
    if frame_count < 2 || (fps - source_fps).abs() < 1e-6 {
        return frame_count as f64;
    }
    let ratio = f64::from(source_fps) / f64::from(fps);
    // The epsilon keeps an exact end frame that f64 rounding would put just short of it.
    (((frame_count - 1) as f64 / ratio) + 1e-9).floor() + 1.0
}

/// Global positions of every joint at every source frame, frame-major:
/// `positions[frame * joints + joint]`.
pub fn global_positions(bvh: &Bvh) -> Vec<Vec3> {
    let all = sample_points(bvh.frame_count, 1.0, 1.0);
    global_positions_at(bvh, &all)
}

/// Global positions at the given sample points (local transforms interpolated).
pub fn global_positions_at(bvh: &Bvh, samples: &[SamplePoint]) -> Vec<Vec3> {
    let joint_count = bvh.joints.len();
    let mut positions = Vec::with_capacity(samples.len() * joint_count);
    let mut rotations = vec![Quat::IDENTITY; joint_count];
    for sample in samples {
        let (values0, values1) = (bvh.frame(sample.i0), bvh.frame(sample.i1));
        let base = positions.len();
        for (j, joint) in bvh.joints.iter().enumerate() {
            let range = joint.first_channel..joint.first_channel + joint.channels.len();
            let (mut translation, mut rotation) =
                local_transform(joint.offset, &joint.channels, &values0[range.clone()]);
            if sample.t > 0.0 {
                let (t1, r1) = local_transform(joint.offset, &joint.channels, &values1[range]);
                translation = translation.lerp(t1, sample.t);
                rotation = rotation.slerp(r1, sample.t);
            }
            let (position, global_rotation) = match joint.parent {
                Some(p) => (
                    positions[base + p] + rotations[p] * translation,
                    rotations[p] * rotation,
                ),
                None => (translation, rotation),
            };
            rotations[j] = global_rotation;
            positions.push(position);
        }
    }
    positions
}

/// Translation and rotation of a joint relative to its parent for one frame.
pub fn local_transform(offset: Vec3, channels: &[Channel], values: &[f32]) -> (Vec3, Quat) {
    let mut translation = offset;
    let mut rotation = Quat::IDENTITY;
    for (channel, &value) in channels.iter().zip(values) {
        match *channel {
            Channel::Position(axis) => translation[axis_index(axis)] = value,
            Channel::Rotation(axis) => {
                let angle = value.to_radians();
                let r = match axis {
                    Axis::X => Quat::from_rotation_x(angle),
                    Axis::Y => Quat::from_rotation_y(angle),
                    Axis::Z => Quat::from_rotation_z(angle),
                };
                rotation *= r;
            }
        }
    }
    (translation, rotation.normalize())
}

fn axis_index(axis: Axis) -> usize {
    match axis {
        Axis::X => 0,
        Axis::Y => 1,
        Axis::Z => 2,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_points_match_motion_resample() {
        let p = sample_points(31, 30.0, 20.0);
        assert_eq!(p.len(), 21);
        assert_eq!(
            p[1],
            SamplePoint {
                i0: 1,
                i1: 2,
                t: 0.5
            }
        );
        assert_eq!(
            p[20],
            SamplePoint {
                i0: 30,
                i1: 30,
                t: 0.0
            }
        );
        assert_eq!(sample_points(4, 30.0, 20.0).len(), 3);
        assert_eq!(sample_points(1, 30.0, 20.0).len(), 1);
        assert_eq!(sample_points(5, 20.0, 20.0).len(), 5);
    }

    #[test]
    fn interpolated_rotation_keeps_bone_length() {
        // A bone swinging 90° between two frames: halfway it is at 45°, still length 1.
        let rotation = [Channel::Rotation(Axis::Z)];
        let (_, r0) = local_transform(Vec3::ZERO, &rotation, &[0.0]);
        let (_, r1) = local_transform(Vec3::ZERO, &rotation, &[90.0]);
        let mid = r0.slerp(r1, 0.5) * Vec3::X;
        assert!((mid.length() - 1.0).abs() < 1e-6);
        assert!((mid - Vec3::new(0.5f32.sqrt(), 0.5f32.sqrt(), 0.0)).length() < 1e-6);
    }
}
