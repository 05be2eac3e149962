//! The motion diffusion model: denoiser, text encoder, noise schedule, samplers, training.
