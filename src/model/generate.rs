//! Text-to-motion generation with a model bundle: seeded noise → sampler chain →
//! de-normalised features → joints. Batched over `count` samples.

use super::denoiser::Denoiser;
use super::mirror_average::MirrorAveraged;
use super::noise::NoiseSource;
use super::sampler::{Condition, SamplerKind, sample_chain_until, schedule_for};
use super::schedule::{DIFFUSION_STEPS, NoiseSchedule};
use super::weights::ModelBundle;
use crate::features::{FeatureError, recover_from_ric};
use crate::interrupt::Interrupt;
use crate::motion::Motion;
use burn::prelude::*;

/// What to generate.
#[derive(Clone, Debug)]
pub struct GenerateRequest {
    /// One prompt per sample.
    pub prompts: Vec<String>,
    /// Frames per motion (20 fps).
    pub frames: usize,
    /// Seed of the initial noise (and DDPM's step noise).
    pub seed: u64,
    /// Sampler.
    pub sampler: SamplerKind,
    /// Classifier-free guidance scale.
    pub guidance_scale: f32,
    /// Average each x̂0 with its left/right mirror ([`MirrorAveraged`]): exactly
    /// symmetric turns and sides at twice the batch.
    pub mirror_average: bool,
}

/// Generated motions.
#[derive(Clone, Debug)]
pub struct Generated {
    /// One motion per prompt.
    pub motions: Vec<Motion>,
    /// `[count, frames, 263]` de-normalised features.
    pub features: Vec<f32>,
    /// Words of each prompt the model does not know (they were ignored).
    pub unknown_words: Vec<Vec<String>>,
}

/// Errors of generation.
#[derive(Debug, thiserror::Error)]
pub enum GenerateError {
    /// Bad request.
    #[error("{0}")]
    Invalid(String),
    /// The model produced unusable numbers.
    #[error("the model produced non-finite features (NaN/Inf); the weights may be corrupt")]
    NonFinite,
    /// An [`Interrupt`] stopped the sampler; nothing was produced.
    #[error("interrupted after {done} of {total} denoising steps; nothing was generated")]
    Interrupted {
        /// Steps finished.
        done: usize,
        /// Steps of the whole chain.
        total: usize,
    },
    /// Recovering joints failed.
    #[error(transparent)]
    Features(#[from] FeatureError),
}

/// `[B, N, F]` initial noise for a request.
pub fn initial_noise(req: &GenerateRequest, features: usize, device: &Device) -> Tensor<3> {
    NoiseSource::new(req.seed).tensor([req.prompts.len(), req.frames, features], device)
}

/// De-normalises `[B, N, F]` model-space samples to host feature rows.
pub fn denormalize_host(bundle: &ModelBundle, x: Tensor<3>) -> Vec<f32> {
    let mut data = x.into_data().try_into_vec::<f32>().expect("f32 tensor");
    let f = bundle.config.features;
    for row in data.chunks_exact_mut(f) {
        for (i, v) in row.iter_mut().enumerate() {
            *v = *v * bundle.std[i] + bundle.mean[i];
        }
    }
    data
}

/// Samples motions for the request; `on_step(done, total)` reports progress.
pub fn generate(
    bundle: &ModelBundle,
    req: &GenerateRequest,
    device: &Device,
    on_step: impl FnMut(usize, usize),
) -> Result<Generated, GenerateError> {
    generate_interruptible(bundle, req, device, on_step, &Interrupt::new())
}

/// [`generate`] that reads `interrupt` before every denoising step and stops with
/// [`GenerateError::Interrupted`] once it is set.
pub fn generate_interruptible(
    bundle: &ModelBundle,
    req: &GenerateRequest,
    device: &Device,
    mut on_step: impl FnMut(usize, usize),
    interrupt: &Interrupt,
) -> Result<Generated, GenerateError> {
    if req.prompts.is_empty() {
        return Err(GenerateError::Invalid("no prompt to generate from".into()));
    }
    if req.frames < 2 || req.frames > bundle.config.max_frames {
        return Err(GenerateError::Invalid(format!(
            "{} frames asked; this model generates 2..={} frames ({:.1} s at 20 fps)",
            req.frames,
            bundle.config.max_frames,
            bundle.config.max_frames as f32 / 20.0
        )));
    }
    let model = bundle.model.valid();
    let prompts: Vec<&str> = req.prompts.iter().map(String::as_str).collect();
    let cond = Condition::new(&bundle.text, &prompts, req.guidance_scale, device);
    let schedule = schedule_for(&NoiseSchedule::cosine(DIFFUSION_STEPS), req.sampler);
    let x_t = initial_noise(req, bundle.config.features, device);
    let mut noise = NoiseSource::new(req.seed ^ 0x5DEE_CE66);
    let total = schedule.len();
    let mut done = 0;
    let on_step = |d, t| {
        done = d;
        on_step(d, t);
    };
    let stop = || interrupt.is_requested();
    let averaged;
    let den: &dyn Denoiser = if req.mirror_average {
        averaged = MirrorAveraged::new(model, &bundle.text, &bundle.mean, &bundle.std, device);
        &averaged
    } else {
        &model
    };
    let x0 = sample_chain_until(
        den,
        &schedule,
        req.sampler,
        x_t,
        &cond,
        &mut noise,
        on_step,
        &stop,
    )
    .ok_or(GenerateError::Interrupted { done, total })?;
    let features = denormalize_host(bundle, x0);
    if features.iter().any(|v| !v.is_finite()) {
        return Err(GenerateError::NonFinite);
    }
    let per = req.frames * bundle.config.features;
    let motions = features
        .chunks_exact(per)
        .map(recover_from_ric)
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Generated {
        motions,
        features,
        unknown_words: cond.unknown_words().to_vec(),
    })
}
