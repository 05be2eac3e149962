//! The common solver API: what to solve ([`SolveRequest`], [`Solver`]), with which model
//! ([`Prior`]), what comes back ([`SolveResult`]) and progress reports ([`Progress`]).

use super::guide::GuideConfig;
use super::ik::IkConfig;
use super::latent::LatentConfig;
use super::lbfgs::LbfgsConfig;
use super::place::Placement;
use crate::model::sampler::SamplerKind;
use crate::model::text::Vocabulary;
use crate::model::{Mdm, ModelBundle};
use crate::motion::Motion;

/// The motion prior the solvers steer: denoiser, vocabulary and normalisation statistics.
#[derive(Clone, Copy, Debug)]
pub struct Prior<'a> {
    /// The denoiser (any mode; solvers make their own inference or frozen copies).
    pub model: &'a Mdm,
    /// Its text vocabulary.
    pub vocab: &'a Vocabulary,
    /// `[263]` feature mean.
    pub mean: &'a [f32],
    /// `[263]` feature std.
    pub std: &'a [f32],
    /// Longest motion the model generates (frames).
    pub max_frames: usize,
}

impl<'a> Prior<'a> {
    /// The prior of a loaded bundle.
    pub fn from_bundle(bundle: &'a ModelBundle) -> Self {
        Prior {
            model: &bundle.model,
            vocab: &bundle.vocab,
            mean: &bundle.mean,
            std: &bundle.std,
            max_frames: bundle.config.max_frames,
        }
    }
}

/// Which solver, with its settings.
#[derive(Clone, Debug, PartialEq)]
pub enum Solver {
    /// The unguided sampler (no optimisation), for comparisons.
    Plain(SamplerKind),
    /// OmniControl-style guidance of μ_t ([`super::guide`]).
    Guide(GuideConfig),
    /// PMG's optimisation of the initial noise through DDIM ([`super::latent`]).
    Latent(LatentConfig),
    /// Direct optimisation of the unguided sample ([`super::ik`]); `ik` or `ik-reg`.
    Ik(IkConfig),
    /// InterControl-style L-BFGS on μ_t ([`super::lbfgs`]).
    Lbfgs(LbfgsConfig),
}

impl Solver {
    /// Short name: `plain`, `guide`, `latent`, `ik`, `ik-reg` or `lbfgs`.
    pub fn name(&self) -> &'static str {
        match self {
            Solver::Plain(_) => "plain",
            Solver::Guide(_) => "guide",
            Solver::Latent(_) => "latent",
            Solver::Ik(c) if c.smoothness > 0.0 => "ik-reg",
            Solver::Ik(_) => "ik",
            Solver::Lbfgs(_) => "lbfgs",
        }
    }

    /// The unguided sampler this solver starts from or steers (same chain and step count),
    /// the fair baseline to compare it with.
    pub fn unguided(&self) -> Solver {
        Solver::Plain(match self {
            Solver::Plain(k) => *k,
            Solver::Guide(c) => SamplerKind::Ddpm(c.steps),
            Solver::Lbfgs(c) => SamplerKind::Ddpm(c.steps),
            Solver::Latent(c) => SamplerKind::Ddim(c.ddim_steps),
            Solver::Ik(c) => c.sampler,
        })
    }

    /// The knobs [`set_knob`](Self::set_knob) accepts for this solver.
    pub fn knob_names(&self) -> &'static [&'static str] {
        match self {
            Solver::Plain(_) => &["steps"],
            Solver::Guide(_) => &[
                "steps",
                "k_early",
                "k_late",
                "late_steps",
                "tau",
                "skeleton",
                "freeze",
                "smooth",
                "feet",
                "early_root",
                "split",
                "late_root",
            ],
            Solver::Latent(_) => &[
                "ddim_steps",
                "iterations",
                "lr",
                "relax",
                "skeleton",
                "ref_root",
                "ref_legs",
            ],
            Solver::Ik(_) => &["ddim_steps", "iterations", "lr", "smoothness"],
            Solver::Lbfgs(_) => &[
                "steps",
                "k_first",
                "k_last",
                "late_steps",
                "history",
                "max_iter",
                "lr",
                "skeleton",
                "early_root",
                "smooth",
            ],
        }
    }

    /// Sets one numeric setting by name (`--knob iterations=30` on the command line).
    /// Counts must be whole and positive; `relax` is 0 or 1. The solver's own check runs
    /// when it starts, so out-of-range values are refused there with its message.
    pub fn set_knob(&mut self, name: &str, value: f64) -> Result<(), String> {
        let count = || -> Result<usize, String> {
            if value.is_finite() && value >= 0.0 && value.fract() == 0.0 && value <= 1e7 {
                Ok(value as usize)
            } else {
                Err(format!("`{name}` must be a whole number, not {value}"))
            }
        };
        let real = || -> Result<f64, String> {
            if value.is_finite() {
                Ok(value)
            } else {
                Err(format!("`{name}` must be finite"))
            }
        };
        let flag = |off: &str, on: &str| -> Result<bool, String> {
            match count()? {
                0 => Ok(false),
                1 => Ok(true),
                _ => Err(format!("`{name}` is 0 ({off}) or 1 ({on})")),
            }
        };
        let (solver, knobs) = (self.name(), self.knob_names().join(", "));
        let unknown = || format!("solver `{solver}` has no knob `{name}`; it has: {knobs}");
        match self {
            Solver::Plain(SamplerKind::Ddim(n) | SamplerKind::Ddpm(n)) => match name {
                "steps" => *n = count()?,
                _ => return Err(unknown()),
            },
            Solver::Guide(c) => match name {
                "steps" => c.steps = count()?,
                "k_early" => c.k_early = count()?,
                "k_late" => c.k_late = count()?,
                "late_steps" => c.late_steps = count()?,
                "tau" => c.tau = real()? as f32,
                "smooth" => c.smooth_frames = real()? as f32,
                "feet" => c.foot_lock = real()? as f32,
                "late_root" => c.late_root_scale = real()? as f32,
                "early_root" => {
                    c.early_root_only =
                        flag("every column", "root columns only before the late steps")?
                }
                "split" => {
                    c.split_terms = flag("one step for the whole error", "a step per statement")?
                }
                "skeleton" => c.keep_skeleton = flag("off", "keep bone lengths")?,
                "freeze" => c.freeze_first_frame = flag("off", "first frame frozen")?,
                _ => return Err(unknown()),
            },
            Solver::Latent(c) => match name {
                "ddim_steps" => c.ddim_steps = count()?,
                "iterations" => c.iterations = count()?,
                "lr" => c.lr = real()?,
                "relax" => {
                    c.relax = if flag("off", "rigid XZ")? {
                        super::latent::Relax::RigidXz
                    } else {
                        super::latent::Relax::None
                    }
                }
                "skeleton" => c.keep_skeleton = flag("off", "keep bone lengths")?,
                "ref_root" => c.ref_root = real()? as f32,
                "ref_legs" => c.ref_legs = real()? as f32,
                _ => return Err(unknown()),
            },
            Solver::Ik(c) => match name {
                "ddim_steps" => c.sampler = SamplerKind::Ddim(count()?),
                "iterations" => c.iterations = count()?,
                "lr" => c.lr = real()?,
                "smoothness" => c.smoothness = real()? as f32,
                _ => return Err(unknown()),
            },
            Solver::Lbfgs(c) => match name {
                "steps" => c.steps = count()?,
                "k_first" => c.k_first = count()?,
                "k_last" => c.k_last = count()?,
                "late_steps" => c.late_steps = count()?,
                "history" => c.history = count()?,
                "max_iter" => c.max_iter = count()?,
                "lr" => c.lr = real()?,
                "skeleton" => c.keep_skeleton = flag("off", "keep bone lengths")?,
                "early_root" => {
                    c.early_root_only =
                        flag("every column", "root columns only before the late steps")?
                }
                "smooth" => c.smooth_frames = real()? as f32,
                _ => return Err(unknown()),
            },
        }
        Ok(())
    }

    /// The solver of that [`name`](Self::name) with its default settings.
    pub fn by_name(name: &str) -> Option<Solver> {
        Some(match name {
            "plain" => Solver::Plain(SamplerKind::Ddpm(1000)),
            "guide" => Solver::Guide(GuideConfig::default()),
            "latent" => Solver::Latent(LatentConfig::default()),
            "ik" => Solver::Ik(IkConfig::ik()),
            "ik-reg" => Solver::Ik(IkConfig::ik_reg()),
            "lbfgs" => Solver::Lbfgs(LbfgsConfig::default()),
            _ => return None,
        })
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
        }
    }

    /// The same request with these start placements (one per person).
    pub fn placed(self, placements: Vec<Placement>) -> Self {
        SolveRequest {
            placements: Some(placements),
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
