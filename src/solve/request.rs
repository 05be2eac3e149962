//! The common solver API: what to solve ([`SolveRequest`]), with which model
//! ([`Prior`]), what comes back ([`SolveResult`]) and progress reports ([`Progress`]).

use super::edit::Edit;
use super::solver::Solver;
use crate::model::control::ControlNet;
use crate::model::prompt::PromptEncoder;
use crate::model::weights::Consistency;
use crate::model::{Mdm, ModelBundle};
use crate::motion::Motion;
use crate::scene::Placement;

/// The motion prior the solvers steer: denoiser, prompt encoder and normalisation statistics.
#[derive(Clone, Copy, Debug)]
pub struct Prior<'a> {
    /// The denoiser (any mode; solvers make their own inference or frozen copies).
    pub model: &'a Mdm,
    /// What turns its prompts into the text condition.
    pub text: &'a PromptEncoder,
    /// `[263]` feature mean.
    pub mean: &'a [f32],
    /// `[263]` feature std.
    pub std: &'a [f32],
    /// Longest motion the model generates (frames).
    pub max_frames: usize,
    /// The realism ControlNet trained on this denoiser, when the bundle has one.
    pub control: Option<&'a ControlNet>,
    /// Set when the denoiser is a consistency-distilled few-step model: solvers that can
    /// run on one use its chain ([`super::driver::Ctx::chain_kind`]) at guidance 1.
    pub consistency: Option<&'a Consistency>,
}

impl<'a> Prior<'a> {
    /// The prior of a loaded bundle.
    pub fn from_bundle(bundle: &'a ModelBundle) -> Self {
        Prior {
            model: &bundle.model,
            text: &bundle.text,
            mean: &bundle.mean,
            std: &bundle.std,
            max_frames: bundle.config.max_frames,
            control: None,
            consistency: bundle.manifest.consistency.as_ref(),
        }
    }

    /// The same prior steered by `control` (see `guide`'s `realism`).
    pub fn with_control(self, control: Option<&'a ControlNet>) -> Self {
        Prior { control, ..self }
    }
}

/// What to solve.
#[derive(Clone, Debug, PartialEq)]
pub struct SolveRequest {
    /// One prompt per person (P = its length).
    pub prompts: Vec<String>,
    /// Frames per motion (20 fps).
    pub frames: usize,
    /// Seed of every random number (initial and step noise).
    pub seed: u64,
    /// Independent samples B solved side by side (each with its own noise).
    pub samples: usize,
    /// Classifier-free guidance scale of the text (2.5 in MDM/PMG/OmniControl).
    pub guidance_scale: f32,
    /// World placement per person; `None`: [`Placement::defaults`] 2 m apart.
    pub placements: Option<Vec<Placement>>,
    /// The solver and its settings.
    pub solver: Solver,
    /// A take to edit instead of starting from noise ([`super::edit`]); its people stand
    /// where the take stands, whatever `placements` says.
    pub edit: Option<Edit>,
    /// Foot cleanup of the result ([`super::cleanup`]), as `gen` cleans its samples; an
    /// edit cleans by its own [`Edit::clean_feet`] instead.
    pub clean_feet: bool,
    /// An edit's foot cleanup inside the solver, followed by `guide`'s polish (a window of
    /// a long motion: a cleanup after the solve left a window's statement 0.024 short),
    /// rather than after the solve (a single edit: measured smoother at its seams).
    pub polish_edit: bool,
}

impl SolveRequest {
    /// One sample, CFG 2.5, default placements.
    pub fn new(prompts: Vec<String>, frames: usize, seed: u64, solver: Solver) -> Self {
        SolveRequest {
            prompts,
            frames,
            seed,
            samples: 1,
            guidance_scale: 2.5,
            placements: None,
            solver,
            edit: None,
            clean_feet: false,
            polish_edit: false,
        }
    }

    /// The same request with these start placements (one per person).
    pub fn placed(self, placements: Vec<Placement>) -> Self {
        SolveRequest {
            placements: Some(placements),
            ..self
        }
    }

    /// The same request with the result's feet cleaned (`true`) or left as solved.
    pub fn cleaned(self, clean_feet: bool) -> Self {
        SolveRequest { clean_feet, ..self }
    }

    /// The same request editing this take.
    pub fn editing(self, edit: Edit) -> Self {
        SolveRequest {
            edit: Some(edit),
            ..self
        }
    }
}

/// What a solve produced.
#[derive(Clone, Debug)]
pub struct SolveResult {
    /// `[sample][person]` world joint positions (placement and relaxation applied).
    pub motions: Vec<Vec<Motion>>,
    /// `[B, P, N, 263]` de-normalised features in the model's canonical frame.
    pub features: Vec<f32>,
    /// `[sample][person]` the rigid transform taking the canonical motion to the world
    /// (the placement, composed with the relaxation when the solver relaxes).
    pub placements: Vec<Vec<Placement>>,
    /// `[B]` error of the returned motions.
    pub error: Vec<f32>,
    /// Error per sample after each denoising step (guide, lbfgs) or before each iteration
    /// (latent, ik; entry 0 is the unguided sample's error). Empty for `plain`.
    pub trace: Vec<Vec<f32>>,
    /// Wall-clock seconds of the whole solve.
    pub seconds: f64,
    /// Words of each person's prompt the model does not know (ignored).
    pub unknown_words: Vec<Vec<String>>,
}

/// What a solver is doing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Running a denoising chain (guided or not).
    Sampling,
    /// Optimising (latent, ik iterations).
    Optimising,
}

/// A progress report: `done` of `total` units of `phase`, with the latest mean error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    /// The phase.
    pub phase: Phase,
    /// Units done.
    pub done: usize,
    /// Units in the phase.
    pub total: usize,
    /// Mean error over samples after this unit, when the unit computes it.
    pub error: Option<f32>,
}
