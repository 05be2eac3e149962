//! `plain`: the unguided sampler, no optimisation; the baseline next to every result.

use super::SolveError;
use super::knobs::{Knob, KnobKind};
use super::request::Progress;
use super::driver::{Ctx, Outcome, check_kind, host};
use super::solver::{Solver, SolverConfig, SolverSpec};
use crate::model::sampler::SamplerKind;

/// Settings of `plain`: which chain.
#[derive(Clone, Debug, PartialEq)]
pub struct PlainConfig {
    /// The chain (DDPM-1000 by default).
    pub sampler: SamplerKind,
}

/// `plain`, for [`super::registry`].
pub const SPECS: &[SolverSpec] = &[SolverSpec {
    name: "plain",
    summary: "nothing: the unguided model, the baseline next to every result",
    make: || Solver::plain(SamplerKind::Ddpm(1000)),
}];

impl SolverConfig for PlainConfig {
    const KNOBS: &'static [Knob<Self>] = &[Knob {
        name: "steps",
        doc: "steps of the chain (DDPM by default)",
        kind: KnobKind::Count,
        get: |c| c.sampler.steps() as f64,
        set: |c, v| c.sampler = c.sampler.with_steps(v as usize),
    }];

    fn name(&self) -> &'static str {
        "plain"
    }

    fn unguided(&self) -> SamplerKind {
        self.sampler
    }

    fn validate(&self) -> Result<(), SolveError> {
        check_kind(self.sampler)
    }

    fn run(&self, ctx: &Ctx, progress: &mut dyn FnMut(Progress)) -> Result<Outcome, SolveError> {
        Ok(Outcome {
            x: host(ctx.sample_edited(ctx.chain_kind(self.sampler), progress)),
            relax: None,
            cleaned: false,
            trace: Vec::new(),
        })
    }

    fn edit_refusal(&self) -> Option<&'static str> {
        None
    }

    fn few_step_refusal(&self) -> Option<&'static str> {
        None
    }
}
