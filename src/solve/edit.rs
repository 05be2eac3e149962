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
//!   the end so they come back exactly. `guide`'s skeleton projection moves each feature
//!   by its `1 − w` too ([`Ctx::hold_change`]), and the seams it scaled get their bones
//!   back ([`EditState::rebuild_seams`]); otherwise the seams stay as the chain left them.
//! * **Untouched time.** [`auto_hold`] finds the frames no statement reads; `mprog run
//!   --from` keeps them ([`AutoHold::time_weights`]), easing into the edit over
//!   [`TIME_MARGIN`] frames before the first frame the program reads.
//!
//! * **The path.** [`Edit::hold_path`] holds the take's turning speed and horizontal root
//!   velocity on every frame the same way, so the body is edited on the take's own path.
//!
//! Kept frames keep their features: pose, velocities and contacts. The root is stored as
//! velocities, so frames kept after an edited window follow on from where the edit leaves
//! the body (MDM's in-betweening does the same); frames kept before it stay in place.
//!
//! Solvers that can edit call [`Ctx::chain_start`], [`Ctx::hold_x0`], [`Ctx::hold_step`]
//! (and [`Ctx::hold_change`]) and [`Ctx::hold_final`]; with no take they change nothing.

use super::SolveError;
use super::cleanup::{FootCleanup, clean_feet};
use super::driver::{Ctx, host};
use super::request::{Phase, Progress};
use super::take::Take;
use crate::features::FEATURE_DIM;
use crate::features::layout::{CONTACT, LOCAL_VEL, RIC, ROOT_Y, ROT};
use crate::model::noise::NoiseSource;
use crate::model::sampler::{
    SamplerKind, consistency_step, ddim_step, guided_x0, posterior_mean, schedule_for,
};
use crate::model::schedule::{DIFFUSION_STEPS, NoiseSchedule};
use crate::objective::MotionError;
use crate::skeleton::{BONE_LENGTHS, NUM_JOINTS, PARENTS};
use burn::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};

/// Strength when none is given (chosen by measurement: the book's editing chapter).
pub const DEFAULT_STRENGTH: f32 = 0.5;

/// Default frames of the blend at each seam of a kept window.
pub const DEFAULT_BLEND: usize = 5;

/// Frames of untouched time next to the frames a program reads that are not held
/// exactly but ease into the edit ([`AutoHold::time_weights`]), chosen by measurement on
/// a real walk with the hand on the head in its second half (the book's editing chapter):
/// with 5 the hand rushed to the head (the wrist's largest acceleration 1.9× the take's),
/// with 10 it stays near the take's own (1.1×); longer margins hold fewer frames.
pub const TIME_MARGIN: usize = 10;

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
    /// Joints whose features are held to the take on every frame (MDM's body-part
    /// editing): the program edits the rest. All `false`: the whole body is free. Build it
    /// with [`auto_hold`] or [`parts_joints`].
    pub hold_joints: [bool; NUM_JOINTS],
    /// RePaint resampling rounds: every [`RESAMPLE_JUMP`] steps the chain is noised back up
    /// that many steps and denoised again, this many times, so the free frames are
    /// re-predicted next to the held ones and the seams agree. 0: off.
    pub resample: usize,
    /// Foot cleanup ([`clean_feet`]) of the result, on what is not held exactly: the
    /// frames and parts the model made skate like its own samples (an in-between's gap
    /// skated 1.6× the real clips), and `gen` cleans its samples the same way.
    pub clean_feet: bool,
}

/// Resampling rounds when frames are kept and none are asked for (measured on a walk→run
/// in-between: the book's editing chapter).
pub const DEFAULT_RESAMPLE: usize = 5;

/// Steps the chain goes back up at each resampling (RePaint's jump length).
pub const RESAMPLE_JUMP: usize = 10;

/// Hips, knees, ankles and feet of both legs.
const LEG_JOINTS: [usize; 8] = [1, 4, 7, 10, 2, 5, 8, 11];

/// The body parts [`auto_hold`] holds or frees as a whole, with their joints.
pub use crate::skeleton::BODY_PARTS;

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

/// The joints of the named [`BODY_PARTS`], held (`true`) or not.
pub fn parts_joints(parts: &[&str]) -> [bool; NUM_JOINTS] {
    let mut held = [false; NUM_JOINTS];
    for (name, joints) in BODY_PARTS {
        if parts.contains(&name) {
            joints.iter().for_each(|&j| held[j] = true);
        }
    }
    held
}

/// What an edit holds when the user does not say: see [`auto_hold`].
#[derive(Clone, Debug, PartialEq)]
pub struct AutoHold {
    /// The program's error does not change when the take moves sideways, so moving the
    /// path cannot help it: the take's path is held.
    pub path: bool,
    /// The [`BODY_PARTS`] the program does not touch, held to the take.
    pub parts: Vec<&'static str>,
    /// Per frame of the take, whether the program leaves it alone: no statement reads it
    /// ([`MotionError::active_frames`]) and the error's gradient on the take does not
    /// reach it. All `false` for an error that cannot say which frames it reads.
    pub untouched: Vec<bool>,
}

impl AutoHold {
    /// The held joints of [`Self::parts`].
    pub fn joints(&self) -> [bool; NUM_JOINTS] {
        parts_joints(&self.parts)
    }

    /// The frame ranges of untouched time held exactly: see [`untouched_ranges`].
    pub fn kept_time(&self, margin: usize) -> Vec<Range<usize>> {
        untouched_ranges(&self.untouched, margin)
    }

    /// Hold weights of the untouched time ([`hold_weights`] of [`Self::kept_time`]): 1 on
    /// the frames held exactly, easing to 0 over the `margin` frames before the first
    /// frame the program reads (and after its last), which are therefore free; empty when
    /// no frame is held.
    pub fn time_weights(&self, margin: usize) -> Vec<f32> {
        let keep = self.kept_time(margin);
        if keep.is_empty() {
            return Vec::new();
        }
        hold_weights(self.untouched.len(), &keep, margin)
    }
}

/// The runs of `untouched` frames, each shortened by `margin` frames at every end that
/// meets a touched frame (not at the motion's ends): the blend of [`hold_weights`] then
/// lies in the untouched time, and every frame the program reads is free.
pub fn untouched_ranges(untouched: &[bool], margin: usize) -> Vec<Range<usize>> {
    let n = untouched.len();
    let mut out = Vec::new();
    let mut t = 0;
    while t < n {
        if !untouched[t] {
            t += 1;
            continue;
        }
        let start = t;
        while t < n && untouched[t] {
            t += 1;
        }
        let lo = if start == 0 { 0 } else { start + margin };
        let hi = if t == n { n } else { t.saturating_sub(margin) };
        if lo < hi {
            out.push(lo..hi);
        }
    }
    out
}

/// The larger of two per-frame hold weights (empty: nothing held).
pub fn merge_holds(a: &[f32], b: &[f32]) -> Vec<f32> {
    match (a.is_empty(), b.is_empty()) {
        (true, _) => b.to_vec(),
        (_, true) => a.to_vec(),
        _ => a.iter().zip(b).map(|(x, y)| x.max(*y)).collect(),
    }
}

/// The default holds of an edit of `take` by `error`, found on the take itself:
/// * a body part is held unless the error's gradient on the take reaches one of its joints
///   (a hand-to-head program frees the arm and the head; legs, torso and the other arm keep
///   the take's motion, so the walk stays the same walk and its feet stay planted);
/// * the path is held unless shifting the whole take sideways changes the error (a program
///   about where the body is, such as a region or a target point, may move the path; one
///   about the body's own shape may not);
/// * a frame is untouched time when no statement reads it (a program about the second
///   half leaves the first alone) and the gradient does not reach it. A frame inside a
///   statement's window that the take already meets has no gradient but is read, so it
///   stays free: the edit may have to move it to meet the frames next to it.
///
/// A program the take already meets touches no body part, and the edit returns the take.
pub fn auto_hold(
    take: &Take,
    error: &dyn MotionError,
    device: &Device,
) -> Result<AutoHold, SolveError> {
    let people = take
        .motions()
        .map_err(|e| SolveError::Invalid(format!("cannot decode the take: {e}")))?;
    let n = take.frames;
    let flat: Vec<f32> = people.iter().flat_map(|m| m.to_flat()).collect();
    let dims = [1, people.len(), n, NUM_JOINTS, 3];
    let ad = device.clone().autodiff();
    let joints = Tensor::<5>::from_data(TensorData::new(flat.clone(), dims), &ad).require_grad();
    let e = error.error(joints.clone());
    let mut touched = [false; NUM_JOINTS];
    // A frame is touched when a statement reads it or the gradient reaches it.
    let mut untouched: Vec<bool> = match error.active_frames(n) {
        Some(active) if active.len() == n => active.iter().map(|a| !a).collect(),
        _ => vec![false; n],
    };
    let grad = e
        .is_tracked()
        .then(|| joints.grad(&e.sum().backward()))
        .flatten();
    if let Some(g) = grad {
        let g = g.abs();
        let per_joint = host(
            g.clone()
                .sum_dim(4)
                .sum_dim(2)
                .sum_dim(1)
                .reshape([NUM_JOINTS]),
        );
        for (t, g) in touched.iter_mut().zip(per_joint) {
            *t = g > 0.0 || !g.is_finite();
        }
        let per_frame = host(g.sum_dim(4).sum_dim(3).sum_dim(1).reshape([n]));
        for (u, g) in untouched.iter_mut().zip(per_frame) {
            *u &= g == 0.0;
        }
    }
    let total = |offset: [f32; 3]| -> f32 {
        let moved: Vec<f32> = flat
            .chunks_exact(3)
            .flat_map(|p| [p[0] + offset[0], p[1] + offset[1], p[2] + offset[2]])
            .collect();
        let j = Tensor::<5>::from_data(TensorData::new(moved, dims), device);
        error.error(j).sum().into_scalar::<f32>()
    };
    let here = total([0.0; 3]);
    let same = |v: f32| (v - here).abs() <= 1e-5 * (1.0 + here.abs());
    let path = same(total([0.73, 0.0, -0.41])) && same(total([-1.9, 0.0, 2.3]));
    let parts = BODY_PARTS
        .iter()
        .filter(|(_, joints)| !joints.iter().any(|&j| touched[j]))
        .map(|(name, _)| *name)
        .collect();
    Ok(AutoHold {
        path,
        parts,
        untouched,
    })
}

/// The feature columns that belong to joint `j`: its root-relative position and rotation,
/// its velocity, its foot contact, and for the pelvis the root height.
fn joint_columns(j: usize) -> Vec<usize> {
    let mut cols = vec![
        LOCAL_VEL.start + 3 * j,
        LOCAL_VEL.start + 3 * j + 1,
        LOCAL_VEL.start + 3 * j + 2,
    ];
    if j == 0 {
        cols.extend(ROOT_Y);
    } else {
        cols.extend(RIC.start + 3 * (j - 1)..RIC.start + 3 * j);
        cols.extend(ROT.start + 6 * (j - 1)..ROT.start + 6 * j);
    }
    // HumanML3D's contact columns: left ankle, left foot, right ankle, right foot.
    if let Some(k) = [7, 10, 8, 11].iter().position(|&f| f == j) {
        cols.push(CONTACT.start + k);
    }
    cols
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
    resample: usize,
    /// Clean the feet: asked for, and not both legs held (held legs are the take's, feet
    /// and all, and cleaning around them moved the joints where free parts meet held ones:
    /// 1.3 cm bone errors at the shoulders of a hand edit).
    clean_feet: bool,
    /// `[B·P, N, 263]` normalised take.
    take: Tensor<3>,
    /// `[B·P, N, 263]` hold weights (`None`: nothing kept).
    hold: Option<Tensor<3>>,
    /// The same, 1 where the weight is 1 and 0 elsewhere (seams left as the chain made them).
    exact: Option<Tensor<3>>,
    /// `[N, 263]` `1 − w`, the share of a step each frame's feature takes (empty: all 1).
    free: Vec<f32>,
    /// Per frame, whether it is a seam: held in part (0 < w < 1).
    seams: Vec<bool>,
    /// Whether a change was scaled on the seams ([`Ctx::hold_change`]: `guide`'s skeleton
    /// projection), so their bones want rebuilding ([`EditState::rebuild_seams`]).
    scaled: AtomicBool,
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
        let body = edit.hold_joints.iter().any(|h| *h);
        let held = !edit.hold.is_empty() || edit.hold_path || body;
        // `[263]`: 1 on the columns held on every frame (the path, the held joints).
        let mut always = vec![0.0f32; FEATURE_DIM];
        if edit.hold_path {
            always[..PATH_COLUMNS].fill(1.0);
        }
        for j in (0..NUM_JOINTS).filter(|&j| edit.hold_joints[j]) {
            joint_columns(j).into_iter().for_each(|c| always[c] = 1.0);
        }
        // `[N, 263]`: the larger of the frame's weight and the column's.
        let weights: Vec<f32> = (0..if held { n } else { 0 })
            .flat_map(|t| {
                let w = edit.hold.get(t).copied().unwrap_or(0.0);
                always.iter().map(move |a| a.max(w))
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
            resample: edit.resample,
            clean_feet: edit.clean_feet && LEG_JOINTS.iter().any(|&j| !edit.hold_joints[j]),
            take,
            hold,
            exact,
            free,
            seams: edit.hold.iter().map(|w| *w > 0.0 && *w < 1.0).collect(),
            scaled: AtomicBool::new(false),
        }
    }
}

impl EditState {
    /// Whether [`Self::clean_free_feet`] does anything.
    pub fn cleans_feet(&self) -> bool {
        self.clean_feet && self.strength != 0.0
    }

    /// The edit's foot cleanup on the denormalised `[B·P, N, 263]` result (`frames` per
    /// motion), when it asks for one: what is held (kept frames, held columns) is put
    /// back afterwards, so only what the model made is touched.
    pub fn clean_free_feet(&self, features: &mut [f32], frames: usize) {
        if !self.cleans_feet() {
            return;
        }
        let before = features.to_vec();
        clean_feet(features, frames, FEATURE_DIM, &FootCleanup::default());
        // By the hold weights: held exactly where they are 1, eased over the seams' blend
        // frames (restoring only the exact frames let a cleaned seam frame jump 1 mm more
        // than the clips of a walk→run in-between).
        if let Some(hold) = &self.hold {
            let hold = host(hold.clone());
            for ((f, b), w) in features.iter_mut().zip(&before).zip(&hold) {
                *f += (b - *f) * w;
            }
        }
    }
}

impl EditState {
    /// The seam frames of the denormalised `[B·P, N, 263]` result (`frames` per motion)
    /// rebuilt from the pelvis outwards, each joint the chain made keeping its bone's
    /// direction and taking the skeleton's length; joints held on the frame stay as they
    /// are. Only after a solver's skeleton projection was scaled there
    /// ([`Ctx::hold_change`]): such a seam frame is part take and part projected edit, a
    /// blend of two poses whose bones are short (the left collar of a walk 6–8 cm short at
    /// a `--keep` seam); a blend of bone directions is a pose. A solver that projects
    /// nothing (`plain`) is left as it made the seams, like the rest of its motion.
    pub fn rebuild_seams(&self, features: &mut [f32], frames: usize) {
        if self.strength == 0.0
            || !self.scaled.load(Ordering::Relaxed)
            || !self.seams.iter().any(|s| *s)
        {
            return;
        }
        for (k, row) in features.chunks_exact_mut(FEATURE_DIM).enumerate() {
            let t = k % frames;
            if !self.seams.get(t).copied().unwrap_or(false) {
                continue;
            }
            let held = |j: usize| {
                self.free
                    .get(t * FEATURE_DIM + RIC.start + 3 * (j - 1))
                    .is_some_and(|f| *f <= 0.0)
            };
            rebuild_bones(row, held);
        }
    }
}

/// A feature row's joints (the ric block, the pelvis at the root height) rebuilt from the
/// pelvis outwards: each joint `held` does not name sits at its parent plus its own bone's
/// direction times the skeleton's length.
fn rebuild_bones(row: &mut [f32], held: impl Fn(usize) -> bool) {
    let at = |row: &[f32], j: usize| -> [f32; 3] {
        if j == 0 {
            [0.0, row[ROOT_Y.start], 0.0]
        } else {
            let c = RIC.start + 3 * (j - 1);
            [row[c], row[c + 1], row[c + 2]]
        }
    };
    let old: Vec<[f32; 3]> = (0..NUM_JOINTS).map(|j| at(row, j)).collect();
    let mut new = old.clone();
    for j in 1..NUM_JOINTS {
        if held(j) {
            continue;
        }
        let parent = PARENTS[j];
        let d: Vec<f32> = (0..3).map(|a| old[j][a] - old[parent][a]).collect();
        let len = d.iter().map(|v| v * v).sum::<f32>().sqrt();
        if len < 1e-6 {
            continue;
        }
        let scale = BONE_LENGTHS[j] / len;
        new[j] = std::array::from_fn(|a| new[parent][a] + d[a] * scale);
        let c = RIC.start + 3 * (j - 1);
        row[c..c + 3].copy_from_slice(&new[j]);
    }
}

/// The take and the hold weights of an edit on one device: [`Ctx::hold_x0`] for chains
/// that run elsewhere than the context's device.
#[derive(Clone)]
pub struct X0Hold {
    take: Tensor<3>,
    w: Tensor<3>,
}

impl X0Hold {
    /// x̂0 with the held frames and columns replaced by the take's (differentiable in x̂0).
    pub fn apply(&self, x0: Tensor<3>) -> Tensor<3> {
        x0.clone() + (self.take.clone() - x0) * self.w.clone()
    }
}

/// The steps of a chain, in the order they run: `first − 1` down to 0, except that with
/// `rounds` of resampling each block of [`RESAMPLE_JUMP`] steps (but the last) is run
/// `rounds` more times, the chain noised back up to the block's top before each rerun
/// (RePaint, Lugmayr et al. 2022, with jump length 10).
pub struct ChainSteps {
    next: usize,
    first: usize,
    rounds: usize,
    resampled: Vec<usize>,
    ran: usize,
}

impl ChainSteps {
    /// The steps of a chain that starts at `first`.
    pub fn new(first: usize, rounds: usize) -> Self {
        ChainSteps {
            next: first,
            first,
            rounds,
            resampled: vec![0; first / RESAMPLE_JUMP + 1],
            ran: 0,
        }
    }

    /// Steps the chain runs in all, reruns included.
    pub fn total(&self) -> usize {
        self.first
            + self.rounds
                * (self.first.saturating_sub(RESAMPLE_JUMP) / RESAMPLE_JUMP)
                * RESAMPLE_JUMP
    }

    /// Steps run so far.
    pub fn ran(&self) -> usize {
        self.ran
    }

    /// The index of the next step to run, or `None` at the end of the chain.
    pub fn next_step(&mut self) -> Option<usize> {
        self.next = self.next.checked_sub(1)?;
        self.ran += 1;
        Some(self.next)
    }

    /// `x` after the step just run, or noised back up to the top of its block when the
    /// block is due another round: `x_b = √(ᾱ_b/ᾱ_a)·x_a + √(1 − ᾱ_b/ᾱ_a)·ε`.
    pub fn after(
        &mut self,
        schedule: &NoiseSchedule,
        x: Tensor<3>,
        noise: &mut NoiseSource,
        device: &Device,
    ) -> Tensor<3> {
        let (i, jump) = (self.next, RESAMPLE_JUMP);
        if self.rounds == 0 || i == 0 || i % jump != 0 || i + jump > self.first {
            return x;
        }
        let block = &mut self.resampled[i / jump];
        if *block >= self.rounds {
            return x;
        }
        *block += 1;
        let ratio = schedule.alphas_cumprod[i + jump - 1] / schedule.alphas_cumprod[i - 1];
        self.next = i + jump;
        let dims = x.dims();
        x * ratio.sqrt() as f32 + noise.tensor(dims, device) * (1.0 - ratio).sqrt() as f32
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

    /// Where `latent`'s chain starts: the steps to run and z, x at the first of them.
    /// Without a take, or at strength 1: every step, from the seeded noise. With one: the
    /// take inverted by deterministic DDIM ([`Ctx::invert_take`]) to the strength's level,
    /// so the chain run from z gives back (close to) the take before any optimisation.
    pub fn latent_start(&self, schedule: &NoiseSchedule) -> (usize, Tensor<3>) {
        let n = schedule.len();
        match &self.edit {
            Some(edit) if edit.strength < 1.0 => {
                let k = ((edit.strength as f64 * n as f64).round() as usize).min(n);
                (k, self.invert_take(schedule, k))
            }
            _ => (n, self.initial_tensor(&self.device)),
        }
    }

    /// DDIM inversion (η = 0) of the take up to level `first − 1` of `schedule`, the x
    /// from which a DDIM chain of `first` steps returns to the take. Each step reads the
    /// model's x̂0 at the next level's timestep from the current x (the usual approximation,
    /// as in guided-diffusion's `ddim_reverse_sample` that DNO uses):
    /// `ε = (x − √ᾱᵢ·x̂0)/√(1 − ᾱᵢ)`, `x ← √ᾱᵢ₊₁·x̂0 + √(1 − ᾱᵢ₊₁)·ε`.
    /// `first` 0 is the take itself. The take's held frames and columns (`hold_x0`) are
    /// the take's own, so inverting them changes nothing.
    pub fn invert_take(&self, schedule: &NoiseSchedule, first: usize) -> Tensor<3> {
        let Some(edit) = &self.edit else {
            return self.initial_tensor(&self.device);
        };
        let den = self.denoiser();
        let cond = self.condition(&self.device);
        let mut x = edit.take.clone();
        for i in 0..first.saturating_sub(1) {
            let x0 = guided_x0(&den, x.clone(), schedule.timesteps[i], &cond);
            let (a, b) = (schedule.alphas_cumprod[i], schedule.alphas_cumprod[i + 1]);
            let eps = (x - x0.clone() * a.sqrt() as f32) / (1.0 - a).sqrt() as f32;
            x = x0 * b.sqrt() as f32 + eps * (1.0 - b).sqrt() as f32;
        }
        x
    }

    /// [`Ctx::hold_x0`] for a chain on `device` (an autodiff one for `latent`): the take
    /// and the hold weights moved there, or `None` when nothing is held.
    pub fn x0_hold_on(&self, device: &Device) -> Option<X0Hold> {
        let edit = self.edit.as_ref()?;
        let w = edit.hold.clone()?;
        Some(X0Hold {
            take: Tensor::from_data(edit.take.clone().into_data(), device),
            w: Tensor::from_data(w.into_data(), device),
        })
    }

    /// The order of a chain's steps from [`Ctx::chain_start`]'s `first`: straight down
    /// without a take, with the edit's resampling rounds when it has some.
    pub fn chain_steps(&self, first: usize) -> ChainSteps {
        let rounds = self.edit.as_ref().map_or(0, |e| e.resample);
        ChainSteps::new(first, rounds)
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

    /// Scales the change a step made, `before` → `after` over `[B·P, N, width]` rows, by
    /// each feature's `1 − w`, as [`Ctx::hold_step`] scales a step: for a change that is
    /// not a gradient step (`guide`'s skeleton projection). Free features keep `after`
    /// exactly; without a take nothing changes.
    pub fn hold_change(&self, before: &[f32], after: &mut [f32], width: usize) {
        let Some(edit) = self.edit.as_ref().filter(|e| !e.free.is_empty()) else {
            return;
        };
        edit.scaled.store(true, Ordering::Relaxed);
        let free = &edit.free;
        for (k, (row, old)) in after
            .chunks_exact_mut(width)
            .zip(before.chunks_exact(width))
            .enumerate()
        {
            let t = k % self.frames;
            let f = &free[t * FEATURE_DIM..t * FEATURE_DIM + width];
            for ((x, b), s) in row.iter_mut().zip(old).zip(f) {
                if *s < 1.0 {
                    *x = b + (*x - b) * s;
                }
            }
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
        let mut steps = self.chain_steps(first);
        while let Some(i) = steps.next_step() {
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
                SamplerKind::Consistency { .. } => consistency_step(&schedule, i, x0, &mut noise),
            };
            x = steps.after(&schedule, x, &mut noise, &self.device);
            progress(Progress {
                phase: Phase::Sampling,
                done: steps.ran(),
                total: steps.total(),
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

    #[test]
    fn a_seam_blend_of_two_poses_gets_its_bones_back() {
        use crate::skeleton::rest_pose;
        // The rest pose, and the same with the left arm swung up (about the shoulder).
        let a = rest_pose();
        let mut b = a;
        let turn = glam::Quat::from_rotation_z(1.5);
        for j in [18, 20] {
            b[j] = a[16] + turn * (a[j] - a[16]);
        }
        let row_of = |p: &[glam::Vec3; NUM_JOINTS]| {
            let mut row = vec![0.0f32; FEATURE_DIM];
            row[ROOT_Y.start] = p[0].y;
            for (c, v) in row[RIC].chunks_exact_mut(3).zip(&p[1..]) {
                c.copy_from_slice(&v.to_array());
            }
            row
        };
        let (ra, rb) = (row_of(&a), row_of(&b));
        let mut row: Vec<f32> = ra.iter().zip(&rb).map(|(x, y)| 0.5 * (x + y)).collect();
        let joint = |row: &[f32], j: usize| match j {
            0 => glam::Vec3::new(0.0, row[ROOT_Y.start], 0.0),
            _ => glam::Vec3::from_slice(&row[RIC.start + 3 * (j - 1)..RIC.start + 3 * j]),
        };
        let bone = |row: &[f32], j: usize| (joint(row, j) - joint(row, PARENTS[j])).length();
        assert!(
            (bone(&row, 20) - BONE_LENGTHS[20]).abs() > 0.05,
            "the blend is short"
        );
        let right_wrist = joint(&row, 21);
        rebuild_bones(&mut row, |j| j == 21);
        for (j, len) in BONE_LENGTHS.iter().enumerate().skip(1) {
            if j != 21 {
                assert!((bone(&row, j) - len).abs() < 1e-4, "joint {j}");
            }
        }
        assert_eq!(joint(&row, 21), right_wrist, "a held joint stays");
        // Between the two poses: the wrist's direction from the elbow is the blend's.
        let elbow = joint(&row, 18);
        let dir = (joint(&row, 20) - elbow).normalize();
        let want = ((a[20] - a[18]) + (b[20] - b[18])).normalize();
        assert!(dir.dot(want) > 0.999, "{dir} vs {want}");
    }

    #[test]
    fn untouched_time_is_held_short_of_what_the_program_reads() {
        let u = |s: &str| s.chars().map(|c| c == '.').collect::<Vec<bool>>();
        // Untouched runs at the motion's ends keep those ends; where they meet a read
        // frame they stop `margin` short of it.
        assert_eq!(untouched_ranges(&u("......xxxx......"), 2), [0..4, 12..16]);
        // A run between two windows loses the margin on both sides; one too short is free.
        assert_eq!(untouched_ranges(&u("xx......xx...xx"), 2), [4..6]);
        assert!(untouched_ranges(&u("xxxx"), 2).is_empty());
        assert_eq!(untouched_ranges(&u("...."), 2), [0..4]);
        assert_eq!(untouched_ranges(&u("..x"), 0), [0..2]);
        // Time holds and kept windows: the larger weight wins; empty is nothing held.
        assert_eq!(
            merge_holds(&[1.0, 0.5, 0.0], &[0.0, 0.75, 0.0]),
            [1.0, 0.75, 0.0]
        );
        assert_eq!(merge_holds(&[], &[0.5]), [0.5]);
        assert_eq!(merge_holds(&[0.5], &[]), [0.5]);
    }
}
