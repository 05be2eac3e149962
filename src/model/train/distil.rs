//! Consistency distillation (MotionLCM §3.3, after LCM): a student that maps any point of
//! the guided teacher's DDIM trajectory straight to its end, so a motion takes 1–4
//! network passes instead of 50 guided ones (100 at batch 1).
//!
//! For a clip x0, a grid step i is drawn and x0 is noised to t_i (q-sample, as in
//! training). The frozen teacher takes one classifier-free guided DDIM step from t_i to
//! t_{i−1} (the skipping step, 1000 / grid timesteps); the target network (the student's
//! EMA, LCM's θ⁻) reads that point, and the student reading x_{t_i} must agree with it:
//! pseudo-Huber of f_θ(x_{t_i}, t_i) − f_θ⁻(x̂_{t_{i−1}}, t_{i−1}), masked per clip. f is
//! the boundary-conditioned x̂0 (`schedule::consistency_scalings`), so f(x, 0) = x and the
//! chain of targets is anchored at the teacher's last step. A tenth of the clips drop the
//! text (`cond_drop`); for those the teacher's unguided x̂0 is the target, so the student
//! keeps an unconditional pass.

use super::losses::{BoneLoss, q_sample, to_device};
use super::text::TrainText;
use crate::model::batch::HostBatch;
use crate::model::config::DistilConfig;
use crate::model::denoiser::{Denoiser, DenoiserInput, Mdm};
use crate::model::schedule::{DIFFUSION_STEPS, NoiseSchedule, consistency_scalings};
use burn::prelude::*;

/// The frozen teacher with its guidance scale and DDIM grid.
pub(super) struct Teacher {
    /// The teacher's denoiser (no gradients).
    pub(super) model: Mdm,
    /// Its classifier-free guidance scale.
    pub(super) guidance: f32,
    /// Its DDIM grid (respaced schedule, ascending timesteps).
    pub(super) grid: NoiseSchedule,
    /// Pseudo-Huber constant.
    pub(super) huber_c: f32,
}

impl Teacher {
    pub(super) fn new(model: Mdm, cfg: &DistilConfig) -> Teacher {
        Teacher {
            model,
            guidance: cfg.guidance as f32,
            grid: NoiseSchedule::cosine(DIFFUSION_STEPS).respaced(cfg.grid),
            huber_c: cfg.huber_c as f32,
        }
    }

    /// The pair of grid timesteps (t_i, t_{i−1}) of each sample, i ≥ 1, read from the
    /// batch's uniform timestep draw.
    fn pairs(&self, batch: &HostBatch) -> (Vec<usize>, Vec<usize>) {
        let n = self.grid.len();
        batch
            .timesteps
            .iter()
            .map(|&t| {
                let i = 1 + t.min(DIFFUSION_STEPS - 1) * (n - 1) / DIFFUSION_STEPS;
                (self.grid.timesteps[i], self.grid.timesteps[i - 1])
            })
            .unzip()
    }

    /// The teacher's guided x̂0 at `x_t`: uncond + s·(cond − uncond) where the clip keeps
    /// its text, the unguided x̂0 where it was dropped.
    fn guided_x0(&self, input: &DenoiserInput) -> Tensor<3> {
        let b = input.timesteps.len();
        let device = input.x_t.device();
        let zeros: Tensor<1> = Tensor::zeros([b], &device);
        let doubled = DenoiserInput {
            x_t: Tensor::cat(vec![input.x_t.clone(), input.x_t.clone()], 0),
            timesteps: [input.timesteps.clone(), input.timesteps.clone()].concat(),
            text: input.text.doubled(),
            keep_text: Tensor::cat(vec![input.keep_text.clone(), zeros], 0),
            padding: input
                .padding
                .clone()
                .map(|p| Tensor::cat(vec![p.clone(), p], 0)),
        };
        let out = self.model.predict_x0(&doubled);
        let c = out.clone().narrow(0, 0, b);
        let u = out.narrow(0, b, b);
        // Dropped text: c == u, so the guided sum is u whatever the scale.
        u.clone() + (c - u) * self.guidance
    }
}

/// `[B, 1, 1]` per-sample scalars.
fn per_sample(values: Vec<f32>, device: &Device) -> Tensor<3> {
    let b = values.len();
    Tensor::from_data(TensorData::new(values, [b, 1, 1]), device)
}

/// f(x, t) = c_skip(t)·x + c_out(t)·x̂0 per sample.
fn boundary(x_t: Tensor<3>, x0: Tensor<3>, timesteps: &[usize]) -> Tensor<3> {
    let device = x_t.device();
    let (skip, out): (Vec<f32>, Vec<f32>) = timesteps
        .iter()
        .map(|&t| {
            let (s, o) = consistency_scalings(t);
            (s as f32, o as f32)
        })
        .unzip();
    x_t * per_sample(skip, &device) + x0 * per_sample(out, &device)
}

/// One DDIM step per sample from `from` to `to` (original timesteps) given x̂0; a step to
/// timestep 0 lands on x̂0 itself, as the sampler's last step does.
fn ddim_to(
    schedule: &NoiseSchedule,
    x_t: Tensor<3>,
    x0: Tensor<3>,
    from: &[usize],
    to: &[usize],
) -> Tensor<3> {
    let device = x_t.device();
    let ab = |t: usize| {
        if t == 0 {
            1.0
        } else {
            schedule.alphas_cumprod[t]
        }
    };
    let mut inv_sqrt_a = Vec::new();
    let mut inv_sigma = Vec::new();
    let mut sqrt_a_to = Vec::new();
    let mut sigma_to = Vec::new();
    for (&f, &t) in from.iter().zip(to) {
        let a = schedule.alphas_cumprod[f];
        inv_sqrt_a.push((1.0 / a.sqrt()) as f32);
        inv_sigma.push((1.0 / (1.0 / a - 1.0).sqrt()) as f32);
        sqrt_a_to.push(ab(t).sqrt() as f32);
        sigma_to.push((1.0 - ab(t)).max(0.0).sqrt() as f32);
    }
    let eps = (x_t * per_sample(inv_sqrt_a, &device) - x0.clone()) * per_sample(inv_sigma, &device);
    x0 * per_sample(sqrt_a_to, &device) + eps * per_sample(sigma_to, &device)
}

/// Masked pseudo-Huber per clip, then the batch mean: √(d² + c²) − c.
fn pseudo_huber(pred: Tensor<3>, target: Tensor<3>, valid: Tensor<3>, c: f32) -> Tensor<1> {
    let [b, _, f] = pred.dims();
    let d2 = (pred - target).powi_scalar(2);
    let err = ((d2 + c * c).sqrt() - c) * valid.clone();
    let per_clip = err.sum_dim(2).sum_dim(1).reshape([b]);
    let frames = valid.sum_dim(1).reshape([b]).clamp_min(1.0);
    (per_clip / (frames * f as f32)).mean()
}

/// The distillation loss of one batch. `student` lives on `train_dev` (with autodiff in
/// training, the plain device in validation); the teacher and `target` on `plain`. With
/// `bones` (the run's `bone_loss`, on `train_dev`) the student's output also pays for
/// bones off the skeleton's lengths: a consistency model's x̂0 is a final sample at every
/// t, not the blurred mean a diffusion model's is at high t.
#[allow(clippy::too_many_arguments)]
pub(super) fn distil_loss(
    student: &Mdm,
    target: &Mdm,
    teacher: &Teacher,
    schedule: &NoiseSchedule,
    batch: &HostBatch,
    text: &TrainText,
    bones: Option<&BoneLoss>,
    train_dev: &Device,
    plain: &Device,
) -> Tensor<1> {
    let (hi, lo) = teacher.pairs(batch);
    // The teacher's step and the target, without gradients.
    let (mut input, x0, _) = to_device(batch, text, plain);
    let x_hi = q_sample(schedule, x0, &hi, batch.noise_seed);
    input.x_t = x_hi.clone();
    input.timesteps = hi.clone();
    let teacher_x0 = teacher.guided_x0(&input);
    let x_lo = ddim_to(schedule, x_hi.clone(), teacher_x0, &hi, &lo);
    input.x_t = x_lo.clone();
    input.timesteps = lo.clone();
    let goal = boundary(x_lo, target.predict_x0(&input), &lo);
    // The student's consistency output at t_i, with gradients.
    let (mut s_input, _, valid) = to_device(batch, text, train_dev);
    let x_hi: Tensor<3> = Tensor::from_data(x_hi.into_data(), train_dev);
    let goal: Tensor<3> = Tensor::from_data(goal.into_data(), train_dev);
    s_input.x_t = x_hi.clone();
    s_input.timesteps = hi.clone();
    let pred = boundary(x_hi, student.predict_x0(&s_input), &hi);
    let loss = pseudo_huber(pred.clone(), goal, valid.clone(), teacher.huber_c);
    match bones {
        Some(b) => loss + b.term(pred, valid) * b.weight,
        None => loss,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ddim_step_to_zero_lands_on_x0_and_keeps_the_noise_otherwise() {
        let device = Device::flex();
        let s = NoiseSchedule::cosine(DIFFUSION_STEPS);
        let x0: Tensor<3> = Tensor::ones([2, 3, 4], &device);
        let eps: Tensor<3> = Tensor::ones([2, 3, 4], &device) * 0.5;
        let (a, b) = (s.alphas_cumprod[500], s.alphas_cumprod[480]);
        let x_t = x0.clone() * a.sqrt() as f32 + eps * (1.0 - a).sqrt() as f32;
        let out = ddim_to(&s, x_t, x0, &[500, 20], &[480, 0]);
        let v = out.into_data().try_to_vec::<f32>().unwrap();
        // Sample 0: √ᾱ_480·1 + √(1−ᾱ_480)·0.5; sample 1: exactly x0.
        let want = b.sqrt() + (1.0 - b).sqrt() * 0.5;
        assert!((v[0] as f64 - want).abs() < 1e-4, "{} {want}", v[0]);
        assert!(v[12..].iter().all(|&x| (x - 1.0).abs() < 1e-5));
    }

    #[test]
    fn pseudo_huber_ignores_padding_and_is_zero_on_agreement() {
        let device = Device::flex();
        let a: Tensor<3> = Tensor::ones([1, 2, 3], &device);
        let valid: Tensor<3> =
            Tensor::from_data(TensorData::new(vec![1.0f32, 0.0], [1, 2, 1]), &device);
        let same = pseudo_huber(a.clone(), a.clone(), valid.clone(), 0.03);
        assert!(same.into_scalar::<f32>().abs() < 1e-7);
        // The padded frame's difference does not count.
        let b = Tensor::cat(vec![a.clone().narrow(1, 0, 1), a.narrow(1, 1, 1) * 5.0], 1);
        let pad_only = pseudo_huber(b, Tensor::ones([1, 2, 3], &device), valid, 0.03);
        assert!(pad_only.into_scalar::<f32>().abs() < 1e-7);
    }
}
