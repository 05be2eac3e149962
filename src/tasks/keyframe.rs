//! OmniControl-style keyframe control: joint positions of held-out test clips at a few
//! frames (or all of them) are the targets; the error is the mean distance to them.
//!
//! All the cells of one clip (joint × density) are solved as one batch: sample `b` carries
//! its own target mask, so the error is one whole-tensor expression over `[B, 1, N, 22, 3]`.

use crate::features::{FEATURE_DIM, recover_from_ric};
use crate::motion::Motion;
use crate::skeleton::NUM_JOINTS;
use burn::prelude::*;
use rand::SeedableRng;
use rand::seq::index::sample;
use rand_chacha::ChaCha8Rng;

/// Joints OmniControl controls, with the names its tables use.
pub const CONTROLLED: [(usize, &str); 6] = [
    (0, "pelvis"),
    (10, "left foot"),
    (11, "right foot"),
    (15, "head"),
    (20, "left wrist"),
    (21, "right wrist"),
];

/// How many frames of a motion are constrained.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Density {
    /// This many frames.
    Frames(usize),
    /// This fraction of the frames (at least one).
    Fraction(f32),
}

impl Density {
    /// OmniControl's densities: 1, 2, 5 frames, 25 % and 100 %.
    pub const ALL: [Density; 5] = [
        Density::Frames(1),
        Density::Frames(2),
        Density::Frames(5),
        Density::Fraction(0.25),
        Density::Fraction(1.0),
    ];

    /// Number of keyframes in a motion of `n` frames.
    pub fn count(self, n: usize) -> usize {
        match self {
            Density::Frames(k) => k.min(n),
            Density::Fraction(f) => ((n as f32 * f).round() as usize).clamp(1, n),
        }
    }

    /// Short label: `1 frame`, `25 %`.
    pub fn label(self) -> String {
        match self {
            Density::Frames(1) => "1 frame".into(),
            Density::Frames(k) => format!("{k} frames"),
            Density::Fraction(f) => format!("{:.0} %", f * 100.0),
        }
    }
}

/// One cell: a joint constrained at some frames of one clip.
#[derive(Clone, Debug)]
pub struct Cell {
    /// Joint index.
    pub joint: usize,
    /// Density.
    pub density: Density,
    /// The constrained frames, ascending.
    pub frames: Vec<usize>,
}

/// The cells of one test clip, solved as one batch.
#[derive(Clone, Debug)]
pub struct KeyframeGoal {
    /// The clip's joints over the first `frames` frames (canonical frame, as generated).
    pub reference: Motion,
    /// One cell per sample.
    pub cells: Vec<Cell>,
}

impl KeyframeGoal {
    /// Cells for every (joint, density) pair, frames drawn from a generator seeded by `seed`.
    /// `features` are the clip's de-normalised feature rows, cut to the motion length.
    pub fn new(
        features: &[f32],
        joints: &[usize],
        densities: &[Density],
        seed: u64,
    ) -> Result<Self, String> {
        let reference = recover_from_ric(features).map_err(|e| e.to_string())?;
        let n = features.len() / FEATURE_DIM;
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut cells = Vec::new();
        for &joint in joints {
            for &density in densities {
                let mut frames = sample(&mut rng, n, density.count(n)).into_vec();
                frames.sort_unstable();
                cells.push(Cell {
                    joint,
                    density,
                    frames,
                });
            }
        }
        Ok(KeyframeGoal { reference, cells })
    }

    /// Frames per motion.
    pub fn frames(&self) -> usize {
        self.reference.len()
    }

    /// `[B, 1, N, 22, 3]` targets and `[B, 1, N, 22, 1]` mask (1 on constrained entries).
    pub fn tensors(&self, device: &Device) -> (Tensor<5>, Tensor<5>) {
        let (b, n) = (self.cells.len(), self.frames());
        let flat = self.reference.to_flat();
        let mut target = Vec::with_capacity(b * flat.len());
        let mut mask = vec![0.0f32; b * n * NUM_JOINTS];
        for (i, cell) in self.cells.iter().enumerate() {
            target.extend_from_slice(&flat);
            for &t in &cell.frames {
                mask[(i * n + t) * NUM_JOINTS + cell.joint] = 1.0;
            }
        }
        (
            Tensor::from_data(TensorData::new(target, [b, 1, n, NUM_JOINTS, 3]), device),
            Tensor::from_data(TensorData::new(mask, [b, 1, n, NUM_JOINTS, 1]), device),
        )
    }

    /// `[B]` mean distance (m) of each sample's constrained joint to its targets, smoothed
    /// by 1 mm near zero so the gradient stays finite at a hit.
    pub fn error(&self, joints: Tensor<5>) -> Tensor<1> {
        let b = joints.dims()[0];
        let (target, mask) = self.tensors(&joints.device());
        let d2 = (joints - target).powi_scalar(2).sum_dim(4); // [B, 1, N, 22, 1]
        let dist = (d2 + 1e-6).sqrt() - 1e-3;
        let count = mask.clone().sum_dim(2).sum_dim(3).reshape([b]);
        (dist * mask).sum_dim(2).sum_dim(3).reshape([b]) / count
    }

    /// Distances (m) of each cell's keyframes in generated motions (one per cell).
    pub fn distances(&self, motions: &[Motion]) -> Vec<Vec<f32>> {
        self.cells
            .iter()
            .zip(motions)
            .map(|(cell, m)| {
                cell.frames
                    .iter()
                    .map(|&t| {
                        (m.frames[t][cell.joint] - self.reference.frames[t][cell.joint]).length()
                    })
                    .collect()
            })
            .collect()
    }
}

/// OmniControl's control metrics over a set of keyframe distances (one list per motion).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ControlErrors {
    /// Fraction of motions with any keyframe farther than 50 cm ("Traj. err.").
    pub traj: f32,
    /// Fraction of keyframes farther than 50 cm ("Loc. err.").
    pub loc: f32,
    /// Mean keyframe distance in metres ("Avg. err.").
    pub avg: f32,
    /// Fraction of motions with any keyframe farther than 5 cm (this benchmark's
    /// "unsuccess rate").
    pub unsuccess: f32,
}

/// OmniControl's threshold for trajectory and location errors (m).
pub const OMNI_THRESHOLD: f32 = 0.5;
/// The benchmark's success threshold (m).
pub const HIT_THRESHOLD: f32 = 0.05;

impl ControlErrors {
    /// The metrics of `distances` (one list per motion).
    pub fn of(distances: &[Vec<f32>]) -> Self {
        let motions = distances.len().max(1) as f32;
        let all: Vec<f32> = distances.iter().flatten().copied().collect();
        let keys = all.len().max(1) as f32;
        let any_over = |th: f32| {
            distances
                .iter()
                .filter(|d| d.iter().any(|&x| x > th))
                .count()
        };
        ControlErrors {
            traj: any_over(OMNI_THRESHOLD) as f32 / motions,
            loc: all.iter().filter(|&&x| x > OMNI_THRESHOLD).count() as f32 / keys,
            avg: all.iter().sum::<f32>() / keys,
            unsuccess: any_over(HIT_THRESHOLD) as f32 / motions,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::{ExtractOptions, extract};
    use glam::Vec3;

    fn walk(n: usize) -> Vec<f32> {
        let rest = crate::skeleton::rest_pose();
        let frames: Vec<_> = (0..=n)
            .map(|t| rest.map(|p| p + Vec3::new(0.0, 0.0, 0.05 * t as f32)))
            .collect();
        extract(&Motion::new(frames), &ExtractOptions::default())
            .unwrap()
            .into_vec()
    }

    #[test]
    fn cells_cover_every_pair_with_the_right_number_of_frames() {
        let g = KeyframeGoal::new(&walk(40), &[0, 20], &Density::ALL, 3).unwrap();
        assert_eq!(g.cells.len(), 10);
        let counts: Vec<usize> = g.cells.iter().take(5).map(|c| c.frames.len()).collect();
        assert_eq!(counts, [1, 2, 5, 10, 40]);
        assert!(
            g.cells
                .iter()
                .all(|c| c.frames.windows(2).all(|w| w[0] < w[1]))
        );
    }

    #[test]
    fn error_is_zero_on_the_reference_and_the_offset_elsewhere() {
        let g = KeyframeGoal::new(&walk(30), &[0, 15], &[Density::Frames(2)], 1).unwrap();
        let dev = Device::flex();
        let n = g.frames();
        let exact: Vec<f32> = [g.reference.to_flat(), g.reference.to_flat()].concat();
        let exact: Tensor<5> = Tensor::from_data(TensorData::new(exact, [2, 1, n, 22, 3]), &dev);
        let e = g
            .error(exact.clone())
            .into_data()
            .try_into_vec::<f32>()
            .unwrap();
        assert!(e.iter().all(|v| v.abs() < 1e-5), "{e:?}");
        let moved =
            exact + Tensor::<1>::from_floats([0.3, 0.0, 0.4], &dev).reshape([1, 1, 1, 1, 3]);
        let e = g.error(moved).into_data().try_into_vec::<f32>().unwrap();
        // The smooth distance sqrt(d² + 1e-6) - 1e-3 is zero at d = 0 and d - 1 mm far away.
        assert!(e.iter().all(|v| (v - 0.499).abs() < 1e-4), "{e:?}");
    }

    #[test]
    fn control_errors_follow_omnicontrol() {
        let m = ControlErrors::of(&[vec![0.01, 0.6], vec![0.02, 0.03]]);
        assert_eq!(m.traj, 0.5);
        assert_eq!(m.loc, 0.25);
        assert!((m.avg - 0.165).abs() < 1e-6);
        assert_eq!(m.unsuccess, 0.5);
    }
}
