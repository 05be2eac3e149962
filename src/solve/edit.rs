//! Editing a take ([`Edit`]): the chain starts from the take instead of noise and keeps
//! the frames it is told to keep.
//!
//! * **Strength (SDEdit).** The take's normalised features x are noised to the step
//!   t* = s·T of the chain, `x_t* = √ᾱ·x + √(1 − ᾱ)·ε` (ε the request's seeded noise), and
//!   only the steps below t* run. s = 0 returns the take; s = 1 starts from pure noise,
//!   exactly as a solve without a take.
//! * **In-painting (MDM).** At every step the model's x̂0 is replaced on kept frames by the
//!   take, `x̂0 ← w·take + (1 − w)·x̂0`, with a per-frame weight `w` that is 1 on kept frames
//!   and falls linearly to 0 over [`Edit::blend`] frames into the edited window, so the
//!   model continues the kept frames without a pop. A guided solver scales its steps by
//!   `1 − w` (kept frames do not move), and frames of weight 1 are put back once more at
//!   the end so they come back exactly (the skeleton projection of `guide`'s late steps
//!   touches every frame); the seams stay as the chain left them.
//!
//! * **The path.** [`Edit::hold_path`] holds the take's turning speed and horizontal root
//!   velocity on every frame the same way, so the body is edited on the take's own path.
//!
//! Kept frames keep their features: pose, velocities and contacts. The root is stored as
//! velocities, so frames kept after an edited window follow on from where the edit leaves
//! the body (MDM's in-betweening does the same); frames kept before it stay in place.
//!
//! Solvers that can edit call [`Ctx::chain_start`], [`Ctx::hold_x0`], [`Ctx::hold_step`]
//! and [`Ctx::hold_final`]; with no take they change nothing.

use super::SolveError;
use super::driver::Ctx;
use super::request::{Phase, Progress};
use super::take::Take;
use crate::features::FEATURE_DIM;
use crate::model::sampler::{SamplerKind, ddim_step, guided_x0, posterior_mean, schedule_for};
use crate::model::schedule::{DIFFUSION_STEPS, NoiseSchedule};
use burn::prelude::*;
use std::ops::Range;

/// Strength when none is given (chosen by measurement: the book's editing chapter).
pub const DEFAULT_STRENGTH: f32 = 0.5;

/// Default frames of the blend at each seam of a kept window.
pub const DEFAULT_BLEND: usize = 5;

/// What to edit and how.
#[derive(Clone, Debug, PartialEq)]
pub struct Edit {
    /// The take (its frame count is the request's).
    pub take: Take,
    /// 0..=1: how far into the chain the take is noised (0: the take, 1: pure noise).
    pub strength: f32,
    /// Per frame, how firmly the frame is held to the take (1: kept, 0: free); empty when
    /// no frame is kept. Build it with [`hold_weights`].
    pub hold: Vec<f32>,
    /// Hold the take's path on every frame: the root's turning speed and horizontal
    /// velocity stay the take's while the body is edited, as MDM holds the root in its
    /// body-part editing. The model walks off the take's path when it re-denoises
    /// it (a real walk drifted 0.9–2.5 m sideways in 7 s); a program that must move the
    /// path ("go around the pillar") leaves this off.
    pub hold_path: bool,
}

/// Path columns of a feature row: turning speed and horizontal velocity. Not the root
/// height: the other joints' heights are the edited body's, and the take's pelvis height
/// on them stretched the hips by up to 8.5 cm.
const PATH_COLUMNS: usize = 3;

/// Per-frame hold weights of `frames` frames: 1 on every frame of `keep`, falling linearly
/// over `blend` frames into the frames next to them (the seams), 0 elsewhere.
pub fn hold_weights(frames: usize, keep: &[Range<usize>], blend: usize) -> Vec<f32> {
    let mut w = vec![0.0f32; frames];
    for r in keep {
        let (lo, hi) = (r.start.min(frames), r.end.min(frames));
        if lo >= hi {
            continue;
        }
        w[lo..hi].fill(1.0);
        for k in 1..=blend {
            let v = 1.0 - k as f32 / (blend + 1) as f32;
            if let Some(t) = lo.checked_sub(k) {
                w[t] = w[t].max(v);
            }
            if hi - 1 + k < frames {
                w[hi - 1 + k] = w[hi - 1 + k].max(v);
            }
        }
    }
    w
}

/// Hold weights of an in-between `frames` long that keeps `context` frames at each end:
/// the blend lies inside the kept frames (the gap has no take to blend towards), so the
/// outer `context − blend` frames are exact and the next `blend` ease into the gap.
pub fn in_between_hold(frames: usize, context: usize, blend: usize) -> Vec<f32> {
    let inner = context.saturating_sub(blend);
    hold_weights(frames, &[0..inner, frames - inner..frames], blend)
}

impl Edit {
    /// Refuses an edit the request cannot run: strength outside 0..=1, people or frames
    /// that differ from the request's, hold weights of the wrong length or range.
    pub fn check(&self, people: usize, frames: usize) -> Result<(), SolveError> {
        let bad = |m: String| Err(SolveError::Invalid(m));
        if !(self.strength.is_finite() && (0.0..=1.0).contains(&self.strength)) {
            return bad(format!(
                "strength {} is outside 0…1 (0 returns the take, 1 ignores it)",
                self.strength
            ));
        }
        if self.take.features.len() != people || self.take.placements.len() != people {
            return bad(format!(
                "the take holds {} motion(s), one per person; the request has {people} people",
                self.take.features.len()
            ));
        }
        if self.take.frames != frames
            || self
                .take
                .features
                .iter()
                .any(|f| f.len() != frames * FEATURE_DIM)
        {
            return bad(format!(
                "the take has {} frames; the request asks for {frames} (the take sets the length)",
                self.take.frames
            ));
        }
        if !self.hold.is_empty() && self.hold.len() != frames {
            return bad(format!(
                "{} hold weights for {frames} frames",
                self.hold.len()
            ));
        }
        if self.hold.iter().any(|w| !(0.0..=1.0).contains(w)) {
            return bad("hold weights must be between 0 and 1".into());
        }
        Ok(())
    }
}

/// An [`Edit`] ready for the chain: the take normalised and repeated per sample, the
/// hold weights broadcast to `[B·P, N, 263]`.
pub struct EditState {
    strength: f32,
    /// `[B·P, N, 263]` normalised take.
    take: Tensor<3>,
    /// `[B·P, N, 263]` hold weights (`None`: nothing kept).
    hold: Option<Tensor<3>>,
    /// The same, 1 where the weight is 1 and 0 elsewhere (seams left as the chain made them).
    exact: Option<Tensor<3>>,
    /// `[N, 263]` `1 − w`, the share of a step each frame's feature takes (empty: all 1).
    free: Vec<f32>,
}

impl EditState {
    /// The state of `edit` for `samples` samples, normalised with `mean`/`std`.
    pub fn new(edit: &Edit, samples: usize, mean: &[f32], std: &[f32], device: &Device) -> Self {
        let n = edit.take.frames;
        let mut x = Vec::with_capacity(samples * edit.take.features.len() * n * FEATURE_DIM);
        for _ in 0..samples {
            for f in &edit.take.features {
                x.extend(
                    f.chunks_exact(FEATURE_DIM).flat_map(|row| {
                        row.iter().zip(mean).zip(std).map(|((v, m), s)| (v - m) / s)
                    }),
                );
            }
        }
        let motions = samples * edit.take.features.len();
        let dims = [motions, n, FEATURE_DIM];
        let take = Tensor::from_data(TensorData::new(x, dims), device);
        let held = !edit.hold.is_empty() || edit.hold_path;
        // `[N, 263]`: the frame's weight, 1 on the path columns when the path is held.
        let weights: Vec<f32> = (0..if held { n } else { 0 })
            .flat_map(|t| {
                let w = edit.hold.get(t).copied().unwrap_or(0.0);
                (0..FEATURE_DIM).map(move |c| {
                    if edit.hold_path && c < PATH_COLUMNS {
                        1.0
                    } else {
                        w
                    }
                })
            })
            .collect();
        let free = weights.iter().map(|w| 1.0 - w).collect();
        let exact_weights: Vec<f32> = weights
            .iter()
            .map(|w| if *w >= 1.0 { 1.0 } else { 0.0 })
            .collect();
        let broadcast = |w: Vec<f32>| {
            Tensor::<3>::from_data(TensorData::new(w, [1, n, FEATURE_DIM]), device).expand(dims)
        };
        let exact = held.then(|| broadcast(exact_weights));
        let hold = held.then(|| broadcast(weights));
        EditState {
            strength: edit.strength,
            take,
            hold,
            exact,
            free,
        }
    }
}

impl Ctx<'_> {
    /// Where a chain over `schedule` starts: the number of steps to run (steps `k−1` down
    /// to 0) and x at the first of them. Without a take: every step, from the seeded noise.
    pub fn chain_start(&self, schedule: &NoiseSchedule) -> (usize, Tensor<3>) {
        let n = schedule.len();
        let Some(edit) = &self.edit else {
            return (n, self.initial_tensor(&self.device));
        };
        let k = ((edit.strength as f64 * n as f64).round() as usize).min(n);
        if k == n {
            return (n, self.initial_tensor(&self.device));
        }
        if k == 0 {
            return (0, edit.take.clone());
        }
        let a = schedule.alphas_cumprod[k - 1];
        let x = edit.take.clone() * a.sqrt() as f32
            + self.initial_tensor(&self.device) * (1.0 - a).sqrt() as f32;
        (k, x)
    }

    /// The model's x̂0 with kept frames replaced by the take (unchanged without one).
    pub fn hold_x0(&self, x0: Tensor<3>) -> Tensor<3> {
        match self.edit.as_ref().and_then(|e| Some((e, e.hold.clone()?))) {
            Some((edit, w)) => x0.clone() + (edit.take.clone() - x0) * w,
            None => x0,
        }
    }

    /// The final sample with kept frames (and a held path) put back exactly. Seams keep
    /// what the chain made of them: re-blending there undid `guide`'s skeleton projection
    /// of its last step, and a blend of two poses shortened bones by up to 16 cm.
    pub fn hold_final(&self, x: Tensor<3>) -> Tensor<3> {
        match self.edit.as_ref().and_then(|e| Some((e, e.exact.clone()?))) {
            Some((edit, w)) => x.clone() + (edit.take.clone() - x) * w,
            None => x,
        }
    }

    /// Scales a step (or gradient) over `[B·P, N, width]` rows (the first `width` columns
    /// of the features) by each feature's `1 − w`, so kept frames and a held path do not
    /// move and seams move partly.
    pub fn hold_step(&self, v: &mut [f32], width: usize) {
        let Some(free) = self
            .edit
            .as_ref()
            .map(|e| &e.free)
            .filter(|f| !f.is_empty())
        else {
            return;
        };
        for (k, row) in v.chunks_exact_mut(width).enumerate() {
            let t = k % self.frames;
            let f = &free[t * FEATURE_DIM..t * FEATURE_DIM + width];
            row.iter_mut().zip(f).for_each(|(x, s)| *x *= s);
        }
    }

    /// The unguided chain of `kind` over the edit (started at its strength, kept frames
    /// held); [`Ctx::sample_plain`] without a take.
    pub fn sample_edited(
        &self,
        kind: SamplerKind,
        progress: &mut dyn FnMut(Progress),
    ) -> Tensor<3> {
        if self.edit.is_none() {
            return self.sample_plain(kind, progress);
        }
        let den = self.denoiser();
        let schedule = schedule_for(&NoiseSchedule::cosine(DIFFUSION_STEPS), kind);
        let cond = self.condition(&self.device);
        let mut noise = self.step_noise();
        let dims = self.dims();
        let (first, mut x) = self.chain_start(&schedule);
        for i in (0..first).rev() {
            let x0 = self.hold_x0(guided_x0(&den, x.clone(), schedule.timesteps[i], &cond));
            x = match kind {
                SamplerKind::Ddim(_) => ddim_step(&schedule, i, x, x0),
                SamplerKind::Ddpm(_) => {
                    let mean = posterior_mean(&schedule, i, x, x0);
                    if i > 0 {
                        let sd = schedule.posterior(i).variance.sqrt();
                        mean + noise.tensor(dims, &self.device) * sd
                    } else {
                        mean
                    }
                }
            };
            progress(Progress {
                phase: Phase::Sampling,
                done: first - i,
                total: first,
                error: None,
            });
        }
        self.hold_final(x)
    }
}

#[cfg(test)]
// A list of one frame range is what `hold_weights` takes, not a range to collect.
#[allow(clippy::single_range_in_vec_init)]
mod tests {
    use super::*;

    #[test]
    fn hold_weights_keep_the_window_and_ramp_into_the_edit() {
        let w = hold_weights(12, &[0..4], 3);
        assert_eq!(&w[..4], &[1.0; 4]);
        assert_eq!(&w[4..7], &[0.75, 0.5, 0.25]);
        assert!(w[7..].iter().all(|v| *v == 0.0));
        // Two windows: an in-between holds both ends; ramps never exceed 1 nor overlap badly.
        let w = hold_weights(10, &[0..3, 7..10], 2);
        let want = [
            1.0,
            1.0,
            1.0,
            2.0 / 3.0,
            1.0 / 3.0,
            1.0 / 3.0,
            2.0 / 3.0,
            1.0,
            1.0,
            1.0,
        ];
        assert!(
            w.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-6),
            "{w:?}"
        );
        assert!(hold_weights(5, &[], 3).iter().all(|v| *v == 0.0));
        // An in-between blends inside its context: frame 4 and 5 of 6 ease out, the gap
        // (frames 6..14) is free.
        let w = in_between_hold(20, 6, 2);
        assert_eq!(&w[..4], &[1.0; 4]);
        assert!(
            w[4] > w[5] && w[5] > 0.0 && w[6..14].iter().all(|v| *v == 0.0),
            "{w:?}"
        );
        assert_eq!(&w[16..], &[1.0; 4]);
        // Blend 0: a hard switch.
        assert_eq!(hold_weights(4, &[1..2], 0), vec![0.0, 1.0, 0.0, 0.0]);
    }
}
