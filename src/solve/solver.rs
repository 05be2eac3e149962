//! What a solver is to the rest of mprog: a [`SolverConfig`] (its settings, knobs and run
//! function) registered by name with a [`SolverSpec`], and held as a [`Solver`]. The CLI,
//! the REPL, the benchmarks and the book find solvers and their knobs only through
//! [`super::registry`].

use super::SolveError;
use super::driver::{Ctx, Outcome};
use super::knobs::{Knob, KnobValue, check};
use super::request::Progress;
use crate::model::sampler::SamplerKind;
use std::any::Any;
use std::fmt;

/// The settings of one solver and what it does with them.
pub trait SolverConfig: Any + Clone + fmt::Debug + PartialEq + Send + Sync {
    /// Its knobs, in help order.
    const KNOBS: &'static [Knob<Self>];

    /// Its registered name (a configuration may answer for two names, e.g. `ik` and
    /// `ik-reg`).
    fn name(&self) -> &'static str;

    /// The unguided chain it starts from or steers (same sampler and step count), the
    /// fair baseline to compare it with.
    fn unguided(&self) -> SamplerKind;

    /// Refuses settings it cannot run, before any work.
    fn validate(&self) -> Result<(), SolveError>;

    /// Solves the request in `ctx`; returns normalised samples.
    fn run(&self, ctx: &Ctx, progress: &mut dyn FnMut(Progress)) -> Result<Outcome, SolveError>;

    /// Why it cannot edit a take (`--from`, [`super::edit`]), or `None` when it can (its
    /// run then starts from [`Ctx::chain_start`] and holds kept frames).
    fn edit_refusal(&self) -> Option<&'static str> {
        Some("it only starts from noise")
    }

    /// Why it cannot run on a consistency-distilled few-step model, or `None` when it can
    /// (its chain then comes from [`Ctx::chain_kind`] or the prior's grid).
    fn few_step_refusal(&self) -> Option<&'static str> {
        Some("it steers a diffusion chain step by step")
    }

    /// True when it runs only on a few-step model.
    fn needs_few_step(&self) -> bool {
        false
    }
}

/// A registered solver: its name, a line on what it moves, and its default settings.
pub struct SolverSpec {
    /// `--solver` name.
    pub name: &'static str,
    /// What it optimises, and whose method it is.
    pub summary: &'static str,
    /// The solver with its default settings.
    pub make: fn() -> Solver,
}

/// One paragraph per registered solver: name, summary, and knobs with their defaults
/// (`--solver` / `:run` help).
pub fn solvers_help() -> String {
    super::registry()
        .iter()
        .map(|spec| {
            let knobs: Vec<String> = (spec.make)()
                .knobs()
                .iter()
                .map(|k| format!("{}={}", k.name, k.shown()))
                .collect();
            format!(
                "{}: {}\n  knobs: {}",
                spec.name,
                spec.summary,
                knobs.join(" ")
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// A solver with its settings.
pub struct Solver(Box<dyn DynSolver>);

impl Solver {
    /// The solver of these settings.
    pub fn new<C: SolverConfig>(config: C) -> Solver {
        Solver(Box::new(config))
    }

    /// The unguided sampler of `kind` (no optimisation), for comparisons.
    pub fn plain(kind: SamplerKind) -> Solver {
        Solver::new(super::plain::PlainConfig { sampler: kind })
    }

    /// The registered solver `name` with its default settings.
    pub fn by_name(name: &str) -> Option<Solver> {
        super::registry()
            .into_iter()
            .find(|s| s.name == name)
            .map(|s| (s.make)())
    }

    /// Every registered name, in help order.
    pub fn names() -> Vec<&'static str> {
        super::registry().iter().map(|s| s.name).collect()
    }

    /// Short name (`guide`, `latent`, …).
    pub fn name(&self) -> &'static str {
        self.0.name()
    }

    /// The unguided sampler this solver starts from or steers.
    pub fn unguided(&self) -> Solver {
        Solver::plain(self.0.unguided())
    }

    /// Its knobs with their current values.
    pub fn knobs(&self) -> Vec<KnobValue> {
        self.0.knobs()
    }

    /// The names of its knobs.
    pub fn knob_names(&self) -> Vec<&'static str> {
        self.knobs().iter().map(|k| k.name).collect()
    }

    /// Sets one knob by name (`--knob iterations=30`). Counts must be whole and ≥ 0, flags
    /// 0 or 1; the solver's own check runs when it starts, so out-of-range values are
    /// refused there with its message.
    pub fn set_knob(&mut self, name: &str, value: f64) -> Result<(), String> {
        self.0.set_knob(name, value)
    }

    /// Its settings, when they are of type `C`.
    pub fn config<C: SolverConfig>(&self) -> Option<&C> {
        self.0.as_any().downcast_ref()
    }

    pub(crate) fn validate(&self) -> Result<(), SolveError> {
        self.0.validate()
    }

    /// Why it cannot edit a take, or `None` when it can.
    pub fn edit_refusal(&self) -> Option<&'static str> {
        self.0.edit_refusal()
    }

    /// Why it cannot run on a few-step model, or `None` when it can.
    pub fn few_step_refusal(&self) -> Option<&'static str> {
        self.0.few_step_refusal()
    }

    /// True when it runs only on a few-step model.
    pub fn needs_few_step(&self) -> bool {
        self.0.needs_few_step()
    }

    /// Whether it can run on a model that is (`few_step`) or is not a few-step one.
    pub fn runs_on(&self, few_step: bool) -> bool {
        if few_step {
            self.few_step_refusal().is_none()
        } else {
            !self.needs_few_step()
        }
    }

    pub(crate) fn run(
        &self,
        ctx: &Ctx,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<Outcome, SolveError> {
        self.0.run(ctx, progress)
    }
}

impl Clone for Solver {
    fn clone(&self) -> Self {
        Solver(self.0.clone_box())
    }
}

impl PartialEq for Solver {
    fn eq(&self, other: &Self) -> bool {
        self.0.eq_dyn(other.0.as_any())
    }
}

/// The settings, as `GuideConfig { steps: 1000, … }` (saved in outputs' meta).
impl fmt::Debug for Solver {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt_dyn(f)
    }
}

/// [`SolverConfig`] with its type erased, so [`Solver`] can hold any.
trait DynSolver: Send + Sync {
    fn name(&self) -> &'static str;
    fn unguided(&self) -> SamplerKind;
    fn knobs(&self) -> Vec<KnobValue>;
    fn set_knob(&mut self, name: &str, value: f64) -> Result<(), String>;
    fn validate(&self) -> Result<(), SolveError>;
    fn edit_refusal(&self) -> Option<&'static str>;
    fn few_step_refusal(&self) -> Option<&'static str>;
    fn needs_few_step(&self) -> bool;
    fn run(&self, ctx: &Ctx, progress: &mut dyn FnMut(Progress)) -> Result<Outcome, SolveError>;
    fn clone_box(&self) -> Box<dyn DynSolver>;
    fn eq_dyn(&self, other: &dyn Any) -> bool;
    fn as_any(&self) -> &dyn Any;
    fn fmt_dyn(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result;
}

impl<C: SolverConfig> DynSolver for C {
    fn name(&self) -> &'static str {
        SolverConfig::name(self)
    }

    fn unguided(&self) -> SamplerKind {
        SolverConfig::unguided(self)
    }

    fn knobs(&self) -> Vec<KnobValue> {
        C::KNOBS
            .iter()
            .map(|k| KnobValue {
                name: k.name,
                doc: k.doc,
                kind: k.kind,
                value: (k.get)(self),
            })
            .collect()
    }

    fn set_knob(&mut self, name: &str, value: f64) -> Result<(), String> {
        let Some(knob) = C::KNOBS.iter().find(|k| k.name == name) else {
            let names: Vec<&str> = C::KNOBS.iter().map(|k| k.name).collect();
            return Err(format!(
                "solver `{}` has no knob `{name}`; it has: {}",
                SolverConfig::name(self),
                names.join(", ")
            ));
        };
        check(name, knob.kind, value)?;
        (knob.set)(self, value);
        Ok(())
    }

    fn validate(&self) -> Result<(), SolveError> {
        SolverConfig::validate(self)
    }

    fn edit_refusal(&self) -> Option<&'static str> {
        SolverConfig::edit_refusal(self)
    }

    fn few_step_refusal(&self) -> Option<&'static str> {
        SolverConfig::few_step_refusal(self)
    }

    fn needs_few_step(&self) -> bool {
        SolverConfig::needs_few_step(self)
    }

    fn run(&self, ctx: &Ctx, progress: &mut dyn FnMut(Progress)) -> Result<Outcome, SolveError> {
        SolverConfig::run(self, ctx, progress)
    }

    fn clone_box(&self) -> Box<dyn DynSolver> {
        Box::new(self.clone())
    }

    fn eq_dyn(&self, other: &dyn Any) -> bool {
        other.downcast_ref::<C>() == Some(self)
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn fmt_dyn(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self, f)
    }
}
