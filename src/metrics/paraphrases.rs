//! Paraphrase robustness (issue 49): does a prompt worded the way a person would write it
//! do what its training caption does? `mprog bench paraphrases` reads a hand-written set
//! (`bench/paraphrases.toml`: captions, other wordings of each, and the judges that decide
//! whether a motion does what the caption says), generates every caption and wording with
//! each seed as `mprog gen` would (its length from the model's length prior, DDIM, no
//! cleanup, as `bench actions`), and tabulates exact-caption success against paraphrase
//! success, with and without `gen`'s nearest-caption conditioning of far prompts.
//!
//! A judge is a [`Measure`] of the motion ([`crate::metrics::actions::MEASURES`]) with a
//! lower and/or upper bound; a motion succeeds when every judge of its entry holds. Judges
//! tagged with a [`Word`] check the caption's direction, side or speed word and are also
//! counted on their own; entries tagged with a [`Pace`] are compared across the set (every
//! fast sample faster than every slow one).

use crate::metrics::actions::{MEASURES, Measure, Track, measure, track};
use crate::model::ModelBundle;
use crate::model::generate::{GenerateError, GenerateRequest, generate};
use crate::model::prompt::{PromptEncoder, swap_side_words};
use crate::model::sampler::SamplerKind;
use crate::model::sentence::{Nearest, Snapped};
use burn::prelude::*;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// Where the set lives in the repository.
pub const DEFAULT_SET: &str = "bench/paraphrases.toml";

/// Length when the model has no length prior (`mprog gen`'s 6 s).
const DEFAULT_FRAMES: usize = 120;

/// A caption's speed class, for the fast-versus-slow check.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Pace {
    /// Runs, dashes, jogs, walks briskly.
    Fast,
    /// Walks slowly, strolls, sneaks.
    Slow,
}

/// The kind of word a judge checks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Word {
    /// Forward, backwards, to the left, to the right.
    Direction,
    /// Left, right, both.
    Side,
    /// Slowly, briskly, runs, dashes.
    Speed,
}

impl Word {
    fn name(self) -> &'static str {
        match self {
            Word::Direction => "direction",
            Word::Side => "side",
            Word::Speed => "speed",
        }
    }
}

/// A measure with its bounds.
#[derive(Clone, Copy)]
pub struct Judge {
    /// What is measured.
    pub measure: &'static Measure,
    /// The value must be at least this.
    pub min: Option<f32>,
    /// The value must be at most this.
    pub max: Option<f32>,
    /// The caption's word this judge checks, if any.
    pub word: Option<Word>,
}

impl std::fmt::Debug for Judge {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.describe())
    }
}

impl Judge {
    /// Whether `value` lies within the bounds (never for NaN).
    pub fn holds(&self, value: f32) -> bool {
        !value.is_nan()
            && self.min.is_none_or(|m| value >= m)
            && self.max.is_none_or(|m| value <= m)
    }

    /// "forward_speed ≥ 0.4", "0.15 ≤ speed ≤ 1", "side: turn ≥ 0".
    pub fn describe(&self) -> String {
        let name = self.measure.name;
        let bounds = match (self.min, self.max) {
            (Some(lo), Some(hi)) => format!("{lo} ≤ {name} ≤ {hi}"),
            (Some(lo), None) => format!("{name} ≥ {lo}"),
            (None, Some(hi)) => format!("{name} ≤ {hi}"),
            (None, None) => name.to_string(),
        };
        match self.word {
            Some(w) => format!("{}: {bounds}", w.name()),
            None => bounds,
        }
    }
}

/// One caption of the set with its wordings and judges.
#[derive(Clone, Debug)]
pub struct Entry {
    /// The exact training caption.
    pub caption: String,
    /// Other wordings of it.
    pub wordings: Vec<String>,
    /// Its speed class, if it names one.
    pub pace: Option<Pace>,
    /// Every judge must hold for a motion to do what the caption says.
    pub judges: Vec<Judge>,
}

impl Entry {
    /// Each judge's measurement of a motion.
    pub fn values(&self, t: &Track) -> Vec<f32> {
        self.judges.iter().map(|j| (j.measure.value)(t)).collect()
    }

    /// Whether every judge holds for these values (from [`Entry::values`]).
    pub fn passes(&self, values: &[f32]) -> bool {
        self.judges.iter().zip(values).all(|(j, &v)| j.holds(v))
    }

    /// Whether every judge of a direction, side or speed word holds; None when the entry
    /// has none.
    pub fn words_right(&self, values: &[f32]) -> Option<bool> {
        let mut words = self
            .judges
            .iter()
            .zip(values)
            .filter(|(j, _)| j.word.is_some())
            .peekable();
        words.peek()?;
        Some(words.all(|(j, &v)| j.holds(v)))
    }
}

/// A parsed paraphrase set.
#[derive(Clone, Debug)]
pub struct ParaphraseSet {
    /// The file it came from.
    pub path: PathBuf,
    /// Its entries, in file order.
    pub entries: Vec<Entry>,
}

/// Why a set could not be read.
#[derive(Debug, thiserror::Error)]
pub enum SetError {
    /// The file could not be read.
    #[error("cannot read the paraphrase set {}: {reason}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The system's reason.
        reason: String,
    },
    /// The file is not TOML.
    #[error("{}: not valid TOML: {reason}", path.display())]
    Toml {
        /// The file.
        path: PathBuf,
        /// The parser's message (with the line).
        reason: String,
    },
    /// The file's shape is wrong.
    #[error("{}: {reason}", path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// One entry is wrong.
    #[error("{}: {entry}: {reason}", path.display())]
    Entry {
        /// The file.
        path: PathBuf,
        /// "entry 3 ("a person jumps", line 120)".
        entry: String,
        /// What is wrong.
        reason: String,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEntry {
    caption: String,
    wordings: Vec<String>,
    #[serde(default)]
    pace: Option<Pace>,
    judges: Vec<RawJudge>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawJudge {
    measure: String,
    #[serde(default)]
    min: Option<f32>,
    #[serde(default)]
    max: Option<f32>,
    #[serde(default)]
    word: Option<Word>,
}

/// Reads and checks a set file.
pub fn read_set(path: &Path) -> Result<ParaphraseSet, SetError> {
    let text = std::fs::read_to_string(path).map_err(|e| SetError::Read {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    parse_set(&text, path)
}

/// Parses and checks a set; `path` names it in errors.
pub fn parse_set(text: &str, path: &Path) -> Result<ParaphraseSet, SetError> {
    let file_err = |reason: String| SetError::File {
        path: path.to_path_buf(),
        reason,
    };
    let table: toml::Table = toml::from_str(text).map_err(|e| SetError::Toml {
        path: path.to_path_buf(),
        reason: e.to_string().trim_end().to_string(),
    })?;
    if let Some(key) = table.keys().find(|k| *k != "entry") {
        return Err(file_err(format!(
            "unknown key `{key}`: a paraphrase set holds only [[entry]] tables"
        )));
    }
    let items = match table.get("entry") {
        None => return Err(file_err("no [[entry]] tables: the set is empty".into())),
        Some(toml::Value::Array(items)) if !items.is_empty() => items,
        Some(_) => {
            return Err(file_err(
                "`entry` must be a list of tables, written [[entry]]".into(),
            ));
        }
    };
    let mut entries: Vec<Entry> = Vec::with_capacity(items.len());
    for (i, item) in items.iter().enumerate() {
        let caption = item.get("caption").and_then(toml::Value::as_str);
        let label = match caption {
            Some(c) => match line_of(text, c) {
                Some(line) => format!("entry {} (\"{c}\", line {line})", i + 1),
                None => format!("entry {} (\"{c}\")", i + 1),
            },
            None => format!("entry {}", i + 1),
        };
        let entry_err = |reason: String| SetError::Entry {
            path: path.to_path_buf(),
            entry: label.clone(),
            reason,
        };
        let raw: RawEntry = item
            .clone()
            .try_into()
            .map_err(|e: toml::de::Error| entry_err(e.message().to_string()))?;
        let entry = check_entry(raw).map_err(entry_err)?;
        if entries.iter().any(|e| e.caption == entry.caption) {
            return Err(entry_err(
                "the caption appears in an earlier entry too".into(),
            ));
        }
        entries.push(entry);
    }
    Ok(ParaphraseSet {
        path: path.to_path_buf(),
        entries,
    })
}

/// The 1-based line of the first `caption = "…"` naming `caption`.
fn line_of(text: &str, caption: &str) -> Option<usize> {
    let quoted = format!("\"{caption}\"");
    text.lines()
        .position(|l| l.trim_start().starts_with("caption") && l.contains(&quoted))
        .map(|i| i + 1)
}

fn check_entry(raw: RawEntry) -> Result<Entry, String> {
    let caption = raw.caption.trim().to_string();
    if caption.is_empty() {
        return Err("the caption is empty".into());
    }
    if raw.wordings.is_empty() {
        return Err("no wordings: give at least one other way to say the caption".into());
    }
    let mut wordings: Vec<String> = Vec::with_capacity(raw.wordings.len());
    for (i, w) in raw.wordings.iter().enumerate() {
        let w = w.trim().to_string();
        if w.is_empty() {
            return Err(format!("wording {} is empty", i + 1));
        }
        if w.eq_ignore_ascii_case(&caption) {
            return Err(format!("wording {} is the caption itself", i + 1));
        }
        if wordings.iter().any(|o| o.eq_ignore_ascii_case(&w)) {
            return Err(format!("wording {} (\"{w}\") is given twice", i + 1));
        }
        wordings.push(w);
    }
    if raw.judges.is_empty() {
        return Err("no judges: say what a motion must do, e.g. judges = [{ measure = \"speed\", min = 2.2 }]".into());
    }
    let judges = raw
        .judges
        .into_iter()
        .enumerate()
        .map(|(i, j)| {
            let n = i + 1;
            let measure = measure(&j.measure).ok_or_else(|| {
                let known: Vec<&str> = MEASURES.iter().map(|m| m.name).collect();
                format!(
                    "judge {n}: unknown measure `{}` (known: {})",
                    j.measure,
                    known.join(", ")
                )
            })?;
            if j.min.is_none() && j.max.is_none() {
                return Err(format!(
                    "judge {n} ({}): give `min`, `max` or both",
                    j.measure
                ));
            }
            if [j.min, j.max].iter().flatten().any(|v| !v.is_finite()) {
                return Err(format!("judge {n} ({}): bounds must be finite", j.measure));
            }
            if let (Some(lo), Some(hi)) = (j.min, j.max)
                && lo > hi
            {
                return Err(format!(
                    "judge {n} ({}): min {lo} is above max {hi}, nothing can pass",
                    j.measure
                ));
            }
            Ok(Judge {
                measure,
                min: j.min,
                max: j.max,
                word: j.word,
            })
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok(Entry {
        caption,
        wordings,
        pace: raw.pace,
        judges,
    })
}

/// How a prompt reaches the denoiser.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Conditioning {
    /// As `mprog gen` does by default: a prompt far from every caption (best cosine below
    /// the snap threshold) is conditioned on the mean of its nearest captions.
    Nearest,
    /// As written (`mprog gen --literal-prompt`).
    Literal,
}

impl Conditioning {
    /// Its name in the totals.
    pub fn label(self) -> &'static str {
        match self {
            Conditioning::Nearest => "nearest captions (`gen`'s default)",
            Conditioning::Literal => "literal (`--literal-prompt`)",
        }
    }
    /// Its name in column headers.
    pub fn short(self) -> &'static str {
        match self {
            Conditioning::Nearest => "nearest",
            Conditioning::Literal => "literal",
        }
    }
}

/// How the bench runs.
#[derive(Clone, Debug)]
pub struct BenchSettings {
    /// Seeds of every prompt.
    pub seeds: Vec<u64>,
    /// DDIM steps.
    pub steps: usize,
    /// Classifier-free guidance scale.
    pub guidance: f32,
    /// Conditionings to run, each a column.
    pub conditioning: Vec<Conditioning>,
    /// At most this many wordings per caption (the first ones).
    pub max_wordings: Option<usize>,
    /// Generate every wording at its caption's length instead of its own.
    pub caption_length: bool,
}

/// One generated motion's measurements.
#[derive(Clone, Debug)]
pub struct Sample {
    /// Each judge's value, in the entry's order.
    pub values: Vec<f32>,
    /// Speed of the pelvis's ground path (m/s), for the fast-versus-slow check.
    pub speed: f32,
}

/// One prompt (the caption or a wording) and its motions.
#[derive(Clone, Debug)]
pub struct PromptRun {
    /// The prompt.
    pub text: String,
    /// Whether it is the entry's caption.
    pub exact: bool,
    /// Length generated.
    pub frames: usize,
    /// The training caption nearest to it.
    pub nearest: Option<Nearest>,
    /// The neighbours that stand in for it under nearest-caption conditioning.
    pub snapped: Option<Snapped>,
    /// Whether nearest-caption and literal conditioning give different text vectors (the
    /// prompt or its left/right-swapped twin is snapped).
    pub differs: bool,
    /// Whether the wording is itself a training caption (then it is no paraphrase).
    pub training_caption: bool,
    /// Samples per conditioning (the run's order) and seed.
    pub samples: Vec<Vec<Sample>>,
}

/// One entry's prompts.
#[derive(Clone, Debug)]
pub struct EntryRun {
    /// The entry.
    pub entry: Entry,
    /// The caption first, then its wordings.
    pub prompts: Vec<PromptRun>,
}

/// A finished bench.
#[derive(Clone, Debug)]
pub struct BenchRun {
    /// The settings it ran with.
    pub settings: BenchSettings,
    /// Its entries.
    pub entries: Vec<EntryRun>,
}

/// Progress of a run: motions done, motions in all, and what was just made.
pub struct Progress<'a> {
    /// Motions generated (or reused) so far.
    pub done: usize,
    /// Motions to generate.
    pub total: usize,
    /// The prompt.
    pub prompt: &'a str,
    /// Its seed.
    pub seed: u64,
    /// Its conditioning.
    pub conditioning: Conditioning,
    /// Whether it passed its judges.
    pub passed: bool,
}

/// Whether `text` is one of the model's training captions (case and surrounding space
/// ignored).
fn is_training_caption(encoder: &PromptEncoder, text: &str) -> bool {
    match encoder {
        PromptEncoder::Sentences(s) => s
            .captions
            .captions()
            .iter()
            .any(|c| c.trim().eq_ignore_ascii_case(text.trim())),
        PromptEncoder::Words(_) => false,
    }
}

/// Generates every entry's caption and wordings with every seed and conditioning, and
/// measures each motion. `bundle` must read prompts as loaded (nearest-caption conditioning
/// on); a literal run switches it to literal reading. Literal samples of prompts that no
/// snapping touches are the nearest-caption samples (the same text vectors, the same
/// motion), not generated twice.
pub fn run_bench(
    bundle: &mut ModelBundle,
    device: &Device,
    entries: &[Entry],
    settings: &BenchSettings,
    mut progress: impl FnMut(Progress<'_>),
) -> Result<BenchRun, GenerateError> {
    let max_frames = bundle.config.max_frames;
    let frames_of = |text: &PromptEncoder, prompt: &str| {
        text.natural_frames(prompt, max_frames)
            .map_or(DEFAULT_FRAMES.min(max_frames), |(f, _)| f)
    };
    let mut runs: Vec<EntryRun> = entries
        .iter()
        .map(|entry| {
            let wordings = entry
                .wordings
                .iter()
                .take(settings.max_wordings.unwrap_or(usize::MAX));
            let caption_frames = frames_of(&bundle.text, &entry.caption);
            let prompts = std::iter::once(&entry.caption)
                .chain(wordings)
                .enumerate()
                .map(|(i, text)| {
                    let exact = i == 0;
                    let snapped = bundle.text.snapped(text);
                    let differs =
                        snapped.is_some() || bundle.text.snapped(&swap_side_words(text)).is_some();
                    PromptRun {
                        text: text.clone(),
                        exact,
                        frames: if exact || settings.caption_length {
                            caption_frames
                        } else {
                            frames_of(&bundle.text, text)
                        },
                        nearest: bundle.text.nearest_caption(text),
                        snapped,
                        differs,
                        training_caption: !exact && is_training_caption(&bundle.text, text),
                        samples: Vec::new(),
                    }
                })
                .collect();
            EntryRun {
                entry: entry.clone(),
                prompts,
            }
        })
        .collect();
    let nearest_run = settings.conditioning.contains(&Conditioning::Nearest);
    let seeds = settings.seeds.len();
    let total: usize = settings
        .conditioning
        .iter()
        .map(|&c| {
            runs.iter()
                .flat_map(|r| &r.prompts)
                .filter(|p| c == Conditioning::Nearest || !nearest_run || p.differs)
                .count()
                * seeds
        })
        .sum();
    let mut done = 0;
    for (ci, &cond) in settings.conditioning.iter().enumerate() {
        if cond == Conditioning::Literal {
            bundle.text.read_literally();
        }
        for run in &mut runs {
            for prompt in &mut run.prompts {
                if cond == Conditioning::Literal && nearest_run && !prompt.differs {
                    let nearest = settings
                        .conditioning
                        .iter()
                        .position(|&c| c == Conditioning::Nearest)
                        .expect("a nearest run");
                    let same = prompt.samples[nearest].clone();
                    prompt.samples.push(same);
                    continue;
                }
                let mut samples = Vec::with_capacity(seeds);
                for &seed in &settings.seeds {
                    let req = GenerateRequest {
                        prompts: vec![prompt.text.clone()],
                        frames: prompt.frames,
                        seed,
                        sampler: SamplerKind::Ddim(settings.steps),
                        guidance_scale: settings.guidance,
                        mirror_average: false,
                    };
                    let out = generate(bundle, &req, device, |_, _| {})?;
                    let t = track(&out.motions[0]);
                    let sample = Sample {
                        values: run.entry.values(&t),
                        speed: t.speed(),
                    };
                    done += 1;
                    progress(Progress {
                        done,
                        total,
                        prompt: &prompt.text,
                        seed,
                        conditioning: cond,
                        passed: run.entry.passes(&sample.values),
                    });
                    samples.push(sample);
                }
                debug_assert_eq!(prompt.samples.len(), ci);
                prompt.samples.push(samples);
            }
        }
    }
    Ok(BenchRun {
        settings: settings.clone(),
        entries: runs,
    })
}

/// A count of successes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Tally {
    /// Successes.
    pub passed: usize,
    /// Cases.
    pub total: usize,
}

impl Tally {
    fn add(&mut self, ok: bool) {
        self.passed += usize::from(ok);
        self.total += 1;
    }
    /// Successes as a fraction (None for no cases).
    pub fn rate(&self) -> Option<f64> {
        (self.total > 0).then(|| self.passed as f64 / self.total as f64)
    }
    /// Whether every case succeeded (and there was one).
    pub fn all(&self) -> bool {
        self.total > 0 && self.passed == self.total
    }
}

impl std::fmt::Display for Tally {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.rate() {
            Some(r) => write!(f, "{}/{} ({:.0} %)", self.passed, self.total, 100.0 * r),
            None => write!(f, "–"),
        }
    }
}

/// The totals of one conditioning.
#[derive(Clone, Debug, Default)]
pub struct Summary {
    /// Exact captions' motions that do what the caption says.
    pub exact: Tally,
    /// Wordings' motions that do what their caption says.
    pub paraphrase: Tally,
    /// Exact captions' motions with every direction/side/speed word right.
    pub words_exact: Tally,
    /// Wordings' motions with every direction/side/speed word right.
    pub words_paraphrase: Tally,
    /// Pairs of an exact fast and an exact slow caption's motions where the fast is faster.
    pub pace_exact: Tally,
    /// The same for wordings.
    pub pace_paraphrase: Tally,
    /// The slowest wording motion of a fast caption (m/s, prompt, seed).
    pub slowest_fast: Option<(f32, String, u64)>,
    /// The fastest wording motion of a slow caption (m/s, prompt, seed).
    pub fastest_slow: Option<(f32, String, u64)>,
}

impl Summary {
    /// Paraphrase success as a fraction of exact success (None when no exact caption
    /// succeeded).
    pub fn ratio(&self) -> Option<f64> {
        match (self.paraphrase.rate(), self.exact.rate()) {
            (Some(p), Some(e)) if e > 0.0 => Some(p / e),
            _ => None,
        }
    }
}

/// The totals of conditioning `ci` (an index into the run's conditionings).
pub fn summary(run: &BenchRun, ci: usize) -> Summary {
    let mut s = Summary::default();
    let mut fast: [Vec<(f32, &str, u64)>; 2] = [Vec::new(), Vec::new()];
    let mut slow: [Vec<(f32, &str, u64)>; 2] = [Vec::new(), Vec::new()];
    for er in &run.entries {
        for p in &er.prompts {
            let kind = usize::from(!p.exact);
            for (sample, &seed) in p.samples[ci].iter().zip(&run.settings.seeds) {
                let pass = er.entry.passes(&sample.values);
                let words = er.entry.words_right(&sample.values);
                if p.exact {
                    s.exact.add(pass);
                    if let Some(w) = words {
                        s.words_exact.add(w);
                    }
                } else {
                    s.paraphrase.add(pass);
                    if let Some(w) = words {
                        s.words_paraphrase.add(w);
                    }
                }
                match er.entry.pace {
                    Some(Pace::Fast) => fast[kind].push((sample.speed, &p.text, seed)),
                    Some(Pace::Slow) => slow[kind].push((sample.speed, &p.text, seed)),
                    None => {}
                }
            }
        }
    }
    for kind in 0..2 {
        let tally = if kind == 0 {
            &mut s.pace_exact
        } else {
            &mut s.pace_paraphrase
        };
        for f in &fast[kind] {
            for sl in &slow[kind] {
                tally.add(f.0 > sl.0);
            }
        }
    }
    let owned = |x: &(f32, &str, u64)| (x.0, x.1.to_string(), x.2);
    s.slowest_fast = fast[1].iter().min_by(|a, b| a.0.total_cmp(&b.0)).map(owned);
    s.fastest_slow = slow[1].iter().max_by(|a, b| a.0.total_cmp(&b.0)).map(owned);
    s
}

fn percent(r: Option<f64>) -> String {
    r.map_or("–".to_string(), |r| format!("{:.0} %", 100.0 * r))
}

fn yes_no(b: bool) -> &'static str {
    if b { "yes" } else { "no" }
}

/// A value as the tables print it: degrees and counts whole, the rest in hundredths.
fn value_text(m: &Measure, v: f32) -> String {
    if m.what.contains("degrees") || m.what.contains("count") {
        format!("{v:.0}")
    } else {
        format!("{v:.2}")
    }
}

/// One sample's cell: ✓ or ✗, then each judge's value, failing ones in bold.
fn cell(entry: &Entry, sample: &Sample) -> String {
    let mark = if entry.passes(&sample.values) {
        "✓"
    } else {
        "✗"
    };
    let values: Vec<String> = entry
        .judges
        .iter()
        .zip(&sample.values)
        .map(|(j, &v)| {
            let t = value_text(j.measure, v);
            if j.holds(v) { t } else { format!("**{t}**") }
        })
        .collect();
    format!("{mark} {}", values.join(" · "))
}

/// The bench's tables as Markdown: the totals per conditioning, one row per caption, one
/// row per prompt and sample.
pub fn tables(run: &BenchRun) -> String {
    let conds = &run.settings.conditioning;
    let seeds = &run.settings.seeds;
    let mut s = String::new();
    s.push_str("### Totals\n\n");
    s.push_str("| conditioning | exact captions | paraphrases | paraphrases / exact | direction, side, speed words right: exact | … paraphrases | fast faster than slow: exact | … paraphrases | words right in every case |\n");
    s.push_str("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |\n");
    let sums: Vec<Summary> = (0..conds.len()).map(|ci| summary(run, ci)).collect();
    for (c, sm) in conds.iter().zip(&sums) {
        let every = sm.words_exact.passed == sm.words_exact.total
            && sm.words_paraphrase.passed == sm.words_paraphrase.total
            && sm.pace_exact.passed == sm.pace_exact.total
            && sm.pace_paraphrase.passed == sm.pace_paraphrase.total;
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            c.label(),
            sm.exact,
            sm.paraphrase,
            percent(sm.ratio()),
            sm.words_exact,
            sm.words_paraphrase,
            sm.pace_exact,
            sm.pace_paraphrase,
            yes_no(every)
        ));
    }
    s.push('\n');
    for (c, sm) in conds.iter().zip(&sums) {
        if let (Some(f), Some(sl)) = (&sm.slowest_fast, &sm.fastest_slow) {
            s.push_str(&format!(
                "- {}: slowest fast wording \"{}\" (seed {}) {:.2} m/s; fastest slow wording \"{}\" (seed {}) {:.2} m/s.\n",
                c.short(),
                f.1,
                f.2,
                f.0,
                sl.1,
                sl.2,
                sl.0
            ));
        }
    }
    let trained: Vec<&str> = run
        .entries
        .iter()
        .flat_map(|e| &e.prompts)
        .filter(|p| p.training_caption)
        .map(|p| p.text.as_str())
        .collect();
    if !trained.is_empty() {
        s.push_str(&format!(
            "- These wordings are training captions themselves, so they are no paraphrases: \"{}\".\n",
            trained.join("\", \"")
        ));
    }
    s.push_str("\n### Per caption\n\n| caption | judges (all must hold) | exact |");
    for c in conds {
        s.push_str(&format!(" paraphrases, {} |", c.short()));
    }
    s.push_str("\n| --- | --- | ---: |");
    for _ in conds {
        s.push_str(" ---: |");
    }
    s.push('\n');
    for er in &run.entries {
        let tally = |ci: usize, exact: bool| {
            let mut t = Tally::default();
            for p in er.prompts.iter().filter(|p| p.exact == exact) {
                for sample in &p.samples[ci] {
                    t.add(er.entry.passes(&sample.values));
                }
            }
            format!("{}/{}", t.passed, t.total)
        };
        let judges: Vec<String> = er.entry.judges.iter().map(Judge::describe).collect();
        let pace = match er.entry.pace {
            Some(Pace::Fast) => " (fast)",
            Some(Pace::Slow) => " (slow)",
            None => "",
        };
        s.push_str(&format!(
            "| {}{pace} | {} | {} |",
            er.entry.caption,
            judges.join("; "),
            tally(0, true)
        ));
        for ci in 0..conds.len() {
            s.push_str(&format!(" {} |", tally(ci, false)));
        }
        s.push('\n');
    }
    s.push_str("\n### Per prompt\n\nEach cell: ✓ when every judge holds, then each judge's value in the order of the caption's judges (bold: misses its bound). \"=\": the same text vectors as under nearest-caption conditioning, so the same motion. *Conditioned on*: how `gen` reads the prompt by default.\n\n");
    s.push_str("| prompt | nearest caption (cosine) | conditioned on | length (s) |");
    for c in conds {
        for seed in seeds {
            s.push_str(&format!(" {} seed {seed} |", c.short()));
        }
    }
    s.push_str("\n| --- | --- | --- | ---: |");
    for _ in 0..conds.len() * seeds.len() {
        s.push_str(" --- |");
    }
    s.push('\n');
    let literal_same = |p: &PromptRun, c: Conditioning| {
        c == Conditioning::Literal && !p.differs && conds.contains(&Conditioning::Nearest)
    };
    for er in &run.entries {
        for p in &er.prompts {
            let prompt = if p.exact {
                format!("**{}** (caption)", p.text)
            } else if p.training_caption {
                format!("{} (a training caption)", p.text)
            } else {
                p.text.clone()
            };
            let nearest = match &p.nearest {
                Some(n) if n.caption == er.entry.caption => format!("its own ({:.2})", n.cosine),
                Some(n) => format!("\"{}\" ({:.2})", n.caption, n.cosine),
                None => "–".into(),
            };
            let conditioned = match (&p.snapped, p.differs) {
                (Some(sn), _) => format!(
                    "mean of {} caption{}",
                    sn.neighbours.len(),
                    if sn.neighbours.len() == 1 { "" } else { "s" }
                ),
                (None, true) => "as written (its mirror snapped)".into(),
                (None, false) => "as written".into(),
            };
            s.push_str(&format!(
                "| {prompt} | {nearest} | {conditioned} | {:.1} |",
                p.frames as f32 / 20.0
            ));
            for (ci, &c) in conds.iter().enumerate() {
                for sample in &p.samples[ci] {
                    if literal_same(p, c) {
                        s.push_str(" = |");
                    } else {
                        s.push_str(&format!(" {} |", cell(&er.entry, sample)));
                    }
                }
            }
            s.push('\n');
        }
    }
    s
}

/// Every measure a judge can use, as a Markdown table.
pub fn measures_table() -> String {
    let mut s = String::from("| measure | what |\n| --- | --- |\n");
    for m in MEASURES {
        s.push_str(&format!("| `{}` | {} |\n", m.name, m.what));
    }
    s
}

#[cfg(test)]
mod tests;
