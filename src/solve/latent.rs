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
use super::host::{extract_head, insert_head};
use crate::scene::Placement;
use super::reference::ReferencePull;
use super::request::{Phase, Progress};
use super::driver::{Ctx, Outcome, ensure_finite, host, mean};
use super::{SolveError, host::check_shape};
use crate::features::FEATURE_DIM;
use crate::model::sampler::{Condition, ddim_step, guided_x0};
use crate::model::schedule::{DIFFUSION_STEPS, NoiseSchedule};
use crate::model::{Denoiser, Mdm};
use burn::prelude::*;

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
}

impl Default for LatentConfig {
    fn default() -> Self {
        LatentConfig {
            ddim_steps: 100,
            iterations: 100,
            lr: 0.005,
            relax: Relax::None,
            relax_lr: 0.02,
            checkpoint: false,
            keep_skeleton: true,
            ref_root: 0.0,
            ref_legs: 0.0,
        }
    }
}

impl LatentConfig {
    fn check_settings(&self) -> Result<(), SolveError> {
        if !(1..=DIFFUSION_STEPS).contains(&self.ddim_steps) || self.iterations == 0 {
            return Err(SolveError::Invalid(format!(
                "latent: {} DDIM steps and {} iterations; use 1..={DIFFUSION_STEPS} steps and ≥ 1 iteration",
                self.ddim_steps, self.iterations
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

/// The DDIM (η = 0) chain from `z`: on an autodiff device with a frozen model it is
/// differentiable with respect to `z`.
pub fn ddim_chain(
    den: &impl Denoiser,
    schedule: &NoiseSchedule,
    z: Tensor<3>,
    cond: &Condition,
) -> Tensor<3> {
    let mut x = z;
    for i in (0..schedule.len()).rev() {
        let x0 = guided_x0(den, x.clone(), schedule.timesteps[i], cond);
        x = ddim_step(schedule, i, x, x0);
    }
    x
}

/// Back-propagates `g = ∂E/∂x̂` through the DDIM steps one at a time: `inputs[k]` is the
/// input of the k-th step run (the chain's first step first); each step is re-run with
/// autodiff and `⟨step(x), g⟩` differentiated. Returns ∂E/∂z.
fn backprop_steps(
    model: &Mdm,
    schedule: &NoiseSchedule,
    cond: &Condition,
    inputs: Vec<Tensor<3>>,
    mut g: Vec<f32>,
    ad: &Device,
) -> Vec<f32> {
    let n = schedule.len();
    for (k, input) in inputs.into_iter().enumerate().rev() {
        let i = n - 1 - k;
        let dims = input.dims();
        let xi = Tensor::<3>::from_data(input.into_data(), ad).require_grad();
        let x0 = guided_x0(model, xi.clone(), schedule.timesteps[i], cond);
        let out = ddim_step(schedule, i, xi.clone(), x0);
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
    let ad = ctx.device.clone().autodiff();
    let model = frozen(ctx.prior.model, &ad);
    let cond = ctx.condition(&ad);
    let schedule = NoiseSchedule::cosine(DIFFUSION_STEPS).respaced(cfg.ddim_steps);
    let dims = ctx.dims();
    let m = ctx.motions();
    let mut z = ctx.initial_noise();
    let mut adam = Adam::new(z.len(), cfg.lr);
    let relax = cfg.relax == Relax::RigidXz;
    // [yaw; x; z] × motions.
    let mut rigid = vec![0.0f32; 3 * m];
    let mut adam_rigid = Adam::new(rigid.len(), cfg.relax_lr);
    let mut trace = Vec::with_capacity(cfg.iterations);
    let mut last = Vec::new();
    let plain_model = ctx.denoiser();
    let plain_cond = ctx.condition(&ctx.device);
    let skeleton = cfg.keep_skeleton;
    let placements = |rigid: &[f32]| -> Vec<Placement> {
        (0..m)
            .map(|i| Placement {
                yaw: rigid[i],
                x: rigid[m + i],
                z: rigid[2 * m + i],
            })
            .collect()
    };
    let mut g_rigid = Vec::new();
    let mut objective = ctx.host_objective();
    let pull = ReferencePull::new(cfg.ref_root, cfg.ref_legs);
    // The chain's raw output at iteration 0, which the pull holds the later ones to.
    let mut reference: Option<Vec<f32>> = None;
    for it in 0..cfg.iterations {
        let at = || format!("iteration {}/{}", it + 1, cfg.iterations);
        let zt = Tensor::<3>::from_data(TensorData::new(z.clone(), dims), &ad).require_grad();
        // Forward: the whole graph, or a plain chain keeping each step's input.
        let (x, inputs) = if cfg.checkpoint {
            let mut xs = Vec::with_capacity(schedule.len());
            let mut xi = Tensor::<3>::from_data(TensorData::new(z.clone(), dims), &ctx.device);
            for i in (0..schedule.len()).rev() {
                xs.push(xi.clone());
                let x0 = guided_x0(&plain_model, xi.clone(), schedule.timesteps[i], &plain_cond);
                xi = ddim_step(&schedule, i, xi, x0);
            }
            let leaf = Tensor::<3>::from_data(xi.into_data(), &ad).require_grad();
            (leaf, xs)
        } else {
            (ddim_chain(&model, &schedule, zt.clone(), &cond), Vec::new())
        };
        // With the skeleton the rigid move is differentiated on the host, else in burn.
        let rt = (relax && !skeleton).then(|| {
            let part = |k: usize| {
                Tensor::<2>::from_data(
                    TensorData::new(
                        rigid[k * m..(k + 1) * m].to_vec(),
                        [ctx.samples, ctx.people],
                    ),
                    &ad,
                )
                .require_grad()
            };
            RigidTensors {
                yaw: part(0),
                x: part(1),
                z: part(2),
            }
        });
        let (e, values) = if skeleton {
            // E(P(x̂)) on the host; the chain sees it as ⟨x̂, ∂E/∂x̂⟩.
            let mut full = host(x.clone().detach());
            let mut head = extract_head(&full, FEATURE_DIM);
            objective.project_skeleton(&head);
            objective.set_rigid(relax.then(|| placements(&rigid)));
            let mut g_head = vec![0.0; head.len()];
            let values = objective.eval(&head, &mut g_head)?;
            g_rigid = objective.rigid_gradient().to_vec();
            ensure_finite(&values, "latent", "error", at)?;
            objective.apply_projection(&mut head);
            objective.stop_projecting();
            insert_head(&mut full, FEATURE_DIM, &head);
            last = full;
            let mut g_full = vec![0.0; last.len()];
            insert_head(&mut g_full, FEATURE_DIM, &g_head);
            let g = Tensor::<3>::from_data(TensorData::new(g_full, dims), &ad);
            ((x.clone() * g).sum().reshape([1]), values)
        } else {
            let e = ctx.error.error(ctx.decoder.joints(x.clone(), rt.as_ref()));
            check_shape(&e, ctx.samples)?;
            let values = host(e.clone());
            ensure_finite(&values, "latent", "error", at)?;
            last = host(x.clone().detach());
            (e, values)
        };
        progress(Progress {
            phase: Phase::Optimising,
            done: it + 1,
            total: cfg.iterations,
            error: Some(mean(&values)),
        });
        trace.push(values);
        if it + 1 == cfg.iterations || !e.is_tracked() {
            break;
        }
        let mut loss = e.sum();
        if let Some(pull) = &pull {
            let raw = host(x.clone().detach());
            let reference = reference.get_or_insert_with(|| raw.clone());
            let mut g = vec![0.0; raw.len()];
            pull.add(&raw, reference, ctx.frames, &mut g);
            // ⟨x̂, g⟩ has the pull's gradient at this x̂.
            let g = Tensor::<3>::from_data(TensorData::new(g, dims), &ad);
            loss = loss + (x.clone() * g).sum();
        }
        let grads = loss.backward();
        let gz = if cfg.checkpoint {
            let g = x
                .grad(&grads)
                .map(host)
                .unwrap_or_else(|| vec![0.0; z.len()]);
            backprop_steps(&model, &schedule, &cond, inputs, g, &ad)
        } else {
            zt.grad(&grads)
                .map(host)
                .unwrap_or_else(|| vec![0.0; z.len()])
        };
        ensure_finite(&gz, "latent", "gradient", at)?;
        adam.step(&mut z, &gz);
        if relax {
            let g = match &rt {
                Some(r) => {
                    let mut g = Vec::with_capacity(3 * m);
                    for t in [&r.yaw, &r.x, &r.z] {
                        match t.grad(&grads) {
                            Some(v) => g.extend(v.into_data().try_to_vec::<f32>().expect("f32")),
                            None => g.extend(std::iter::repeat_n(0.0, m)),
                        }
                    }
                    g
                }
                None => std::mem::take(&mut g_rigid),
            };
            ensure_finite(&g, "latent", "gradient", at)?;
            adam_rigid.step(&mut rigid, &g);
        }
    }
    let relax = relax.then(|| placements(&rigid));
    Ok(Outcome {
        x: last,
        relax,
        trace,
    })
}

/// `latent`, for [`super::registry`].
pub const SPECS: &[SolverSpec] = &[SolverSpec {
    name: "latent",
    summary: "the initial noise z of a DDIM chain, Adam through the whole chain (PMG)",
    make: || Solver::new(LatentConfig::default()),
}];

impl SolverConfig for LatentConfig {
    const KNOBS: &'static [Knob<Self>] = &[
        knob!(Count, "ddim_steps", "length of the DDIM chain the gradient goes through", ddim_steps),
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
    ];

    fn name(&self) -> &'static str {
        "latent"
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
        Some("it optimises the noise of a DDIM chain, and inverting a take to its noise (DDIM inversion) is not implemented")
    }
}
