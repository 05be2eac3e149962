//! PMG's latent-noise optimisation (reference-algorithms §1.1–1.3): the DDIM chain
//! (η = 0, 100 steps, CFG 2.5 with both passes batched) is a deterministic function
//! x̂ = D(z) of the initial noise z; Adam minimises E(D(z)) over z with the gradient
//! through the whole chain (frozen denoiser: no parameter gradients, dropout off).
//!
//! ```text
//! z ← x_T (seeded);  for it in 0..iterations:
//!     x̂ ← DDIM(z);  record E(x̂);  if it is not the last: z ← Adam(z, ∂E/∂z)
//! return x̂ of the last forward (after iterations − 1 updates), as PMG does
//! ```
//!
//! Relaxation (PMG §3.4, simple form): with [`Relax::RigidXz`] every (sample, person) also
//! gets a rigid horizontal transform (yaw, x, z), applied in its own frame before its
//! placement and optimised jointly with z by its own Adam. This is PMG's "relax the goal,
//! then move the motion onto the true goal" for goals that only care about positions up to
//! a horizontal rigid motion (planes, lines, point pairs), done in one loop instead of
//! relaxation rounds.
//!
//! Skeleton (mprog's addition, on by default: [`LatentConfig::keep_skeleton`]): the error
//! is that of `P(x̂)`, the chain's output with its bone lengths restored and its planted
//! feet kept on the floor ([`super::bones`]), and `P(x̂)` is what is returned. The chain's
//! own output keeps no skeleton when z is pushed to meet a program: limbs stretched by
//! 6–18 cm in the cookbook's `latent` runs. The gradient goes through `P` on the fused
//! host path ([`super::host`]) and enters the chain as `⟨x̂, ∂E/∂x̂⟩`; with relaxation the
//! rigid move is applied there too and its gradient computed on the host
//! ([`HostObjective::set_rigid`](super::host::HostObjective::set_rigid)). Without the
//! skeleton the rigid move is differentiated through the burn decoder.
//!
//! Editing a take (DNO's editing): z starts from the take inverted by deterministic DDIM
//! to the strength's level ([`Ctx::latent_start`]), the chain runs only the steps below
//! it, and every x̂0 of the chain has the edit's held frames and columns put in
//! ([`X0Hold`]), so the gradient reaches z only through what the edit may change.
//!
//! Memory: with [`LatentConfig::checkpoint`] off (the default, as PMG), the graph of the
//! whole chain (steps × 2 CFG passes) is kept for one backward (measured: 1519 MiB peak RSS
//! at 100 steps, 120 frames, one motion; it grows with B·P). With it on, the forward runs
//! without autodiff and keeps only each step's input x_i; the backward then re-runs one
//! step at a time with autodiff and back-propagates the incoming gradient through it
//! (vector–Jacobian product), so only one step's graph is alive (measured: 58 MiB peak RSS,
//! identical errors) for about one extra forward pass per iteration (measured 1.3–1.8×
//! slower on a loaded 2-core machine).

use super::knobs::{Knob, KnobKind, knob};
use super::solver::{Solver, SolverConfig, SolverSpec};
use crate::model::sampler::SamplerKind;
use super::adam::Adam;
use super::decode::RigidTensors;
use super::host::{HostObjective, extract_head, insert_head};
use crate::scene::Placement;
use super::reference::ReferencePull;
use super::request::{Phase, Progress};
use super::driver::{Ctx, Outcome, ensure_finite, host, mean};
use super::{SolveError, host::check_shape};
use crate::features::FEATURE_DIM;
use super::edit::X0Hold;
use crate::model::sampler::{Condition, ddim_step, guided_x0};
use crate::model::schedule::{DIFFUSION_STEPS, NoiseSchedule, consistency_timesteps};
use crate::model::{Denoiser, Mdm};
use burn::prelude::*;
use burn::tensor::Gradients;

/// Whether the motion may move rigidly in the horizontal plane while it is optimised.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Relax {
    /// No relaxation.
    None,
    /// A yaw and an XZ translation per (sample, person), optimised with z.
    RigidXz,
}

/// Settings of `latent`; defaults are PMG's.
#[derive(Clone, Debug, PartialEq)]
pub struct LatentConfig {
    /// DDIM steps (100).
    pub ddim_steps: usize,
    /// Steps of the chain when the prior is a few-step model (4): its consistency
    /// timesteps, each re-noised along its own ε̂ (DDIM's rule), so x̂ = D(z) stays a
    /// deterministic function of z, as DNO and MotionLCM's control optimise it.
    pub fast_steps: usize,
    /// Forward passes (100; the last one's sample is returned).
    pub iterations: usize,
    /// Adam learning rate on z (0.005, constant).
    pub lr: f64,
    /// Relaxation.
    pub relax: Relax,
    /// Adam learning rate of the relaxation's yaw (rad) and translation (m).
    pub relax_lr: f64,
    /// Re-run each DDIM step during the backward instead of keeping the whole graph.
    pub checkpoint: bool,
    /// Measure and return the chain's output through the skeleton projection (see the
    /// module notes), with or without relaxation.
    pub keep_skeleton: bool,
    /// Weight of PMG's pull of the root columns towards the iteration-0 sample
    /// ([`super::reference`]; 0 = off, as PMG's configs without `reg`).
    pub ref_root: f32,
    /// Weight of the same pull on the leg columns.
    pub ref_legs: f32,
    /// Put each motion's z back on the sphere of radius √(frames · features) after every
    /// Adam step, where Gaussian noise of that size lies (DNO keeps z there too): a
    /// z pushed off it is noise the model never saw.
    pub sphere: bool,
    /// Run only on a few-step (consistency-distilled) model: `latent-fast`.
    pub few_step: bool,
}

impl Default for LatentConfig {
    fn default() -> Self {
        LatentConfig {
            ddim_steps: 100,
            fast_steps: crate::model::sampler::FEW_STEPS,
            iterations: 100,
            lr: 0.005,
            relax: Relax::None,
            relax_lr: 0.02,
            checkpoint: false,
            keep_skeleton: true,
            ref_root: 0.0,
            ref_legs: 0.0,
            sphere: false,
            few_step: false,
        }
    }
}

impl LatentConfig {
    /// `latent-fast`: the noise of a few-step model's 4-step chain (DNO's and MotionLCM's
    /// control by noise optimisation), 100 iterations at lr 0.05, z kept on the Gaussian
    /// shell and the root pulled lightly to the first sample (chosen on the main job and
    /// the PMG tasks: book, "A few-step model").
    pub fn fast() -> Self {
        LatentConfig {
            iterations: 100,
            lr: 0.05,
            sphere: true,
            ref_root: 0.3,
            few_step: true,
            ..LatentConfig::default()
        }
    }
}

impl LatentConfig {
    fn check_settings(&self) -> Result<(), SolveError> {
        if !(1..=DIFFUSION_STEPS).contains(&self.ddim_steps)
            || !(1..=DIFFUSION_STEPS).contains(&self.fast_steps)
            || self.iterations == 0
        {
            return Err(SolveError::Invalid(format!(
                "latent: {} DDIM steps, {} few-model steps and {} iterations; use 1..={DIFFUSION_STEPS} steps and ≥ 1 iteration",
                self.ddim_steps, self.fast_steps, self.iterations
            )));
        }
        if !(self.lr.is_finite() && self.lr >= 0.0 && self.relax_lr.is_finite()) {
            return Err(SolveError::Invalid(
                "latent: learning rates must be finite".into(),
            ));
        }
        if ![self.ref_root, self.ref_legs]
            .iter()
            .all(|w| w.is_finite() && *w >= 0.0)
        {
            return Err(SolveError::Invalid(
                "latent: the reference pulls `ref_root` and `ref_legs` must be finite and ≥ 0"
                    .into(),
            ));
        }
        Ok(())
    }
}

/// The DDIM (η = 0) chain from `z` over the steps `first − 1` down to 0 (all of them, or
/// an edit's part), with an edit's held frames and columns put into every x̂0. On an
/// autodiff device with a frozen model it is differentiable with respect to `z`.
fn ddim_chain(
    den: &impl Denoiser,
    schedule: &NoiseSchedule,
    first: usize,
    z: Tensor<3>,
    cond: &Condition,
    hold: Option<&X0Hold>,
) -> Tensor<3> {
    let mut x = z;
    for i in (0..first).rev() {
        x = ddim_step_held(den, schedule, i, x, cond, hold);
    }
    x
}

/// One DDIM step, x̂0 held where an edit holds it.
fn ddim_step_held(
    den: &impl Denoiser,
    schedule: &NoiseSchedule,
    i: usize,
    x: Tensor<3>,
    cond: &Condition,
    hold: Option<&X0Hold>,
) -> Tensor<3> {
    let x0 = guided_x0(den, x.clone(), schedule.timesteps[i], cond);
    let x0 = match hold {
        Some(h) => h.apply(x0),
        None => x0,
    };
    ddim_step(schedule, i, x, x0)
}

/// Back-propagates `g = ∂E/∂x̂` through the DDIM steps one at a time: `inputs[k]` is the
/// input of the k-th step run (the chain's first step, `first − 1`, first); each step is
/// re-run with autodiff and `⟨step(x), g⟩` differentiated. Returns ∂E/∂z.
fn backprop_steps(
    model: &Mdm,
    schedule: &NoiseSchedule,
    cond: &Condition,
    hold: Option<&X0Hold>,
    inputs: Vec<Tensor<3>>,
    mut g: Vec<f32>,
    ad: &Device,
) -> Vec<f32> {
    let first = inputs.len();
    for (k, input) in inputs.into_iter().enumerate().rev() {
        let i = first - 1 - k;
        let dims = input.dims();
        let xi = Tensor::<3>::from_data(input.into_data(), ad).require_grad();
        let out = ddim_step_held(model, schedule, i, xi.clone(), cond, hold);
        let up = Tensor::<3>::from_data(TensorData::new(g, dims), ad);
        let grads = (out * up).sum().backward();
        g = xi
            .grad(&grads)
            .map(host)
            .unwrap_or_else(|| vec![0.0; dims.iter().product()]);
    }
    g
}

/// A copy of the denoiser on `autodiff` whose parameters take no gradient and whose
/// dropout is off: gradients flow through it to its inputs only.
pub fn frozen(model: &Mdm, autodiff: &Device) -> Mdm {
    model.clone().fork(autodiff).freeze()
}

/// Runs the optimisation.
fn run(
    ctx: &Ctx,
    cfg: &LatentConfig,
    progress: &mut dyn FnMut(Progress),
) -> Result<Outcome, SolveError> {
    let mut chain = Chain::new(ctx, cfg);
    let m = ctx.motions();
    let mut z = chain.start();
    // Strength 0 (no steps) has nothing to optimise: one pass returns the take.
    let iterations = if chain.first == 0 { 1 } else { cfg.iterations };
    let mut adam = Adam::new(z.len(), cfg.lr);
    let relax = cfg.relax == Relax::RigidXz;
    // [yaw; x; z] × motions.
    let mut rigid = vec![0.0f32; 3 * m];
    let mut adam_rigid = Adam::new(rigid.len(), cfg.relax_lr);
    let mut trace = Vec::with_capacity(iterations);
    let mut last = Vec::new();
    let mut objective = ctx.host_objective();
    let pull = ReferencePull::new(cfg.ref_root, cfg.ref_legs);
    // The chain's raw output at iteration 0, which the pull holds the later ones to.
    let mut reference: Option<Vec<f32>> = None;
    for it in 0..iterations {
        let at = || format!("iteration {}/{}", it + 1, iterations);
        let forward = chain.forward(&z);
        // With the skeleton the rigid move is differentiated on the host, else in burn.
        let rt = (relax && !cfg.keep_skeleton).then(|| chain.rigid_tensors(&rigid));
        let scored = if cfg.keep_skeleton {
            let placed = relax.then(|| placements(&rigid));
            chain.score_on_host(&mut objective, &forward.x, placed, at)?
        } else {
            chain.score_in_graph(&forward.x, rt.as_ref(), at)?
        };
        last = scored.sample;
        progress(Progress {
            phase: Phase::Optimising,
            done: it + 1,
            total: iterations,
            error: Some(mean(&scored.values)),
        });
        trace.push(scored.values);
        if it + 1 == iterations || !scored.error.is_tracked() {
            break;
        }
        let loss = chain.loss_with_pull(scored.error, &forward.x, pull.as_ref(), &mut reference);
        let grads = loss.backward();
        let gz = chain.noise_gradient(forward, &grads, z.len());
        ensure_finite(&gz, "latent", "gradient", at)?;
        adam.step(&mut z, &gz);
        if cfg.sphere {
            onto_sphere(&mut z, m);
        }
        if relax {
            let g = match &rt {
                Some(r) => rigid_gradient(r, &grads, m),
                None => scored.rigid_gradient,
            };
            ensure_finite(&g, "latent", "gradient", at)?;
            adam_rigid.step(&mut rigid, &g);
        }
    }
    let relax = relax.then(|| placements(&rigid));
    if ctx.edit.is_some() {
        let x = Tensor::<3>::from_data(TensorData::new(last, ctx.dims()), &ctx.device);
        last = host(ctx.hold_final(x));
    }
    Ok(Outcome {
        x: last,
        relax,
        cleaned: false,
        trace,
    })
}

/// Scales each of the `motions` equal parts of `z` to norm √(its length).
fn onto_sphere(z: &mut [f32], motions: usize) {
    let len = z.len() / motions.max(1);
    for part in z.chunks_exact_mut(len) {
        let norm = part.iter().map(|v| (*v as f64).powi(2)).sum::<f64>().sqrt();
        if norm > 0.0 {
            let k = ((len as f64).sqrt() / norm) as f32;
            part.iter_mut().for_each(|v| *v *= k);
        }
    }
}

/// The rigid moves `[yaw; x; z] × motions` as placements, one per motion.
fn placements(rigid: &[f32]) -> Vec<Placement> {
    let m = rigid.len() / 3;
    (0..m)
        .map(|i| Placement {
            yaw: rigid[i],
            x: rigid[m + i],
            z: rigid[2 * m + i],
        })
        .collect()
}

/// ∂E/∂(yaw, x, z) of the rigid moves differentiated in burn, `[yaw; x; z] × m`.
fn rigid_gradient(r: &RigidTensors, grads: &Gradients, m: usize) -> Vec<f32> {
    let mut g = Vec::with_capacity(3 * m);
    for t in [&r.yaw, &r.x, &r.z] {
        match t.grad(grads) {
            Some(v) => g.extend(v.into_data().try_to_vec::<f32>().expect("f32")),
            None => g.extend(std::iter::repeat_n(0.0, m)),
        }
    }
    g
}

/// The DDIM chain as `latent` runs it: on a frozen autodiff copy of the model, or (with
/// `checkpoint`) forward on the plain model and backward one step at a time.
struct Chain<'a, 'c> {
    ctx: &'a Ctx<'c>,
    checkpoint: bool,
    ad: Device,
    model: Mdm,
    cond: Condition,
    schedule: NoiseSchedule,
    plain_model: Mdm,
    plain_cond: Condition,
    /// Steps the chain runs (`first − 1` down to 0): all of them, or an edit's part.
    first: usize,
    /// An edit's held x̂0, on the autodiff device and on the plain one.
    hold_ad: Option<X0Hold>,
    hold_plain: Option<X0Hold>,
}

/// One forward pass from z.
struct Forward {
    /// z as an autodiff leaf (the whole graph hangs from it without checkpointing).
    zt: Tensor<3>,
    /// The chain's output x̂ (with checkpointing an autodiff leaf of its own).
    x: Tensor<3>,
    /// With checkpointing, each step's input, first step first.
    inputs: Vec<Tensor<3>>,
}

/// The error of one forward pass.
struct Scored {
    /// Per sample `[B]`, to differentiate (with the skeleton, `⟨x̂, ∂E/∂x̂⟩` summed).
    error: Tensor<1>,
    /// Per sample, on the host.
    values: Vec<f32>,
    /// What the iteration returns: x̂, or `P(x̂)` with the skeleton.
    sample: Vec<f32>,
    /// With the skeleton, ∂E/∂(yaw, x, z) of the rigid moves, from the host.
    rigid_gradient: Vec<f32>,
}

impl<'a, 'c> Chain<'a, 'c> {
    fn new(ctx: &'a Ctx<'c>, cfg: &LatentConfig) -> Self {
        let ad = ctx.device.clone().autodiff();
        let model = frozen(ctx.prior.model, &ad);
        let cond = ctx.condition(&ad);
        let base = NoiseSchedule::cosine(DIFFUSION_STEPS);
        let schedule = match ctx.prior.consistency {
            Some(c) => base.at(&consistency_timesteps(c.grid, cfg.fast_steps)),
            None => base.respaced(cfg.ddim_steps),
        };
        Chain {
            ctx,
            checkpoint: cfg.checkpoint,
            model,
            cond,
            first: schedule.len(),
            schedule,
            plain_model: ctx.denoiser(),
            plain_cond: ctx.condition(&ctx.device),
            hold_ad: ctx.x0_hold_on(&ad),
            hold_plain: ctx.x0_hold_on(&ctx.device),
            ad,
        }
    }

    /// Where the optimisation starts: z, and the chain set to run from it. An edit starts
    /// from its take inverted to the strength's level ([`Ctx::latent_start`]).
    fn start(&mut self) -> Vec<f32> {
        let (first, z) = self.ctx.latent_start(&self.schedule);
        self.first = first;
        host(z)
    }

    /// Forward: the whole graph, or a plain chain keeping each step's input.
    fn forward(&self, z: &[f32]) -> Forward {
        let (dims, ad) = (self.ctx.dims(), &self.ad);
        let zt = Tensor::<3>::from_data(TensorData::new(z.to_vec(), dims), ad).require_grad();
        if !self.checkpoint {
            let x = ddim_chain(
                &self.model,
                &self.schedule,
                self.first,
                zt.clone(),
                &self.cond,
                self.hold_ad.as_ref(),
            );
            return Forward {
                zt,
                x,
                inputs: Vec::new(),
            };
        }
        let schedule = &self.schedule;
        let mut inputs = Vec::with_capacity(self.first);
        let mut xi = Tensor::<3>::from_data(TensorData::new(z.to_vec(), dims), &self.ctx.device);
        for i in (0..self.first).rev() {
            inputs.push(xi.clone());
            xi = ddim_step_held(
                &self.plain_model,
                schedule,
                i,
                xi,
                &self.plain_cond,
                self.hold_plain.as_ref(),
            );
        }
        let x = Tensor::<3>::from_data(xi.into_data(), ad).require_grad();
        Forward { zt, x, inputs }
    }

    /// The rigid moves as autodiff leaves `[samples, people]` each.
    fn rigid_tensors(&self, rigid: &[f32]) -> RigidTensors {
        let (ctx, m) = (self.ctx, self.ctx.motions());
        let part = |k: usize| {
            Tensor::<2>::from_data(
                TensorData::new(rigid[k * m..(k + 1) * m].to_vec(), [ctx.samples, ctx.people]),
                &self.ad,
            )
            .require_grad()
        };
        RigidTensors {
            yaw: part(0),
            x: part(1),
            z: part(2),
        }
    }

    /// E(P(x̂)) on the host; the chain sees it as ⟨x̂, ∂E/∂x̂⟩.
    fn score_on_host(
        &self,
        objective: &mut HostObjective,
        x: &Tensor<3>,
        placed: Option<Vec<Placement>>,
        at: impl FnOnce() -> String,
    ) -> Result<Scored, SolveError> {
        let mut full = host(x.clone().detach());
        let mut head = extract_head(&full, FEATURE_DIM);
        objective.project_skeleton(&head);
        objective.set_rigid(placed);
        let mut g_head = vec![0.0; head.len()];
        let values = objective.eval(&head, &mut g_head)?;
        let rigid_gradient = objective.rigid_gradient().to_vec();
        ensure_finite(&values, "latent", "error", at)?;
        objective.apply_projection(&mut head);
        objective.stop_projecting();
        insert_head(&mut full, FEATURE_DIM, &head);
        let mut g_full = vec![0.0; full.len()];
        insert_head(&mut g_full, FEATURE_DIM, &g_head);
        let g = Tensor::<3>::from_data(TensorData::new(g_full, self.ctx.dims()), &self.ad);
        Ok(Scored {
            error: (x.clone() * g).sum().reshape([1]),
            values,
            sample: full,
            rigid_gradient,
        })
    }

    /// E(x̂) through the burn decoder (and the rigid moves, when relaxed).
    fn score_in_graph(
        &self,
        x: &Tensor<3>,
        rt: Option<&RigidTensors>,
        at: impl FnOnce() -> String,
    ) -> Result<Scored, SolveError> {
        let ctx = self.ctx;
        let e = ctx.error.error(ctx.decoder.joints(x.clone(), rt));
        check_shape(&e, ctx.samples)?;
        let values = host(e.clone());
        ensure_finite(&values, "latent", "error", at)?;
        Ok(Scored {
            error: e,
            values,
            sample: host(x.clone().detach()),
            rigid_gradient: Vec::new(),
        })
    }

    /// The summed error plus, with a reference pull, ⟨x̂, g⟩ with g the pull's gradient
    /// at this x̂ (the first iteration's x̂ becomes the reference).
    fn loss_with_pull(
        &self,
        error: Tensor<1>,
        x: &Tensor<3>,
        pull: Option<&ReferencePull>,
        reference: &mut Option<Vec<f32>>,
    ) -> Tensor<1> {
        let loss = error.sum();
        let Some(pull) = pull else {
            return loss;
        };
        let raw = host(x.clone().detach());
        let reference = reference.get_or_insert_with(|| raw.clone());
        let mut g = vec![0.0; raw.len()];
        pull.add(&raw, reference, self.ctx.frames, &mut g);
        let g = Tensor::<3>::from_data(TensorData::new(g, self.ctx.dims()), &self.ad);
        loss + (x.clone() * g).sum()
    }

    /// ∂loss/∂z (`len` values): read off z, or back-propagated step by step from x̂.
    fn noise_gradient(
        &self,
        forward: Forward,
        grads: &Gradients,
        len: usize,
    ) -> Vec<f32> {
        if self.checkpoint {
            let g = forward
                .x
                .grad(grads)
                .map(host)
                .unwrap_or_else(|| vec![0.0; len]);
            backprop_steps(
                &self.model,
                &self.schedule,
                &self.cond,
                self.hold_ad.as_ref(),
                forward.inputs,
                g,
                &self.ad,
            )
        } else {
            forward
                .zt
                .grad(grads)
                .map(host)
                .unwrap_or_else(|| vec![0.0; len])
        }
    }
}

/// `latent`, for [`super::registry`].
pub const SPECS: &[SolverSpec] = &[
    SolverSpec {
        name: "latent",
        summary: "the initial noise z of a DDIM chain, Adam through the whole chain (PMG)",
        make: || Solver::new(LatentConfig::default()),
    },
    SolverSpec {
        name: "latent-fast",
        summary: "latent through a few-step model's 4-step chain (DNO, MotionLCM; models/fast)",
        make: || Solver::new(LatentConfig::fast()),
    },
];

impl SolverConfig for LatentConfig {
    const KNOBS: &'static [Knob<Self>] = &[
        knob!(Count, "ddim_steps", "length of the DDIM chain the gradient goes through", ddim_steps),
        knob!(Count, "fast_steps", "length of the chain on a few-step (consistency-distilled) model", fast_steps),
        knob!(Count, "iterations", "Adam iterations on z (the last forward pass is returned)", iterations),
        knob!(Real, "lr", "Adam's learning rate on z", lr),
        Knob {
            name: "relax",
            doc: "1: also optimise a rigid horizontal move of each person (PMG §3.4)",
            kind: KnobKind::Flag {
                off: "off",
                on: "rigid XZ",
            },
            get: |c| if c.relax == Relax::RigidXz { 1.0 } else { 0.0 },
            set: |c, v| {
                c.relax = if v != 0.0 {
                    Relax::RigidXz
                } else {
                    Relax::None
                }
            },
        },
        knob!(
            Flag("off", "keep bone lengths"),
            "skeleton",
            "1: measure and return the chain's output with the skeleton restored, also with `relax=1`; 0: PMG's raw output",
            keep_skeleton
        ),
        knob!(Real, "ref_root", "weight of PMG's pull of the root columns (yaw and XZ velocity, height) towards the iteration-0 sample; 0: off", ref_root),
        knob!(Real, "ref_legs", "weight of the same pull on the legs' columns (hips, knees, ankles, toes; foot contacts); 0: off", ref_legs),
        knob!(
            Flag("off", "on the sphere"),
            "sphere",
            "1: keep each motion's z on the Gaussian shell (norm √(frames·263)) after every step",
            sphere
        ),
    ];

    fn name(&self) -> &'static str {
        if self.few_step { "latent-fast" } else { "latent" }
    }

    fn unguided(&self) -> SamplerKind {
        SamplerKind::Ddim(self.ddim_steps)
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

    fn few_step_refusal(&self) -> Option<&'static str> {
        None
    }

    fn needs_few_step(&self) -> bool {
        self.few_step
    }
}
