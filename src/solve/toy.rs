//! `toy`, a test-only solver: the proof that a new solver is its file plus one line in
//! the registry (`registry!` in `solve/mod.rs`). It takes the unguided DDIM sample and
//! moves its features down the error's gradient, `iterations` times, each step sized to
//! remove the fraction `step` of the linearised error (a Polyak step).

use super::SolveError;
use super::host::{extract_head, insert_head};
use super::knobs::{Knob, knob};
use super::request::Progress;
use super::driver::{Ctx, Outcome, ensure_finite, host};
use super::solver::{Solver, SolverConfig, SolverSpec};
use crate::features::FEATURE_DIM;
use crate::model::sampler::SamplerKind;

/// Settings of `toy`.
#[derive(Clone, Debug, PartialEq)]
pub struct ToyConfig {
    /// Steps of the DDIM sample it starts from.
    pub ddim_steps: usize,
    /// Gradient steps.
    pub iterations: usize,
    /// Fraction of the linearised error each step removes.
    pub step: f64,
}

/// `toy`, for [`super::registry`].
pub const SPECS: &[SolverSpec] = &[SolverSpec {
    name: "toy",
    summary: "the unguided DDIM sample, then fixed gradient steps (test only)",
    make: || {
        Solver::new(ToyConfig {
            ddim_steps: 8,
            iterations: 10,
            step: 0.5,
        })
    },
}];

impl SolverConfig for ToyConfig {
    const KNOBS: &'static [Knob<Self>] = &[
        knob!(Count, "ddim_steps", "steps of the DDIM sample it starts from", ddim_steps),
        knob!(Count, "iterations", "gradient steps", iterations),
        knob!(Real, "step", "fraction of the linearised error each step removes", step),
    ];

    fn name(&self) -> &'static str {
        "toy"
    }

    fn unguided(&self) -> SamplerKind {
        SamplerKind::Ddim(self.ddim_steps)
    }

    fn validate(&self) -> Result<(), SolveError> {
        super::driver::check_kind(self.unguided())
    }

    fn run(&self, ctx: &Ctx, progress: &mut dyn FnMut(Progress)) -> Result<Outcome, SolveError> {
        let mut x = host(ctx.sample_plain(self.unguided(), progress));
        let mut objective = ctx.host_objective();
        let mut trace = Vec::new();
        for it in 0..self.iterations {
            let mut head = extract_head(&x, FEATURE_DIM);
            let mut grad = vec![0.0; head.len()];
            let values = objective.eval(&head, &mut grad)?;
            ensure_finite(&grad, "toy", "gradient", || format!("iteration {}", it + 1))?;
            let error: f64 = values.iter().map(|&v| f64::from(v)).sum();
            let norm: f64 = grad.iter().map(|&g| f64::from(g) * f64::from(g)).sum();
            let scale = if norm > 0.0 { self.step * error / norm } else { 0.0 };
            for (h, g) in head.iter_mut().zip(&grad) {
                *h -= (scale * f64::from(*g)) as f32;
            }
            insert_head(&mut x, FEATURE_DIM, &head);
            trace.push(values);
        }
        Ok(Outcome {
            x,
            relax: None,
            trace,
            cleaned: false,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{tiny_bundle, wrist_up};
    use super::super::{Prior, SolveRequest, solve};
    use super::*;
    use burn::prelude::*;

    #[test]
    fn a_registered_solver_is_found_configured_and_run_by_name() {
        assert!(Solver::names().contains(&"toy"));
        let mut toy = Solver::by_name("toy").unwrap();
        assert_eq!(toy.knob_names(), ["ddim_steps", "iterations", "step"]);
        toy.set_knob("iterations", 30.0).unwrap();
        assert_eq!(toy.config::<ToyConfig>().unwrap().iterations, 30);
        assert!(toy.set_knob("lr", 1.0).unwrap_err().contains("step"));
        let bundle = tiny_bundle();
        let prior = Prior::from_bundle(&bundle);
        let dev = Device::flex();
        let error = |s: Solver| {
            let req = SolveRequest::new(vec!["a person walks".into()], 16, 5, s);
            solve(&prior, &req, &wrist_up, &dev, |_| {}).unwrap().error[0]
        };
        let (before, after) = (error(toy.unguided()), error(toy));
        assert!(after < 0.5 * before, "{before} -> {after}");
    }
}
