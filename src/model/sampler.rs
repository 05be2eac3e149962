//! Samplers over a [`Denoiser`]: classifier-free guided x̂0, DDIM (η = 0) and ancestral
//! DDPM steps, and whole chains. Solvers reuse the step functions to insert guidance.

use super::denoiser::{Denoiser, DenoiserInput};
use super::noise::NoiseSource;
use super::prompt::{PromptEncoder, TextBatch};
use super::schedule::{NoiseSchedule, consistency_timesteps};
use burn::prelude::*;

/// Which chain to run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SamplerKind {
    /// Deterministic DDIM with this many steps.
    Ddim(usize),
    /// Ancestral DDPM with this many (respaced) steps; 1000 = the full chain.
    Ddpm(usize),
    /// A consistency model's multistep chain (LCM): `steps` jumps to x̂0 on its
    /// distillation's DDIM grid of `grid` steps, re-noised in between.
    Consistency {
        /// Network passes.
        steps: usize,
        /// The distillation's grid (`Manifest::consistency`).
        grid: usize,
    },
}

/// Passes of a consistency model's chain unless asked otherwise (LCM's and MotionLCM's
/// default: more steps add little).
pub const FEW_STEPS: usize = 4;

/// `gen`'s chain and guidance scale for a bundle: DDIM 50 at 2.5 for a diffusion model,
/// its own [`FEW_STEPS`]-step chain at 1 for a consistency-distilled one.
pub fn default_chain(manifest: &super::weights::Manifest) -> (SamplerKind, f32) {
    match &manifest.consistency {
        Some(c) => (
            SamplerKind::Consistency {
                steps: FEW_STEPS.min(c.grid),
                grid: c.grid,
            },
            1.0,
        ),
        None => (SamplerKind::Ddim(50), 2.5),
    }
}

impl SamplerKind {
    /// Steps of the chain.
    pub fn steps(self) -> usize {
        match self {
            SamplerKind::Ddim(k) | SamplerKind::Ddpm(k) => k,
            SamplerKind::Consistency { steps, .. } => steps,
        }
    }

    /// The same kind with `steps` steps.
    pub fn with_steps(self, steps: usize) -> SamplerKind {
        match self {
            SamplerKind::Ddim(_) => SamplerKind::Ddim(steps),
            SamplerKind::Ddpm(_) => SamplerKind::Ddpm(steps),
            SamplerKind::Consistency { grid, .. } => SamplerKind::Consistency { steps, grid },
        }
    }
}

/// The text condition of a batch, encoded once and reused at every step.
#[derive(Clone, Debug)]
pub struct Condition {
    /// Prompts then the same prompts again (the unconditional half), when guided.
    pub text: TextBatch,
    /// Words of each prompt that the model cannot read.
    unknown: Vec<Vec<String>>,
    /// Classifier-free guidance scale (1 = plain conditional model).
    pub guidance_scale: f32,
    batch: usize,
}

impl Condition {
    /// Encodes `prompts` (one per sample).
    pub fn new(
        prompts_encoder: &PromptEncoder,
        prompts: &[&str],
        guidance_scale: f32,
        device: &Device,
    ) -> Self {
        let text = prompts_encoder.batch(prompts, device);
        Condition {
            text: if guidance_scale != 1.0 {
                text.doubled()
            } else {
                text
            },
            unknown: prompts
                .iter()
                .map(|p| prompts_encoder.unknown_words(p))
                .collect(),
            guidance_scale,
            batch: prompts.len(),
        }
    }

    /// Words of each prompt that the model does not know.
    pub fn unknown_words(&self) -> &[Vec<String>] {
        &self.unknown
    }
}

/// x̂0 with classifier-free guidance: uncond + s·(cond − uncond), both passes in one batch.
pub fn guided_x0(
    den: &(impl Denoiser + ?Sized),
    x_t: Tensor<3>,
    timestep: usize,
    cond: &Condition,
) -> Tensor<3> {
    let device = x_t.device();
    let b = cond.batch;
    if cond.guidance_scale == 1.0 {
        let input = DenoiserInput {
            x_t,
            timesteps: vec![timestep; b],
            text: cond.text.clone(),
            keep_text: Tensor::ones([b], &device),
            padding: None,
        };
        return den.predict_x0(&input);
    }
    let keep: Vec<f32> = (0..2 * b).map(|i| if i < b { 1.0 } else { 0.0 }).collect();
    let input = DenoiserInput {
        x_t: Tensor::cat(vec![x_t.clone(), x_t], 0),
        timesteps: vec![timestep; 2 * b],
        text: cond.text.clone(),
        keep_text: Tensor::from_data(TensorData::new(keep, [2 * b]), &device),
        padding: None,
    };
    let out = den.predict_x0(&input);
    let c = out.clone().narrow(0, 0, b);
    let u = out.narrow(0, b, b);
    u.clone() + (c - u) * cond.guidance_scale
}

/// One DDIM step (η = 0) from step `i` to `i − 1` given x̂0.
pub fn ddim_step(s: &NoiseSchedule, i: usize, x_t: Tensor<3>, x0: Tensor<3>) -> Tensor<3> {
    let a = s.alphas_cumprod[i];
    let a_prev = s.alpha_cumprod_prev(i);
    // ε̂ = (x_t/√ᾱ − x̂0)/√(1/ᾱ − 1); x_prev = √ᾱ_prev x̂0 + √(1−ᾱ_prev) ε̂
    let eps = (x_t * (1.0 / a.sqrt()) - x0.clone()) * (1.0 / (1.0 / a - 1.0).sqrt());
    x0 * a_prev.sqrt() + eps * (1.0 - a_prev).sqrt()
}

/// One step of a consistency chain from step `i` to `i − 1`: the clean estimate noised
/// afresh to the previous step's level (x̂0 itself after the last).
pub fn consistency_step(
    s: &NoiseSchedule,
    i: usize,
    x0: Tensor<3>,
    noise: &mut NoiseSource,
) -> Tensor<3> {
    if i == 0 {
        return x0;
    }
    let a_prev = s.alphas_cumprod[i - 1];
    let z = noise.tensor(x0.dims(), &x0.device());
    x0 * a_prev.sqrt() + z * (1.0 - a_prev).sqrt()
}

/// Posterior mean μ(x̂0, x_t) of step `i`.
pub fn posterior_mean(s: &NoiseSchedule, i: usize, x_t: Tensor<3>, x0: Tensor<3>) -> Tensor<3> {
    let p = s.posterior(i);
    x0 * p.coef_x0 + x_t * p.coef_xt
}

/// Runs a whole chain from the initial noise `x_t` (`[B, N, F]`, normalised space).
/// `noise` supplies DDPM's per-step noise; DDIM ignores it.
pub fn sample_chain(
    den: &impl Denoiser,
    schedule: &NoiseSchedule,
    kind: SamplerKind,
    x_t: Tensor<3>,
    cond: &Condition,
    noise: &mut NoiseSource,
    on_step: impl FnMut(usize, usize),
) -> Tensor<3> {
    let never = || false;
    sample_chain_until(den, schedule, kind, x_t, cond, noise, on_step, &never)
        .expect("never stopped")
}

/// [`sample_chain`] that asks `stop()` before each step and returns `None` when it says
/// so (an interrupted run: nothing is sampled to the end).
#[allow(clippy::too_many_arguments)]
pub fn sample_chain_until(
    den: &(impl Denoiser + ?Sized),
    schedule: &NoiseSchedule,
    kind: SamplerKind,
    mut x_t: Tensor<3>,
    cond: &Condition,
    noise: &mut NoiseSource,
    mut on_step: impl FnMut(usize, usize),
    stop: &dyn Fn() -> bool,
) -> Option<Tensor<3>> {
    let device = x_t.device();
    let dims = x_t.dims();
    let n = schedule.len();
    for i in (0..n).rev() {
        if stop() {
            return None;
        }
        let x0 = guided_x0(den, x_t.clone(), schedule.timesteps[i], cond);
        x_t = match kind {
            SamplerKind::Ddim(_) => ddim_step(schedule, i, x_t, x0),
            SamplerKind::Ddpm(_) => {
                let mean = posterior_mean(schedule, i, x_t, x0);
                if i > 0 {
                    let sd = schedule.posterior(i).variance.sqrt();
                    mean + noise.tensor(dims, &device) * sd
                } else {
                    mean
                }
            }
            SamplerKind::Consistency { .. } => consistency_step(schedule, i, x0, noise),
        };
        on_step(n - i, n);
    }
    Some(x_t)
}

/// The schedule a sampler kind runs on.
pub fn schedule_for(base: &NoiseSchedule, kind: SamplerKind) -> NoiseSchedule {
    match kind {
        SamplerKind::Ddim(k) | SamplerKind::Ddpm(k) => base.respaced(k),
        SamplerKind::Consistency { steps, grid } => base.at(&consistency_timesteps(grid, steps)),
    }
}
