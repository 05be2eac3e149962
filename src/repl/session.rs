//! The REPL backend: a [`Session`] holds the program typed or loaded so far, the current
//! motion and the model bundle, and answers one input at a time with a [`Reply`]. It
//! knows nothing of terminals, so tests drive it directly.
//!
//! Adding a command means: a variant in
//! [`super::command::Command`] and its row in `COMMANDS`, and a method here that reads
//! [`Session::program`], [`Session::motion`] and [`Session::bundle`] and hands a result to
//! [`Session::set_motion`].

use super::command::{self, Command, Input};
use super::probe;
use super::reply::{Item, Reply};
use crate::features::recover_from_ric;
use crate::formats::bvh_export::BvhExportOptions;
use crate::formats::{LoadedMotion, OutputJob, read_motion, write_outputs};
use crate::lang::{Diagnostics, Program, Severity, compile};
use crate::model::ModelBundle;
use crate::model::generate::{GenerateRequest, generate};
use crate::model::sampler::default_chain;
use crate::motion::Motion;
use crate::skeleton::FPS;
use crate::solve::cleanup::{FootCleanup, clean_generated};
use crate::solve::{
    BODY_PARTS, DEFAULT_STRENGTH, Edit, Prior, SolveRequest, Solver, Take, auto_hold, solve,
};
use burn::tensor::Device;
use std::path::{Path, PathBuf};

/// Name the session's program has in diagnostics.
pub const SOURCE_NAME: &str = "<repl>";

/// Diagnostics the REPL does not show: a session starts with no length and no
/// constraints, and that is fine until a motion is scored.
const QUIET: &[&str] = &[
    crate::lang::codes::MISSING_LENGTH,
    crate::lang::codes::EMPTY_PROGRAM,
];

/// The motion commands work on.
#[derive(Clone, Debug)]
pub struct CurrentMotion {
    /// One motion per person, all at 20 fps.
    pub people: Vec<Motion>,
    /// Where it came from (file name, or the `:gen` request).
    pub origin: String,
    /// Provenance written into its outputs' meta: for a loaded take its path and hash,
    /// for an edit also the strength and what was held.
    pub provenance: crate::formats::Meta,
}

impl CurrentMotion {
    /// Frames shared by every person.
    pub fn frames(&self) -> usize {
        self.people.iter().map(Motion::len).min().unwrap_or(0)
    }
}

/// One REPL session.
pub struct Session {
    program: String,
    motion: Option<CurrentMotion>,
    /// The motion loaded with `:motion`, which `:run` edits (cleared by `:gen`).
    take: Option<CurrentMotion>,
    model_dir: Option<PathBuf>,
    bundle: Option<ModelBundle>,
    device: Device,
    /// The rig `:save` puts `.bvh` and `.glb` motions on (`:rig`).
    rig: Option<crate::formats::Character>,
}

impl Session {
    /// A session with no program and no motion; `:gen` loads the bundle in `model_dir`.
    pub fn new(model_dir: Option<PathBuf>) -> Self {
        Session {
            program: String::new(),
            motion: None,
            take: None,
            model_dir,
            bundle: None,
            device: Device::flex(),
            rig: None,
        }
    }

    /// Answers one (possibly multi-line) input.
    pub fn handle(&mut self, text: &str) -> Reply {
        match command::parse(text) {
            Err(e) => Reply::error(e),
            Ok(Input::Empty) => Reply::default(),
            Ok(Input::Code(code)) => self.add_code(&code),
            Ok(Input::Command(c)) => self.run_command(c),
        }
    }

    /// Runs one command.
    pub fn run_command(&mut self, c: Command) -> Reply {
        match c {
            Command::Load(path) => self.load(&path),
            Command::Motion(path) => self.load_motion(&path),
            Command::Gen {
                prompt,
                seconds,
                seed,
            } => self.gen_motion(&prompt, seconds, seed),
            Command::Run {
                solver,
                seed,
                knobs,
            } => self.run_program(&solver, seed, &knobs),
            Command::Eval(text) => probe::eval(self, &text),
            Command::Grad(text) => probe::grad(self, &text),
            Command::Score => probe::score(self),
            Command::Render(path) | Command::View(path) => self.export(&path),
            Command::Save(path) => self.save(&path),
            Command::Rig(arg) => self.set_rig(arg.as_ref()),
            Command::Show => Reply::text(self.show()),
            Command::Drop { first, last } => self.drop_lines(first, last),
            Command::Clear => {
                self.program.clear();
                Reply::text("program cleared")
            }
            Command::Help(topic) => help(topic.as_deref()),
            Command::Quit => Reply {
                items: Vec::new(),
                quit: true,
            },
        }
    }

    /// The session's program source.
    pub fn source(&self) -> &str {
        &self.program
    }

    /// The session's program compiled, or its diagnostics (an empty session has none).
    pub fn program(&self) -> Result<Program, Diagnostics> {
        compile(&self.program, SOURCE_NAME, &[])
    }

    /// The current motion.
    pub fn motion(&self) -> Option<&CurrentMotion> {
        self.motion.as_ref()
    }

    /// Makes `people` the current motion (resampled to 20 fps).
    pub fn set_motion(&mut self, people: Vec<Motion>, origin: impl Into<String>) {
        let people = people
            .into_iter()
            .map(|m| {
                if (m.fps - FPS).abs() > 1e-3 {
                    m.resample(FPS)
                } else {
                    m
                }
            })
            .collect();
        self.motion = Some(CurrentMotion {
            people,
            origin: origin.into(),
            provenance: crate::formats::Meta::new(),
        });
    }

    /// The model bundle, loaded on first use.
    pub fn bundle(&mut self) -> Result<&ModelBundle, String> {
        if self.bundle.is_none() {
            let Some(dir) = self.model_dir.clone() else {
                return Err("no model bundle: start the REPL with `--model DIR`".into());
            };
            let b = ModelBundle::load(&dir, &self.device).map_err(|e| {
                format!(
                    "cannot load the model bundle in {}: {e} (train one with `mprog train`, or pass --model DIR)",
                    dir.display()
                )
            })?;
            self.bundle = Some(b);
        }
        Ok(self.bundle.as_ref().expect("loaded above"))
    }

    /// The device tensors are evaluated on.
    pub fn device(&self) -> &Device {
        &self.device
    }

    /// Adds code to the program if the whole still checks; otherwise shows why.
    fn add_code(&mut self, code: &str) -> Reply {
        let start = self.program.len();
        let candidate = format!("{}{code}\n", self.program);
        let diags = visible(crate::lang::check_source(&candidate, SOURCE_NAME, &[]));
        if diags.has_errors() {
            return Reply::diagnostics(diags);
        }
        self.program = candidate;
        let mut reply = Reply::default();
        let fresh: Vec<_> = diags
            .items
            .iter()
            .filter(|d| d.span.start >= start)
            .cloned()
            .collect();
        if !fresh.is_empty() {
            reply.push(Item::Diagnostics(Diagnostics::new(
                SOURCE_NAME,
                diags.source.clone(),
                fresh,
            )));
        }
        if self.motion.is_some() {
            probe::score_new(self, start, &mut reply);
        }
        reply
    }

    fn load(&mut self, path: &Path) -> Reply {
        let text = match std::fs::read_to_string(path) {
            Ok(t) => t,
            Err(e) => return Reply::error(format!("cannot read {}: {e}", path.display())),
        };
        let name = path.display().to_string();
        let diags = crate::lang::check_source(&text, &name, &[]);
        if diags.has_errors() {
            let mut r = Reply::diagnostics(diags);
            r.push(Item::Error(format!(
                "{name} not loaded; the session's program is unchanged"
            )));
            return r;
        }
        self.program = if text.ends_with('\n') {
            text
        } else {
            format!("{text}\n")
        };
        let mut reply = Reply::default();
        if diags.warnings().next().is_some() {
            reply.push(Item::Diagnostics(diags));
        }
        let lines = self.program.lines().count();
        reply.push(Item::Text(format!(
            "loaded {name} ({lines} lines); `:show` prints it, `:score` scores it"
        )));
        reply
    }

    fn load_motion(&mut self, path: &Path) -> Reply {
        let name = path.display().to_string();
        let people = match read_motion(path) {
            Err(e) => return Reply::error(e.to_string()),
            Ok(LoadedMotion::Joints { people, .. }) => {
                people.into_iter().map(|p| p.motion).collect()
            }
            Ok(LoadedMotion::Features(array)) => match recover_from_ric(&array.data) {
                Ok(m) => vec![m],
                Err(e) => {
                    return Reply::error(format!(
                        "{name}: recovering joints from HumanML3D features: {e}"
                    ));
                }
            },
        };
        self.set_motion(people, name);
        if let Some(m) = self.motion.as_mut() {
            m.provenance
                .insert("take".into(), path.display().to_string().into());
            if let Ok(hash) = crate::fsutil::sha256_hex(path) {
                m.provenance.insert("take_sha256".into(), hash.into());
            }
        }
        self.take = self.motion.clone();
        Reply::text(format!(
            "{}\n`:run` now edits this take (`strength=S`, 0…1, default {DEFAULT_STRENGTH}); `:gen` ends that",
            self.describe_motion()
        ))
    }

    fn gen_motion(&mut self, prompt: &str, seconds: f32, seed: u64) -> Reply {
        let frames = (seconds * FPS).round() as usize;
        let device = self.device.clone();
        let out = match self.bundle() {
            Err(e) => return Reply::error(e),
            Ok(bundle) => {
                // `mprog gen`'s chain for this model (a few-step model's own).
                let (sampler, guidance_scale) = default_chain(&bundle.manifest);
                let req = GenerateRequest {
                    prompts: vec![prompt.to_string()],
                    frames,
                    seed,
                    sampler,
                    guidance_scale,
                    mirror_average: false,
                };
                generate(bundle, &req, &device, |_, _| {}).and_then(|mut g| {
                    // As `mprog gen` does by default.
                    clean_generated(&mut g, frames, &FootCleanup::default())?;
                    Ok(g)
                })
            }
        };
        match out {
            Err(e) => Reply::error(format!("generation failed: {e}")),
            Ok(g) => {
                self.take = None;
                let unknown = g.unknown_words.first().cloned().unwrap_or_default();
                self.set_motion(
                    g.motions,
                    format!("gen \"{prompt}\" {seconds}s seed {seed}"),
                );
                let mut r = Reply::text(self.describe_motion());
                r.push(self.plausibility(&[Some(prompt.to_string())]));
                if !unknown.is_empty() {
                    r.push(Item::Warning(format!(
                        "the model does not know: {}",
                        unknown.join(", ")
                    )));
                }
                r
            }
        }
    }

    /// `:run`: the session's program solved with the model; the result becomes the current
    /// motion and its per-statement errors are shown.
    fn run_program(&mut self, name: &str, seed: u64, knobs: &[(String, f64)]) -> Reply {
        let program = match self.program() {
            Ok(p) => p,
            Err(d) if !real_errors(&d) => {
                return Reply::error(
                    "the program is not complete yet: it needs `length` and at least one constraint",
                );
            }
            Err(d) => return Reply::diagnostics(d),
        };
        let Some(mut solver) = Solver::by_name(name) else {
            return Reply::error(format!(
                "unknown solver `{name}`; use {}",
                Solver::names().join(", ")
            ));
        };
        let mut strength = None;
        for (k, v) in knobs {
            if k == "strength" {
                strength = Some(*v as f32);
            } else if let Err(e) = solver.set_knob(k, *v) {
                return Reply::error(e);
            }
        }
        let Some(prompts) = program.prompts().into_iter().collect::<Option<Vec<_>>>() else {
            return Reply::error("every person needs a prompt: add `prompt \"…\"` to the program");
        };
        let prompt_list: Vec<Option<String>> = prompts.iter().cloned().map(Some).collect();
        let edit = match (&self.take, strength) {
            (None, Some(_)) => {
                return Reply::error("`strength` edits a take: load one with `:motion FILE` first");
            }
            (None, None) => None,
            (Some(take), s) => match take_edit(take, s.unwrap_or(DEFAULT_STRENGTH), &program) {
                Ok(e) => Some(e),
                Err(e) => return Reply::error(e),
            },
        };
        let frames = edit.as_ref().map_or(program.length(), |e| e.take.frames);
        let mut req =
            SolveRequest::new(prompts, frames, seed, solver.clone()).placed(program.placements());
        let mut provenance = crate::formats::Meta::new();
        let origin = match (edit, &self.take) {
            (Some(e), Some(take)) => {
                let s = e.strength;
                let held = held_summary(&e);
                provenance = take.provenance.clone();
                provenance.insert("strength".into(), s.into());
                provenance.insert("keep_path".into(), e.hold_path.into());
                provenance.insert("held_parts".into(), serde_json::json!(held_parts(&e)));
                req = req.editing(e);
                format!(
                    ":run {} seed {seed} editing {} at strength {s} ({held})",
                    solver.name(),
                    take.origin
                )
            }
            _ => format!(":run {} seed {seed}", solver.name()),
        };
        let device = self.device.clone();
        // Travelling people face along their path and walkers stay upright, as in `run`.
        let texts: Vec<Vec<&str>> = req.prompts.iter().map(|p| vec![p.as_str()]).collect();
        let steering = crate::metrics::crouch::prompt_steering(&texts, false);
        let along = crate::solve::facing::FacingAlongPath::steered(&program, &steering);
        let error: &dyn crate::solve::MotionError = &along;
        // Longer than the model makes, or prompts on a timeline: window by window.
        let spans = program
            .timelines()
            .into_iter()
            .map(|line| line.into_iter().map(|t| (t.from, t.to, t.text)).collect())
            .collect();
        let timelines =
            crate::solve::long::timelines(spans, &req.prompts, frames, program.length());
        // A long take is edited window by window, as `mprog run` edits it.
        let long_take = req.edit.as_ref().zip(self.take.as_ref()).map(|(e, t)| {
            let people = t
                .people
                .iter()
                .map(|m| Motion {
                    frames: m.frames[..=frames.min(m.len() - 1)].to_vec(),
                    fps: m.fps,
                })
                .collect();
            crate::solve::long::LongTake::of(e, people)
        });
        let result = match self.bundle() {
            Err(e) => return Reply::error(e),
            Ok(bundle) => {
                let prior = Prior::from_bundle(bundle);
                let windowed = frames > prior.max_frames || timelines.iter().any(|t| t.len() > 1);
                match (windowed, &req.edit) {
                    (true, edit) => {
                        let take = edit.as_ref().and(long_take);
                        // Actions at their own length, except where a take is edited.
                        let action_frames = match take {
                            Some(_) => Vec::new(),
                            None => crate::solve::long::action_frames(
                                prior.text,
                                &timelines,
                                prior.max_frames,
                            ),
                        };
                        let long = crate::solve::long::LongRequest {
                            timelines,
                            take,
                            action_frames,
                            placements: req.placements.clone(),
                            ..crate::solve::long::LongRequest::new(
                                Vec::new(),
                                frames,
                                seed,
                                solver.clone(),
                            )
                        };
                        crate::solve::long::solve_long(&prior, &long, error, &device, |_| {})
                    }
                    (false, _) => solve(&prior, &req, error, &device, |_| {}),
                }
            }
        };
        match result {
            Err(e) => Reply::error(format!("{} failed: {e}", solver.name())),
            Ok(r) => {
                let seconds = r.seconds;
                let people = r.motions.into_iter().next().unwrap_or_default();
                self.set_motion(people, origin);
                if let Some(m) = self.motion.as_mut() {
                    m.provenance = provenance;
                }
                let mut reply = Reply::text(format!(
                    "{} in {seconds:.1} s; {}",
                    solver.name(),
                    self.describe_motion()
                ));
                for item in probe::score(self).items {
                    reply.push(item);
                }
                reply.push(self.plausibility(&prompt_list));
                reply
            }
        }
    }

    /// The plausibility report of the current motion (`mprog run` prints the same, with the
    /// statements active at each problem), against the bundle's envelope.
    fn plausibility(&self, prompts: &[Option<String>]) -> Item {
        let Some(m) = &self.motion else {
            return Item::Text(String::new());
        };
        let env = match self.model_dir.as_deref() {
            Some(dir) => match crate::model::weights::envelope_or_builtin(dir) {
                Ok(env) => env,
                Err(e) => return Item::Warning(format!("no plausibility report: {e}")),
            },
            None => crate::dataset::envelope::Envelope::builtin(),
        };
        let report = crate::metrics::plausibility::check(&m.people, prompts, &env);
        let text = report.lines().join("\n");
        if report.ok {
            Item::Text(text)
        } else {
            Item::Warning(text)
        }
    }

    /// The program's timeline and geometry for the current motion when the program is
    /// complete; nothing if not.
    fn motion_meta(&self, m: &CurrentMotion) -> Result<crate::formats::Meta, String> {
        match self.program() {
            Ok(program) => crate::view::program::program_meta(&program, &m.people, &self.device)
                .map_err(|e| format!("cannot score the motion: {e}")),
            Err(_) => Ok(crate::formats::Meta::new()),
        }
    }

    fn save(&self, path: &Path) -> Reply {
        let is_program = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("mprog"));
        if !is_program {
            return self.export(path);
        }
        if self.program.trim().is_empty() {
            return Reply::error("the program is empty: nothing to save");
        }
        let mut text = self.program.clone();
        if !text.ends_with('\n') {
            text.push('\n');
        }
        match crate::fsutil::write_bytes_atomic(path, text.as_bytes()) {
            Ok(()) => Reply::text(format!("wrote {}", path.display())),
            Err(e) => Reply::error(format!("cannot write {}: {e}", path.display())),
        }
    }

    /// `:rig`: shows, sets (`FILE [MAP]`) or drops (`-`) the rig saved motions go on.
    fn set_rig(&mut self, arg: Option<&(PathBuf, Option<PathBuf>)>) -> Reply {
        const NONE: &str = "no rig: .bvh and .glb motions are saved on the 22-joint skeleton";
        match arg {
            None => Reply::text(self.rig.as_ref().map_or(NONE.into(), |r| r.summary())),
            Some((p, None)) if p == Path::new("-") => {
                self.rig = None;
                Reply::text(NONE)
            }
            Some((p, map)) => match crate::formats::Character::load(p, map.as_deref()) {
                Ok(rig) => {
                    let summary = rig.summary();
                    self.rig = Some(rig);
                    Reply::text(summary)
                }
                Err(e) => Reply::error(e.to_string()),
            },
        }
    }

    /// Writes the current motion as any output kind (`:save`, `:render`, `:view`), with
    /// the program's timeline and geometry in its meta and titled with where the motion
    /// came from (after `:gen` the program's prompt is not what was generated).
    fn export(&self, path: &Path) -> Reply {
        if let Err(e) = crate::formats::output_kind(path) {
            return Reply::error(format!("{e} (or .mprog for the program)"));
        }
        let Some(m) = &self.motion else {
            return Reply::error(NO_MOTION);
        };
        let mut meta = match self.motion_meta(m) {
            Ok(meta) => meta,
            Err(e) => return Reply::error(e),
        };
        meta.insert("origin".into(), m.origin.clone().into());
        meta.extend(m.provenance.clone());
        let job = OutputJob {
            people: &m.people,
            meta: &meta,
            title: &m.origin,
            bvh: &BvhExportOptions::default(),
            rig: self.rig.as_ref(),
        };
        match write_outputs(&[path.to_path_buf()], &job) {
            Ok(written) => Reply::text(
                written
                    .iter()
                    .map(|p| format!("wrote {}", p.display()))
                    .collect::<Vec<_>>()
                    .join("\n"),
            ),
            Err(e) => Reply::error(e.to_string()),
        }
    }

    fn describe_motion(&self) -> String {
        match &self.motion {
            None => "no motion".into(),
            Some(m) => {
                let f = m.frames();
                let people = m.people.len();
                format!(
                    "motion: {} — {} person{}, {f} frames ({:.2} s at 20 fps)",
                    m.origin,
                    people,
                    if people == 1 { "" } else { "s" },
                    f as f32 / FPS
                )
            }
        }
    }

    /// Deletes lines `first..=last` when what is left still checks; otherwise keeps the
    /// program and shows why (e.g. a block's closing brace would be left alone).
    fn drop_lines(&mut self, first: usize, last: usize) -> Reply {
        let lines: Vec<&str> = self.program.lines().collect();
        if last > lines.len() {
            return Reply::error(format!(
                "the program has {} line(s); `:show` numbers them",
                lines.len()
            ));
        }
        let kept: String = lines
            .iter()
            .enumerate()
            .filter(|(i, _)| !(first - 1..last).contains(i))
            .map(|(_, l)| format!("{l}\n"))
            .collect();
        let diags = visible(crate::lang::check_source(&kept, SOURCE_NAME, &[]));
        if diags.has_errors() {
            let mut reply = Reply::error(format!(
                "not dropped: without line(s) {first}-{last} the program no longer checks (drop a whole block at once)"
            ));
            reply.push(Item::Diagnostics(diags));
            return reply;
        }
        let gone: Vec<String> = lines[first - 1..last]
            .iter()
            .map(|l| format!("  {l}"))
            .collect();
        self.program = kept;
        Reply::text(format!("dropped:\n{}", gone.join("\n")))
    }

    fn show(&self) -> String {
        if self.program.trim().is_empty() {
            return "(the program is empty: type statements, or `:load FILE`)".into();
        }
        self.program
            .lines()
            .enumerate()
            .map(|(i, l)| format!("{:3} │ {l}", i + 1))
            .collect::<Vec<_>>()
            .join("\n")
    }
}

/// The edit of `take` at `strength` by `program`: every frame may change, none is kept
/// (windows are `mprog run --keep`'s); the path and the body parts the program does not
/// touch are held ([`auto_hold`]).
fn take_edit(take: &CurrentMotion, strength: f32, program: &Program) -> Result<Edit, String> {
    if !(strength.is_finite() && (0.0..=1.0).contains(&strength)) {
        return Err(format!(
            "strength {strength} is outside 0…1 (0 returns the take, 1 ignores it)"
        ));
    }
    let take = Take::encode(&take.people)
        .map_err(|e| format!("cannot encode the take {}: {e}", take.origin))?;
    let auto = auto_hold(&take, program, &Device::flex()).map_err(|e| e.to_string())?;
    Ok(Edit {
        take,
        strength,
        hold: Vec::new(),
        hold_path: auto.path,
        hold_joints: auto.joints(),
        resample: 0,
        clean_feet: true,
    })
}

/// The [`BODY_PARTS`] an edit holds.
fn held_parts(e: &Edit) -> Vec<&'static str> {
    BODY_PARTS
        .iter()
        .filter(|(_, joints)| joints.iter().all(|&j| e.hold_joints[j]))
        .map(|(name, _)| *name)
        .collect()
}

/// What an edit holds, in words: "path and legs held" style.
fn held_summary(e: &Edit) -> String {
    let parts = held_parts(e);
    let path = if e.hold_path {
        "path held"
    } else {
        "path free"
    };
    if parts.is_empty() {
        format!("{path}, whole body free")
    } else {
        format!("{path}, held: {}", parts.join(", "))
    }
}

/// Message when a command needs a motion.
pub const NO_MOTION: &str =
    "no current motion: `:motion FILE` loads one, `:gen \"PROMPT\"` generates one";

/// Drops the diagnostics the REPL keeps quiet about.
pub fn visible(d: Diagnostics) -> Diagnostics {
    let items = d
        .items
        .into_iter()
        .filter(|i| !QUIET.contains(&i.code))
        .collect();
    Diagnostics::new(&d.name, d.source, items)
}

/// True when `d` holds an error other than the quiet ones.
pub fn real_errors(d: &Diagnostics) -> bool {
    d.items
        .iter()
        .any(|i| i.severity == Severity::Error && !QUIET.contains(&i.code))
}

fn help(topic: Option<&str>) -> Reply {
    if let Some(t) = topic {
        return match command::find(t) {
            Some(c) if c.name == "run" => Reply::text(format!(
                ":{} {}\n    {}{}\nSolvers:\n{}",
                c.name,
                c.args,
                c.help,
                aliases(c),
                crate::solve::solvers_help()
            )),
            Some(c) => Reply::text(format!(
                ":{} {}\n    {}{}",
                c.name,
                c.args,
                c.help,
                aliases(c)
            )),
            None => Reply::error(format!("no command `:{t}`")),
        };
    }
    let mut s = String::from(
        "Type mprog statements to add them to the session's program (a line continues while a\n\
         bracket is open or it ends with an operator). Commands:\n",
    );
    for c in command::COMMANDS {
        let head = format!(":{} {}", c.name, c.args);
        s.push_str(&format!("  {head:34} {}{}\n", c.help, aliases(c)));
    }
    s.push_str(&format!(
        "Output kinds of :save, :render and :view, by extension:\n{}\n",
        crate::formats::outputs::kinds_help()
            .lines()
            .map(|l| format!("  {l}"))
            .collect::<Vec<_>>()
            .join("\n")
    ));
    s.push_str(
        "Tab completes joints, functions, keywords and commands; history is kept between sessions.",
    );
    Reply::text(s)
}

fn aliases(c: &command::CommandDoc) -> String {
    if c.aliases.is_empty() {
        String::new()
    } else {
        format!(
            " (also {})",
            c.aliases
                .iter()
                .map(|a| format!(":{a}"))
                .collect::<Vec<_>>()
                .join(", ")
        )
    }
}
