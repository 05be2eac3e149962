//! Realism guidance for `guide` (OmniControl §3.2): when the prior has a ControlNet, every
//! denoising step's x̂0 comes from the denoiser steered by a hint, so the whole body answers
//! a constraint instead of the joints the gradient reaches.
//!
//! OmniControl's hint is explicit joint targets; a program is not. The hint is derived from
//! the spatial guidance's own iterate, as InterControl derives its ControlNet's condition
//! from its IK targets:
//!
//! * **which** joints and frames: those where the program's gradient with respect to the
//!   joint positions is non-zero at the start of the step's inner loop (the statements it
//!   is still working on; a satisfied hinge has none);
//! * **where**: the positions the inner loop moved them to, in each person's canonical
//!   frame (the model's own).
//!
//! The first step has no hint (nothing is known yet); each later step uses the hint of the
//! step before. A step whose hint controls nothing (the first, or every statement met) is
//! not steered at all: the ControlNet was trained with at least one hinted frame, and an
//! empty hint is a question it never saw. A keyframe program's hint is its keyframes: its
//! joints, on its frames, at the places the inner loop put them (the targets, once it has
//! met them).
//!
//! Cost ([`Realism::new`]): one ControlNet pass can steer both halves of the
//! classifier-free-guidance batch, and a pass's additions can be reused on the next
//! steps; `guide` and `lbfgs` do both by default (knobs `realism_shared`,
//! `realism_every`).

use super::SolveError;
use super::driver::{Ctx, host};
use crate::features::recover_from_ric_tensor;
use crate::model::Denoiser;
use crate::model::control::{ControlNet, Controlled, Hint, WithControls};
use crate::model::denoiser::DenoiserInput;
use crate::model::sampler::{Condition, guided_x0};
use crate::skeleton::NUM_JOINTS;
use burn::prelude::*;
use std::cell::RefCell;

/// The steering of one guided chain: the ControlNet and the current hint, or nothing.
pub struct Realism<'a> {
    control: Option<(&'a ControlNet, Hint)>,
    /// Whether the current hint controls any joint on any frame.
    hinted: bool,
    /// One ControlNet pass per step, on the text-conditioned half of classifier-free
    /// guidance, steering both halves ([`Controlled::shared_guidance`]).
    shared_guidance: bool,
    /// The ControlNet runs on every `every`-th steered step; the steps between reuse its
    /// additions.
    every: usize,
    /// The last ControlNet additions, and the steered steps since they were computed.
    cached: Option<(Vec<Tensor<3>>, usize)>,
}

/// The steered denoiser, keeping the ControlNet's additions of its call.
struct Recording<'a> {
    steered: Controlled<'a>,
    controls: RefCell<Option<Vec<Tensor<3>>>>,
}

impl Denoiser for Recording<'_> {
    fn predict_x0(&self, input: &DenoiserInput) -> Tensor<3> {
        let (x0, controls) = self.steered.predict_x0_and_controls(input);
        *self.controls.borrow_mut() = Some(controls);
        x0
    }
}

impl<'a> Realism<'a> {
    /// Steering with `control` when given (the hint starts empty), else none;
    /// `shared_guidance`: see [`Controlled::shared_guidance`]; the ControlNet runs on every
    /// `every`-th steered step (1: each), the others reuse its last additions.
    pub fn new(
        ctx: &Ctx,
        control: Option<&'a ControlNet>,
        shared_guidance: bool,
        every: usize,
    ) -> Realism<'a> {
        Realism {
            control: control.map(|c| (c, Hint::empty(ctx.motions(), ctx.frames, &ctx.device))),
            hinted: false,
            shared_guidance,
            every: every.max(1),
            cached: None,
        }
    }

    /// Whether a ControlNet steers the chain.
    pub fn is_on(&self) -> bool {
        self.control.is_some()
    }

    /// Classifier-free guided x̂0, through the ControlNet when there is one, `steer`, and
    /// the hint controls something; a step within `every` of the last ControlNet pass
    /// reuses that pass's additions.
    pub fn x0(
        &mut self,
        den: &crate::model::Mdm,
        x_t: Tensor<3>,
        t: usize,
        cond: &Condition,
        steer: bool,
    ) -> Tensor<3> {
        let Some((control, hint)) = self.control.as_ref().filter(|_| steer && self.hinted) else {
            // An unsteered step ends the reuse: the next steered step runs the ControlNet.
            self.cached = None;
            return guided_x0(den, x_t, t, cond);
        };
        if let Some((controls, age)) = &mut self.cached
            && *age < self.every
        {
            *age += 1;
            let reused = WithControls {
                base: den,
                controls,
            };
            return guided_x0(&reused as &dyn Denoiser, x_t, t, cond);
        }
        let recording = Recording {
            steered: Controlled {
                base: den,
                control,
                hint: hint.clone(),
                shared_guidance: self.shared_guidance,
            },
            controls: RefCell::new(None),
        };
        let x0 = guided_x0(&recording as &dyn Denoiser, x_t, t, cond);
        self.cached = recording.controls.into_inner().map(|c| (c, 1));
        x0
    }

    /// After a step's inner loop moved μ from `before` to `after` (host `[B·P, N, 263]`,
    /// normalised): the hint for the next step.
    pub fn update(&mut self, ctx: &Ctx, before: &[f32], after: &[f32]) -> Result<(), SolveError> {
        if let Some((_, hint)) = &mut self.control {
            *hint = program_hint(ctx, before, after)?;
            let mask = hint.values.clone().narrow(2, NUM_JOINTS * 3, NUM_JOINTS);
            self.hinted = mask.sum().into_scalar::<f32>() > 0.0;
        }
        Ok(())
    }
}

/// The hint of a step: the joints and frames where the program's gradient is non-zero at
/// `before`, placed where they are in `after` (canonical frame).
pub fn program_hint(ctx: &Ctx, before: &[f32], after: &[f32]) -> Result<Hint, SolveError> {
    let dims = ctx.dims();
    let [bp, n, _] = dims;
    let ad = ctx.device.clone().autodiff();
    let x = Tensor::<3>::from_data(TensorData::new(before.to_vec(), dims), &ctx.device);
    let placed = ctx.decoder.joints(x, None).into_data();
    let joints = Tensor::<5>::from_data(placed, &ad).require_grad(); // [B, P, N, 22, 3]
    let e = ctx.error.error(joints.clone());
    let touched: Vec<f32> = if e.is_tracked() {
        joints
            .grad(&e.sum().backward())
            .map(|g| {
                host(
                    g.abs()
                        .sum_dim(4)
                        .greater_elem(0.0)
                        .float()
                        .reshape([bp * n * NUM_JOINTS]),
                )
            })
            .unwrap_or_else(|| vec![0.0; bp * n * NUM_JOINTS])
    } else {
        vec![0.0; bp * n * NUM_JOINTS]
    };
    let mask = Tensor::<3>::from_data(TensorData::new(touched, [bp, n, NUM_JOINTS]), &ctx.device);
    let stat = |v: &[f32]| {
        Tensor::<3>::from_data(TensorData::new(v.to_vec(), [1, 1, v.len()]), &ctx.device)
    };
    let x = Tensor::<3>::from_data(TensorData::new(after.to_vec(), dims), &ctx.device);
    let canonical = recover_from_ric_tensor(x * stat(&ctx.decoder.std) + stat(&ctx.decoder.mean));
    Ok(Hint::new(canonical, mask))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::control::ControlNet;
    use crate::objective::MotionError;
    use crate::scene::Placement;
    use crate::solve::decode::Decoder;
    use crate::solve::guide::GuideConfig;
    use crate::solve::tests::tiny_bundle;
    use crate::solve::{Prior, SolveRequest, Solver, solve};

    const FRAMES: usize = 16;

    /// Left wrist (20) at a point on frame 4, right ankle (8) above 3 m on frame 11 (out
    /// of reach, so never satisfied: a satisfied hinge has no gradient and no hint).
    fn keyframes(j: Tensor<5>) -> Tensor<1> {
        let [b, _, _, _, _] = j.dims();
        let target =
            Tensor::<1>::from_floats([0.3, 1.2, 0.4], &j.device()).reshape([1, 1, 1, 1, 3]);
        let wrist = j.clone().narrow(2, 4, 1).narrow(3, 20, 1) - target;
        let reach = (wrist.square().sum_dim(4) + 1e-12).sqrt().reshape([b]);
        let ankle = j.narrow(2, 11, 1).narrow(3, 8, 1).narrow(4, 1, 1);
        let lift = (ankle.neg() + 3.0).clamp_min(0.0).reshape([b]);
        reach + lift
    }

    #[test]
    fn a_keyframe_programs_hint_is_its_keyframes() {
        let bundle = tiny_bundle();
        let device = Device::flex();
        let error: &dyn MotionError = &keyframes;
        let ctx = Ctx {
            prior: Prior::from_bundle(&bundle),
            error,
            device: device.clone(),
            samples: 1,
            people: 1,
            frames: FRAMES,
            seed: 1,
            guidance_scale: 1.0,
            prompts: vec!["a person walks forward".into()],
            decoder: Decoder::new(&bundle.mean, &bundle.std, &[Placement::IDENTITY]),
            edit: None,
            clean_feet: false,
            polish_edit: false,
        };
        let before = ctx.initial_noise();
        let after: Vec<f32> = before.iter().map(|v| v * 0.5 + 0.1).collect();
        let hint = program_hint(&ctx, &before, &after).unwrap();
        let v = host(hint.values);
        let dim = crate::model::control::HINT_DIM;
        let mut controlled = Vec::new();
        for f in 0..FRAMES {
            for j in 0..NUM_JOINTS {
                if v[f * dim + NUM_JOINTS * 3 + j] == 1.0 {
                    controlled.push((f, j));
                }
            }
        }
        assert_eq!(
            controlled,
            vec![(4, 20), (11, 8)],
            "the keyframes' joints and frames"
        );
        // Their targets are where `after` puts them (canonical frame), the rest is zero.
        let x = Tensor::<3>::from_data(TensorData::new(after, ctx.dims()), &device);
        let joints = host(ctx.decoder.joints(x, None));
        for (f, j) in controlled {
            for c in 0..3 {
                let want = joints[(f * NUM_JOINTS + j) * 3 + c];
                let got = v[f * dim + j * 3 + c];
                assert!(
                    (want - got).abs() < 1e-5,
                    "frame {f} joint {j}: {got} vs {want}"
                );
            }
        }
        let free: f32 = (0..FRAMES)
            .flat_map(|f| (0..NUM_JOINTS * 3).map(move |k| (f, k)))
            .filter(|&(f, k)| !((f == 4 && k / 3 == 20) || (f == 11 && k / 3 == 8)))
            .map(|(f, k)| v[f * dim + k].abs())
            .sum();
        assert_eq!(free, 0.0);
    }

    /// A short guided chain.
    fn short_guide() -> GuideConfig {
        GuideConfig {
            steps: 20,
            k_early: 2,
            k_late: 5,
            late_steps: 3,
            ..GuideConfig::default()
        }
    }

    /// The keyframe program solved with `cfg`, steered by `control` when given.
    fn guided(
        bundle: &crate::model::ModelBundle,
        cfg: GuideConfig,
        control: Option<&ControlNet>,
    ) -> crate::solve::SolveResult {
        guided_on(&keyframes, bundle, cfg, control)
    }

    /// `error` solved with `cfg`, steered by `control` when given.
    fn guided_on(
        error: &dyn MotionError,
        bundle: &crate::model::ModelBundle,
        cfg: GuideConfig,
        control: Option<&ControlNet>,
    ) -> crate::solve::SolveResult {
        let req = SolveRequest::new(
            vec!["a person walks forward".into()],
            FRAMES,
            3,
            Solver::new(cfg),
        );
        let prior = Prior::from_bundle(bundle).with_control(control);
        solve(&prior, &req, error, &Device::flex(), |_| {}).unwrap()
    }

    /// A ControlNet for the tiny bundle with random (non-zero) weights, so it steers.
    fn random_control(bundle: &crate::model::ModelBundle) -> ControlNet {
        ControlNet::from_base(&bundle.model, &Device::flex()).randomised(&Device::flex())
    }

    #[test]
    fn a_fresh_control_net_leaves_guide_unchanged() {
        let bundle = tiny_bundle();
        let control = ControlNet::from_base(&bundle.model, &Device::flex());
        let plain = guided(&bundle, short_guide(), None);
        let steered = guided(&bundle, short_guide(), Some(&control));
        assert_eq!(
            plain.features, steered.features,
            "a zero ControlNet adds zero"
        );
    }

    #[test]
    fn a_met_program_gives_no_hint_and_is_not_steered() {
        let bundle = tiny_bundle();
        let control = random_control(&bundle);
        // Every ankle above −100 m: met everywhere, so its gradient is zero.
        let met = |j: Tensor<5>| {
            let [b, _, _, _, _] = j.dims();
            let ankle = j.narrow(3, 8, 1).narrow(4, 1, 1);
            (ankle.neg() - 100.0).clamp_min(0.0).sum_dim(2).reshape([b])
        };
        let solve_with = |realism| {
            let cfg = GuideConfig {
                realism,
                ..short_guide()
            };
            guided_on(&met, &bundle, cfg, Some(&control))
        };
        assert_eq!(solve_with(true).features, solve_with(false).features);
    }

    #[test]
    fn a_shared_pass_steers_differently_from_a_pass_per_half() {
        let bundle = tiny_bundle();
        let control = random_control(&bundle);
        let go = |realism_shared| {
            guided(
                &bundle,
                GuideConfig {
                    realism_shared,
                    ..short_guide()
                },
                Some(&control),
            )
        };
        // Guidance 2.5: the text-free half is steered by the conditioned pass's controls.
        let (shared, own) = (go(true), go(false));
        assert_ne!(shared.features, own.features);
        assert!(shared.features.iter().all(|v| v.is_finite()));
    }

    #[test]
    fn reusing_the_control_nets_additions_between_passes_changes_the_steering_a_little() {
        let bundle = tiny_bundle();
        let control = random_control(&bundle);
        let go = |realism_every| {
            guided(
                &bundle,
                GuideConfig {
                    realism_every,
                    ..short_guide()
                },
                Some(&control),
            )
        };
        let off = guided(
            &bundle,
            GuideConfig {
                realism: false,
                ..short_guide()
            },
            Some(&control),
        );
        let (each, second, once) = (go(1), go(2), go(100));
        assert_ne!(each.features, second.features, "reused additions are stale");
        assert_ne!(second.features, once.features);
        assert_ne!(
            once.features, off.features,
            "one pass still steers every step"
        );
        // Reuse is deterministic.
        assert_eq!(go(2).features, second.features);
        let bad = GuideConfig {
            realism_every: 0,
            ..short_guide()
        };
        assert!(bad.check_settings().is_err());
    }

    #[test]
    fn realism_share_steers_only_the_first_steps() {
        let bundle = tiny_bundle();
        let control = random_control(&bundle);
        let base = short_guide();
        let go = |cfg: GuideConfig| guided(&bundle, cfg, Some(&control));
        let off = go(GuideConfig {
            realism: false,
            ..base.clone()
        });
        let none = go(GuideConfig {
            realism_share: 0.0,
            ..base.clone()
        });
        let half = go(GuideConfig {
            realism_share: 0.5,
            ..base.clone()
        });
        let all = go(GuideConfig {
            realism_share: 1.0,
            ..base.clone()
        });
        assert_eq!(off.features, none.features, "a share of 0 steers nothing");
        assert_ne!(off.features, half.features, "a random ControlNet steers");
        assert_ne!(
            half.features, all.features,
            "the later steps are steered too"
        );
        let bad = GuideConfig {
            realism_share: 1.5,
            ..base
        };
        assert!(bad.check_settings().is_err());
    }
}
