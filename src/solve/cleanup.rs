//! Foot cleanup of a finished motion: planted feet stop sliding, the path stays.
//!
//! The shipped model's walks slide their planted feet (foot skating 0.69 on "walk" against
//! 0.21 for real walks): most of the sliding frames are a toe on the floor creeping at
//! 0.5–1 m/s, where a real planted toe stays put. This pass is the animator's foot lock,
//! done on the generated features rather than by hand:
//!
//! 1. the skeleton projection `P` ([`super::bones`]) is set up on the motion: bones at the
//!    skeleton's lengths, a foot that is on the floor stays on it;
//! 2. the toe-frame pairs that are planted (low and slower than
//!    [`FootCleanup::planted_speed`]) are recorded once ([`FootLock`]);
//! 3. a few Polyak steps on the ric block (joint positions in the body's own frame) reduce
//!    the slide of those pairs, through `P` and `recover_from_ric`; the direction is
//!    smoothed over frames so a leg moves over a few frames, not in one. The root columns
//!    (facing, velocity, height) are not touched: the motion keeps its path and speed,
//!    the legs reach back to where the foot was put down.
//!
//! 4. the same steps keep the motion inside the training data's envelope
//!    ([`EnvelopeGuard`]: no joint under the floor, no acceleration beyond the largest
//!    recorded, no torso folded further than any recorded frame): without it the cleanup
//!    put a whole-body snap of 0.12–0.15 m/frame² into 8 of 80 `gen` walks, 0.7–1 s before
//!    their end, which the raw samples did not have (book, plausibility chapter).
//!
//! It changes only what `recover_from_ric` reads (the first 67 columns); the motion's
//! joints, and every export made from them, are the cleaned ones.

use super::bones::SkeletonProjection;
use super::envelope::EnvelopeGuard;
use super::feet::FootLock;
use super::guide::smooth_over_frames;
use super::host::{HEAD, HostFk, extract_head, insert_head};
use crate::features::layout::FEATURE_DIM;
use crate::features::{FeatureError, recover_from_ric};
use crate::model::generate::Generated;
use crate::skeleton::NUM_JOINTS;

/// Settings of [`clean_feet`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FootCleanup {
    /// Polyak steps.
    pub iterations: usize,
    /// Fraction of the linearised slide each step removes.
    pub fraction: f32,
    /// Largest change of one joint coordinate per step (metres).
    pub max_step: f32,
    /// σ (frames) of the Gaussian smoothing of each step's direction.
    pub smooth_frames: f32,
    /// A toe on the floor slower than this (m/s) is planted; faster, it is swinging.
    /// 1.5 (with 100 iterations) against 1.0 (60): the wider prior's walks skate 0.147 →
    /// 0.126 with the cleanup, at a peak acceleration of 0.151 against 0.134 (`mprog eval
    /// --count 32 --foot-cleanup`, 2026-12-05). Moving the root too (`root_share` 0.6)
    /// reached 0.117 but slowed walks from 0.82 to 0.59 m/s and bent their paths.
    pub planted_speed: f32,
    /// Scale of the root's horizontal velocity in each step (0: the path is kept).
    pub root_share: f32,
    /// Weight of the envelope penalty beside the foot lock (0: off).
    pub envelope: f32,
}

impl Default for FootCleanup {
    fn default() -> Self {
        FootCleanup {
            iterations: 100,
            fraction: 0.5,
            max_step: 0.02,
            smooth_frames: 1.5,
            planted_speed: 1.5,
            root_share: 0.0,
            envelope: 1.0,
        }
    }
}

/// What [`clean_feet`] did, summed over the motions.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CleanupReport {
    /// Planted toe-frame pairs found.
    pub planted: usize,
    /// Slide of a planted pair before the pass (metres per frame; the mean over each
    /// motion's pairs, averaged over the motions).
    pub slide_before: f32,
    /// The same after it.
    pub slide_after: f32,
}

const J3: usize = NUM_JOINTS * 3;

/// Cleans the feet of de-normalised feature rows `[M, frames, width]` in place.
pub fn clean_feet(
    rows: &mut [f32],
    frames: usize,
    width: usize,
    cfg: &FootCleanup,
) -> CleanupReport {
    if frames < 2 || rows.is_empty() {
        return CleanupReport::default();
    }
    let motions = rows.len() / (frames * width);
    let mut head = extract_head(rows, width);
    let mut projection = SkeletonProjection::new(&head, frames);
    let mut fk = HostFk::default();
    let mut projected = vec![0.0; head.len()];
    let mut joints = vec![0.0; motions * frames * J3];
    projection.forward(&head, &mut projected);
    fk.forward(&projected, frames, &mut joints);
    let lock = FootLock::with_speed(&joints, frames, 1, 1.0, cfg.planted_speed, 0.0);
    let planted = lock.planted();
    let guard = (cfg.envelope > 0.0).then(|| EnvelopeGuard::new(frames, 1, cfg.envelope));
    let mean_slide = |penalty: &[f32]| penalty.iter().sum::<f32>() / motions as f32;
    let mut g_joints = vec![0.0; joints.len()];
    let first = lock.eval(&joints, &mut g_joints);
    let mut report = CleanupReport {
        planted,
        slide_before: mean_slide(&first),
        slide_after: mean_slide(&first),
    };
    if planted == 0 {
        return report;
    }
    let mut g_projected = vec![0.0; head.len()];
    let mut g_head = vec![0.0; head.len()];
    let per = frames * HEAD;
    for _ in 0..cfg.iterations {
        projection.forward(&head, &mut projected);
        fk.forward(&projected, frames, &mut joints);
        g_joints.fill(0.0);
        let mut penalty = lock.eval(&joints, &mut g_joints);
        if let Some(guard) = &guard {
            let outside = guard.eval(&joints, &mut g_joints);
            penalty.iter_mut().zip(outside).for_each(|(p, o)| *p += o);
        }
        fk.backward(&projected, &g_joints, &mut g_projected);
        projection.backward(&g_projected, &mut g_head);
        // Only the ric block moves: the path, facing and root height stay the model's.
        for row in g_head.chunks_exact_mut(HEAD) {
            row[0] = 0.0;
            row[1] *= cfg.root_share;
            row[2] *= cfg.root_share;
            row[3] = 0.0;
        }
        let direction = smooth_over_frames(&g_head, frames, HEAD, cfg.smooth_frames);
        for (m, p) in penalty.iter().enumerate() {
            let (g, d) = (
                &g_head[m * per..(m + 1) * per],
                &direction[m * per..(m + 1) * per],
            );
            let slope: f32 = g.iter().zip(d).map(|(a, b)| a * b).sum();
            if *p <= 0.0 || slope <= 0.0 {
                continue;
            }
            let largest = d.iter().fold(0.0f32, |a, v| a.max(v.abs()));
            let step = (cfg.fraction * p / slope).min(cfg.max_step / largest.max(f32::EPSILON));
            for (h, v) in head[m * per..(m + 1) * per].iter_mut().zip(d) {
                *h -= step * v;
            }
        }
    }
    projection.forward(&head, &mut projected);
    fk.forward(&projected, frames, &mut joints);
    g_joints.fill(0.0);
    report.slide_after = mean_slide(&lock.eval(&joints, &mut g_joints));
    insert_head(rows, width, &projected);
    report
}

/// [`clean_feet`] on generated motions: cleans their features and recovers their joints
/// again.
pub fn clean_generated(
    generated: &mut Generated,
    frames: usize,
    cfg: &FootCleanup,
) -> Result<CleanupReport, FeatureError> {
    let report = clean_feet(&mut generated.features, frames, FEATURE_DIM, cfg);
    generated.motions = generated
        .features
        .chunks_exact(frames * FEATURE_DIM)
        .map(recover_from_ric)
        .collect::<Result<Vec<_>, _>>()?;
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::{ExtractOptions, extract};
    use crate::motion::Motion;
    use crate::skeleton::{BONE_LENGTHS, PARENTS, rest_pose};
    use glam::Vec3;

    /// The rest pose gliding forward at `speed` m/s, feet on the floor: every toe skates.
    fn glide(frames: usize, speed: f32) -> Vec<f32> {
        let pose = rest_pose();
        let motion = Motion::new(
            (0..=frames)
                .map(|t| pose.map(|p| p + Vec3::Z * speed * t as f32 / 20.0))
                .collect(),
        );
        extract(&motion, &ExtractOptions::default())
            .unwrap()
            .into_vec()
    }

    fn joints(rows: &[f32]) -> Motion {
        recover_from_ric(rows).unwrap()
    }

    #[test]
    fn a_gliding_body_plants_its_feet_and_keeps_its_path_and_bones() {
        // 36 cm of glide: within reach of legs that stay put.
        let frames = 12;
        let mut rows = glide(frames, 0.6);
        let before = rows.clone();
        let report = clean_feet(&mut rows, frames, FEATURE_DIM, &FootCleanup::default());
        assert_eq!(
            report.planted,
            2 * (frames - 1),
            "both toes, every frame pair"
        );
        assert!(report.slide_after < 0.5 * report.slide_before, "{report:?}");
        let after = joints(&rows);
        // The root columns (facing, velocity, height) are the model's.
        for (a, b) in rows
            .chunks_exact(FEATURE_DIM)
            .zip(before.chunks_exact(FEATURE_DIM))
        {
            assert_eq!(a[..3], b[..3]);
        }
        // Every bone has the skeleton's length.
        for pose in &after.frames {
            for j in 1..NUM_JOINTS {
                let len = (pose[j] - pose[PARENTS[j]]).length();
                assert!((len - BONE_LENGTHS[j]).abs() < 1e-4, "joint {j}: {len}");
            }
        }
    }

    #[test]
    fn cleanup_is_deterministic_and_leaves_a_still_body_alone() {
        let frames = 30;
        let mut a = glide(frames, 0.6);
        let mut b = a.clone();
        let cfg = FootCleanup::default();
        assert_eq!(
            clean_feet(&mut a, frames, FEATURE_DIM, &cfg),
            clean_feet(&mut b, frames, FEATURE_DIM, &cfg)
        );
        assert_eq!(a, b);
        let mut still = glide(frames, 0.0);
        let original = joints(&still);
        let report = clean_feet(&mut still, frames, FEATURE_DIM, &cfg);
        assert_eq!(report.slide_before, 0.0);
        let cleaned = joints(&still);
        for (p, q) in original.frames.iter().zip(&cleaned.frames) {
            for (x, y) in p.iter().zip(q) {
                assert!((*x - *y).length() < 1e-4, "{x} moved to {y}");
            }
        }
    }
}
