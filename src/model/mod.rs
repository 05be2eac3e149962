//! The motion diffusion model: denoiser, text encoder, noise schedule, samplers, training.
//!
//! Everything works in the normalised HumanML3D feature space `[batch, frames, 263]`;
//! `features::recover_from_ric` turns samples into joints.

pub mod batch;
pub mod config;
pub mod control;
pub mod denoiser;
pub mod ema;
pub mod generate;
pub mod lengths;
pub mod mirror_average;
pub mod moc;
pub mod noise;
pub mod prompt;
pub mod sampler;
pub mod schedule;
pub mod sentence;
pub mod text;
pub mod train;
pub mod weights;

pub use config::{ModelConfig, TrainConfig};
pub use denoiser::{Denoiser, DenoiserInput, Mdm};
pub use weights::ModelBundle;

#[cfg(test)]
mod sentence_model_tests;
#[cfg(test)]
mod tests;
