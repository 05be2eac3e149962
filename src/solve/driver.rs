//! [`solve`]: validates a request, builds what every solver shares ([`Ctx`]: condition,
//! noise, decoder), runs the chosen solver and turns its normalised samples into world
//! motions, features and final errors.

use super::cleanup::{FootCleanup, clean_feet};
use super::decode::Decoder;
use super::edit::EditState;
use super::host::{HostObjective, check_shape};
use super::request::{Phase, Prior, Progress, SolveRequest, SolveResult};
use super::{MotionError, SolveError};
use crate::features::{FEATURE_DIM, recover_from_ric};
use crate::model::Mdm;
use crate::model::noise::NoiseSource;
use crate::model::sampler::{Condition, FEW_STEPS, SamplerKind, sample_chain, schedule_for};
use crate::model::schedule::{DIFFUSION_STEPS, NoiseSchedule};
use crate::motion::Motion;
use crate::scene::{DEFAULT_SPACING, Placement};
use crate::skeleton::NUM_JOINTS;
use burn::prelude::*;
use std::time::Instant;

/// Seed offset of DDPM's per-step noise (the same as `model::generate`, so an unguided
/// `plain` solve reproduces `generate`).
const STEP_NOISE: u64 = 0x5DEE_CE66;

/// Everything a solver needs besides its own settings (see [`super::SolverConfig::run`]).
pub struct Ctx<'a> {
    pub prior: Prior<'a>,
    pub error: &'a dyn MotionError,
    /// Plain (non-autodiff) device.
    pub device: Device,
    /// Samples B.
    pub samples: usize,
    /// People P.
    pub people: usize,
    /// Frames N.
    pub frames: usize,
    pub seed: u64,
    pub guidance_scale: f32,
    /// One prompt per motion, sample-major (`b·P + p`).
    pub prompts: Vec<String>,
    pub decoder: Decoder,
    /// The take being edited, if any ([`super::edit`]).
    pub edit: Option<EditState>,
    /// Clean the result's feet ([`super::cleanup`]): asked for and not an edit (an edit
    /// cleans by its own settings).
    pub clean_feet: bool,
    /// An edit's cleanup is the solver's, with its polish ([`SolveRequest::polish_edit`]).
    pub polish_edit: bool,
}

/// What a solver hands back: normalised samples and, when it relaxes, a transform per motion.
pub struct Outcome {
    /// `[B·P, N, 263]` normalised.
    pub x: Vec<f32>,
    /// Per motion, applied before the placement.
    pub relax: Option<Vec<Placement>>,
    pub trace: Vec<Vec<f32>>,
    /// The solver cleaned the feet itself ([`Ctx::clean_feet`]); the driver does not again.
    pub cleaned: bool,
}

impl Ctx<'_> {
    /// The fused host evaluation of this request's error (the inner loops of guide, IK
    /// and lbfgs's late steps).
    pub fn host_objective(&self) -> HostObjective<'_> {
        HostObjective::new(
            self.error,
            &self.decoder,
            self.samples,
            self.frames,
            &self.device,
        )
    }

    /// Motions in the batch (B·P).
    pub fn motions(&self) -> usize {
        self.samples * self.people
    }

    /// `[B·P, N, 263]`.
    pub fn dims(&self) -> [usize; 3] {
        [self.motions(), self.frames, FEATURE_DIM]
    }

    /// The chain `kind` runs as on this prior: a few-step model's own chain (its
    /// [`FEW_STEPS`] passes, unless `kind` is already one) in place of a diffusion chain.
    pub fn chain_kind(&self, kind: SamplerKind) -> SamplerKind {
        match (self.prior.consistency, kind) {
            (Some(_), SamplerKind::Consistency { .. }) | (None, _) => kind,
            (Some(c), _) => SamplerKind::Consistency {
                steps: FEW_STEPS.min(c.grid),
                grid: c.grid,
            },
        }
    }

    /// The encoded prompts (CFG-doubled) on `device`.
    pub fn condition(&self, device: &Device) -> Condition {
        let p: Vec<&str> = self.prompts.iter().map(String::as_str).collect();
        Condition::new(self.prior.text, &p, self.guidance_scale, device)
    }

    /// Host values of the initial noise x_T.
    pub fn initial_noise(&self) -> Vec<f32> {
        NoiseSource::new(self.seed).values(self.dims().iter().product())
    }

    /// Initial noise as a tensor on `device`.
    pub fn initial_tensor(&self, device: &Device) -> Tensor<3> {
        Tensor::from_data(TensorData::new(self.initial_noise(), self.dims()), device)
    }

    /// DDPM's per-step noise stream.
    pub fn step_noise(&self) -> NoiseSource {
        NoiseSource::new(self.seed ^ STEP_NOISE)
    }

    /// Inference copy of the denoiser (no autodiff, dropout off).
    pub fn denoiser(&self) -> Mdm {
        self.prior.model.valid()
    }

    /// The unguided chain of `kind` from the initial noise.
    pub fn sample_plain(&self, kind: SamplerKind, progress: &mut dyn FnMut(Progress)) -> Tensor<3> {
        let den = self.denoiser();
        let schedule = schedule_for(&NoiseSchedule::cosine(DIFFUSION_STEPS), kind);
        let cond = self.condition(&self.device);
        let mut noise = self.step_noise();
        sample_chain(
            &den,
            &schedule,
            kind,
            self.initial_tensor(&self.device),
            &cond,
            &mut noise,
            |done, total| {
                progress(Progress {
                    phase: Phase::Sampling,
                    done,
                    total,
                    error: None,
                })
            },
        )
    }
}

/// Host copy of a tensor.
pub(crate) fn host<const D: usize>(t: Tensor<D>) -> Vec<f32> {
    t.into_data().try_to_vec::<f32>().expect("f32 tensor")
}

/// Mean of per-sample errors (for progress reports).
pub(crate) fn mean(v: &[f32]) -> f32 {
    v.iter().sum::<f32>() / v.len().max(1) as f32
}

/// Fails with [`SolveError::NonFinite`] when any value is NaN/Inf.
pub(crate) fn ensure_finite(
    values: &[f32],
    solver: &'static str,
    what: &'static str,
    at: impl FnOnce() -> String,
) -> Result<(), SolveError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(SolveError::NonFinite {
            solver,
            what,
            at: at(),
        })
    }
}

/// The registered solvers that `accepts`, as "a or b" for a refusal's hint.
fn takers(accepts: impl Fn(&super::Solver) -> bool) -> String {
    super::registry()
        .iter()
        .filter(|s| accepts(&(s.make)()))
        .map(|s| s.name)
        .collect::<Vec<_>>()
        .join(" or ")
}

fn validate(prior: &Prior, req: &SolveRequest) -> Result<Vec<Placement>, SolveError> {
    let bad = |m: String| Err(SolveError::Invalid(m));
    if req.prompts.is_empty() {
        return bad("no prompt: give one prompt per person".into());
    }
    if req.samples == 0 {
        return bad("0 samples asked; ask for at least 1".into());
    }
    if req.frames < 2 || req.frames > prior.max_frames {
        return bad(format!(
            "{} frames asked; this model generates 2..={} frames ({:.1} s at 20 fps)",
            req.frames,
            prior.max_frames,
            prior.max_frames as f32 / 20.0
        ));
    }
    if !(req.guidance_scale.is_finite()) {
        return bad("the classifier-free guidance scale must be a finite number".into());
    }
    if prior.consistency.is_some()
        && let Some(why) = req.solver.few_step_refusal()
    {
        return bad(format!(
            "solver `{}` cannot run on a few-step (consistency-distilled) model: {why}; use {}, or a diffusion model",
            req.solver.name(),
            takers(|s| s.few_step_refusal().is_none())
        ));
    }
    if prior.consistency.is_none() && req.solver.needs_few_step() {
        return bad(format!(
            "solver `{}` runs on a few-step (consistency-distilled) model such as models/fast; pass --model models/fast, or use latent",
            req.solver.name()
        ));
    }
    if let Some(edit) = &req.edit {
        if let Some(why) = req.solver.edit_refusal() {
            return bad(format!(
                "solver `{}` cannot edit a take: {why}; use {}",
                req.solver.name(),
                takers(|s| s.edit_refusal().is_none())
            ));
        }
        edit.check(req.prompts.len(), req.frames)?;
    }
    let placements = match &req.placements {
        _ if req.edit.is_some() => req.edit.as_ref().expect("edit").take.placements.clone(),
        Some(p) if p.len() != req.prompts.len() => {
            return bad(format!(
                "{} placements for {} people; give one per person",
                p.len(),
                req.prompts.len()
            ));
        }
        Some(p) => p.clone(),
        None => Placement::defaults(req.prompts.len(), DEFAULT_SPACING),
    };
    if placements
        .iter()
        .any(|q| !(q.yaw.is_finite() && q.x.is_finite() && q.z.is_finite()))
    {
        return bad("a placement is not finite".into());
    }
    req.solver.validate()?;
    Ok(placements)
}

/// Sampler kinds need at least one step and at most the base schedule's 1000.
pub(crate) fn check_kind(kind: SamplerKind) -> Result<(), SolveError> {
    match kind {
        SamplerKind::Ddim(k) | SamplerKind::Ddpm(k) if (1..=DIFFUSION_STEPS).contains(&k) => Ok(()),
        SamplerKind::Consistency { steps, grid } if (1..=grid).contains(&steps) => Ok(()),
        _ => Err(SolveError::Invalid(format!(
            "{kind:?}: a chain needs 1..={DIFFUSION_STEPS} steps"
        ))),
    }
}

/// Solves `req` with the prior, minimising `error`. `device` is a plain (non-autodiff)
/// device; autodiff copies are made where a solver needs gradients. `on_progress` is called
/// after every denoising step or iteration.
pub fn solve(
    prior: &Prior,
    req: &SolveRequest,
    error: &dyn MotionError,
    device: &Device,
    mut on_progress: impl FnMut(Progress),
) -> Result<SolveResult, SolveError> {
    let start = Instant::now();
    let placements = validate(prior, req)?;
    let people = req.prompts.len();
    let ctx = Ctx {
        prior: *prior,
        error,
        device: device.clone(),
        samples: req.samples,
        people,
        frames: req.frames,
        seed: req.seed,
        // A few-step model's teacher guidance is in its weights.
        guidance_scale: if prior.consistency.is_some() {
            1.0
        } else {
            req.guidance_scale
        },
        prompts: (0..req.samples)
            .flat_map(|_| req.prompts.iter().cloned())
            .collect(),
        decoder: Decoder::new(prior.mean, prior.std, &placements),
        edit: req
            .edit
            .as_ref()
            .map(|e| EditState::new(e, req.samples, prior.mean, prior.std, device)),
        clean_feet: req.clean_feet && req.edit.is_none(),
        polish_edit: req.polish_edit,
    };
    let progress: &mut dyn FnMut(Progress) = &mut on_progress;
    let out = req.solver.run(&ctx, progress)?;
    ensure_finite(&out.x, req.solver.name(), "sample", || {
        "the end of the solve".into()
    })?;
    finish(&ctx, out, &placements, start, req)
}

/// Features, world motions and errors of a solver's outcome.
fn finish(
    ctx: &Ctx,
    out: Outcome,
    placements: &[Placement],
    start: Instant,
    req: &SolveRequest,
) -> Result<SolveResult, SolveError> {
    let mut features = out.x;
    for row in features.chunks_exact_mut(FEATURE_DIM) {
        for ((v, s), m) in row.iter_mut().zip(ctx.prior.std).zip(ctx.prior.mean) {
            *v = *v * s + m;
        }
    }
    match &ctx.edit {
        Some(edit) => {
            if !out.cleaned {
                edit.clean_free_feet(&mut features, ctx.frames);
            }
            edit.rebuild_seams(&mut features, ctx.frames);
        }
        None if ctx.clean_feet && !out.cleaned => {
            clean_feet(
                &mut features,
                ctx.frames,
                FEATURE_DIM,
                &FootCleanup::default(),
            );
        }
        None => {}
    }
    let per = ctx.frames * FEATURE_DIM;
    let mut motions = Vec::with_capacity(ctx.samples);
    let mut world = Vec::with_capacity(ctx.samples);
    let mut flat = Vec::with_capacity(ctx.motions() * ctx.frames * NUM_JOINTS * 3);
    for b in 0..ctx.samples {
        let mut people = Vec::with_capacity(ctx.people);
        let mut places = Vec::with_capacity(ctx.people);
        for (p, outer) in placements.iter().enumerate() {
            let m = b * ctx.people + p;
            let place = match &out.relax {
                Some(r) => outer.compose(&r[m]),
                None => *outer,
            };
            let mut motion: Motion = recover_from_ric(&features[m * per..(m + 1) * per])?;
            for pose in &mut motion.frames {
                for j in pose.iter_mut() {
                    *j = place.apply(*j);
                }
            }
            flat.extend(motion.to_flat());
            people.push(motion);
            places.push(place);
        }
        motions.push(people);
        world.push(places);
    }
    let joints = Tensor::<5>::from_data(
        TensorData::new(flat, [ctx.samples, ctx.people, ctx.frames, NUM_JOINTS, 3]),
        &ctx.device,
    );
    let e = ctx.error.error(joints);
    check_shape(&e, ctx.samples)?;
    let error = host(e);
    ensure_finite(&error, req.solver.name(), "error", || {
        "the returned motions".into()
    })?;
    let p: Vec<&str> = req.prompts.iter().map(String::as_str).collect();
    let unknown_words = p
        .iter()
        .map(|text| ctx.prior.text.unknown_words(text))
        .collect();
    Ok(SolveResult {
        motions,
        features,
        placements: world,
        error,
        trace: out.trace,
        seconds: start.elapsed().as_secs_f64(),
        unknown_words,
    })
}
