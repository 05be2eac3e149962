//! OmniControl's spatial guidance (reference-algorithms §2.2), generalised from "distance
//! to target joints" to any [`MotionError`](super::MotionError).
//!
//! At every step of an ancestral DDPM chain (the full 1000 steps, or respaced):
//! ```text
//! x̂0 ← CFG denoiser(x_t);  μ ← posterior mean(x̂0, x_t)
//! K ← K_late if the step is one of the last T_s, else K_early
//! repeat K times:  g ← ∂E(recover_from_ric(μ·Std + Mean), placed)/∂μ;  g[frame 0] ← 0
//!                  μ ← μ − τ·Σ̂·g
//! x_{t−1} ← μ + σ_t·ε   (no noise at the last step)
//! ```
//! mprog's additions, each turned back by its knob and each on by default (why each was
//! made, with the renders and numbers behind it: the book's "Six places where `guide`
//! departs from OmniControl" and its realism section):
//! * early steps move only the root columns ([`FusedSettings::early_root_only`], `early_root`);
//! * the last T_s steps keep bone lengths and planted feet ([`FusedSettings::keep_skeleton`],
//!   [`super::bones`]), hold planted toes ([`FusedSettings::foot_lock`], [`super::feet`])
//!   and hold back the joint acceleration they add over the first
//!   [`ACCEL_HOLD_ITERATIONS`] iterations of each ([`FusedSettings::accel_hold`], `accel`,
//!   [`super::accel`]),
//!   smooth the step over frames ([`GuideConfig::smooth_frames`]), give each statement its
//!   own Polyak step ([`FusedSettings::split_terms`]) and scale the root columns down
//!   ([`FusedSettings::late_root_scale`], `late_root`);
//! * frame 0 is not frozen ([`GuideConfig::freeze_first_frame`], `freeze`);
//! * the registered solver (`run`, the REPL, MCP) runs a short chain chosen by measurement,
//!   [`GuideConfig::measured`]; `paper=1` gives OmniControl's schedule back.
//!
//! The denoiser is not in the inner loop: only FK, the error and its gradient are, through
//! the fused host path ([`super::host`]) by default. Where the reference code and the paper
//! differ, and the step-size rule ([`StepRule::Polyak`] by default): the book's "`guide`:
//! paper, code, and the step size".

use super::knobs::{Knob, KnobKind, knob};
use super::solver::{Solver, SolverConfig, SolverSpec};
use crate::model::sampler::SamplerKind;
use super::SolveError;
use super::host::{HEAD, HostObjective, TermGradients, check_shape, extract_head, insert_head};
use super::request::{Phase, Progress};
use super::driver::{Ctx, Outcome, ensure_finite, host, mean};
use crate::features::FEATURE_DIM;
use super::cleanup::{FootCleanup, clean_feet};
use super::realism::Realism;
use crate::features::{denormalize_slice, normalize_slice};
use crate::model::sampler::posterior_mean;
use crate::model::schedule::{DIFFUSION_STEPS, NoiseSchedule};
use burn::prelude::*;

/// How Σ̂ is derived from the posterior variance Σ_t.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum VarianceRule {
    /// Σ̂ = max(Σ_t, floor): OmniControl's code.
    Floor,
    /// Σ̂ = min(Σ_t, cap): OmniControl's paper (App. A.2).
    Cap,
}

/// How one inner iteration's step is sized.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StepRule {
    /// `μ ← μ − τ·Σ̂·∇E`: OmniControl's update (τ = 20 without the 1/V, see the module doc).
    Gradient,
    /// `μ_b ← μ_b − min(1, τ·Σ̂)·max(E_b, 0)/‖∇E_b‖²·∇E_b` per sample b: a Polyak step that
    /// would remove the fraction min(1, τ·Σ̂) of the (linearised) error, whatever the error's
    /// units, weights or the number of frames it averages over. No single feature moves more
    /// than [`MAX_POLYAK_DELTA`] per iteration (flat regions would otherwise give huge steps).
    Polyak,
}

/// Root columns of a feature row: yaw velocity, XZ velocity, height.
pub(crate) const ROOT_COLUMNS: usize = 4;

/// Column of the root (pelvis) height in a feature row.
const ROOT_HEIGHT: usize = 3;

/// The lowest and highest pelvis of the training data (m): the minimum and maximum over
/// the 631,632 frames of `data/combined` (feature column 3). The early steps keep μ's root
/// height inside it. A pose statement the early root-only steps cannot meet ("lying on
/// the back" on a standing body) otherwise pushes the height down at every step, with
/// nothing to stop it: μ's pelvis reached −7.4 m, and the late steps, pulling it back
/// through the floor penalty smoothed over time, threw the body 2.8 m into the air.
pub const ROOT_HEIGHT_RANGE: (f32, f32) = (0.046, 1.945);

/// Default weight of the acceleration hold ([`FusedSettings::accel_hold`]). With the
/// shipped ControlNet on the keyframe family (6 clips, the bench's fast settings) it took
/// guide's peak acceleration from 0.119 to 0.096 m/frame², under 1.2× the unguided chain's
/// (0.087), for a keyframe error of 0.016 m against 0.013 and skating 0.129 against 0.116
/// (unguided 0.122; book, solvers chapter).
pub const ACCEL_HOLD: f32 = 0.25;

/// Default weight of the envelope penalty ([`FusedSettings::envelope`], [`super::envelope`]).
pub const ENVELOPE: f32 = 1.0;

/// Iterations of each late step the acceleration hold acts over: the bench's whole late
/// step. It shapes the edit while the program is being met; a program still unmet after
/// them is pushed on without it. Held over all of the CLI's 500, an unmet program (HSI-2
/// asks for the head below 0.5 m with the feet on the floor) spread its pull over the
/// whole clip, and the walk under the barrier became a crouch from the first second, its
/// facing spinning (book, solvers chapter).
pub const ACCEL_HOLD_ITERATIONS: usize = 50;

/// Largest change of one normalised feature in one Polyak iteration.
pub const MAX_POLYAK_DELTA: f32 = 0.5;

/// Settings of `guide`; defaults are OmniControl's inference settings.
#[derive(Clone, Debug, PartialEq)]
pub struct GuideConfig {
    /// DDPM steps (1000 = the full chain; fewer = respaced).
    pub steps: usize,
    /// Gradient steps per denoising step before the last `late_steps` (K_e = 10).
    pub k_early: usize,
    /// Gradient steps on each of the last `late_steps` steps (K_l = 500).
    pub k_late: usize,
    /// T_s = 10.
    pub late_steps: usize,
    /// τ = 20 (see the module doc for why there is no 1/V).
    pub tau: f32,
    /// The 0.01 of the variance rule.
    pub variance_bound: f64,
    /// Floor (code) or cap (paper).
    pub variance_rule: VarianceRule,
    /// Step size rule.
    pub step_rule: StepRule,
    /// Zero the gradient of frame 0 (the reference code does; off by default, see the
    /// module notes).
    pub freeze_first_frame: bool,
    /// σ in frames of the Gaussian the gradient is smoothed with over time before each
    /// step of the last `late_steps` steps (0: OmniControl's raw gradient).
    pub smooth_frames: f32,
    /// `Some`: the inner loop runs through the fused host FK (fast), with mprog's additions
    /// to OmniControl's update; `None`: through the burn graph (the reference, for tests and
    /// checks), OmniControl's plain update.
    pub fused: Option<FusedSettings>,
    /// Steer every denoising step through the prior's ControlNet with a hint derived from
    /// the program ([`super::realism`]); acts only when the bundle has a ControlNet.
    pub realism: bool,
    /// Share of the chain's steps, from the first (noisiest) on, that the ControlNet
    /// steers (0–1; 1: every step, as OmniControl). The ControlNet is a second encoder
    /// pass per step: steering the early steps, where pose and path are decided, costs
    /// that much less. 0.5 by default: on the keyframe tasks the first half skated less
    /// than every step did, at the same acceleration and FID (steps 8,500 and 9,700 of
    /// the ControlNet's training; book, solvers chapter).
    pub realism_share: f32,
    /// The ControlNet runs once per step, on the text-conditioned half of classifier-free
    /// guidance, and steers both halves: half its cost. OmniControl runs it on each half;
    /// on the keyframe tasks the two steer alike (skating 0.016 / 0.018, acceleration
    /// 0.154 / 0.156, `mprog bench tasks --family keyframe --clips 2`, 2026-12-05), and
    /// the shared pass costs 1.54× the unguided chain against 1.87×.
    pub realism_shared: bool,
    /// The ControlNet runs on every `realism_every`-th steered step and the steps between
    /// reuse its additions (1: every step, as OmniControl). Neighbouring steps of a
    /// 1000-step chain see nearly the same x_t and hint; 2 halves the ControlNet's cost.
    pub realism_every: usize,
}

/// mprog's additions to OmniControl's inner loop. They exist only on the fused host path,
/// so [`GuideConfig::fused`] holds them there and nowhere else.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FusedSettings {
    /// In the last `late_steps` steps, optimise through the skeleton projection and write
    /// it back ([`super::bones`]): bone lengths kept, planted feet kept on the floor.
    pub keep_skeleton: bool,
    /// Weight of the slide penalty on planted feet in the last `late_steps` steps
    /// ([`super::feet`]); 0 turns it off.
    pub foot_lock: f32,
    /// Weight of the penalty on the joint acceleration the last `late_steps` steps add
    /// ([`super::accel`]); 0 turns it off.
    pub accel_hold: f32,
    /// Weight of the penalty on leaving the training data's envelope (joints below the
    /// floor, accelerations beyond the largest recorded) over every iteration of the last
    /// `late_steps` steps ([`super::envelope`]); 0 turns it off.
    pub envelope: f32,
    /// Before the last `late_steps` steps, step only the root columns (yaw velocity, XZ
    /// velocity, height): the path is steered while the denoiser keeps the pose its own
    /// (see the module notes).
    pub early_root_only: bool,
    /// In the last `late_steps` steps, size the Polyak step of each term of the error (each
    /// statement) on its own and step along the sum (see the module notes); `false` sizes
    /// one step for the whole error.
    pub split_terms: bool,
    /// In the last `late_steps` steps, the root columns' share of each step direction
    /// (a diagonal preconditioner, 0..=1; 1: the plain gradient). Moving the root moves
    /// every joint of every later frame, so its gradient dominates: a contact the prompt
    /// does not make is met by walking the people into each other. Small values make the
    /// late steps meet it with the pose instead (see the module notes). Default 0.01.
    pub late_root_scale: f32,
    /// Iterations of the program's error after the foot cleanup ([`clean_and_polish`]).
    /// Default [`POLISH_ITERATIONS`].
    pub polish_iterations: usize,
}

impl FusedSettings {
    /// None of the additions: OmniControl's plain update, which the graph path runs.
    pub const PLAIN: FusedSettings = FusedSettings {
        keep_skeleton: false,
        foot_lock: 0.0,
        accel_hold: 0.0,
        envelope: 0.0,
        early_root_only: false,
        split_terms: false,
        late_root_scale: 1.0,
        polish_iterations: POLISH_ITERATIONS,
    };

    fn check_settings(&self) -> Result<(), SolveError> {
        if !(self.accel_hold.is_finite() && self.accel_hold >= 0.0) {
            return Err(SolveError::Invalid(
                "guide: the acceleration hold's weight must be finite and ≥ 0".into(),
            ));
        }
        if !(self.envelope.is_finite() && self.envelope >= 0.0) {
            return Err(SolveError::Invalid(
                "guide: the envelope penalty's weight must be finite and ≥ 0".into(),
            ));
        }
        if !(self.foot_lock.is_finite() && self.foot_lock >= 0.0) {
            return Err(SolveError::Invalid(
                "guide: the foot lock's weight must be finite and ≥ 0".into(),
            ));
        }
        if !(self.late_root_scale.is_finite() && (0.0..=1.0).contains(&self.late_root_scale)) {
            return Err(SolveError::Invalid(
                "guide: late_root (the root columns' share of the late steps) must be between 0 and 1".into(),
            ));
        }
        Ok(())
    }
}

impl Default for FusedSettings {
    fn default() -> Self {
        FusedSettings {
            keep_skeleton: true,
            foot_lock: 1.0,
            accel_hold: ACCEL_HOLD,
            envelope: ENVELOPE,
            early_root_only: true,
            split_terms: true,
            late_root_scale: 0.01,
            polish_iterations: POLISH_ITERATIONS,
        }
    }
}

impl Default for GuideConfig {
    fn default() -> Self {
        GuideConfig {
            steps: DIFFUSION_STEPS,
            k_early: 10,
            k_late: 500,
            late_steps: 10,
            tau: 20.0,
            variance_bound: 0.01,
            variance_rule: VarianceRule::Floor,
            step_rule: StepRule::Polyak,
            freeze_first_frame: false,
            smooth_frames: 4.0,
            fused: Some(FusedSettings::default()),
            realism: true,
            realism_share: 0.5,
            realism_shared: true,
            realism_every: 2,
        }
    }
}

/// The chain's length and effort: what `paper=1` switches between.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct ChainSchedule {
    steps: usize,
    k_late: usize,
    late_steps: usize,
    polish_iterations: usize,
}

/// OmniControl's: 1000 DDPM steps, K = 500 on the last 10.
const PAPER_SCHEDULE: ChainSchedule = ChainSchedule {
    steps: DIFFUSION_STEPS,
    k_late: 500,
    late_steps: 10,
    polish_iterations: POLISH_ITERATIONS,
};

/// `run`'s, by measurement (the book's benchmarks, "`run`'s chain"): 100 respaced steps,
/// K = 200 on the last 5 and a 300-iteration polish meet and look as the paper schedule
/// does on the sentence bench and the cookbook, 6–10 times faster. Fewer late iterations
/// (K = 50) left five cookbook programs millimetres short of met.
const MEASURED_SCHEDULE: ChainSchedule = ChainSchedule {
    steps: 100,
    k_late: 200,
    late_steps: 5,
    polish_iterations: 300,
};

impl GuideConfig {
    /// The default settings on [`MEASURED_SCHEDULE`]'s chain: what the registered solver
    /// (`run`, the REPL, MCP) uses.
    pub fn measured() -> Self {
        let mut cfg = GuideConfig::default();
        cfg.set_schedule(MEASURED_SCHEDULE);
        cfg
    }

    fn schedule(&self) -> ChainSchedule {
        ChainSchedule {
            steps: self.steps,
            k_late: self.k_late,
            late_steps: self.late_steps,
            polish_iterations: self.fused.map_or(POLISH_ITERATIONS, |f| f.polish_iterations),
        }
    }

    fn set_schedule(&mut self, s: ChainSchedule) {
        self.steps = s.steps;
        self.k_late = s.k_late;
        self.late_steps = s.late_steps;
        if let Some(fused) = self.fused.as_mut() {
            fused.polish_iterations = s.polish_iterations;
        }
    }

    pub(crate) fn check_settings(&self) -> Result<(), SolveError> {
        if !(1..=DIFFUSION_STEPS).contains(&self.steps) {
            return Err(SolveError::Invalid(format!(
                "guide: {} steps; use 1..={DIFFUSION_STEPS}",
                self.steps
            )));
        }
        if !(self.tau.is_finite() && self.tau >= 0.0 && self.variance_bound >= 0.0) {
            return Err(SolveError::Invalid(
                "guide: τ and the variance bound must be finite and ≥ 0".into(),
            ));
        }
        if !(self.realism_share.is_finite() && (0.0..=1.0).contains(&self.realism_share)) {
            return Err(SolveError::Invalid(
                "guide: realism_share (the share of steps the ControlNet steers) must be between 0 and 1".into(),
            ));
        }
        if !(1..=100).contains(&self.realism_every) {
            return Err(SolveError::Invalid(
                "guide: realism_every (how often the ControlNet runs) must be 1..=100 steps".into(),
            ));
        }
        if !(self.smooth_frames.is_finite() && (0.0..=100.0).contains(&self.smooth_frames)) {
            return Err(SolveError::Invalid(
                "guide: smooth_frames (σ of the gradient's smoothing over time) must be between 0 and 100 frames".into(),
            ));
        }
        match &self.fused {
            Some(fused) => fused.check_settings(),
            None => Ok(()),
        }
    }

    /// Inner iterations at step `i` of the chain (counted from 0 = the last, cleanest).
    pub fn iterations_at(&self, i: usize) -> usize {
        if i < self.late_steps {
            self.k_late
        } else {
            self.k_early
        }
    }

    /// σ (frames) of the gradient's smoothing at step `i` (0 = the last): `smooth_frames`
    /// in the last `late_steps` steps, 0 before.
    pub fn smoothing_at(&self, i: usize) -> f32 {
        if i < self.late_steps {
            self.smooth_frames
        } else {
            0.0
        }
    }

    /// Σ̂ of a posterior variance.
    pub fn sigma_hat(&self, variance: f64) -> f64 {
        match self.variance_rule {
            VarianceRule::Floor => variance.max(self.variance_bound),
            VarianceRule::Cap => variance.min(self.variance_bound),
        }
    }
}

/// Runs the guided chain.
fn run(
    ctx: &Ctx,
    cfg: &GuideConfig,
    progress: &mut dyn FnMut(Progress),
) -> Result<Outcome, SolveError> {
    let den = ctx.denoiser();
    let schedule = NoiseSchedule::cosine(DIFFUSION_STEPS).respaced(cfg.steps);
    let cond = ctx.condition(&ctx.device);
    let mut noise = ctx.step_noise();
    let dims = ctx.dims();
    let mut objective = ctx.host_objective();
    // A take starts the chain part-way down and holds its kept frames (`super::edit`).
    let (n, mut x) = ctx.chain_start(&schedule);
    let mut trace = Vec::with_capacity(n);
    let mut realism = Realism::new(
        ctx,
        ctx.prior.control.filter(|_| cfg.realism),
        cfg.realism_shared,
        cfg.realism_every,
    );
    let mut steps = ctx.chain_steps(n);
    // The first `steered` steps of the chain go through the ControlNet.
    let steered = (cfg.realism_share as f64 * n as f64).ceil() as usize;
    let steers = |i: usize| n.saturating_sub(1 + i) < steered;
    while let Some(i) = steps.next_step() {
        let x0 = ctx.hold_x0(realism.x0(
            &den,
            x.clone(),
            schedule.timesteps[i],
            &cond,
            steers(i),
        ));
        let mut mu = posterior_mean(&schedule, i, x, x0);
        let k = cfg.iterations_at(i);
        let post = schedule.posterior(i);
        let step = (cfg.tau as f64 * cfg.sigma_hat(post.variance_clipped)) as f32;
        let at = |it: usize| format!("denoising step {}/{n} (inner iteration {})", n - i, it + 1);
        let mut last = None;
        if k > 0 {
            let mut full = host(mu);
            // The hint is for the next step: only worth deriving when it is steered.
            let before = (realism.is_on() && i > 0 && steers(i - 1)).then(|| full.clone());
            let values = match &cfg.fused {
                Some(fused) => {
                    let inner = Inner::at(cfg, fused, i, k, step);
                    guide_fused(ctx, cfg, &mut objective, &mut full, inner, i, &at)?
                }
                None => guide_graph(ctx, cfg, &mut full, k, step, i, &at)?,
            };
            if let Some(before) = before {
                realism.update(ctx, &before, &full)?;
            }
            mu = Tensor::from_data(TensorData::new(full, dims), &ctx.device);
            last = Some(mean(&values));
            trace.push(values);
        }
        x = if i > 0 {
            mu + noise.tensor(dims, &ctx.device) * post.variance.sqrt()
        } else {
            mu
        };
        x = steps.after(&schedule, x, &mut noise, &ctx.device);
        progress(Progress {
            phase: Phase::Sampling,
            done: steps.ran(),
            total: steps.total(),
            error: last,
        });
    }
    let mut x = host(ctx.hold_final(x));
    // A window's edit cleans only what it does not hold, and is polished the same way.
    let asks = ctx.clean_feet
        || (ctx.polish_edit && ctx.edit.as_ref().is_some_and(|e| e.cleans_feet()));
    let cleaned = asks && cfg.fused.is_some();
    if let Some(fused) = cfg.fused.as_ref().filter(|_| cleaned) {
        let values = clean_and_polish(ctx, cfg, fused, &schedule, &mut objective, &mut x)?;
        trace.push(values);
    }
    Ok(Outcome {
        x,
        relax: None,
        trace,
        cleaned,
    })
}

/// Iterations of the program's error after the foot cleanup ([`clean_and_polish`]), by
/// default.
pub const POLISH_ITERATIONS: usize = 100;

/// The foot cleanup `gen` gives its samples ([`super::cleanup`]), then
/// `polish_iterations` iterations of the last step's inner loop with the feet as the
/// cleanup planted them locked. The cleanup stands every planted foot still, which moves
/// the body by millimetres (the projection rests it on its lowest foot): cleaned and not
/// polished, statements met to 1e-4 came back at 0.001–0.003 (a facing keyframe, a
/// pelvis height), reported "not met" where the motion was right. Returns the error of
/// the last evaluation.
fn clean_and_polish(
    ctx: &Ctx,
    cfg: &GuideConfig,
    fused: &FusedSettings,
    schedule: &NoiseSchedule,
    objective: &mut HostObjective,
    x: &mut [f32],
) -> Result<Vec<f32>, SolveError> {
    let (mean, std) = (ctx.prior.mean, ctx.prior.std);
    denormalize_slice(x, mean, std).map_err(|e| SolveError::Invalid(e.to_string()))?;
    match &ctx.edit {
        Some(edit) => edit.clean_free_feet(x, ctx.frames),
        None => {
            clean_feet(x, ctx.frames, FEATURE_DIM, &FootCleanup::default());
        }
    }
    normalize_slice(x, mean, std).map_err(|e| SolveError::Invalid(e.to_string()))?;
    let step = (cfg.tau as f64 * cfg.sigma_hat(schedule.posterior(0).variance_clipped)) as f32;
    let inner = Inner {
        fix_envelope: true,
        ..Inner::at(cfg, fused, 0, fused.polish_iterations, step)
    };
    let at = |it: usize| format!("the polish after the foot cleanup (iteration {})", it + 1);
    guide_fused(ctx, cfg, objective, x, inner, 0, &at)
}

/// One denoising step's inner loop on the fused path: K iterations of this step size, and
/// what the additions ([`FusedSettings`]) do at this step.
#[derive(Clone, Copy)]
struct Inner {
    k: usize,
    step: f32,
    /// Through the skeleton projection.
    skeleton: bool,
    /// The foot lock's weight (0: without).
    foot_lock: f32,
    /// The acceleration hold's weight (0: without).
    accel_hold: f32,
    /// The envelope penalty's weight (0: without).
    envelope: f32,
    /// Columns of a head row that move: the root's, or all of them.
    moving: usize,
    /// A Polyak step per term.
    split: bool,
    /// The root columns' share of each step direction.
    root_scale: f32,
    /// Keep the root height inside [`ROOT_HEIGHT_RANGE`] after every iteration.
    bound_root_height: bool,
    /// Step on the penalties where the program is met but the motion is outside the
    /// envelope (the polish; [`TermGradients::share_penalty`]).
    fix_envelope: bool,
}

impl Inner {
    /// The inner loop at step `i` of the chain (0 = the last): the late additions act in
    /// the last `late_steps` steps, root-only steps before them.
    fn at(cfg: &GuideConfig, fused: &FusedSettings, i: usize, k: usize, step: f32) -> Inner {
        let late = i < cfg.late_steps;
        Inner {
            k,
            step,
            skeleton: fused.keep_skeleton && late,
            foot_lock: if late { fused.foot_lock } else { 0.0 },
            accel_hold: if late { fused.accel_hold } else { 0.0 },
            envelope: if late { fused.envelope } else { 0.0 },
            moving: if fused.early_root_only && !late {
                ROOT_COLUMNS
            } else {
                HEAD
            },
            // Split in the late steps only: early, where only the path moves, statements
            // that conflict over the path each pulled it their own way (HSI-4's "duck under
            // the barrier" met by stopping short of it, against "end past it": 0.76 m short).
            split: fused.split_terms && cfg.step_rule == StepRule::Polyak && late,
            root_scale: if late { fused.late_root_scale } else { 1.0 },
            bound_root_height: !late,
            fix_envelope: false,
        }
    }
}

/// K steps on the head columns of `full` through the fused host path; returns the error
/// of the last evaluation.
fn guide_fused(
    ctx: &Ctx,
    cfg: &GuideConfig,
    objective: &mut HostObjective,
    full: &mut [f32],
    Inner {
        k,
        step,
        skeleton,
        foot_lock,
        accel_hold,
        envelope,
        moving,
        split,
        root_scale,
        bound_root_height,
        fix_envelope,
    }: Inner,
    i: usize,
    at: &dyn Fn(usize) -> String,
) -> Result<Vec<f32>, SolveError> {
    let sigma = cfg.smoothing_at(i);
    let mut head = extract_head(full, FEATURE_DIM);
    let mut grad = vec![0.0; head.len()];
    let mut values = Vec::new();
    if skeleton {
        objective.project_skeleton(&head);
    }
    if foot_lock > 0.0 {
        objective.lock_feet(&head, foot_lock);
    }
    if accel_hold > 0.0 {
        objective.hold_accel(&head, accel_hold);
    }
    objective.keep_in_envelope(envelope);
    let mut terms = TermGradients::default();
    let mut combined = vec![0.0; head.len()];
    let mut total = Vec::new();
    for it in 0..k {
        if it == ACCEL_HOLD_ITERATIONS && accel_hold > 0.0 {
            objective.release_accel();
        }
        if split {
            objective.eval_terms(&head, &mut terms)?;
            values.clone_from(&terms.total);
            ensure_finite(&values, "guide", "error", || at(it))?;
            let alone = outside_alone(objective, fix_envelope);
            terms.share_penalty(&alone);
            combined.fill(0.0);
            for (term, g) in terms.values.iter().zip(terms.grads.iter_mut()) {
                ensure_finite(term, "guide", "error", || at(it))?;
                ensure_finite(g, "guide", "gradient", || at(it))?;
                let mut dir = step_direction(ctx, cfg, g, HEAD, sigma);
                scale_root(&mut dir, root_scale);
                add_polyak_step(&mut combined, g, &dir, term, step);
            }
            let per = term_block(&head, &values);
            apply_capped(&mut head, &combined, per, (HEAD, moving));
            continue;
        }
        values = objective.eval(&head, &mut grad)?;
        // The step removes a fraction of program error + foot penalty, whose gradient
        // `grad` is; the program's own error is what gets reported. A sample whose error
        // is 0 takes no step: the penalty alone has nothing to shape
        // ([`TermGradients::share_penalty`]).
        let alone = outside_alone(objective, fix_envelope);
        total.clear();
        total.extend(
            values
                .iter()
                .zip(objective.penalty())
                .zip(&alone)
                .map(|((e, p), a)| if *e > 0.0 || *a { e + p } else { 0.0 }),
        );
        ensure_finite(&values, "guide", "error", || at(it))?;
        ensure_finite(&grad, "guide", "gradient", || at(it))?;
        let mut dir = step_direction(ctx, cfg, &mut grad, HEAD, sigma);
        scale_root(&mut dir, root_scale);
        // Early root-only steps take the step the full gradient calls for, on the root
        // columns alone: restricting the direction must not enlarge the step (a pose error
        // with a small root gradient would otherwise push the root height by metres).
        apply_step(cfg, &mut head, &grad, &dir, &total, step, (HEAD, moving));
        if bound_root_height {
            clamp_root_height(&mut head, ctx.prior.mean, ctx.prior.std);
        }
    }
    objective.unlock_feet();
    if skeleton {
        // The error was of P(head): make that what the chain carries on with, as far as
        // each feature of a take is free (`1 − w`). P squares the shoulders into its rigid
        // T, which a take's need not be (a retargeted walk's collars 0.10 m apart, P's
        // 0.30 m): applied in full on a seam's frames it moved the left collar 0.2 m in
        // the one frame after the last held one.
        let before = ctx.edit.is_some().then(|| head.clone());
        objective.apply_projection(&mut head);
        objective.stop_projecting();
        if let Some(before) = before {
            ctx.hold_change(&before, &mut head, HEAD);
        }
    }
    insert_head(full, FEATURE_DIM, &head);
    Ok(values)
}

/// Per sample, whether its penalties step on their own: with `fix_envelope`, where the
/// last evaluation left the motion outside the envelope.
fn outside_alone(objective: &HostObjective, fix_envelope: bool) -> Vec<bool> {
    objective
        .outside()
        .iter()
        .map(|&o| fix_envelope && o > 0.0)
        .collect()
}

/// Clamps the root height of every normalised `[.., HEAD]` row into [`ROOT_HEIGHT_RANGE`].
pub(crate) fn clamp_root_height(head: &mut [f32], mean: &[f32], std: &[f32]) {
    let (m, s) = (mean[ROOT_HEIGHT], std[ROOT_HEIGHT].max(1e-6));
    let (lo, hi) = ((ROOT_HEIGHT_RANGE.0 - m) / s, (ROOT_HEIGHT_RANGE.1 - m) / s);
    for row in head.chunks_exact_mut(HEAD) {
        row[ROOT_HEIGHT] = row[ROOT_HEIGHT].clamp(lo, hi);
    }
}

/// The step direction of gradient `g` (`[M, N, width]`): `g` smoothed over frames by
/// σ = `sigma`; with a frozen first frame, frame 0 of both `g` and the direction zeroed.
fn step_direction(
    ctx: &Ctx,
    cfg: &GuideConfig,
    g: &mut [f32],
    width: usize,
    sigma: f32,
) -> Vec<f32> {
    let mut dir = smooth_over_frames(g, ctx.frames, width, sigma);
    if cfg.freeze_first_frame {
        for m in 0..ctx.motions() {
            let f0 = m * ctx.frames * width;
            g[f0..f0 + width].fill(0.0);
            dir[f0..f0 + width].fill(0.0);
        }
    }
    // Frames kept from a take do not move; seams move partly.
    ctx.hold_step(g, width);
    ctx.hold_step(&mut dir, width);
    dir
}

/// Scales the root columns of a `[.., HEAD]` direction by `r` (a diagonal preconditioner:
/// the Polyak step divides by ⟨g, d⟩, so it stays a descent step sized for the term).
fn scale_root(dir: &mut [f32], r: f32) {
    if r == 1.0 {
        return;
    }
    for row in dir.chunks_exact_mut(HEAD) {
        row[..ROOT_COLUMNS].iter_mut().for_each(|d| *d *= r);
    }
}

/// The same K steps through the burn graph (decoder + error, autodiff).
fn guide_graph(
    ctx: &Ctx,
    cfg: &GuideConfig,
    full: &mut [f32],
    k: usize,
    step: f32,
    i: usize,
    at: &dyn Fn(usize) -> String,
) -> Result<Vec<f32>, SolveError> {
    let sigma = cfg.smoothing_at(i);
    let ad = ctx.device.clone().autodiff();
    let dims = ctx.dims();
    let mut values = Vec::new();
    for it in 0..k {
        let var = Tensor::<3>::from_data(TensorData::new(full.to_vec(), dims), &ad).require_grad();
        let e = ctx.error.error(ctx.decoder.joints(var.clone(), None));
        check_shape(&e, ctx.samples)?;
        values = host(e.clone());
        ensure_finite(&values, "guide", "error", || at(it))?;
        let mut g = if e.is_tracked() {
            var.grad(&e.sum().backward()).map(host)
        } else {
            None
        }
        .unwrap_or_else(|| vec![0.0; full.len()]);
        ensure_finite(&g, "guide", "gradient", || at(it))?;
        let dir = step_direction(ctx, cfg, &mut g, FEATURE_DIM, sigma);
        apply_step(
            cfg,
            full,
            &g,
            &dir,
            &values,
            step,
            (FEATURE_DIM, FEATURE_DIM),
        );
    }
    Ok(values)
}

/// `x ← x − s·d` along direction `d` (the gradient `g`, smoothed or not) with `s` from the
/// step rule; `x`, `g` and `d` hold the samples one after the other (equal blocks),
/// `values` their errors. The linearised error drops by `s·⟨g, d⟩`. `(width, moving)`:
/// rows are `width` wide and only their first `moving` columns change; `s` is the one the
/// whole direction calls for.
fn apply_step(
    cfg: &GuideConfig,
    x: &mut [f32],
    g: &[f32],
    d: &[f32],
    values: &[f32],
    step: f32,
    (width, moving): (usize, usize),
) {
    let moves = |k: usize| k % width < moving;
    match cfg.step_rule {
        StepRule::Gradient => {
            for (k, (x, d)) in x.iter_mut().zip(d).enumerate() {
                if moves(k) {
                    *x -= step * d;
                }
            }
        }
        StepRule::Polyak => {
            let mut c = vec![0.0; x.len()];
            add_polyak_step(&mut c, g, d, values, step);
            apply_capped(x, &c, term_block(x, values), (width, moving));
        }
    }
}

/// Adds to `combined` the Polyak step of one term: per sample block, direction `d` (the
/// term's gradient `g`, smoothed or not) times `min(1, step)·e/⟨g, d⟩`, the step that
/// removes that fraction of the term's linearised error. Blocks whose term is ≤ 0 or flat
/// add nothing.
fn add_polyak_step(combined: &mut [f32], g: &[f32], d: &[f32], values: &[f32], step: f32) {
    let per = combined.len() / values.len();
    let fraction = step.min(1.0) as f64;
    let blocks = combined
        .chunks_exact_mut(per)
        .zip(g.chunks_exact(per))
        .zip(d.chunks_exact(per));
    for (((cb, gb), db), &e) in blocks.zip(values) {
        let slope: f64 = gb
            .iter()
            .zip(db)
            .map(|(g, d)| (*g as f64) * (*d as f64))
            .sum();
        if slope <= 1e-20 || e <= 0.0 {
            continue;
        }
        let s = (fraction * e as f64 / slope) as f32;
        for (c, d) in cb.iter_mut().zip(db) {
            *c += s * d;
        }
    }
}

/// Samples' block length in `x` (one block per error value).
fn term_block(x: &[f32], values: &[f32]) -> usize {
    x.len() / values.len().max(1)
}

/// `x ← x − c` on the first `moving` of every `width` columns, per sample block of `per`
/// values scaled down so that no value moves more than [`MAX_POLYAK_DELTA`]. The terms'
/// steps are sized on their whole gradients: restricting the columns (early root-only
/// steps) must not enlarge them.
fn apply_capped(x: &mut [f32], c: &[f32], per: usize, (width, moving): (usize, usize)) {
    let moves = |k: usize| k % width < moving;
    for (xb, cb) in x.chunks_exact_mut(per).zip(c.chunks_exact(per)) {
        let c_max = cb
            .iter()
            .enumerate()
            .filter(|(k, _)| moves(*k))
            .fold(0.0f32, |m, (_, v)| m.max(v.abs()));
        if c_max == 0.0 {
            continue;
        }
        let scale = (MAX_POLYAK_DELTA / c_max).min(1.0);
        for (k, (x, c)) in xb.iter_mut().zip(cb).enumerate() {
            if moves(k) {
                *x -= scale * c;
            }
        }
    }
}

/// Each column of `[M, N, width]` rows convolved over its N frames with a Gaussian of σ
/// `sigma` frames (zero outside the motion, so the operator is symmetric and positive
/// semi-definite and the result stays a descent direction); `sigma` 0 returns `v`
/// unchanged. Every column gets the same kernel.
pub fn smooth_over_frames(v: &[f32], frames: usize, width: usize, sigma: f32) -> Vec<f32> {
    if sigma <= 0.0 || frames < 2 {
        return v.to_vec();
    }
    let radius = ((3.0 * sigma).ceil() as usize).min(frames - 1);
    // Weights sum to 1, so a gradient that is already smooth over time (a dense constraint)
    // comes out as it went in: unnormalised, the Polyak step's cap on the largest change
    // shrank with the kernel's mass and a dense error stopped falling (GEO-1's walker
    // stayed through its wall).
    let raw: Vec<f32> = (0..=radius)
        .map(|k| (-0.5 * (k as f32 / sigma).powi(2)).exp())
        .collect();
    let mass = raw[0] + 2.0 * raw[1..].iter().sum::<f32>();
    let kernel: Vec<f32> = raw.iter().map(|w| w / mass).collect();
    let mut out = vec![0.0; v.len()];
    for (src, dst) in v
        .chunks_exact(frames * width)
        .zip(out.chunks_exact_mut(frames * width))
    {
        for t in 0..frames {
            let row = &mut dst[t * width..(t + 1) * width];
            let lo = t.saturating_sub(radius);
            let hi = (t + radius).min(frames - 1);
            for u in lo..=hi {
                let w = kernel[t.abs_diff(u)];
                for (o, x) in row.iter_mut().zip(&src[u * width..(u + 1) * width]) {
                    *o += w * x;
                }
            }
        }
    }
    out
}

/// `guide`, for [`super::registry`].
pub const SPECS: &[SolverSpec] = &[SolverSpec {
    name: "guide",
    summary: "the posterior mean μ_t, K gradient steps at every DDPM step (OmniControl)",
    make: || Solver::new(GuideConfig::measured()),
}];

/// A knob on a field of [`FusedSettings`]. On the graph path (`fused: None`, made only in
/// code) it reads as the plain update's value, and setting it turns the fused path on with
/// that one addition.
macro_rules! fused_knob {
    ($kind:ident $(($off:literal, $on:literal))?, $name:literal, $doc:expr, $field:ident) => {{
        const ON_FUSED: Knob<FusedSettings> = knob!($kind $(($off, $on))?, $name, $doc, $field);
        Knob {
            name: ON_FUSED.name,
            doc: ON_FUSED.doc,
            kind: ON_FUSED.kind,
            get: |c: &GuideConfig| (ON_FUSED.get)(&c.fused.unwrap_or(FusedSettings::PLAIN)),
            set: |c: &mut GuideConfig, v| {
                (ON_FUSED.set)(c.fused.get_or_insert(FusedSettings::PLAIN), v)
            },
        }
    }};
}

impl SolverConfig for GuideConfig {
    const KNOBS: &'static [Knob<Self>] = &[
        Knob {
            name: "paper",
            doc: "1: OmniControl's schedule (1000 DDPM steps, k_late 500 on the last 10, polish 100); 0: the measured short chain (100 steps, k_late 200 on the last 5, polish 300). Knobs after it change single settings",
            kind: KnobKind::Flag {
                off: "the measured short chain",
                on: "OmniControl's schedule",
            },
            get: |c: &GuideConfig| f64::from(u8::from(c.schedule() == PAPER_SCHEDULE)),
            set: |c: &mut GuideConfig, v| {
                c.set_schedule(if v != 0.0 { PAPER_SCHEDULE } else { MEASURED_SCHEDULE })
            },
        },
        knob!(Count, "steps", "DDPM steps (fewer = respaced chain, faster, rougher)", steps),
        knob!(Count, "k_early", "gradient iterations per step before the last `late_steps`", k_early),
        knob!(Count, "k_late", "gradient iterations per step during the last `late_steps`", k_late),
        knob!(Count, "late_steps", "T_s: the last steps that get `k_late` iterations and the late-step additions", late_steps),
        knob!(Real, "tau", "OmniControl's strength τ", tau),
        fused_knob!(
            Flag("OmniControl's plain inner loop", "keep bone lengths"),
            "skeleton",
            "1: the last `late_steps` optimise through the skeleton (bone lengths kept, planted feet kept on the floor); 0: OmniControl's plain inner loop",
            keep_skeleton
        ),
        knob!(
            Flag("off", "first frame frozen"),
            "freeze",
            "1: zero the gradient of frame 0, as OmniControl's reference code does",
            freeze_first_frame
        ),
        knob!(Real, "smooth", "σ in frames of the Gaussian each late step's gradient is smoothed with over time; 0: OmniControl's raw gradient", smooth_frames),
        fused_knob!(Real, "feet", "weight of the slide penalty on planted toes in the last `late_steps`; 0: off", foot_lock),
        fused_knob!(Real, "accel", "weight of the penalty on the joint acceleration the last `late_steps` add (jerks where keyframes are scattered); 0: off", accel_hold),
        fused_knob!(Real, "envelope", "weight of the penalty on joints below the floor and accelerations beyond the training data's largest, over all of the last `late_steps`; 0: off", envelope),
        fused_knob!(
            Flag("every column", "root columns only before the late steps"),
            "early_root",
            "1: before the last `late_steps`, step only the root columns (the path) and leave the pose to the model; 0: every column from the first step, as OmniControl",
            early_root_only
        ),
        fused_knob!(
            Flag("one step for the whole error", "a step per statement"),
            "split",
            "1: in the last `late_steps`, each statement gets its own step size and the iteration steps along their sum; 0: one step for the whole error, as OmniControl",
            split_terms
        ),
        knob!(
            Flag("off", "through the ControlNet"),
            "realism",
            "1: when the model has a ControlNet, every denoising step's x̂0 is steered by it with a hint taken from the program's gradient and the inner loop's iterate (OmniControl's realism guidance); 0: off",
            realism
        ),
        knob!(
            Real,
            "realism_share",
            "share of the denoising steps, from the first (noisiest) on, whose x̂0 the ControlNet steers, 0–1; 1: every step, as OmniControl",
            realism_share
        ),
        knob!(
            Count,
            "realism_every",
            "the ControlNet runs on every k-th steered step, the steps between reuse its additions; 1: every step, as OmniControl",
            realism_every
        ),
        knob!(
            Flag("a pass per half, as OmniControl", "one pass for both halves"),
            "realism_shared",
            "1: the ControlNet runs once per step, on the text-conditioned half of classifier-free guidance, and steers both halves (half its cost); 0: a pass per half, as OmniControl",
            realism_shared
        ),
        fused_knob!(Count, "polish", "iterations of the program's error after the foot cleanup, feet locked where the cleanup planted them", polish_iterations),
        fused_knob!(Real, "late_root", "share of the root columns (path) in each step of the last `late_steps`, 0–1: the late steps meet contacts and keyframes with the pose instead of by moving the people; 1: OmniControl's plain gradient", late_root_scale),
    ];

    fn name(&self) -> &'static str {
        "guide"
    }

    fn unguided(&self) -> SamplerKind {
        SamplerKind::Ddpm(self.steps)
    }

    fn validate(&self) -> Result<(), SolveError> {
        self.check_settings()
    }

    fn run(&self, ctx: &Ctx, progress: &mut dyn FnMut(Progress)) -> Result<Outcome, SolveError> {
        run(ctx, self, progress)
    }

    fn edit_refusal(&self) -> Option<&'static str> {
        None
    }
}
