//! Solvers: steer the motion diffusion model so its samples minimise a differentiable
//! error on joint positions ([`MotionError`]), for one or many people.
//!
//! The solvers know nothing of the `.mprog` language: anything that maps joints
//! `[batch, people, frames, 22, 3]` (metres, Y up, world placement applied) to an error per
//! sample `[batch]` can drive them. They share the denoiser ([`Prior`]), the seeded noise,
//! the world placement of each person ([`Placement`]) and `recover_from_ric`.
//!
//! | solver | module | what is optimised | reference |
//! | --- | --- | --- | --- |
//! | `guide` | [`guide`] | posterior mean μ_t, K gradient steps at every DDPM step | OmniControl spatial guidance (reference-algorithms §2.2) |
//! | `latent` | [`latent`] | initial noise z of a DDIM-100 chain, Adam through the chain | PMG (§1.1–1.3) |
//! | `ik`, `ik-reg` | [`ik`] | the unguided sample's normalised features, Adam, optional smoothness | PMG's IK / IK+Reg baselines (§5.2) |
//! | `lbfgs` | [`lbfgs`] | posterior mean μ_t, fresh L-BFGS at every DDPM step | InterControl IK guidance (§3.2) |
//! | `plain` | [`plain`] | nothing (the unguided sampler, for comparisons) | — |
//!
//! Each solver describes itself: its settings implement [`SolverConfig`] (knobs with their
//! meaning and setter, validation, the run) and its module's `SPECS` give its name and
//! defaults; [`registry`] lists them. A new solver is its file and one line in
//! `registry!` below (`toy`, a test-only solver, shows the minimum).
//!
//! Editing a take ([`take`], [`edit`]): a request may carry an [`Edit`], a motion the user
//! has, encoded to features with its world placement; `guide` and `plain` start their chain
//! part-way down from it (its strength) and hold its kept frames at every step, the other
//! solvers refuse it with their reason ([`SolverConfig::edit_refusal`]).
//!
//! Many people: P prompts are sampled as one batch of B·P motions (sample-major: index
//! `b·P + p`, CFG doubles it to 2·B·P), each person's joints are moved into the world by
//! its [`Placement`] (two people: InterControl's facing placement 2 m apart; more: a circle)
//! and the error sees `[B, P, N, 22, 3]`.
//!
//! ```no_run
//! use burn::prelude::*;
//! use mprog::model::ModelBundle;
//! use mprog::solve::{Prior, SolveRequest, Solver, GuideConfig, solve};
//! # fn demo() -> Result<(), Box<dyn std::error::Error>> {
//! let device = Device::flex();
//! let bundle = ModelBundle::load(&mprog::model::weights::default_model_dir(), &device)?;
//! // Pelvis at (0, 0.9, 3) on the last frame.
//! let error = |j: Tensor<5>| {
//!     let [b, _, n, _, _] = j.dims();
//!     let target = Tensor::<1>::from_floats([0.0, 0.9, 3.0], &j.device()).reshape([1, 1, 1, 1, 3]);
//!     let d = j.narrow(2, n - 1, 1).narrow(3, 0, 1) - target;
//!     d.square().sum_dim(4).sqrt().reshape([b])
//! };
//! let req = SolveRequest::new(vec!["a person walks forward".into()], 120, 7, Solver::new(GuideConfig::default()));
//! let out = solve(&Prior::from_bundle(&bundle), &req, &error, &device, |_| {})?;
//! println!("error {:?} in {:.1} s", out.error, out.seconds);
//! # Ok(()) }
//! ```

pub mod accel;
pub mod adam;
pub mod bones;
pub mod cleanup;
mod decode;
mod driver;
pub mod edit;
pub mod envelope;
pub mod facing;
pub mod feet;
pub mod host;
pub mod knobs;
pub mod long;
mod realism;
pub mod reference;
mod request;
mod solver;
pub mod take;

/// Declares the solver modules and [`registry`], which lists their [`SolverSpec`]s (each
/// module's `SPECS`) in help order.
macro_rules! registry {
    ($($(#[$attr:meta])* $module:ident),* $(,)?) => {
        $($(#[$attr])* pub mod $module;)*

        /// Every solver: name, summary, defaults and (through them) knobs. The CLI, the
        /// REPL, the benchmarks and the book read it.
        pub fn registry() -> Vec<&'static SolverSpec> {
            let mut all = Vec::new();
            $($(#[$attr])* all.extend($module::SPECS.iter());)*
            all
        }
    };
}

// A new solver is its file and one line here.
registry! {
    guide,
    latent,
    ik,
    lbfgs,
    plain,
    #[cfg(test)]
    toy,
}

#[cfg(test)]
mod edit_tests;
#[cfg(test)]
mod tests;

pub use crate::scene::{DEFAULT_SPACING, Placement};
pub use decode::{Decoder, RigidTensors};
pub use driver::{Ctx, Outcome, solve};
pub use edit::{
    AutoHold, BODY_PARTS, DEFAULT_BLEND, DEFAULT_RESAMPLE, DEFAULT_STRENGTH, Edit, TIME_MARGIN,
    auto_hold, hold_weights, in_between_hold, merge_holds, parts_joints, untouched_ranges,
};
pub use guide::{FusedSettings, GuideConfig, StepRule, VarianceRule};
pub use ik::IkConfig;
pub use knobs::{KnobKind, KnobValue};
pub use latent::{LatentConfig, Relax};
pub use lbfgs::LbfgsConfig;
pub use plain::PlainConfig;
pub use request::{Phase, Prior, Progress, SolveRequest, SolveResult};
pub use solver::{Solver, SolverConfig, SolverSpec, solvers_help};
pub use take::Take;

pub use crate::objective::MotionError;

/// Why a solve failed.
#[derive(Debug, thiserror::Error)]
pub enum SolveError {
    /// The request cannot be run (no prompt, bad length, bad settings).
    #[error("{0}")]
    Invalid(String),
    /// The error or its gradient became NaN/Inf.
    #[error(
        "{solver}: the {what} became NaN or infinite at {at}; the error function or the step size is unstable there"
    )]
    NonFinite {
        /// Which solver.
        solver: &'static str,
        /// "error", "gradient" or "sample".
        what: &'static str,
        /// Where: the denoising step or iteration, human-readable.
        at: String,
    },
    /// The error function returned a tensor of the wrong shape.
    #[error("the error function returned shape {got:?}; expected [{batch}] (one error per sample)")]
    BadErrorShape {
        /// What it returned.
        got: Vec<usize>,
        /// Samples in the batch.
        batch: usize,
    },
    /// Turning features into joints failed.
    #[error(transparent)]
    Features(#[from] crate::features::FeatureError),
}
