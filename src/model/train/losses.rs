//! The loss of one training batch: masked x0 MSE plus MDM's geometric terms (foot
//! contact, velocity) and the extra root-column MSE.

use super::augment::noisy_vectors;
use super::text::TrainText;
use crate::dataset::FEATURE_DIM;
use crate::features::layout::{CONTACT, RIC, ROOT_Y, ROOT_YAW_VEL};
use crate::features::recover_from_ric_tensor;
use crate::model::batch::HostBatch;
use crate::model::config::TrainConfig;
use crate::model::denoiser::{Denoiser, DenoiserInput, Mdm};
use crate::model::noise::NoiseSource;
use crate::model::prompt::{SentenceBatch, TextBatch};
use crate::model::schedule::NoiseSchedule;
use crate::skeleton::{BONE_LENGTHS, FOOT_LEFT, FOOT_RIGHT, NUM_JOINTS, PARENTS};
use burn::prelude::*;

/// A batch moved to tensors.
pub(crate) fn to_device(
    batch: &HostBatch,
    text: &TrainText,
    device: &Device,
) -> (DenoiserInput, Tensor<3>, Tensor<3>) {
    let b = batch.captions.len();
    let n = batch.frames;
    let x0: Tensor<3> = Tensor::from_data(
        TensorData::new(batch.x0.clone(), [b, n, FEATURE_DIM]),
        device,
    );
    let valid: Vec<f32> = batch
        .padding
        .iter()
        .map(|&p| if p { 0.0 } else { 1.0 })
        .collect();
    let valid: Tensor<3> = Tensor::from_data(TensorData::new(valid, [b, n, 1]), device);
    let captions: Vec<&str> = batch.captions.iter().map(String::as_str).collect();
    let text = match text.batch(&captions, device) {
        TextBatch::Sentences(s) if batch.text_noise > 0.0 => {
            let (vectors, mirrored) =
                noisy_vectors(s.vectors, s.mirrored, batch.text_noise, batch.noise_seed);
            TextBatch::Sentences(SentenceBatch {
                vectors,
                mirrored,
                tokens: s.tokens,
            })
        }
        other => other,
    };
    let text = match text {
        TextBatch::Sentences(s) if !batch.eos_keep.is_empty() => {
            let keep =
                Tensor::<2>::from_data(TensorData::new(batch.eos_keep.clone(), [b, 1]), device);
            TextBatch::Sentences(SentenceBatch {
                vectors: s.vectors * keep,
                ..s
            })
        }
        other => other,
    };
    let input = DenoiserInput {
        x_t: x0.clone(),
        timesteps: batch.timesteps.clone(),
        text,
        keep_text: Tensor::from_data(TensorData::new(batch.keep_text.clone(), [b]), device),
        padding: Some(Tensor::from_data(
            TensorData::new(batch.padding.clone(), [b, n]),
            device,
        )),
    };
    (input, x0, valid)
}

/// Noises x0 to each sample's timestep: x_t = √ᾱ x0 + √(1−ᾱ) ε.
pub(crate) fn q_sample(
    schedule: &NoiseSchedule,
    x0: Tensor<3>,
    timesteps: &[usize],
    seed: u64,
) -> Tensor<3> {
    let device = x0.device();
    let dims = x0.dims();
    let (a, s): (Vec<f32>, Vec<f32>) = timesteps
        .iter()
        .map(|&t| {
            let ab = schedule.alphas_cumprod[t];
            (ab.sqrt() as f32, (1.0 - ab).sqrt() as f32)
        })
        .unzip();
    let b = timesteps.len();
    let a: Tensor<3> = Tensor::from_data(TensorData::new(a, [b, 1, 1]), &device);
    let s: Tensor<3> = Tensor::from_data(TensorData::new(s, [b, 1, 1]), &device);
    let eps = NoiseSource::new(seed).tensor(dims, &device);
    x0 * a + eps * s
}

/// Masked x0 MSE: Σ over valid frames and features / (#valid frames · F).
pub fn masked_mse(pred: Tensor<3>, x0: Tensor<3>, valid: Tensor<3>) -> Tensor<1> {
    let f = pred.dims()[2] as f32;
    let err = (pred - x0).powi_scalar(2) * valid.clone();
    err.sum() / (valid.sum() * f)
}

/// Masked x0 MSE averaged per sample, then over the batch (MDM's `masked_l2`): each clip
/// counts the same, however many of its frames are padding.
pub fn per_clip_mse(pred: Tensor<3>, x0: Tensor<3>, valid: Tensor<3>) -> Tensor<1> {
    let [b, _, f] = pred.dims();
    let err = (pred - x0).powi_scalar(2) * valid.clone();
    let per_clip = err.sum_dim(2).sum_dim(1).reshape([b]);
    let frames = valid.sum_dim(1).reshape([b]).clamp_min(1.0);
    (per_clip / (frames * f as f32)).mean()
}

/// Masked x0 MSE of the root columns alone (yaw velocity, XZ velocity, height).
pub fn root_mse(pred: Tensor<3>, x0: Tensor<3>, valid: Tensor<3>) -> Tensor<1> {
    let root = ROOT_YAW_VEL.start..ROOT_Y.end;
    let cols = |t: Tensor<3>| t.narrow(2, root.start, root.len());
    masked_mse(cols(pred), cols(x0), valid)
}

/// Foot-contact loss (MDM's L_foot): the squared per-frame displacement, in cm², of each
/// foot joint (ankles and toes) of the predicted motion on the frame pairs where the
/// data's contact label says that joint is planted, averaged over those pairs.
pub struct FootLoss {
    /// Weight of the term in the training loss.
    pub weight: f32,
    /// `[1, 1, 263]` feature mean, to de-normalise predictions.
    pub mean: Tensor<3>,
    /// `[1, 1, 263]` feature std.
    pub std: Tensor<3>,
}

impl FootLoss {
    /// The loss for a dataset's statistics, or None when `weight` is 0.
    pub fn new(weight: f64, mean: &[f32], std: &[f32], device: &Device) -> Option<Self> {
        let stat =
            |v: &[f32]| Tensor::from_data(TensorData::new(v.to_vec(), [1, 1, v.len()]), device);
        (weight > 0.0).then(|| FootLoss {
            weight: weight as f32,
            mean: stat(mean),
            std: stat(std),
        })
    }

    /// The term for normalised prediction and target `[B, N, 263]`, `valid` `[B, N, 1]`.
    pub fn term(&self, pred: Tensor<3>, x0: Tensor<3>, valid: Tensor<3>) -> Tensor<1> {
        let [b, n, _] = pred.dims();
        if n < 2 {
            return Tensor::zeros([1], &pred.device());
        }
        let device = pred.device();
        let joints = recover_from_ric_tensor(pred * self.std.clone() + self.mean.clone());
        let feet: Vec<i64> = FOOT_LEFT
            .iter()
            .chain(FOOT_RIGHT.iter())
            .map(|&j| j as i64)
            .collect();
        let feet = joints.select(2, Tensor::from_data(TensorData::new(feet, [4]), &device)); // [B, N, 4, 3]
        let step = (feet.clone().narrow(1, 1, n - 1) - feet.narrow(1, 0, n - 1)).mul_scalar(100.0);
        let slide = step.powi_scalar(2).sum_dim(3).reshape([b, n - 1, 4]);
        let c = CONTACT.start;
        let label = x0.narrow(2, c, 4) * self.std.clone().narrow(2, c, 4)
            + self.mean.clone().narrow(2, c, 4);
        let both_valid = valid.clone().narrow(1, 0, n - 1) * valid.narrow(1, 1, n - 1);
        let planted = label.narrow(1, 0, n - 1).greater_elem(0.5).float() * both_valid;
        (slide * planted.clone()).sum() / (planted.sum() + 1.0)
    }
}

/// Velocity loss (MDM's L_vel) on the joint positions the features store (root height and
/// the 21 root-relative joints): the squared error, in cm² per joint, of the predicted
/// per-frame displacement against the data's, averaged over valid frame pairs. The x0 MSE
/// treats every frame alone, so an undertrained model's errors are independent from frame
/// to frame and show as jitter; this term penalises exactly that high-frequency part.
pub struct VelocityLoss {
    /// Weight of the term in the training loss.
    pub weight: f32,
    /// `[1, 1, 64]` feature std of the position block, to de-normalise the error (the
    /// mean cancels in a difference).
    pub std: Tensor<3>,
}

/// The feature columns the velocity loss reads: root height then the 21 joints' x, y, z.
const POSITION_COLUMNS: std::ops::Range<usize> = ROOT_Y.start..RIC.end;

impl VelocityLoss {
    /// The loss for a dataset's statistics, or None when `weight` is 0.
    pub fn new(weight: f64, std: &[f32], device: &Device) -> Option<Self> {
        let cols = std[POSITION_COLUMNS].to_vec();
        let len = cols.len();
        (weight > 0.0).then(|| VelocityLoss {
            weight: weight as f32,
            std: Tensor::from_data(TensorData::new(cols, [1, 1, len]), device),
        })
    }

    /// The term for normalised prediction and target `[B, N, 263]`, `valid` `[B, N, 1]`.
    pub fn term(&self, pred: Tensor<3>, x0: Tensor<3>, valid: Tensor<3>) -> Tensor<1> {
        let n = pred.dims()[1];
        if n < 2 {
            return Tensor::zeros([1], &pred.device());
        }
        let cols = POSITION_COLUMNS;
        let err = (pred.narrow(2, cols.start, cols.len()) - x0.narrow(2, cols.start, cols.len()))
            * self.std.clone()
            * 100.0;
        let step = err.clone().narrow(1, 1, n - 1) - err.narrow(1, 0, n - 1);
        let both_valid = valid.clone().narrow(1, 0, n - 1) * valid.narrow(1, 1, n - 1);
        // Sum over the columns / 3 = squared displacement error per joint (root height
        // counts as a third of a joint).
        let per_pair =
            step.powi_scalar(2).sum_dim(2) * both_valid.clone() / (cols.len() as f32 / 3.0);
        per_pair.sum() / (both_valid.sum() + 1.0)
    }
}

/// Bone-length loss: the squared difference, in cm², between each bone of the predicted
/// pose and its length on the skeleton every training clip is retargeted to
/// ([`BONE_LENGTHS`]), averaged over the 21 bones and the valid frames. The features store
/// each joint's position on its own, so nothing else ties a forearm to one length; the
/// wider prior's samples stretched bones by 4 % (std/mean over time; the chest 12 %)
/// where the data's vary by 0. Lengths do not depend on the heading or the ground
/// position, so the pose is read straight from the feature block: the pelvis at
/// `(0, root height, 0)` and the 21 root-relative joints.
pub struct BoneLoss {
    /// Weight of the term in the training loss.
    pub weight: f32,
    /// `[1, 1, 64]` feature mean of the position block.
    pub mean: Tensor<3>,
    /// `[1, 1, 64]` feature std of the position block.
    pub std: Tensor<3>,
    /// `[1, 1, 21]` bone lengths in cm, bones 1..22 (child joint order).
    pub lengths: Tensor<3>,
}

impl BoneLoss {
    /// The loss for a dataset's statistics, or None when `weight` is 0.
    pub fn new(weight: f64, mean: &[f32], std: &[f32], device: &Device) -> Option<Self> {
        let block = |v: &[f32]| {
            let cols = v[POSITION_COLUMNS].to_vec();
            let len = cols.len();
            Tensor::from_data(TensorData::new(cols, [1, 1, len]), device)
        };
        let lengths: Vec<f32> = BONE_LENGTHS[1..].iter().map(|l| l * 100.0).collect();
        (weight > 0.0).then(|| BoneLoss {
            weight: weight as f32,
            mean: block(mean),
            std: block(std),
            lengths: Tensor::from_data(TensorData::new(lengths, [1, 1, NUM_JOINTS - 1]), device),
        })
    }

    /// The term for a normalised prediction `[B, N, 263]`, `valid` `[B, N, 1]`.
    pub fn term(&self, pred: Tensor<3>, valid: Tensor<3>) -> Tensor<1> {
        let b = pred.dims()[0];
        let device = pred.device();
        self.weighted_term(pred, valid, Tensor::ones([b, 1, 1], &device))
    }

    /// [`Self::term`] with each clip's squared errors scaled by `weights` `[B, 1, 1]` (the
    /// mean still over every valid frame of the batch).
    pub fn weighted_term(
        &self,
        pred: Tensor<3>,
        valid: Tensor<3>,
        weights: Tensor<3>,
    ) -> Tensor<1> {
        let [b, n, _] = pred.dims();
        let device = pred.device();
        let cols = POSITION_COLUMNS;
        let block = (pred.narrow(2, cols.start, cols.len()) * self.std.clone() + self.mean.clone())
            .mul_scalar(100.0);
        let height = block.clone().narrow(2, 0, 1);
        let zero = Tensor::<3>::zeros([b, n, 1], &device);
        let pelvis = Tensor::cat(vec![zero.clone(), height, zero], 2);
        let joints = Tensor::cat(vec![pelvis, block.narrow(2, 1, cols.len() - 1)], 2)
            .reshape([b, n, NUM_JOINTS, 3]);
        let parents: Vec<i64> = PARENTS[1..].iter().map(|&p| p as i64).collect();
        let parents = Tensor::from_data(TensorData::new(parents, [NUM_JOINTS - 1]), &device);
        let children = joints.clone().narrow(2, 1, NUM_JOINTS - 1);
        let bones = children - joints.select(2, parents);
        let length = bones
            .powi_scalar(2)
            .sum_dim(3)
            .reshape([b, n, NUM_JOINTS - 1]);
        // sqrt(x + ε): a zero-length bone has no direction, and its gradient stays finite.
        let length = length.add_scalar(1e-6).sqrt();
        let err = (length - self.lengths.clone()).powi_scalar(2) * valid.clone() * weights;
        err.sum() / ((valid.sum() + 1.0) * (NUM_JOINTS - 1) as f32)
    }
}

/// Each sample's x0-MSE weight under [`TrainConfig::low_noise_below`]: `(1−ᾱ_t0)/(1−ᾱ_t)`
/// below `t0`, at most `cap`, and 1 from `t0` on (the noise variance of `t0` over `t`'s),
/// with `alphas_cumprod` the base schedule's ᾱ.
pub fn low_noise_weights(
    alphas_cumprod: &[f64],
    timesteps: &[usize],
    t0: usize,
    cap: f32,
) -> Vec<f32> {
    let last = alphas_cumprod.len() - 1;
    let noise = |t: usize| 1.0 - alphas_cumprod[t.min(last)];
    timesteps
        .iter()
        .map(|&t| {
            if t >= t0 {
                1.0
            } else {
                ((noise(t0) / noise(t).max(f64::MIN_POSITIVE)) as f32).clamp(1.0, cap.max(1.0))
            }
        })
        .collect()
}

/// The geometric terms added to the x0 MSE in training (each None when its weight is 0).
#[derive(Default)]
pub struct GeometricLosses {
    /// MDM's foot-contact term.
    pub foot: Option<FootLoss>,
    /// MDM's velocity term.
    pub velocity: Option<VelocityLoss>,
    /// The bone-length term.
    pub bones: Option<BoneLoss>,
    /// Weigh the bone term of each clip by ᾱ_t ([`TrainConfig::bone_loss_by_signal`]).
    pub bones_by_signal: bool,
    /// Weight of the extra root-column MSE (None when 0).
    pub root: Option<f32>,
    /// The x0 MSE per clip ([`per_clip_mse`]) rather than per frame.
    pub per_clip: bool,
    /// `(t₀, cap)` of [`TrainConfig::low_noise_below`] (None when off).
    pub low_noise: Option<(usize, f32)>,
}

impl GeometricLosses {
    /// The terms a training config asks for, with the dataset's statistics.
    pub fn new(cfg: &TrainConfig, mean: &[f32], std: &[f32], device: &Device) -> Self {
        GeometricLosses {
            foot: FootLoss::new(cfg.foot_loss, mean, std, device),
            velocity: VelocityLoss::new(cfg.velocity_loss, std, device),
            bones: BoneLoss::new(cfg.bone_loss, mean, std, device),
            bones_by_signal: cfg.bone_loss_by_signal,
            root: (cfg.root_loss > 0.0).then_some(cfg.root_loss as f32),
            per_clip: cfg.loss_per_clip,
            low_noise: (cfg.low_noise_below > 0)
                .then_some((cfg.low_noise_below, cfg.low_noise_loss_cap as f32)),
        }
    }
}

/// Loss of one batch: the x0 MSE plus the geometric terms that are on.
pub(super) fn batch_loss(
    model: &Mdm,
    schedule: &NoiseSchedule,
    batch: &HostBatch,
    text: &TrainText,
    geometric: &GeometricLosses,
    device: &Device,
) -> Tensor<1> {
    let (mut input, x0, valid) = to_device(batch, text, device);
    input.x_t = q_sample(schedule, x0.clone(), &batch.timesteps, batch.noise_seed);
    let pred = model.predict_x0(&input);
    prediction_loss(pred, x0, valid, &batch.timesteps, schedule, geometric)
}

/// The loss of a prediction of clean motions noised at `timesteps`: the x0 MSE plus the
/// geometric terms that are on (the base's training and the ControlNet's share it).
pub(super) fn prediction_loss(
    pred: Tensor<3>,
    x0: Tensor<3>,
    valid: Tensor<3>,
    timesteps: &[usize],
    schedule: &NoiseSchedule,
    geometric: &GeometricLosses,
) -> Tensor<1> {
    let device = &pred.device();
    // A clip weighed by w: its error scaled by √w, (√w·e)² = w·e².
    let weighted = match geometric.low_noise {
        Some((t0, cap)) => {
            let root_w: Vec<f32> = low_noise_weights(&schedule.alphas_cumprod, timesteps, t0, cap)
                .iter()
                .map(|w| w.sqrt())
                .collect();
            let b = root_w.len();
            let root_w: Tensor<3> = Tensor::from_data(TensorData::new(root_w, [b, 1, 1]), device);
            x0.clone() + (pred.clone() - x0.clone()) * root_w
        }
        None => pred.clone(),
    };
    let mut loss = if geometric.per_clip {
        per_clip_mse(weighted, x0.clone(), valid.clone())
    } else {
        masked_mse(weighted, x0.clone(), valid.clone())
    };
    if let Some(f) = &geometric.foot {
        loss = loss
            + f.term(pred.clone(), x0.clone(), valid.clone())
                .mul_scalar(f.weight);
    }
    if let Some(v) = &geometric.velocity {
        loss = loss
            + v.term(pred.clone(), x0.clone(), valid.clone())
                .mul_scalar(v.weight);
    }
    if let Some(l) = &geometric.bones {
        let term = if geometric.bones_by_signal {
            let signal: Vec<f32> = timesteps
                .iter()
                .map(|&t| schedule.alphas_cumprod[t] as f32)
                .collect();
            let b = signal.len();
            let signal: Tensor<3> = Tensor::from_data(TensorData::new(signal, [b, 1, 1]), device);
            l.weighted_term(pred.clone(), valid.clone(), signal)
        } else {
            l.term(pred.clone(), valid.clone())
        };
        loss = loss + term.mul_scalar(l.weight);
    }
    if let Some(w) = geometric.root {
        loss = loss + root_mse(pred, x0, valid).mul_scalar(w);
    }
    loss
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn low_noise_weights_grow_as_the_noise_shrinks_below_t0_and_are_capped() {
        let a = NoiseSchedule::cosine(crate::model::schedule::DIFFUSION_STEPS).alphas_cumprod;
        let w = low_noise_weights(&a, &[0, 50, 99, 100, 900], 100, 50.0);
        assert_eq!(w[0], 50.0, "t = 0 is capped");
        let want = ((1.0 - a[100]) / (1.0 - a[50])) as f32;
        assert!((w[1] - want).abs() < 1e-3 && w[1] > 1.0, "{w:?} vs {want}");
        assert!(w[2] >= 1.0 && w[2] < w[1]);
        assert_eq!(&w[3..], &[1.0, 1.0]);
    }

    #[test]
    fn per_clip_mse_weighs_clips_not_frames() {
        let device = Device::default();
        // Clip 0: 1 valid frame with squared error 4; clip 1: 3 valid frames with error 0.
        let pred = Tensor::<3>::from_data(
            TensorData::new(vec![2.0f32, 0., 0., 0., 0., 0., 0., 0.], [2, 4, 1]),
            &device,
        );
        let x0 = Tensor::<3>::zeros([2, 4, 1], &device);
        let valid = Tensor::<3>::from_data(
            TensorData::new(vec![1.0f32, 0., 0., 0., 1., 1., 1., 0.], [2, 4, 1]),
            &device,
        );
        let per_frame = masked_mse(pred.clone(), x0.clone(), valid.clone()).into_scalar::<f32>();
        let per_clip = per_clip_mse(pred, x0, valid).into_scalar::<f32>();
        assert!((per_frame - 1.0).abs() < 1e-6, "{per_frame}"); // 4 / 4 frames
        assert!((per_clip - 2.0).abs() < 1e-6, "{per_clip}"); // (4/1 + 0/3) / 2
    }

    /// Features of the rest pose (pelvis 0.93 m up, every joint root-relative), `[1, 2, 263]`.
    fn rest_features(stretch_left_forearm: f32) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
        let pose = crate::skeleton::rest_pose();
        let mut row = vec![0.0f32; FEATURE_DIM];
        row[ROOT_Y.start] = pose[0].y;
        for j in 1..NUM_JOINTS {
            let mut p = pose[j] - pose[0];
            p.y += pose[0].y;
            if j == 20 {
                // The left wrist (a leaf) moved along the forearm: only that bone grows.
                p += (pose[20] - pose[18]).normalize() * stretch_left_forearm;
            }
            for a in 0..3 {
                row[RIC.start + (j - 1) * 3 + a] = p[a];
            }
        }
        let x = [row.clone(), row].concat();
        (x, vec![0.0; FEATURE_DIM], vec![1.0; FEATURE_DIM])
    }

    #[test]
    fn bone_loss_is_zero_on_the_skeleton_and_counts_a_stretch_in_cm() {
        let device = Device::default();
        let valid = Tensor::<3>::ones([1, 2, 1], &device);
        let term = |stretch: f32| {
            let (x, mean, std) = rest_features(stretch);
            let loss = BoneLoss::new(1.0, &mean, &std, &device).unwrap();
            let pred = Tensor::<3>::from_data(TensorData::new(x, [1, 2, FEATURE_DIM]), &device);
            loss.term(pred, valid.clone()).into_scalar::<f32>()
        };
        assert!(term(0.0) < 1e-3, "{}", term(0.0));
        // One bone 2 cm long on both frames: 4 cm² / 21 bones, (2 frames / 3) of the mean.
        let stretched = term(0.02);
        let want = 4.0 / 21.0 * 2.0 / 3.0;
        assert!((stretched - want).abs() < 0.02, "{stretched} vs {want}");
        // Weighted by a signal fraction of 0.25, the same stretch counts a quarter.
        let (x, mean, std) = rest_features(0.02);
        let loss = BoneLoss::new(1.0, &mean, &std, &device).unwrap();
        let pred = Tensor::<3>::from_data(TensorData::new(x, [1, 2, FEATURE_DIM]), &device);
        let quarter = loss
            .weighted_term(pred, valid, Tensor::full([1, 1, 1], 0.25, &device))
            .into_scalar::<f32>();
        assert!((quarter - stretched / 4.0).abs() < 1e-3, "{quarter}");
    }
}
