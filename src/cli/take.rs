//! `mprog run --from take.bvh`: the flags that edit a take, read and checked before the
//! model loads. In: [`TakeArgs`] and the program. Out: a [`TakePlan`] (the take's people,
//! the windows, the strength and the provenance written into the outputs' meta), and, with
//! the model's statistics, the library's [`Edit`].
//!
//! Frames on the command line count the edit's frames: a take of F frames gives F − 1
//! (HumanML3D's features drop the last frame), numbered 0 to F − 2.

use burn::tensor::Device;
use miette::{Result, miette};
use mprog::formats::{LoadedMotion, Meta, read_motion};
use mprog::lang::Program;
use mprog::motion::Motion;
use mprog::solve::take::frames_of;
use mprog::solve::{
    DEFAULT_BLEND, DEFAULT_RESAMPLE, DEFAULT_STRENGTH, Edit, TIME_MARGIN, Take, auto_hold,
    hold_weights, merge_holds, parts_joints,
};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// Frames of each take kept around the gap of an in-between when `--context` is not given.
pub const DEFAULT_CONTEXT: usize = 20;

/// Flags of `mprog run` that edit a take.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct TakeArgs {
    /// Edit this take (.bvh, .npy, .json) instead of generating from noise: it is
    /// retargeted to the model's skeleton, noised to `--strength` and denoised with the
    /// program's guidance. The take sets the length and where each person stands.
    #[arg(long, value_name = "TAKE")]
    pub from: Option<PathBuf>,
    /// 0…1: how much of the take the model may change (0 returns the take, 1 ignores it).
    #[arg(
        long,
        requires = "from",
        value_name = "S",
        allow_negative_numbers = true
    )]
    pub strength: Option<f32>,
    /// Frames `a..b` (`a..`, `..b`) held to the take at every step (in-painting);
    /// repeatable.
    #[arg(long, requires = "from", value_name = "A..B", value_parser = parse_range, conflicts_with = "edit")]
    pub keep: Vec<RangeArg>,
    /// The inverse of `--keep`: only frames `a..b` change; the rest is held to the take.
    #[arg(long, requires = "from", value_name = "A..B", value_parser = parse_range)]
    pub edit: Option<RangeArg>,
    /// Hold the take's path (root position and facing) on every frame. By default the path
    /// is held when the program's error does not change as the take moves sideways (a
    /// program about the body's own shape), and free otherwise.
    #[arg(long, requires = "from", conflicts_with_all = ["to", "free_path"])]
    pub keep_path: bool,
    /// Let the path change even when the program is only about the body's shape.
    #[arg(long, requires = "from", conflicts_with = "to")]
    pub free_path: bool,
    /// Let every body part change. By default the parts the program does not touch (torso,
    /// head, each arm, each leg) keep the take's motion: a hand program leaves the legs, and
    /// so the gait and the planted feet, as they were.
    #[arg(long, requires = "from", conflicts_with = "to")]
    pub free_body: bool,
    /// Let every frame change. By default the frames no statement reads (outside every
    /// window of the program) keep the take's motion, easing into the edit over
    /// `--time-margin` frames before the first frame the program reads and after its last.
    #[arg(long, requires = "from", conflicts_with = "to")]
    pub free_time: bool,
    /// Frames of untouched time next to the program's windows that ease from the take into
    /// the edit (they may change; the frames the program reads are free).
    #[arg(long, requires = "from", conflicts_with_all = ["to", "free_time"], value_name = "FRAMES", default_value_t = TIME_MARGIN)]
    pub time_margin: usize,
    /// RePaint resampling rounds at the seams of kept frames (default 5 when frames are kept
    /// or an in-between is made, 0 otherwise); each round reruns the chain's steps once.
    #[arg(long, requires = "from", value_name = "ROUNDS")]
    pub resample: Option<usize>,
    /// Frames over which a kept window blends into the edited one at each seam.
    #[arg(long, requires = "from", value_name = "FRAMES", default_value_t = DEFAULT_BLEND)]
    pub blend: usize,
    /// Use only frames `a..b` of the take file (before encoding), e.g. to fit the model's
    /// longest motion.
    #[arg(long, requires = "from", value_name = "A..B", value_parser = parse_range)]
    pub take_frames: Option<RangeArg>,
    /// In-betweening: start with the end of `--from`, end with the start of this take,
    /// and generate the gap; the program's `length` is the whole motion.
    #[arg(long, requires = "from", value_name = "TAKE", conflicts_with_all = ["keep", "edit", "strength", "take_frames"])]
    pub to: Option<PathBuf>,
    /// Frames of each take an in-between keeps (the end of `--from`, the start of `--to`).
    #[arg(long, requires = "to", value_name = "FRAMES", default_value_t = DEFAULT_CONTEXT)]
    pub context: usize,
}

/// A frame range from the command line; open ends are `None`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RangeArg {
    pub start: Option<usize>,
    pub end: Option<usize>,
}

impl RangeArg {
    /// The range within `frames` frames, or an error naming the flag when it leaves them
    /// or is empty.
    fn resolve(&self, flag: &str, frames: usize, what: &str) -> Result<Range<usize>> {
        let (a, b) = (self.start.unwrap_or(0), self.end.unwrap_or(frames));
        if b > frames || a >= b {
            return Err(miette!(
                help = format!("use frames within 0..{frames}"),
                "{flag} {self} is outside the take: {what} has {frames} frames (0..{frames})"
            ));
        }
        Ok(a..b)
    }
}

impl std::fmt::Display for RangeArg {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let show = |v: Option<usize>| v.map_or(String::new(), |v| v.to_string());
        write!(f, "{}..{}", show(self.start), show(self.end))
    }
}

/// Parses `a..b`, `a..` or `..b` (frames).
pub fn parse_range(s: &str) -> Result<RangeArg, String> {
    let (a, b) = s
        .split_once("..")
        .ok_or_else(|| format!("expected a frame range A..B, got `{s}`"))?;
    let num = |v: &str| -> Result<Option<usize>, String> {
        let v = v.trim();
        if v.is_empty() {
            return Ok(None);
        }
        v.parse()
            .map(Some)
            .map_err(|_| format!("`{v}` is not a frame number"))
    };
    Ok(RangeArg {
        start: num(a)?,
        end: num(b)?,
    })
}

/// A take file read and checked, and what to do with it.
pub struct TakePlan {
    /// Per person, the take (the `--take-frames` part, or an in-between's two ends).
    pub people: Vec<Motion>,
    /// The `--to` take's people (in-betweening).
    pub after: Option<Vec<Motion>>,
    /// 0…1.
    pub strength: f32,
    /// Kept frame ranges of the edit.
    pub keep: Vec<Range<usize>>,
    /// Frames of the edit.
    pub frames: usize,
    /// Blend frames at each seam.
    pub blend: usize,
    /// Hold the take's path on every frame: `Some` when a flag says so, `None` to decide by
    /// the program ([`auto_hold`]).
    pub keep_path: Option<bool>,
    /// Hold the body parts the program does not touch.
    pub hold_body: bool,
    /// Hold the frames no statement reads (not for an in-between: its gap is no take).
    pub hold_time: bool,
    /// Frames of untouched time that ease into the edit at each seam.
    pub time_margin: usize,
    /// Resampling rounds.
    pub resample: usize,
    /// Provenance for the outputs' meta.
    pub meta: Meta,
}

/// SHA-256 of a file, hex.
fn sha256(path: &Path) -> Result<String> {
    mprog::fsutil::sha256_hex(path)
        .map_err(|e| miette!("cannot read the take {}: {e}", path.display()))
}

/// The people of a take file, with its hash.
fn read_take(path: &Path, people: usize) -> Result<(Vec<Motion>, String)> {
    let hash = sha256(path)?;
    let loaded =
        read_motion(path).map_err(|e| miette!("cannot read the take {}: {e}", path.display()))?;
    let motions: Vec<Motion> = match loaded {
        LoadedMotion::Joints { people, .. } => people.into_iter().map(|p| p.motion).collect(),
        LoadedMotion::Features(array) => {
            vec![mprog::features::recover_from_ric(&array.data).map_err(|e| {
                miette!(
                    "cannot read the take {}: HumanML3D features: {e}",
                    path.display()
                )
            })?]
        }
    };
    if motions.len() != people {
        return Err(miette!(
            help = "give a take with one motion per person of the program (a .json or [P,N,22,3] .npy holds several)",
            "the take {} holds {} {}; the program has {people}",
            path.display(),
            motions.len(),
            if motions.len() == 1 {
                "person"
            } else {
                "people"
            },
        ));
    }
    let frames = motions.iter().map(Motion::len).min().unwrap_or(0);
    if frames < 3 {
        return Err(miette!(
            "the take {} has {frames} frames; an edit needs at least 3",
            path.display()
        ));
    }
    if motions.iter().any(|m| m.len() != frames) {
        return Err(miette!(
            "the people of the take {} have different frame counts",
            path.display()
        ));
    }
    Ok((motions, hash))
}

/// Most resampling rounds `--resample` takes: each round reruns the chain once.
pub const MAX_RESAMPLE: usize = 20;

/// `--resample`, or `default`; refused above [`MAX_RESAMPLE`].
fn resample_rounds(args: &TakeArgs, default: usize) -> Result<usize> {
    let rounds = args.resample.unwrap_or(default);
    if rounds > MAX_RESAMPLE {
        return Err(miette!(
            help = format!(
                "each round reruns the chain once; {DEFAULT_RESAMPLE} closes the seams of a walk→run in-between"
            ),
            "--resample {rounds} is more than {MAX_RESAMPLE} rounds"
        ));
    }
    Ok(rounds)
}

/// Checks the flags against the take files and the program, before the model loads.
/// `max_frames`: the model's longest motion.
pub fn plan(args: &TakeArgs, program: &Program, max_frames: usize) -> Result<Option<TakePlan>> {
    let Some(from) = &args.from else {
        return Ok(None);
    };
    let strength = args.strength.unwrap_or(DEFAULT_STRENGTH);
    if !(strength.is_finite() && (0.0..=1.0).contains(&strength)) {
        return Err(miette!(
            help = "0 returns the take, 1 generates from noise as without --from",
            "--strength {strength} is outside 0…1"
        ));
    }
    let count = program.people().len().max(1);
    let (mut people, hash) = read_take(from, count)?;
    let mut meta = Meta::new();
    meta.insert("take".into(), from.display().to_string().into());
    meta.insert("take_sha256".into(), hash.into());
    if let Some(to) = &args.to {
        return plan_between(args, program, max_frames, people, to, meta).map(Some);
    }
    if let Some(r) = args.take_frames {
        let window = r.resolve("--take-frames", people[0].len(), "the take file")?;
        people = people
            .iter()
            .map(|m| frames_of(m, window.start, window.end).expect("checked range"))
            .collect();
        meta.insert(
            "take_frames".into(),
            serde_json::json!([window.start, window.end]),
        );
    }
    let frames = people[0].len() - 1;
    // Longer than the model makes: edited in windows (`solve::long`), up to a program's
    // longest motion.
    let longest = mprog::lang::check::MAX_LENGTH;
    if frames > longest {
        return Err(miette!(
            help = format!(
                "pick a part with --take-frames a..b (at most {} frames)",
                longest + 1
            ),
            "the take {} gives {frames} frames; a motion is at most {longest} ({} s)",
            from.display(),
            longest / 20
        ));
    }
    let keep = match (&args.edit, args.keep.as_slice()) {
        (Some(e), _) => {
            let e = e.resolve("--edit", frames, "the edit")?;
            [0..e.start, e.end..frames]
                .into_iter()
                .filter(|r| !r.is_empty())
                .collect()
        }
        (None, ks) => ks
            .iter()
            .map(|k| k.resolve("--keep", frames, "the edit"))
            .collect::<Result<Vec<_>>>()?,
    };
    if program.length() != frames {
        eprintln!(
            "warning: the program's `length` is {} frames and the take gives {frames}; the take's length wins (times in % and `end` follow it, frame numbers and seconds stay where they are)",
            program.length()
        );
    }
    meta.insert("strength".into(), f64::from(strength).into());
    meta.insert("kept_frames".into(), ranges_json(&keep));
    meta.insert(
        "edited_frames".into(),
        ranges_json(&complement(&keep, frames)),
    );
    meta.insert("blend".into(), args.blend.into());
    let resample = resample_rounds(args, if keep.is_empty() { 0 } else { DEFAULT_RESAMPLE })?;
    meta.insert("resample".into(), resample.into());
    Ok(Some(TakePlan {
        people,
        after: None,
        strength,
        keep,
        frames,
        blend: args.blend,
        keep_path: match (args.keep_path, args.free_path) {
            (true, _) => Some(true),
            (_, true) => Some(false),
            _ => None,
        },
        hold_body: !args.free_body,
        hold_time: !args.free_time,
        time_margin: args.time_margin,
        resample,
        meta,
    }))
}

/// `--from A --to B`: A's last `context` frames, a gap, B's first `context` frames.
fn plan_between(
    args: &TakeArgs,
    program: &Program,
    max_frames: usize,
    before: Vec<Motion>,
    to: &Path,
    mut meta: Meta,
) -> Result<TakePlan> {
    let count = before.len();
    let (after, hash) = read_take(to, count)?;
    let c = args.context;
    let frames = program.length();
    if frames > max_frames {
        return Err(miette!(
            "the program's length is {frames} frames; this model generates at most {max_frames}"
        ));
    }
    if c == 0 || 2 * c >= frames {
        return Err(miette!(
            help = "lower --context or lengthen the program",
            "--context {c} leaves no gap: the in-between is {frames} frames (the program's length) and keeps {c} at each end"
        ));
    }
    for (flag, path, people) in [
        ("--from", &args.from, &before),
        ("--to", &Some(to.to_path_buf()), &after),
    ] {
        if people[0].len() < c + 1 {
            return Err(miette!(
                help = "lower --context",
                "{flag} {}: {} frames; an in-between keeping {c} frames of it needs {}",
                path.as_ref()
                    .map_or(String::new(), |p| p.display().to_string()),
                people[0].len(),
                c + 1
            ));
        }
    }
    let n = before[0].len();
    let before: Vec<Motion> = before
        .iter()
        .map(|m| frames_of(m, n - c - 1, n).expect("checked length"))
        .collect();
    let after_part: Vec<Motion> = after
        .iter()
        .map(|m| frames_of(m, 0, c + 1).expect("checked length"))
        .collect();
    if c <= args.blend {
        return Err(miette!(
            help = "raise --context or lower --blend",
            "--context {c} is not longer than --blend {}: an in-between blends inside the frames it keeps",
            args.blend
        ));
    }
    // The blend eases out inside the kept frames: the gap has no take to blend towards.
    let inner = c - args.blend;
    let keep = vec![0..inner, frames - inner..frames];
    meta.insert("to".into(), to.display().to_string().into());
    meta.insert("to_sha256".into(), hash.into());
    meta.insert("context".into(), c.into());
    meta.insert("strength".into(), 1.0.into());
    meta.insert("kept_frames".into(), ranges_json(&keep));
    meta.insert(
        "edited_frames".into(),
        ranges_json(&complement(&keep, frames)),
    );
    meta.insert("blend".into(), args.blend.into());
    let resample = resample_rounds(args, DEFAULT_RESAMPLE)?;
    meta.insert("resample".into(), resample.into());
    Ok(TakePlan {
        people: before,
        after: Some(after_part),
        strength: 1.0,
        keep,
        frames,
        blend: args.blend,
        keep_path: Some(false),
        hold_body: false,
        hold_time: false,
        time_margin: 0,
        resample,
        meta,
    })
}

/// What `run --from` prints of the held time: the frames and seconds held exactly and the
/// margin that eases into the edit.
fn held_time_line(time: &[Range<usize>], frames: usize, margin: usize) -> String {
    if time.is_empty() {
        return "editing the take: every frame free (the program reads them all, or --free-time)"
            .into();
    }
    let fps = mprog::skeleton::FPS;
    let spans: Vec<String> = time
        .iter()
        .map(|r| {
            format!(
                "frames {}..{} ({:.2}–{:.2} s)",
                r.start,
                r.end,
                r.start as f32 / fps,
                r.end as f32 / fps
            )
        })
        .collect();
    format!(
        "editing the take: untouched time held to the take: {} of {frames}; the {margin} frames ({:.2} s) next to what the program reads ease into the edit (--free-time, --time-margin change this)",
        spans.join(", "),
        margin as f32 / fps
    )
}

fn ranges_json(r: &[Range<usize>]) -> serde_json::Value {
    serde_json::json!(r.iter().map(|r| [r.start, r.end]).collect::<Vec<_>>())
}

/// The frames of `0..frames` outside `keep`.
fn complement(keep: &[Range<usize>], frames: usize) -> Vec<Range<usize>> {
    let mut kept = vec![false; frames];
    for r in keep {
        kept[r.clone()].fill(true);
    }
    let mut out = Vec::new();
    let mut t = 0;
    while t < frames {
        if kept[t] {
            t += 1;
            continue;
        }
        let start = t;
        while t < frames && !kept[t] {
            t += 1;
        }
        out.push(start..t);
    }
    out
}

impl TakePlan {
    /// The library's edit: the take encoded (an in-between spliced around a gap of the
    /// model's mean features `mean`), the hold weights of the kept windows, and the path and
    /// body parts held where `program` leaves them alone; what is held goes into the meta.
    pub fn edit(&mut self, mean: &[f32], program: &Program) -> Result<Edit> {
        let encode = |people: &[Motion]| {
            Take::encode(people).map_err(|e| miette!("cannot encode the take: {e}"))
        };
        let mut take = encode(&self.people)?;
        if let Some(after) = &self.after {
            let b = encode(after)?;
            take = Take::splice(&take, &b, self.frames, mean)
                .ok_or_else(|| miette!("the in-between leaves no gap"))?;
        }
        let auto = auto_hold(&take, program, &Device::flex())
            .map_err(|e| miette!("cannot analyse the program on the take: {e}"))?;
        // Untouched time: held exactly `time_margin` frames short of what the program reads.
        let margin = self.time_margin;
        let (time, time_weights) = if self.hold_time {
            (auto.kept_time(margin), auto.time_weights(margin))
        } else {
            (Vec::new(), Vec::new())
        };
        let hold_path = self.keep_path.unwrap_or(auto.path);
        let parts = if self.hold_body {
            auto.parts
        } else {
            Vec::new()
        };
        eprintln!(
            "editing the take: path {}; {} (--keep-path/--free-path, --free-body change this)",
            if hold_path { "held" } else { "free" },
            if parts.is_empty() {
                "every body part free".to_string()
            } else {
                format!("held to the take: {}", parts.join(", "))
            }
        );
        eprintln!("{}", held_time_line(&time, self.frames, margin));
        self.meta.insert("held_time".into(), ranges_json(&time));
        if self.hold_time {
            self.meta.insert("time_margin".into(), margin.into());
        }
        // The cleanup skips edits that hold both legs (see `Edit::clean_feet`).
        let legs_held = ["left leg", "right leg"].iter().all(|l| parts.contains(l));
        self.meta.insert("foot_cleanup".into(), (!legs_held).into());
        self.meta.insert("keep_path".into(), hold_path.into());
        self.meta
            .insert("held_parts".into(), serde_json::json!(parts));
        Ok(Edit {
            hold: merge_holds(
                &if self.keep.is_empty() {
                    Vec::new()
                } else {
                    // An in-between's kept ranges already stop `blend` short of the gap.
                    hold_weights(self.frames, &self.keep, self.blend)
                },
                &time_weights,
            ),
            take,
            strength: self.strength,
            hold_path,
            hold_joints: parts_joints(&parts),
            resample: self.resample,
            clean_feet: true,
        })
    }
}

#[cfg(test)]
// A list of one frame range is what `complement` takes, not a range to collect.
#[allow(clippy::single_range_in_vec_init)]
mod tests {
    use super::*;

    #[test]
    fn ranges_parse_and_resolve() {
        let r = parse_range("10..20").unwrap();
        assert_eq!(r.resolve("--keep", 30, "x").unwrap(), 10..20);
        assert_eq!(
            parse_range("..5")
                .unwrap()
                .resolve("--keep", 30, "x")
                .unwrap(),
            0..5
        );
        assert_eq!(
            parse_range("25..")
                .unwrap()
                .resolve("--keep", 30, "x")
                .unwrap(),
            25..30
        );
        assert!(parse_range("5").is_err());
        assert!(parse_range("a..3").is_err());
        assert!(
            parse_range("10..40")
                .unwrap()
                .resolve("--keep", 30, "x")
                .is_err()
        );
        assert!(
            parse_range("9..9")
                .unwrap()
                .resolve("--keep", 30, "x")
                .is_err()
        );
        assert_eq!(complement(&[0..3, 7..10], 10), vec![3..7]);
        assert_eq!(complement(&[2..4], 6), vec![0..2, 4..6]);
    }
}
