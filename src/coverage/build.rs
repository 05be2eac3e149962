//! Building the coverage set from a training set's clips: every frame is made canonical
//! ([`super::pose::canonical`]) and kept as a new pose unless one already kept lies within
//! the cover distance of it (largest joint distance), a greedy ε-cover; each clip keeps,
//! per frame, the index of the nearest kept pose, so runs of frames (how long a pose is
//! held) survive.

use super::pose::{Pose, canonical, frame_pose, joint_distance};
use super::{Clip, Coverage, NO_POSE};
use crate::skeleton::NUM_JOINTS;
use std::collections::HashMap;

/// One clip to add.
pub struct ClipInput<'a> {
    /// Its name in the training set.
    pub name: &'a str,
    /// Its first caption.
    pub caption: &'a str,
    /// Joint positions, `frames × 22 × 3`.
    pub joints: &'a [f32],
}

/// Cell of the lookup grid: four coordinates that tell poses apart (the pelvis's and both
/// wrists' heights, the feet's stride), in units of the cover distance; two poses within
/// the cover distance are in the same or neighbouring cells.
fn cell(p: &Pose, size: f32) -> [i32; 4] {
    let q = |v: f32| (v / size).floor() as i32;
    [q(p[0][1]), q(p[20][1]), q(p[21][1]), q(p[7][2] - p[8][2])]
}

/// The nearest kept pose within `cover` of `p`, if any.
fn find(grid: &HashMap<[i32; 4], Vec<u32>>, poses: &[Pose], p: &Pose, cover: f32) -> Option<u32> {
    let c = cell(p, cover);
    let mut best: Option<(f32, u32)> = None;
    // The stride is a difference of two joints, so it moves up to twice the cover.
    for d0 in -1..=1 {
        for d1 in -1..=1 {
            for d2 in -1..=1 {
                for d3 in -2..=2 {
                    let key = [c[0] + d0, c[1] + d1, c[2] + d2, c[3] + d3];
                    if let Some(list) = grid.get(&key) {
                        for &i in list {
                            let d = joint_distance(&poses[i as usize], p);
                            if d <= cover && best.is_none_or(|(b, _)| d < b) {
                                best = Some((d, i));
                            }
                        }
                    }
                }
            }
        }
    }
    best.map(|(_, i)| i)
}

/// The coverage set of `clips` with cover distance `cover` (m). `mirrored` says the
/// training set also holds every clip's left/right mirror image (so the search reads
/// each pose mirrored too); `source` says what it was built from.
pub fn build(clips: &[ClipInput<'_>], source: &str, cover: f32, mirrored: bool) -> Coverage {
    let mut poses: Vec<Pose> = Vec::new();
    let mut grid: HashMap<[i32; 4], Vec<u32>> = HashMap::new();
    let mut out = Vec::with_capacity(clips.len());
    for c in clips {
        let n = c.joints.len() / (NUM_JOINTS * 3);
        let mut frames = Vec::with_capacity(n);
        for t in 0..n {
            let p = canonical(&frame_pose(c.joints, t));
            if p.iter().flatten().any(|v| !v.is_finite()) {
                frames.push(NO_POSE);
                continue;
            }
            let i = find(&grid, &poses, &p, cover).unwrap_or_else(|| {
                let i = poses.len() as u32;
                grid.entry(cell(&p, cover)).or_default().push(i);
                poses.push(p);
                i
            });
            frames.push(i);
        }
        out.push(Clip {
            name: c.name.to_string(),
            caption: c.caption.to_string(),
            frames,
        });
    }
    Coverage::new(source.to_string(), cover, mirrored, poses, out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(poses: &[Pose]) -> Vec<f32> {
        poses.iter().flatten().flatten().copied().collect()
    }

    #[test]
    fn near_frames_share_a_pose_and_far_ones_do_not() {
        let rest = crate::skeleton::rest_pose().map(|v| [v.x, v.y, v.z]);
        let mut near = rest;
        near[20][1] += 0.01;
        let mut far = rest;
        far[20][1] += 0.3;
        // A moved and turned copy is the same pose.
        let moved = rest.map(|[x, y, z]| [z + 3.0, y, -x]);
        let joints = flat(&[rest, near, far, moved]);
        let clips = [ClipInput {
            name: "a",
            caption: "a person stands",
            joints: &joints,
        }];
        let cov = build(&clips, "test", 0.04, true);
        assert_eq!(cov.poses.len(), 2);
        assert_eq!(cov.clips[0].frames, [0, 0, 1, 0]);
    }
}
