//! PMG's baselines IK and IK+Reg (PMG §5.2): sample once without guidance (DDIM-100, the
//! sampler PMG gives every baseline), then optimise **the motion's normalised features**
//! (all 263 columns of every frame) directly with Adam on the error, with no diffusion prior.
//!
//! * `ik`: the error alone.
//! * `ik-reg`: error + λ·mean_t ‖x[t+1] − x[t]‖², PMG's L2 frame-difference regulariser on
//!   the motion representation x (normalised features, so every feature counts in units of
//!   its own spread; squared norm over the 263 features, mean over frame pairs), summed
//!   over people; λ = 0.1 by default.
//!
//! Only the 67 columns that reach the joints get gradient from the error; the regulariser
//! smooths every column. The error and its gradient go through the fused host path.

use super::knobs::{Knob, KnobKind, knob};
use super::solver::{Solver, SolverConfig, SolverSpec};
use super::SolveError;
use super::adam::Adam;
use super::host::{extract_head, insert_head};
use super::request::{Phase, Progress};
use super::driver::{Ctx, Outcome, check_kind, ensure_finite, host, mean};
use crate::features::FEATURE_DIM;
use crate::model::sampler::SamplerKind;

/// Settings of `ik`.
#[derive(Clone, Debug, PartialEq)]
pub struct IkConfig {
    /// The unguided sampler the motion starts from (DDIM-100).
    pub sampler: SamplerKind,
    /// Adam iterations (100).
    pub iterations: usize,
    /// Adam learning rate (0.005, PMG's setting for every method).
    pub lr: f64,
    /// λ of the frame-difference regulariser (0 = plain IK).
    pub smoothness: f32,
}

impl IkConfig {
    /// Plain IK.
    pub fn ik() -> Self {
        IkConfig {
            sampler: SamplerKind::Ddim(100),
            iterations: 100,
            lr: 0.005,
            smoothness: 0.0,
        }
    }

    /// IK with the regulariser, λ = 0.1.
    pub fn ik_reg() -> Self {
        IkConfig {
            smoothness: 0.1,
            ..Self::ik()
        }
    }

    fn check_settings(&self) -> Result<(), SolveError> {
        check_kind(self.sampler)?;
        if !(self.lr.is_finite()
            && self.lr >= 0.0
            && self.smoothness.is_finite()
            && self.smoothness >= 0.0)
        {
            return Err(SolveError::Invalid(
                "ik: learning rate and smoothness must be finite and ≥ 0".into(),
            ));
        }
        Ok(())
    }
}

/// Adds λ·mean_t ‖x[t+1] − x[t]‖² of each motion to `grad` (full features) and returns its
/// value per motion.
pub fn add_smoothness(x: &[f32], frames: usize, lambda: f32, grad: &mut [f32]) -> Vec<f32> {
    let per = frames * FEATURE_DIM;
    let pairs = frames.saturating_sub(1).max(1) as f32;
    let scale = lambda / pairs;
    x.chunks_exact(per)
        .zip(grad.chunks_exact_mut(per))
        .map(|(xm, gm)| {
            let mut value = 0.0f64;
            for t in 0..frames.saturating_sub(1) {
                for f in 0..FEATURE_DIM {
                    let (a, b) = (t * FEATURE_DIM + f, (t + 1) * FEATURE_DIM + f);
                    let d = xm[b] - xm[a];
                    value += (d * d) as f64;
                    gm[b] += 2.0 * scale * d;
                    gm[a] -= 2.0 * scale * d;
                }
            }
            (value * scale as f64) as f32
        })
        .collect()
}

/// Runs the unguided sample and the optimisation.
fn run(
    ctx: &Ctx,
    cfg: &IkConfig,
    progress: &mut dyn FnMut(Progress),
) -> Result<Outcome, SolveError> {
    let mut x = host(ctx.sample_plain(cfg.sampler, progress));
    let mut objective = ctx.host_objective();
    let mut adam = Adam::new(x.len(), cfg.lr);
    let mut grad = vec![0.0; x.len()];
    let mut trace = Vec::with_capacity(cfg.iterations);
    for it in 0..cfg.iterations {
        let at = || format!("iteration {}/{}", it + 1, cfg.iterations);
        let head = extract_head(&x, FEATURE_DIM);
        let mut g_head = vec![0.0; head.len()];
        let values = objective.eval(&head, &mut g_head)?;
        ensure_finite(&values, "ik", "error", at)?;
        grad.fill(0.0);
        insert_head(&mut grad, FEATURE_DIM, &g_head);
        if cfg.smoothness > 0.0 {
            add_smoothness(&x, ctx.frames, cfg.smoothness, &mut grad);
        }
        ensure_finite(&grad, "ik", "gradient", at)?;
        adam.step(&mut x, &grad);
        progress(Progress {
            phase: Phase::Optimising,
            done: it + 1,
            total: cfg.iterations,
            error: Some(mean(&values)),
        });
        trace.push(values);
    }
    Ok(Outcome {
        x,
        relax: None,
        trace,
        cleaned: false,
    })
}

/// `ik` and `ik-reg` (the same solver, with and without the regulariser), for
/// [`super::registry`].
pub const SPECS: &[SolverSpec] = &[
    SolverSpec {
        name: "ik",
        summary: "the unguided sample's features directly, Adam (PMG's IK baseline)",
        make: || Solver::new(IkConfig::ik()),
    },
    SolverSpec {
        name: "ik-reg",
        summary: "as `ik`, plus a frame-difference regulariser (PMG's IK+Reg baseline)",
        make: || Solver::new(IkConfig::ik_reg()),
    },
];

impl SolverConfig for IkConfig {
    const KNOBS: &'static [Knob<Self>] = &[
        Knob {
            name: "ddim_steps",
            doc: "steps of the unguided DDIM sample the optimisation starts from",
            kind: KnobKind::Count,
            get: |c| c.sampler.steps() as f64,
            set: |c, v| c.sampler = SamplerKind::Ddim(v as usize),
        },
        knob!(Count, "iterations", "Adam iterations on the features", iterations),
        knob!(Real, "lr", "Adam's learning rate (PMG's 0.005 barely moves our normalised features; the benchmark uses 0.05)", lr),
        knob!(Real, "smoothness", "λ of the frame-difference regulariser; > 0 is `ik-reg`", smoothness),
    ];

    fn name(&self) -> &'static str {
        if self.smoothness > 0.0 { "ik-reg" } else { "ik" }
    }

    fn unguided(&self) -> SamplerKind {
        self.sampler
    }

    fn validate(&self) -> Result<(), SolveError> {
        self.check_settings()
    }

    fn run(&self, ctx: &Ctx, progress: &mut dyn FnMut(Progress)) -> Result<Outcome, SolveError> {
        run(ctx, self, progress)
    }
    fn edit_refusal(&self) -> Option<&'static str> {
        Some("it optimises the unguided sample's features, not a take's")
    }
}
