//! Long motions and prompt timelines: a motion longer than the model makes, or one whose
//! prompt changes over time, is made window by window with the editing machinery.
//!
//! * **Windows.** The timeline is cut where any person's prompt starts; each stretch is
//!   split into windows of at most the model's length. Every window after the first starts
//!   [`LongRequest::context`] frames before its first new frame and keeps those frames
//!   from the motion made so far: they are a take ([`Take::encode`] of the world joints,
//!   so the window stands where the motion is) held by MDM-style in-painting
//!   ([`super::edit`]), and the model continues them under the window's own prompt.
//! * **Actions at their own length.** A prompt whose training clips are shorter than the
//!   model's length ([`LongRequest::action_frames`], the bundle's median clip length of the
//!   nearest caption) gets windows no longer than that, context and blend included (at
//!   least [`MIN_ACTION_FRAMES`] new frames): "a person runs forward" is a run at its
//!   clips' 3.1 s (2.7 m/s) and a jog in one 7 s window (1.3–1.5 m/s), so a 6 s run span
//!   is made as three windows of 2 s new frames each.
//! * **Blends.** Each window runs on past the next one's first new frame (to the end of
//!   two prompts' written overlap, at least [`PROMPT_BLEND`] frames where the prompt
//!   changes, [`SEAM_BLEND`] where it continues), and the next window holds those frames
//!   with a weight that falls from 1 to 0 along a half cosine, flat at both ends: the new
//!   window takes over gradually.
//! * **Stitching.** Kept frames come back from the take's features, which re-targets the
//!   body to the model's skeleton: the stitched motion cross-fades from the motion so far
//!   to the new window over the kept frames, so the seam shows no pop.
//! * **Steering.** Each window's error is the whole program on the whole motion: the frames
//!   made so far (fixed), the window, and placeholders after it (its last pose, no
//!   gradient), with every statement counting only its frames before the window's end
//!   ([`MotionError::error_until`]). A constraint at 7 s and one at 19 s are each met by
//!   the window that makes their frames; a `during` across a seam is steered by both.
//!
//! The cost is one window solve per window: linear in the length, and memory stays that
//! of one window (plus the motion itself).

use super::edit::Edit;
use super::request::{Prior, Progress, SolveRequest, SolveResult};
use super::solver::Solver;
use super::take::Take;
use super::{MotionError, SolveError, solve};
use crate::features::FEATURE_DIM;
use crate::motion::Motion;
use crate::scene::Placement;
use crate::skeleton::NUM_JOINTS;
use burn::prelude::*;
use std::time::Instant;

/// Frames each window keeps from the motion before it, by default (1 s at 20 fps).
pub const DEFAULT_CONTEXT: usize = 20;

/// Resampling rounds of a window by default: none (measured in the book's timeline page:
/// the held context alone keeps the seams as smooth as the windows, and every round costs
/// a chain).
pub const DEFAULT_WINDOW_RESAMPLE: usize = 0;

/// Frames over which a new prompt takes over from the one before (at least; a longer
/// overlap of the two spans is used as written): the earlier window runs on this far under
/// its prompt, and the later one holds those frames with a weight falling from 1 to 0 (the
/// model switched actions within a frame or two without it: a 0.12 m/frame² head jump from
/// a walk into a run).
pub const PROMPT_BLEND: usize = 20;

/// Frames over which a window continuing the same prompt takes over from the one before
/// (the earlier window runs on this far, the later one fades them out). Measured: with 10
/// the guided seams of a walk jolted the head at 0.16–0.32 m/frame² (the guide's late
/// steps pull the free frames the fade lets go of too quickly); with 20, 0.083 against
/// 0.097 inside the windows (the book's timeline page).
pub const SEAM_BLEND: usize = 20;

/// The fewest new frames a window is cut to for a short action ([`LongRequest::action_frames`]).
pub const MIN_ACTION_FRAMES: usize = 40;

/// A prompt asked for over more than this multiple of its action's length is made in
/// windows of that length even where one window would hold it (`gen`): "a person jumps
/// up and down in place" over 8 s in one window never left the floor (lowest foot at most
/// 0.048 m, seeds 1 and 2); in windows of the jump's own length it jumped (0.30–0.31 m).
pub const ACTION_STRETCH: f32 = 1.5;

/// Whether some span of `timelines` is longer than [`ACTION_STRETCH`] × its prompt's
/// action ([`action_frames`]).
pub fn stretches_an_action(
    timelines: &[Vec<PromptSpan>],
    action_frames: &[(String, usize)],
) -> bool {
    timelines.iter().flatten().any(|span| {
        action_frames.iter().any(|(prompt, frames)| {
            *prompt == span.prompt && (span.to - span.from) as f32 > ACTION_STRETCH * *frames as f32
        })
    })
}

/// [`LongRequest::action_frames`] of every prompt of `timelines`: the model's proposal for
/// its length (the median length of its nearest caption's training clips), where the
/// bundle has one.
pub fn action_frames(
    text: &crate::model::prompt::PromptEncoder,
    timelines: &[Vec<PromptSpan>],
    max_frames: usize,
) -> Vec<(String, usize)> {
    let mut out: Vec<(String, usize)> = Vec::new();
    for span in timelines.iter().flatten() {
        if out.iter().any(|(p, _)| *p == span.prompt) {
            continue;
        }
        if let Some((frames, _)) = text.natural_frames(&span.prompt, max_frames) {
            out.push((span.prompt.clone(), frames));
        }
    }
    out
}

/// A take a long request edits (`mprog run --from` with a take longer than the model
/// makes, or with a prompt timeline): each window edits its stretch of the take, the frames
/// kept from the window before in front of it, with the whole edit's holds.
#[derive(Clone, Debug, PartialEq)]
pub struct LongTake {
    /// Per person, the take's world joints: the request's frames + 1 (F joint frames give
    /// F − 1 feature rows).
    pub people: Vec<Motion>,
    /// How far into each window's chain the take is noised ([`Edit::strength`]).
    pub strength: f32,
    /// Per frame of the whole motion, how firmly it is held to the take (empty: none), as
    /// [`Edit::hold`]: untouched time at 1.
    pub hold: Vec<f32>,
    /// [`Edit::hold_path`].
    pub hold_path: bool,
    /// [`Edit::hold_joints`].
    pub hold_joints: [bool; NUM_JOINTS],
    /// [`Edit::resample`], of every window.
    pub resample: usize,
}

impl LongTake {
    /// The long take of `edit` (its strength and holds), on the take's world joints
    /// `people`.
    pub fn of(edit: &Edit, people: Vec<Motion>) -> LongTake {
        LongTake {
            people,
            strength: edit.strength,
            hold: edit.hold.clone(),
            hold_path: edit.hold_path,
            hold_joints: edit.hold_joints,
            resample: edit.resample,
        }
    }
}

/// One prompt of a person's timeline: frames `[from, to)`.
#[derive(Clone, Debug, PartialEq)]
pub struct PromptSpan {
    /// First frame.
    pub from: usize,
    /// One past the last frame.
    pub to: usize,
    /// What the person does.
    pub prompt: String,
}

/// Each person's timeline for a motion of `frames`: the program's spans `(from, to,
/// prompt)` as written, a span to the program's `end` running on to `frames` (a take's
/// length wins over the program's); a person without spans has one prompt, `prompts[p]`,
/// for the whole motion.
pub fn timelines(
    spans: Vec<Vec<(usize, usize, String)>>,
    prompts: &[String],
    frames: usize,
    end: usize,
) -> Vec<Vec<PromptSpan>> {
    spans
        .into_iter()
        .zip(prompts)
        .map(|(line, prompt)| {
            if line.is_empty() {
                return vec![PromptSpan {
                    from: 0,
                    to: frames,
                    prompt: prompt.clone(),
                }];
            }
            line.into_iter()
                .map(|(from, to, prompt)| PromptSpan {
                    from,
                    to: if to >= end { to.max(frames) } else { to },
                    prompt,
                })
                .collect()
        })
        .collect()
}

/// A long motion or a timeline to solve.
#[derive(Clone, Debug, PartialEq)]
pub struct LongRequest {
    /// Per person, the prompts in time order, covering `0..frames` (consecutive spans may
    /// overlap: a blend).
    pub timelines: Vec<Vec<PromptSpan>>,
    /// Frames of the whole motion.
    pub frames: usize,
    /// Seed of the first window (later windows derive theirs from it).
    pub seed: u64,
    /// Independent samples, made one after another.
    pub samples: usize,
    /// Classifier-free guidance scale.
    pub guidance_scale: f32,
    /// World placement per person at frame 0.
    pub placements: Option<Vec<Placement>>,
    /// The solver of every window.
    pub solver: Solver,
    /// Frames each window keeps from the one before.
    pub context: usize,
    /// Foot cleanup of every window's new frames (as `gen` cleans its samples).
    pub clean_feet: bool,
    /// RePaint resampling rounds of every window after the first ([`Edit::resample`]);
    /// each round adds about the chain's length again.
    pub resample: usize,
    /// The take edited, if any: each window then edits its stretch of it.
    pub take: Option<LongTake>,
    /// Per prompt, the frames of its action (the median length of the training clips of
    /// its nearest caption): windows under it are no longer, context and blend included.
    /// Empty: every window as long as the model makes.
    pub action_frames: Vec<(String, usize)>,
}

impl LongRequest {
    /// One prompt per person for the whole motion.
    pub fn new(prompts: Vec<String>, frames: usize, seed: u64, solver: Solver) -> Self {
        LongRequest {
            timelines: prompts
                .into_iter()
                .map(|prompt| {
                    vec![PromptSpan {
                        from: 0,
                        to: frames,
                        prompt,
                    }]
                })
                .collect(),
            frames,
            seed,
            samples: 1,
            guidance_scale: 2.5,
            placements: None,
            solver,
            context: DEFAULT_CONTEXT,
            clean_feet: false,
            resample: DEFAULT_WINDOW_RESAMPLE,
            take: None,
            action_frames: Vec::new(),
        }
    }

    /// Whether this request needs windows: longer than the model makes, or a prompt that
    /// changes over time.
    pub fn needs_windows(&self, max_frames: usize) -> bool {
        self.frames > max_frames || self.timelines.iter().any(|t| t.len() > 1)
    }
}

/// One window of the plan.
#[derive(Clone, Debug, PartialEq)]
pub struct Window {
    /// First frame (the kept context starts here).
    pub start: usize,
    /// First new frame: `[start, cut)` is kept from the motion before.
    pub cut: usize,
    /// One past the last frame.
    pub end: usize,
    /// Per person, the prompt of the window.
    pub prompts: Vec<String>,
    /// Per frame of the window, how firmly it is held to the motion before (1: kept).
    pub hold: Vec<f32>,
}

impl Window {
    /// Frames of the window.
    pub fn len(&self) -> usize {
        self.end - self.start
    }

    /// Whether the window has no frames.
    pub fn is_empty(&self) -> bool {
        self.end == self.start
    }
}

/// Cuts a timeline into windows of at most `max_frames`, each after the first keeping
/// `context` frames of the one before and blending into it; under a prompt listed in
/// `action_frames`, windows no longer than that, context and blend included (at least
/// [`MIN_ACTION_FRAMES`] new frames). See the module docs.
pub fn plan_windows(
    timelines: &[Vec<PromptSpan>],
    frames: usize,
    max_frames: usize,
    context: usize,
    action_frames: &[(String, usize)],
) -> Result<Vec<Window>, SolveError> {
    let bad = |m: String| Err(SolveError::Invalid(m));
    if timelines.is_empty() {
        return bad("no prompt: give one timeline per person".into());
    }
    // Blends are at most an eighth of a window (the tests' tiny model makes 40 frames).
    let (seam_blend, prompt_blend) = (
        SEAM_BLEND.min(max_frames / 8),
        PROMPT_BLEND.min(max_frames / 8),
    );
    if context == 0 || context + seam_blend + 20 > max_frames {
        return bad(format!(
            "a window keeps {context} frames of the one before; give 1..={} so each window \
             has at least 1 s of new frames",
            max_frames.saturating_sub(20 + seam_blend)
        ));
    }
    for (p, line) in timelines.iter().enumerate() {
        let covered = line.first().is_some_and(|s| s.from == 0)
            && line.last().is_some_and(|s| s.to >= frames)
            && line
                .windows(2)
                .all(|w| w[1].from > w[0].from && w[1].from <= w[0].to)
            && line.iter().all(|s| s.from < s.to);
        if !covered {
            return bad(format!(
                "person {}'s prompts do not cover frames 0..{frames} in order",
                p + 1
            ));
        }
    }
    // Cuts: every frame where someone's prompt starts.
    let mut cuts: Vec<usize> = timelines
        .iter()
        .flatten()
        .map(|s| s.from)
        .filter(|&f| f < frames)
        .collect();
    cuts.push(0);
    cuts.sort_unstable();
    cuts.dedup();
    // The prompt of person p from frame `at` on: the latest span started by then.
    let prompt_at = |p: usize, at: usize| -> String {
        timelines[p]
            .iter()
            .rev()
            .find(|s| s.from <= at)
            .map(|s| s.prompt.clone())
            .unwrap_or_default()
    };
    // Frames the motion before a prompt cut runs on past it: the spans' own overlap, at
    // least PROMPT_BLEND.
    let blend_at = |cut: usize| -> usize {
        timelines
            .iter()
            .filter(|line| line.iter().any(|s| s.from == cut))
            .filter_map(|line| line.iter().rev().find(|s| s.from < cut))
            .map(|s| s.to.saturating_sub(cut))
            .max()
            .unwrap_or(0)
            .max(prompt_blend)
    };
    // New frames of each window, and the blend at its cut (its first new frames, made by
    // the window before under the earlier prompt and faded out).
    let mut parts: Vec<(usize, usize, usize)> = Vec::new();
    for (i, &cut) in cuts.iter().enumerate() {
        let next = cuts.get(i + 1).copied().unwrap_or(frames);
        let out_blend = if next < frames { blend_at(next) } else { 0 };
        let action = (0..timelines.len())
            .filter_map(|p| {
                let prompt = prompt_at(p, cut);
                action_frames
                    .iter()
                    .find(|(a, _)| *a == prompt)
                    .map(|&(_, f)| f)
            })
            .min()
            // The whole window (context, new frames, blend) as long as the action: with
            // only its new frames that long, a 6 s run span made 1.61 m/s, the walk held
            // before each window slowing it; this way 1.96 m/s.
            .map_or(usize::MAX, |f| {
                f.saturating_sub(context + prompt_blend + 1)
                    .max(MIN_ACTION_FRAMES)
            });
        // Every window but the very first keeps `context` frames; each runs on one frame
        // past its blend (a take of F frames has F − 1 feature rows).
        let capacity = max_frames
            .saturating_sub(context + out_blend.max(seam_blend) + 1)
            .min(action)
            .max(1);
        let total = next - cut;
        let count = total.div_ceil(capacity).max(1);
        for k in 0..count {
            let from = cut + total * k / count;
            let to = cut + total * (k + 1) / count;
            let blend = match (k, cut) {
                (_, 0) if k == 0 => 0,
                (0, _) => blend_at(cut),
                _ => seam_blend,
            };
            parts.push((from, to, blend));
        }
    }
    let mut windows = Vec::with_capacity(parts.len());
    for (k, &(from, to, blend)) in parts.iter().enumerate() {
        let start = from.saturating_sub(context);
        // Run on through the next window's blend.
        let end = parts
            .get(k + 1)
            .map_or(to, |&(_, _, next_blend)| to + next_blend + 1)
            .min(frames)
            .min(start + max_frames);
        let kept = from - start;
        let mut hold = vec![0.0f32; end - start];
        hold[..kept].fill(1.0);
        if kept > 0 {
            let fade = blend.min(end - from);
            for (j, h) in hold[kept..kept + fade].iter_mut().enumerate() {
                *h = fade_out(j, fade);
            }
        }
        let prompts = (0..timelines.len()).map(|p| prompt_at(p, from)).collect();
        windows.push(Window {
            start,
            cut: from,
            end,
            prompts,
            hold,
        });
    }
    Ok(windows)
}

/// Weight of frame `j` of a fade over `len` frames: from 1 to 0 along a half cosine, flat
/// at both ends, so the blend of the held frames into the new ones changes no velocity
/// abruptly (a linear fade left a kink at each end: 0.09–0.13 m/frame² jolts of the head).
fn fade_out(j: usize, len: usize) -> f32 {
    let s = (j + 1) as f32 / (len + 1) as f32;
    0.5 * (1.0 + (std::f32::consts::PI * s).cos())
}

/// The error a window steers by: the whole motion (the frames made so far, the window,
/// placeholders after it) under the program, counting frames before the window's end.
struct WindowError<'a> {
    inner: &'a dyn MotionError,
    /// `[people, start, 22, 3]` world joints made so far (flat).
    before: Vec<f32>,
    /// The same as a `[1, people, start, 22, 3]` tensor on the device last asked for: the
    /// guide evaluates the error thousands of times a window, and the frames made so far
    /// (up to 200 s of them) are the same every time.
    before_tensor: std::sync::Mutex<Option<Tensor<5>>>,
    people: usize,
    start: usize,
    frames: usize,
}

impl WindowError<'_> {
    fn whole(&self, window: Tensor<5>) -> (Tensor<5>, usize) {
        let [b, p, n, _, _] = window.dims();
        let device = window.device();
        let mut parts = Vec::with_capacity(3);
        if self.start > 0 {
            let mut cached = self.before_tensor.lock().unwrap_or_else(|e| e.into_inner());
            let before = match cached.as_ref().filter(|t| t.device() == device) {
                Some(t) => t.clone(),
                None => {
                    let t = Tensor::<5>::from_data(
                        TensorData::new(
                            self.before.clone(),
                            [1, self.people, self.start, NUM_JOINTS, 3],
                        ),
                        &device,
                    );
                    *cached = Some(t.clone());
                    t
                }
            };
            parts.push(before.expand([b, p, self.start, NUM_JOINTS, 3]));
        }
        let end = self.start + n;
        parts.push(window.clone());
        if end < self.frames {
            let last = window.narrow(2, n - 1, 1).detach();
            parts.push(last.expand([b, p, self.frames - end, NUM_JOINTS, 3]));
        }
        (Tensor::cat(parts, 2), end)
    }
}

impl MotionError for WindowError<'_> {
    fn error(&self, joints: Tensor<5>) -> Tensor<1> {
        let (whole, until) = self.whole(joints);
        self.inner.error_until(whole, until)
    }

    fn terms(&self, joints: Tensor<5>) -> Tensor<2> {
        let (whole, until) = self.whole(joints);
        self.inner.terms_until(whole, until)
    }
}

/// What a long solve is doing, for progress bars.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LongProgress {
    /// Window being made (0-based) and how many there are.
    pub window: usize,
    pub windows: usize,
    /// Sample being made and how many.
    pub sample: usize,
    pub samples: usize,
    /// The window's own progress.
    pub step: Progress,
}

impl LongProgress {
    /// Units done and in total over every window and sample (each window counted as the
    /// current one's units).
    pub fn overall(&self) -> (usize, usize) {
        let per = self.step.total.max(1);
        let before = self.sample * self.windows + self.window;
        (
            before * per + self.step.done,
            per * self.windows * self.samples,
        )
    }
}

/// A seed per window: the request's for the first, mixed for the others.
fn window_seed(seed: u64, sample: usize, window: usize) -> u64 {
    let s = seed.wrapping_add(sample as u64);
    if window == 0 {
        s
    } else {
        s ^ (window as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
    }
}

/// Solves a long request window by window (see the module docs). `error` is the whole
/// program on the whole motion.
pub fn solve_long(
    prior: &Prior,
    req: &LongRequest,
    error: &dyn MotionError,
    device: &Device,
    mut on_progress: impl FnMut(LongProgress),
) -> Result<SolveResult, SolveError> {
    let started = Instant::now();
    let windows = plan_windows(
        &req.timelines,
        req.frames,
        prior.max_frames,
        req.context,
        &req.action_frames,
    )?;
    if windows.len() > 1
        && let Some(why) = req.solver.edit_refusal()
    {
        return Err(SolveError::Invalid(format!(
            "solver `{}` cannot make a motion in windows (each window keeps the frames of \
             the one before, an edit): {why}; use guide, lbfgs, latent or plain",
            req.solver.name()
        )));
    }
    if req.samples == 0 {
        return Err(SolveError::Invalid(
            "0 samples asked; ask for at least 1".into(),
        ));
    }
    let people = req.timelines.len();
    if let Some(t) = &req.take {
        let fits = t.people.len() == people
            && t.people.iter().all(|m| m.len() == req.frames + 1)
            && (t.hold.is_empty() || t.hold.len() == req.frames);
        if !fits {
            return Err(SolveError::Invalid(format!(
                "the take to edit must have {people} people of {} frames (and a hold per frame)",
                req.frames + 1
            )));
        }
    }
    let mut motions = Vec::with_capacity(req.samples);
    let mut features = Vec::new();
    let mut placements = Vec::with_capacity(req.samples);
    let mut trace = Vec::new();
    let mut unknown_words: Vec<Vec<String>> = vec![Vec::new(); people];
    for sample in 0..req.samples {
        let mut made: Vec<Motion> = vec![Motion::new(Vec::new()); people];
        let mut rows: Vec<Vec<f32>> = vec![Vec::new(); people];
        let mut first_places = Vec::new();
        for (w, win) in windows.iter().enumerate() {
            let before: Vec<f32> = made
                .iter()
                .flat_map(|m| m.frames[..win.start].iter())
                .flat_map(|p| p.iter().flat_map(|v| v.to_array()))
                .collect();
            let window_error = WindowError {
                inner: error,
                before,
                before_tensor: Default::default(),
                people,
                start: win.start,
                frames: req.frames,
            };
            let edit = match &req.take {
                Some(take) => Some(take_edit(req, take, win, &made)?),
                None => window_edit(req, win, &made, prior.mean, w == 0)?,
            };
            // The frames kept from the window before, cross-faded when stitched.
            let held = win.hold.iter().take_while(|h| **h >= 1.0).count();
            let mut sreq = SolveRequest::new(
                win.prompts.clone(),
                win.len(),
                window_seed(req.seed, sample, w),
                req.solver.clone(),
            );
            sreq.guidance_scale = req.guidance_scale;
            sreq.placements = req.placements.clone();
            sreq.polish_edit = true;
            if let Some(e) = edit {
                sreq = sreq.editing(e);
            }
            let out = solve(prior, &sreq, &window_error, device, |step| {
                on_progress(LongProgress {
                    window: w,
                    windows: windows.len(),
                    sample,
                    samples: req.samples,
                    step,
                })
            })?;
            if w == 0 {
                first_places = out.placements[0].clone();
            }
            for (p, words) in out.unknown_words.iter().enumerate() {
                for word in words {
                    if !unknown_words[p].contains(word) {
                        unknown_words[p].push(word.clone());
                    }
                }
            }
            stitch(&mut made, &mut rows, win, held, &out);
            trace.extend(out.trace);
        }
        motions.push(made);
        for r in rows {
            features.extend(r);
        }
        placements.push(first_places);
    }
    // The whole program on the whole motions.
    let flat: Vec<f32> = motions.iter().flatten().flat_map(|m| m.to_flat()).collect();
    let joints = Tensor::<5>::from_data(
        TensorData::new(flat, [req.samples, people, req.frames, NUM_JOINTS, 3]),
        device,
    );
    let e = error.error(joints);
    let errors = e.into_data().try_to_vec::<f32>().unwrap_or_default();
    Ok(SolveResult {
        motions,
        features,
        placements,
        error: errors,
        trace,
        seconds: started.elapsed().as_secs_f64(),
        unknown_words,
    })
}

/// The edit of window `win`: the frames kept from the motion so far as a take, then the
/// model's mean features for the new frames (pure noise starts them: strength 1). The
/// first window edits nothing, unless feet are cleaned (an empty edit cleans them).
fn window_edit(
    req: &LongRequest,
    win: &Window,
    made: &[Motion],
    mean: &[f32],
    first: bool,
) -> Result<Option<Edit>, SolveError> {
    let n = win.len();
    if first {
        if !req.clean_feet {
            return Ok(None);
        }
        let places = req
            .placements
            .clone()
            .unwrap_or_else(|| Placement::defaults(made.len(), crate::scene::DEFAULT_SPACING));
        let take = Take {
            features: vec![mean.repeat(n); made.len()],
            placements: places,
            frames: n,
        };
        return Ok(Some(Edit {
            take,
            strength: 1.0,
            hold: Vec::new(),
            hold_path: false,
            hold_joints: [false; NUM_JOINTS],
            resample: 0,
            clean_feet: true,
        }));
    }
    // Joint frames [start, have) give have − start − 1 feature rows (as HumanML3D's
    // extraction does): frames start..have-1 of the take.
    let have = made[0].len().min(win.end);
    let parts: Vec<Motion> = made
        .iter()
        .map(|m| Motion {
            frames: m.frames[win.start..have].to_vec(),
            fps: m.fps,
        })
        .collect();
    let mut take = Take::encode(&parts).map_err(|e| {
        SolveError::Invalid(format!("cannot encode frames {}..{have}: {e}", win.start))
    })?;
    let rows = take.frames.min(n);
    for f in &mut take.features {
        f.truncate(rows * FEATURE_DIM);
        for _ in rows..n {
            f.extend_from_slice(mean);
        }
    }
    take.frames = n;
    // Only frames the take has can be held.
    let mut hold = win.hold.clone();
    hold[rows..].fill(0.0);
    Ok(Some(Edit {
        take,
        strength: 1.0,
        hold,
        hold_path: false,
        hold_joints: [false; NUM_JOINTS],
        resample: req.resample,
        clean_feet: req.clean_feet,
    }))
}

/// The edit of window `win` of a long take: the frames kept from the motion so far, then
/// the take's own frames, held as the window's blend and the whole edit's holds say
/// (whichever holds more), noised as far as the edit's strength.
fn take_edit(
    req: &LongRequest,
    take: &LongTake,
    win: &Window,
    made: &[Motion],
) -> Result<Edit, SolveError> {
    let n = win.len();
    let have = made[0].len().clamp(win.start, win.end);
    let parts: Vec<Motion> = made
        .iter()
        .zip(&take.people)
        .map(|(m, t)| Motion {
            frames: [&m.frames[win.start..have], &t.frames[have..=win.end]].concat(),
            fps: t.fps,
        })
        .collect();
    let encoded = Take::encode(&parts).map_err(|e| {
        SolveError::Invalid(format!(
            "cannot encode the take's frames {}..{}: {e}",
            win.start, win.end
        ))
    })?;
    let hold: Vec<f32> = (0..n)
        .map(|j| {
            let edit = take.hold.get(win.start + j).copied().unwrap_or(0.0);
            win.hold[j].max(edit)
        })
        .collect();
    let hold = if hold.iter().all(|h| *h == 0.0) {
        Vec::new()
    } else {
        hold
    };
    Ok(Edit {
        take: encoded,
        strength: take.strength,
        hold,
        hold_path: take.hold_path,
        hold_joints: take.hold_joints,
        resample: take.resample,
        clean_feet: req.clean_feet,
    })
}

/// Puts a window's motion into the motion so far: cross-faded over the frames it kept
/// (they come back re-targeted, a few millimetres off), its own from the cut on.
fn stitch(
    made: &mut [Motion],
    rows: &mut [Vec<f32>],
    win: &Window,
    exact: usize,
    out: &SolveResult,
) {
    let n = win.len();
    for (p, motion) in made.iter_mut().enumerate() {
        let new = &out.motions[0][p];
        let keep = motion.len().min(win.start + exact);
        motion.frames.truncate(keep);
        for t in 0..n {
            let g = win.start + t;
            let pose = if g < keep {
                // Cross-fade over the exact kept frames: 0 → 1.
                let a = (t + 1) as f32 / (exact + 1) as f32;
                let old = motion.frames[g];
                std::array::from_fn(|j| old[j].lerp(new.frames[t][j], a))
            } else {
                new.frames[t]
            };
            if g < keep {
                motion.frames[g] = pose;
            } else {
                motion.frames.push(pose);
            }
        }
        let feat = &out.features[p * n * FEATURE_DIM..(p + 1) * n * FEATURE_DIM];
        rows[p].truncate(win.start * FEATURE_DIM);
        rows[p].extend_from_slice(feat);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solve::GuideConfig;
    use crate::solve::tests::tiny_bundle;

    fn span(from: usize, to: usize, prompt: &str) -> PromptSpan {
        PromptSpan {
            from,
            to,
            prompt: prompt.into(),
        }
    }

    /// Every frame is made by some window, windows fit the model, and each after the first
    /// keeps `context` frames of the motion made before it.
    fn check_plan(windows: &[Window], frames: usize, max: usize, context: usize) {
        assert_eq!(windows[0].start, 0);
        assert_eq!(windows[0].cut, 0);
        assert_eq!(windows.last().unwrap().end, frames);
        for pair in windows.windows(2) {
            let (a, b) = (&pair[0], &pair[1]);
            assert!(b.cut > a.cut && b.cut <= a.end, "{a:?} then {b:?}");
            assert_eq!(b.cut - b.start, context);
            assert!(b.start >= a.start);
        }
        for w in windows {
            assert!(w.len() <= max && w.end > w.cut, "{w:?}");
            assert_eq!(w.hold.len(), w.len());
            assert!(w.hold[..w.cut - w.start].iter().all(|&h| h > 0.0));
            assert!(w.hold.windows(2).all(|h| h[1] <= h[0]), "hold falls: {w:?}");
        }
    }

    #[test]
    fn a_short_action_gets_windows_of_its_own_length() {
        let line = vec![vec![
            span(0, 140, "a person walks forward"),
            span(140, 260, "a person runs forward"),
        ]];
        let plain = plan_windows(&line, 260, 196, 20, &[]).unwrap();
        let actions = [("a person runs forward".to_string(), 62)];
        let w = plan_windows(&line, 260, 196, 20, &actions).unwrap();
        check_plan(&w, 260, 196, 20);
        assert_eq!(plain.len(), 2, "the walk, then the 6 s run in one window");
        assert_eq!(
            w.len(),
            4,
            "the walk, then the run as three windows of 2 s new frames"
        );
        assert_eq!((w[1].cut, w[2].cut, w[3].cut), (140, 180, 220));
        // 62 − context − blend − 1 is under MIN_ACTION_FRAMES: 40 new frames a window.
        assert_eq!(w[3].cut - w[2].cut, MIN_ACTION_FRAMES);
        // Never under MIN_ACTION_FRAMES new frames, and no change for a long action.
        let tiny = [("a person runs forward".to_string(), 5)];
        assert_eq!(plan_windows(&line, 260, 196, 20, &tiny).unwrap().len(), 4);
        let long = [("a person walks forward".to_string(), 196)];
        assert_eq!(plan_windows(&line, 260, 196, 20, &long).unwrap(), plain);
    }

    #[test]
    fn a_long_motion_is_cut_into_windows_that_keep_the_second_before() {
        let line = vec![vec![span(0, 600, "a person walks forward")]];
        let w = plan_windows(&line, 600, 196, 20, &[]).unwrap();
        check_plan(&w, 600, 196, 20);
        assert_eq!(w.len(), 4, "600 frames at 155 new frames a window");
        // Each window runs on SEAM_BLEND frames; the next fades them out, flat at both ends.
        assert_eq!(w[0].end, w[1].cut + SEAM_BLEND + 1);
        let h = &w[1].hold;
        assert_eq!(h[..20], [1.0; 20]);
        assert!(
            h[20] < 1.0 && h[20] > 0.99 && h[39] > 0.0 && h[39] < 0.01,
            "{h:?}"
        );
        assert_eq!(h[40], 0.0);
    }

    #[test]
    fn a_timeline_cuts_where_a_prompt_starts_and_blends_its_overlap() {
        // walk 0–8.5 s, jog 7.5–14 s (a 1 s overlap, written), sit 14–20 s (touching).
        let line = vec![vec![
            span(0, 170, "walk"),
            span(150, 280, "jog"),
            span(280, 400, "sit"),
        ]];
        let w = plan_windows(&line, 400, 196, 20, &[]).unwrap();
        check_plan(&w, 400, 196, 20);
        let prompts: Vec<&str> = w.iter().map(|w| w.prompts[0].as_str()).collect();
        assert_eq!(prompts, ["walk", "jog", "sit"]);
        // The walk runs on through the overlap; the jog holds it fading out.
        assert_eq!((w[0].end, w[1].cut, w[1].start), (171, 150, 130));
        let fade = &w[1].hold[20..40];
        assert!(
            fade[0] > 0.9 && fade[19] > 0.0 && fade[19] < 0.1,
            "{fade:?}"
        );
        assert_eq!(w[1].hold[40], 0.0);
        // Touching spans still blend over PROMPT_BLEND frames.
        assert_eq!(
            (w[1].end, w[2].start, w[2].cut),
            (281 + PROMPT_BLEND, 260, 280)
        );
    }

    #[test]
    fn people_with_their_own_timelines_share_the_cuts() {
        let lines = vec![
            vec![span(0, 100, "walk"), span(100, 200, "wave")],
            vec![span(0, 150, "stand"), span(150, 200, "sit")],
        ];
        let w = plan_windows(&lines, 200, 196, 20, &[]).unwrap();
        check_plan(&w, 200, 196, 20);
        let pairs: Vec<(usize, [&str; 2])> = w
            .iter()
            .map(|w| (w.cut, [w.prompts[0].as_str(), w.prompts[1].as_str()]))
            .collect();
        assert_eq!(
            pairs,
            [
                (0, ["walk", "stand"]),
                (100, ["wave", "stand"]),
                (150, ["wave", "sit"])
            ]
        );
    }

    #[test]
    fn bad_timelines_are_refused() {
        let gap = vec![vec![span(0, 50, "a"), span(60, 100, "b")]];
        assert!(plan_windows(&gap, 100, 196, 20, &[]).is_err());
        let short = vec![vec![span(0, 50, "a")]];
        assert!(plan_windows(&short, 100, 196, 20, &[]).is_err());
        let ok = vec![vec![span(0, 100, "a")]];
        assert!(
            plan_windows(&ok, 100, 196, 190, &[]).is_err(),
            "context leaves no new frames"
        );
        assert!(plan_windows(&[], 100, 196, 20, &[]).is_err());
    }

    /// Right wrist at least 1.6 m up on frame `frame`, counting only frames before `until`.
    struct WristUpAt(usize);

    impl MotionError for WristUpAt {
        fn error(&self, j: Tensor<5>) -> Tensor<1> {
            let n = j.dims()[2];
            self.error_until(j, n)
        }

        fn error_until(&self, j: Tensor<5>, until: usize) -> Tensor<1> {
            let b = j.dims()[0];
            if self.0 >= until {
                return Tensor::zeros([b], &j.device());
            }
            let y = j.narrow(2, self.0, 1).narrow(3, 21, 1).narrow(4, 1, 1);
            (y.neg() + 1.6).clamp_min(0.0).reshape([b])
        }
    }

    /// Keyframes in the first and the last window, each met by the window that makes it.
    struct Both(WristUpAt, WristUpAt);

    impl MotionError for Both {
        fn error(&self, j: Tensor<5>) -> Tensor<1> {
            self.0.error(j.clone()) + self.1.error(j)
        }

        fn error_until(&self, j: Tensor<5>, until: usize) -> Tensor<1> {
            self.0.error_until(j.clone(), until) + self.1.error_until(j, until)
        }
    }

    #[test]
    fn a_long_guided_motion_meets_keyframes_in_its_first_and_last_windows_without_seams() {
        let bundle = tiny_bundle();
        let prior = Prior::from_bundle(&bundle);
        let solver = Solver::new(GuideConfig {
            steps: 40,
            k_late: 30,
            late_steps: 5,
            ..GuideConfig::default()
        });
        let mut req = LongRequest::new(vec!["a person walks forward".into()], 90, 3, solver);
        req.context = 10;
        let error = Both(WristUpAt(8), WristUpAt(80));
        let mut windows = 0;
        let out = solve_long(&prior, &req, &error, &Device::flex(), |p| {
            windows = p.windows
        })
        .unwrap();
        assert_eq!(
            windows, 4,
            "90 frames in windows of 40 keeping 10, blending 5"
        );
        let m = &out.motions[0][0];
        assert_eq!(m.len(), 90);
        assert!(out.error[0] < 0.05, "both keyframes met: {:?}", out.error);
        assert!(m.frames[8][21].y > 1.55 && m.frames[80][21].y > 1.55);
        // The seams are as smooth as the windows: the largest pelvis step across a seam
        // is no larger than twice the largest inside the windows.
        let plan = plan_windows(&req.timelines, 90, 40, 10, &[]).unwrap();
        let step = |t: usize| (m.frames[t + 1][0] - m.frames[t][0]).length();
        let seams: Vec<usize> = plan[1..].iter().flat_map(|w| w.start..w.cut + 2).collect();
        let seam = seams.iter().map(|&t| step(t)).fold(0.0, f32::max);
        let inside = (0..89)
            .filter(|t| !seams.contains(t))
            .map(step)
            .fold(0.0, f32::max);
        assert!(
            seam <= 2.0 * inside + 1e-3,
            "seam step {seam} vs inside {inside}"
        );
    }

    /// A take longer than the model makes, edited in windows: the time the edit holds stays
    /// the take's, the keyframe in the last window is met.
    #[test]
    fn a_long_take_is_edited_in_windows_keeping_its_untouched_time() {
        let bundle = tiny_bundle();
        let prior = Prior::from_bundle(&bundle);
        // A rest pose walking 4 cm a frame, arms swinging, 90 frames.
        let walk = Motion::new(
            (0..90)
                .map(|t| {
                    let mut p = crate::skeleton::rest_pose();
                    let swing = 0.15 * (t as f32 * 0.4).sin();
                    p[20].z += swing;
                    p[21].z -= swing;
                    p.map(|v| v + glam::Vec3::new(0.5, 0.0, 0.04 * t as f32))
                })
                .collect(),
        );
        let take = vec![walk];
        // What the take is on the model's skeleton (an edit keeps that).
        let want = Take::encode(&take).unwrap().motions().unwrap().remove(0);
        let solver = Solver::new(GuideConfig {
            steps: 40,
            k_late: 30,
            late_steps: 5,
            ..GuideConfig::default()
        });
        let mut req = LongRequest::new(vec!["a person walks forward".into()], 89, 3, solver);
        req.context = 10;
        // Frames 0..50 untouched, eased out over 5 frames; the rest free.
        let mut hold = vec![0.0; 89];
        hold[..50].fill(1.0);
        for (j, h) in hold[50..55].iter_mut().enumerate() {
            *h = fade_out(j, 5);
        }
        req.take = Some(LongTake {
            people: take.clone(),
            strength: 0.7,
            hold,
            hold_path: false,
            hold_joints: [false; NUM_JOINTS],
            resample: 0,
        });
        let error = WristUpAt(80);
        let mut windows = 0;
        let out = solve_long(&prior, &req, &error, &Device::flex(), |p| {
            windows = p.windows
        })
        .unwrap();
        assert!(windows > 2, "{windows} windows");
        let m = &out.motions[0][0];
        assert_eq!(m.len(), 89);
        assert!(out.error[0] < 0.05, "the keyframe is met: {:?}", out.error);
        let worst = (0..45)
            .flat_map(|t| (0..NUM_JOINTS).map(move |j| (t, j)))
            .map(|(t, j)| m.frames[t][j].distance(want.frames[t][j]))
            .fold(0.0, f32::max);
        assert!(worst < 0.02, "untouched time moved {worst} m");
        let moved = m.frames[80][21].distance(want.frames[80][21]);
        println!("untouched time within {worst} m; frame 80's wrist moved {moved} m");
        assert!(moved > 0.05, "the edited time is edited ({moved} m)");
        // A take that does not fit the request is refused.
        req.frames = 60;
        let e = solve_long(&prior, &req, &error, &Device::flex(), |_| {}).unwrap_err();
        assert!(e.to_string().contains("the take to edit"), "{e}");
    }

    #[test]
    fn the_same_long_request_gives_the_same_motion() {
        let bundle = tiny_bundle();
        let prior = Prior::from_bundle(&bundle);
        let mut req = LongRequest::new(
            vec!["a person waves".into()],
            70,
            5,
            Solver::plain(crate::model::sampler::SamplerKind::Ddim(10)),
        );
        req.context = 10;
        req.clean_feet = true;
        let zero = |j: Tensor<5>| Tensor::<1>::zeros([j.dims()[0]], &j.device());
        let a = solve_long(&prior, &req, &zero, &Device::flex(), |_| {}).unwrap();
        let b = solve_long(&prior, &req, &zero, &Device::flex(), |_| {}).unwrap();
        assert_eq!(a.motions, b.motions);
        assert_eq!(a.motions[0][0].len(), 70);
        assert_eq!(a.features.len(), 70 * FEATURE_DIM);
    }

    #[test]
    fn solvers_that_cannot_edit_refuse_windows() {
        let bundle = tiny_bundle();
        let solver = Solver::by_name("ik").unwrap();
        let mut req = LongRequest::new(vec!["a person waves".into()], 70, 5, solver);
        req.context = 10;
        let zero = |j: Tensor<5>| Tensor::<1>::zeros([j.dims()[0]], &j.device());
        let e = solve_long(
            &Prior::from_bundle(&bundle),
            &req,
            &zero,
            &Device::flex(),
            |_| {},
        )
        .unwrap_err();
        assert!(
            e.to_string().contains("cannot make a motion in windows"),
            "{e}"
        );
    }
}
