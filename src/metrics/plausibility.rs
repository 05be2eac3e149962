//! Plausibility: is an output something a real body could do? Each person of a result is
//! held against an [`Envelope`] measured on real clips (`mprog data envelope`, shipped as
//! `models/default/envelope.json`), and every problem is located in time:
//!
//! | kind | flagged when | measured against |
//! | --- | --- | --- |
//! | `acceleration` | a joint's ‖p[t+1] − 2p[t] + p[t−1]‖ exceeds [`ACCEL_MARGIN`] × the largest acceleration of that joint in 99 % of real clips | the envelope's `accel_peak` (p99 over clips) |
//! | `speed` | a joint's speed exceeds [`SPEED_MARGIN`] × the largest speed of that joint in 99 % of real clips | the envelope's `speed_peak` (p99 over clips) |
//! | `floor_penetration` | the lowest joint is more than [`FLOOR_DEPTH`] below y = 0 | a fixed 2 cm (the envelope's `floor` is quoted) |
//! | `foot_skating` | the whole motion's foot skating ratio exceeds [`SKATING_MARGIN`] × the real clips' 99th percentile (of the clips that move, for an output that moves) | the envelope's `skating`, `skating_moving` |
//! | `interpenetration` | two people's body capsules ([`CAPSULES`]) overlap by more than [`OVERLAP_DEPTH`] | fixed radii |
//! | `rigid_deformation` | a distance no bone holds (hip width, shoulder width, the spine) leaves the real range widened by [`RIGID_SLACK`] | the envelope's `rigid` |
//! | `facing` | moving faster than [`FACING_SPEED`] backwards or sideways for [`FACING_FRAMES`] frames, when the prompt does not ask for it | fixed angles |
//! | `crouch` | the pelvis more than [`CROUCH_DROP`](super::crouch::CROUCH_DROP) below its median height for 3 frames, when the prompt asks for walking or running and nothing low ([`super::crouch`]) | real walks and runs (0.11 m on 99 % of clips) |
//! | `invalid` | a coordinate is not a finite number | — |
//!
//! Consecutive bad frames (gaps up to [`GAP`] frames) form one [`Problem`]. The report
//! knows nothing of programs: the command line fills [`Problem::statements`] with the
//! statements active at the problem's frames.

use crate::dataset::envelope::{Envelope, MOVING_SPEED, RIGID_PAIRS, RigidRange, Spread};
use crate::motion::Motion;
pub use crate::skeleton::capsules::{CAPSULES, Capsule, segment_closest, segment_distance};
use crate::skeleton::{JOINT_NAMES, NUM_JOINTS, rest_pose};
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// A joint is flagged above this multiple of the acceleration 99 % of real clips stay under.
pub const ACCEL_MARGIN: f32 = 1.5;
/// A joint is flagged above this multiple of the speed 99 % of real clips stay under.
pub const SPEED_MARGIN: f32 = 1.25;
/// Depth below the floor (m) from which a frame penetrates.
pub const FLOOR_DEPTH: f32 = 0.02;
/// Foot skating is flagged above this multiple of the real clips' 99th percentile.
pub const SKATING_MARGIN: f32 = 1.0;
/// Rigid distances may leave the real [min, max] ratio by this much (fraction of rest).
pub const RIGID_SLACK: f32 = 0.15;
/// Largest angle (degrees) between the hip line and the collar line: the torso twisted
/// about the spine. In `data/combined` it is 7° at the median, 40° at the 99.9th
/// percentile of frames and 59° at the 99.99th; CMU's ballet (05_06, a cartwheel, and the
/// leap 05_16) reach 89° and 125°, so the check sits above every recorded frame. A late
/// guidance step once turned the shoulder girdle 180° on the hips, which no distance
/// check saw.
pub const TORSO_TWIST_DEG: f32 = 130.0;
/// Pelvis speed (m/s) above which the direction of travel is compared with the facing.
pub const FACING_SPEED: f32 = 0.5;
/// Angle (degrees) between travel and facing above which a person walks backwards.
pub const BACKWARDS_DEG: f32 = 120.0;
/// Angle (degrees) above which (and up to [`BACKWARDS_DEG`]) a person walks sideways.
pub const SIDEWAYS_DEG: f32 = 60.0;
/// Frames (0.5 s) a person must walk backwards or sideways to be flagged.
pub const FACING_FRAMES: usize = 10;
/// Overlap (m) of two people's capsules beyond which they interpenetrate.
pub const OVERLAP_DEPTH: f32 = 0.03;
/// Bad frames this far apart still form one problem.
pub const GAP: usize = 2;

/// Words of a prompt that ask for walking backwards or sideways (the facing check is then
/// skipped for that person).
pub const FACING_EXEMPT: &[&str] = &[
    "backward",
    "back up",
    "backs up",
    "backing",
    "backs away",
    "back away",
    "retreat",
    "moonwalk",
    "sideways",
    "side step",
    "sidestep",
    "side-step",
    "to the side",
    "to the left",
    "to the right",
    "step left",
    "steps left",
    "step right",
    "steps right",
    "strafe",
    "shuffle",
    "crab",
    "grapevine",
    "lateral",
];

pub use super::crouch::{crouch_check, prompt_forbids_crouch};

/// Phrases before "to the left/right" that name a bend of the path.
const TURN_PHRASES: &[&str] = &[
    "circle to the",
    "circles to the",
    "turn to the",
    "turns to the",
    "turning to the",
    "curve to the",
    "curves to the",
    "veer to the",
    "veers to the",
    "bend to the",
    "bends to the",
];

/// What is wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// A joint accelerates beyond the real maximum.
    Acceleration,
    /// A joint moves faster than the real maximum.
    Speed,
    /// The body goes through the floor.
    FloorPenetration,
    /// Planted feet slide.
    FootSkating,
    /// Two people overlap.
    Interpenetration,
    /// A part that does not deform does.
    RigidDeformation,
    /// Walking backwards or sideways.
    Facing,
    /// The pelvis sinks far below its walking height in a walk or run.
    Crouch,
    /// Coordinates that are not numbers.
    Invalid,
}

impl Kind {
    /// What it is in a sentence: "met by a snap at …".
    pub fn noun(self) -> &'static str {
        match self {
            Kind::Acceleration => "a snap",
            Kind::Speed => "a superhuman speed",
            Kind::FloorPenetration => "going through the floor",
            Kind::FootSkating => "foot skating",
            Kind::Interpenetration => "people overlapping",
            Kind::RigidDeformation => "a deformed body",
            Kind::Facing => "walking against the facing",
            Kind::Crouch => "a crouch the prompt does not ask for",
            Kind::Invalid => "invalid coordinates",
        }
    }

    /// The name in the report ("acceleration").
    pub fn name(self) -> &'static str {
        match self {
            Kind::Acceleration => "acceleration",
            Kind::Speed => "speed",
            Kind::FloorPenetration => "floor penetration",
            Kind::FootSkating => "foot skating",
            Kind::Interpenetration => "interpenetration",
            Kind::RigidDeformation => "rigid part deformed",
            Kind::Facing => "facing against the path",
            Kind::Crouch => "crouch",
            Kind::Invalid => "invalid",
        }
    }
}

/// One located problem.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Problem {
    /// The person, 1-based.
    pub person: usize,
    /// What is wrong.
    pub kind: Kind,
    /// Where on the body ("head", "hip width (left_hip–right_hip)", "torso ↔ person 2's head").
    pub part: String,
    /// The joint that went furthest, when one did.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joint: Option<String>,
    /// First and last frame (20 fps), inclusive.
    pub frames: [usize; 2],
    /// The same in seconds (frame / fps).
    pub seconds: [f32; 2],
    /// The worst value over those frames.
    pub value: f32,
    /// The limit it passed.
    pub limit: f32,
    /// Unit of value and limit.
    pub unit: String,
    /// What the limit is measured against.
    pub against: String,
    /// The program's statements active at those frames (filled by the caller).
    #[serde(default)]
    pub statements: Vec<String>,
}

impl Problem {
    /// "5.85–5.95 s".
    pub fn when(&self) -> String {
        if self.frames[0] == self.frames[1] {
            format!("{:.2} s", self.seconds[0])
        } else {
            format!("{:.2}–{:.2} s", self.seconds[0], self.seconds[1])
        }
    }

    /// How far past its limit it went (1 at the limit, larger is worse).
    pub fn severity(&self) -> f32 {
        let below = self.kind == Kind::RigidDeformation && self.value < self.limit;
        let r = if below {
            self.limit / self.value.max(1e-6)
        } else {
            self.value / self.limit.max(1e-6)
        };
        if r.is_finite() { r } else { f32::INFINITY }
    }

    fn comparison(&self) -> &'static str {
        if self.kind == Kind::RigidDeformation && self.value < self.limit {
            "<"
        } else {
            ">"
        }
    }

    /// One line for a terminal.
    pub fn line(&self) -> String {
        let joint = match &self.joint {
            Some(j) if *j != self.part => format!(" ({j})"),
            _ => String::new(),
        };
        let mut s = format!(
            "person {}, {} (frames {}–{}): {} of {}{joint}: {} {} {} {}, against {}",
            self.person,
            self.when(),
            self.frames[0],
            self.frames[1],
            self.kind.name(),
            self.part,
            fmt_value(self.value),
            self.comparison(),
            fmt_value(self.limit),
            self.unit,
            self.against
        );
        if !self.statements.is_empty() {
            s.push_str(&format!("; active: {}", self.statements.join(", ")));
        }
        s
    }
}

/// One line for every problem of a (person, kind, part): its stretches in time, the
/// worst value, and the statements active over all of them.
fn group_line(group: &[&Problem]) -> String {
    let worst = group
        .iter()
        .copied()
        .max_by(|a, b| a.severity().total_cmp(&b.severity()))
        .expect("a group has problems");
    let mut times: Vec<String> = group.iter().take(4).map(|p| p.when()).collect();
    if group.len() > 4 {
        times.push(format!("… ({} stretches)", group.len()));
    }
    let joint = match &worst.joint {
        Some(j) if *j != worst.part => format!(" ({j})"),
        _ => String::new(),
    };
    let mut statements: Vec<&str> = Vec::new();
    for p in group {
        for s in &p.statements {
            if !statements.contains(&s.as_str()) {
                statements.push(s);
            }
        }
    }
    let mut s = format!(
        "person {}, {} of {}{joint} at {}: {} {} {} {}, against {}",
        worst.person,
        worst.kind.name(),
        worst.part,
        times.join(", "),
        fmt_value(worst.value),
        worst.comparison(),
        fmt_value(worst.limit),
        worst.unit,
        worst.against
    );
    if !statements.is_empty() {
        s.push_str(&format!("; active: {}", statements.join(", ")));
    }
    s
}

fn fmt_value(v: f32) -> String {
    if v.abs() >= 10.0 {
        format!("{v:.1}")
    } else if v.abs() >= 0.1 {
        format!("{v:.2}")
    } else {
        format!("{v:.3}")
    }
}

/// The plausibility of a result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// No problem found.
    pub ok: bool,
    /// The envelope checked against (its `source`).
    pub envelope: String,
    /// Every problem, by person, then time.
    pub problems: Vec<Problem>,
    /// Foot skating of each person, with what it is measured against.
    #[serde(default)]
    pub skating: Vec<String>,
}

impl Report {
    /// Lines for a terminal: a verdict, then one line per problem.
    pub fn lines(&self) -> Vec<String> {
        let mut out = vec![if self.ok {
            format!("plausibility: ok (against {})", self.envelope)
        } else {
            format!(
                "plausibility: {} problem{} (against {})",
                self.problems.len(),
                if self.problems.len() == 1 { "" } else { "s" },
                self.envelope
            )
        }];
        out.extend(self.skating.iter().map(|s| format!("  {s}")));
        let mut groups: Vec<Vec<&Problem>> = Vec::new();
        for p in &self.problems {
            match groups.iter_mut().find(|g| {
                let q = g[0];
                (q.person, q.kind, &q.part) == (p.person, p.kind, &p.part)
            }) {
                Some(g) => g.push(p),
                None => groups.push(vec![p]),
            }
        }
        out.extend(groups.iter().map(|g| format!("  {}", group_line(g))));
        out
    }

    /// The report as a JSON value (`meta.plausibility`).
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::to_value(self).expect("report serialises")
    }

    /// The problems that overlap frames `a..=b`, of any kind.
    pub fn overlapping(&self, a: usize, b: usize) -> impl Iterator<Item = &Problem> {
        self.problems
            .iter()
            .filter(move |p| p.frames[0] <= b && a <= p.frames[1])
    }
}

/// Whether a prompt asks for walking backwards or sideways.
pub fn prompt_allows_facing(prompt: &str) -> bool {
    let mut p = prompt.to_lowercase();
    // "walks in a circle to the right" and "turns to the left" say where the path bends,
    // not that the body steps sideways.
    for bend in TURN_PHRASES {
        p = p.replace(bend, " ");
    }
    FACING_EXEMPT.iter().any(|w| p.contains(w))
}

/// Holds every person against `env`. `prompts[i]` is person i's prompt (for the facing
/// check; `None` or a missing entry: no exemption).
pub fn check(people: &[Motion], prompts: &[Option<String>], env: &Envelope) -> Report {
    let mut problems = Vec::new();
    let mut skating = Vec::new();
    for (i, m) in people.iter().enumerate() {
        let person = i + 1;
        let fps = if m.fps > 0.0 { m.fps } else { 20.0 };
        let bad: Vec<bool> = m
            .frames
            .iter()
            .map(|f| f.iter().any(|p| !p.is_finite()))
            .collect();
        if bad.iter().any(|&b| b) {
            for (a, b) in runs(&bad, GAP) {
                problems.push(Problem {
                    person,
                    kind: Kind::Invalid,
                    part: "joint positions".into(),
                    joint: None,
                    frames: [a, b],
                    seconds: [a as f32 / fps, b as f32 / fps],
                    value: f32::NAN,
                    limit: 0.0,
                    unit: String::new(),
                    against: "coordinates must be finite numbers".into(),
                    statements: Vec::new(),
                });
            }
            continue;
        }
        let prompt = prompts.get(i).and_then(|p| p.as_deref());
        let mut found = Vec::new();
        joint_checks(m, env, &mut found);
        floor_check(m, env, &mut found);
        let (line, skate) = skating_check(m, env);
        skating.push(if people.len() > 1 {
            format!("person {person}: {line}")
        } else {
            line
        });
        found.extend(skate);
        rigid_checks(m, env, &mut found);
        if !prompt.is_some_and(prompt_allows_facing) {
            facing_check(m, &mut found);
        }
        if prompt.is_some_and(prompt_forbids_crouch) {
            crouch_check(m, &mut found);
        }
        for p in &mut found {
            p.person = person;
            p.seconds = [p.frames[0] as f32 / fps, p.frames[1] as f32 / fps];
        }
        problems.extend(found);
    }
    for i in 0..people.len() {
        for j in i + 1..people.len() {
            if people[i].is_finite() && people[j].is_finite() {
                overlap_check(&people[i], &people[j], i + 1, j + 1, &mut problems);
            }
        }
    }
    problems.sort_by(|a, b| {
        (a.person, a.frames[0], a.kind as u8).cmp(&(b.person, b.frames[0], b.kind as u8))
    });
    Report {
        ok: problems.is_empty(),
        envelope: env.source.clone(),
        problems,
        skating,
    }
}

/// Runs of `true` as inclusive (first, last) pairs; runs `gap` or fewer apart are joined.
pub fn runs(flags: &[bool], gap: usize) -> Vec<(usize, usize)> {
    let mut out: Vec<(usize, usize)> = Vec::new();
    for (t, _) in flags.iter().enumerate().filter(|(_, f)| **f) {
        match out.last_mut() {
            Some(last) if t <= last.1 + gap + 1 => last.1 = t,
            _ => out.push((t, t)),
        }
    }
    out
}

fn blank(kind: Kind, part: &str, frames: (usize, usize)) -> Problem {
    Problem {
        person: 0,
        kind,
        part: part.into(),
        joint: None,
        frames: [frames.0, frames.1],
        seconds: [0.0, 0.0],
        value: 0.0,
        limit: 0.0,
        unit: String::new(),
        against: String::new(),
        statements: Vec::new(),
    }
}

/// Every joint's acceleration and speed against the real clips' peaks, grouped by body part.
fn joint_checks(m: &Motion, env: &Envelope, out: &mut Vec<Problem>) {
    let n = m.len();
    // Speed of step t → t + 1, placed at frame t + 1 (so a frame is where it arrives).
    let speed = |t: usize, j: usize| (m.frames[t][j] - m.frames[t - 1][j]).length() * m.fps;
    let accel = |t: usize, j: usize| {
        (m.frames[t + 1][j] - 2.0 * m.frames[t][j] + m.frames[t - 1][j]).length()
    };
    struct Check<'a> {
        kind: Kind,
        measure: &'a dyn Fn(usize, usize) -> f32,
        spreads: &'a [Spread],
        margin: f32,
        unit: &'static str,
        what: &'static str,
        range: std::ops::Range<usize>,
    }
    let checks = [
        Check {
            kind: Kind::Acceleration,
            measure: &accel,
            spreads: &env.accel_peak,
            margin: ACCEL_MARGIN,
            unit: "m/frame²",
            what: "acceleration",
            range: 1..n.saturating_sub(1),
        },
        Check {
            kind: Kind::Speed,
            measure: &speed,
            spreads: &env.speed_peak,
            margin: SPEED_MARGIN,
            unit: "m/s",
            what: "speed",
            range: 1..n,
        },
    ];
    for Check {
        kind,
        measure,
        spreads,
        margin,
        unit,
        what,
        range,
    } in checks
    {
        for (part, joints) in crate::skeleton::BODY_PARTS {
            let mut flags = vec![false; n];
            // (ratio to limit, value, joint) of the worst joint at each frame.
            let mut worst = vec![(0.0f32, 0.0f32, 0usize); n];
            for t in range.clone() {
                for &j in joints {
                    let limit = spreads[j].p99 * margin;
                    if limit <= 0.0 {
                        continue;
                    }
                    let v = measure(t, j);
                    if v > limit {
                        flags[t] = true;
                        if v / limit > worst[t].0 {
                            worst[t] = (v / limit, v, j);
                        }
                    }
                }
            }
            for (a, b) in runs(&flags, GAP) {
                let (_, value, j) = worst[a..=b]
                    .iter()
                    .copied()
                    .fold((0.0, 0.0, 0), |w, x| if x.0 > w.0 { x } else { w });
                let real = spreads[j].p99;
                let mut p = blank(kind, part, (a, b));
                p.joint = Some(JOINT_NAMES[j].into());
                p.value = value;
                p.limit = real * margin;
                p.unit = unit.into();
                p.against = format!(
                    "{margin} × the {} {what} that 99 % of real clips stay under ({})",
                    JOINT_NAMES[j],
                    fmt_value(real)
                );
                out.push(p);
            }
        }
    }
}

fn floor_check(m: &Motion, env: &Envelope, out: &mut Vec<Problem>) {
    let lowest: Vec<(f32, usize)> = m
        .frames
        .iter()
        .map(|f| {
            f.iter()
                .enumerate()
                .map(|(j, p)| (p.y, j))
                .fold((f32::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a })
        })
        .collect();
    let flags: Vec<bool> = lowest.iter().map(|(y, _)| *y < -FLOOR_DEPTH).collect();
    for (a, b) in runs(&flags, GAP) {
        let (y, j) = lowest[a..=b]
            .iter()
            .copied()
            .fold((f32::INFINITY, 0), |w, x| if x.0 < w.0 { x } else { w });
        let mut p = blank(Kind::FloorPenetration, JOINT_NAMES[j], (a, b));
        p.value = -y;
        p.limit = FLOOR_DEPTH;
        p.unit = "m below the floor".into();
        p.against = format!(
            "a fixed {:.0} cm (real clips: lowest joint at {:.1} cm in their lowest 0.1% of frames)",
            FLOOR_DEPTH * 100.0,
            env.floor.p0_1 * 100.0
        );
        out.push(p);
    }
}

/// The figure printed for foot skating, with what it is measured against, and a problem
/// when it is beyond the limit.
fn skating_check(m: &Motion, env: &Envelope) -> (String, Option<Problem>) {
    let steps = crate::metrics::per_motion::skating_steps(m);
    let ratio = if steps.is_empty() {
        0.0
    } else {
        steps.iter().filter(|&&s| s).count() as f32 / steps.len() as f32
    };
    let moving = crate::metrics::per_motion::mean_root_speed(m) > MOVING_SPEED
        && env.skating_moving.p99 > 0.0;
    let (real, which) = if moving {
        (&env.skating_moving, "real clips moving > 0.5 m/s")
    } else {
        (&env.skating, "real clips")
    };
    let limit = real.p99 * SKATING_MARGIN;
    let against = format!(
        "{which}: mean {:.3}, p95 {:.3}, p99 {:.3}",
        real.mean, real.p95, real.p99
    );
    let line = format!(
        "foot skating {ratio:.3} (share of frame steps with a sliding planted foot; {against}; flagged above the p99)"
    );
    if ratio <= limit || limit <= 0.0 {
        return (line, None);
    }
    // Locate it: the longest stretch of skating steps (gaps of 4 steps joined).
    let (a, b) = runs(&steps, 4)
        .into_iter()
        .max_by_key(|(a, b)| b - a)
        .unwrap_or((0, 0));
    let mut p = blank(Kind::FootSkating, "feet", (a, b + 1));
    p.value = ratio;
    p.limit = limit;
    p.unit = "of the motion's steps".into();
    p.against = format!("{against} (the frames are its longest stretch)");
    (line, Some(p))
}

fn rigid_checks(m: &Motion, env: &Envelope, out: &mut Vec<Problem>) {
    for r in &env.rigid {
        rigid_check(m, r, out);
    }
    twist_check(m, out);
}

/// The angle (degrees) between the hip line (left − right hip) and the collar line.
pub fn torso_twist(pose: &[Vec3; NUM_JOINTS]) -> f32 {
    let (hips, collars) = (pose[1] - pose[2], pose[13] - pose[14]);
    let cos = hips.dot(collars) / (hips.length() * collars.length()).max(1e-9);
    cos.clamp(-1.0, 1.0).acos().to_degrees()
}

fn twist_check(m: &Motion, out: &mut Vec<Problem>) {
    let twist: Vec<f32> = m.frames.iter().map(torso_twist).collect();
    let flags: Vec<bool> = twist.iter().map(|&d| d > TORSO_TWIST_DEG).collect();
    for (s, e) in runs(&flags, GAP) {
        let mut p = blank(
            Kind::RigidDeformation,
            "torso twist (hip line to collar line)",
            (s, e),
        );
        p.value = twist[s..=e].iter().copied().fold(0.0, f32::max);
        p.limit = TORSO_TWIST_DEG;
        p.unit = "°".into();
        p.against =
            "real clips: 40° at the 99.9th percentile of frames, 125° at most (ballet)".into();
        out.push(p);
    }
}

fn rigid_check(m: &Motion, r: &RigidRange, out: &mut Vec<Problem>) {
    let [a, b] = r.joints;
    let lo = r.ratio.min - RIGID_SLACK;
    let hi = r.ratio.max + RIGID_SLACK;
    let ratios: Vec<f32> = m
        .frames
        .iter()
        .map(|f| (f[a] - f[b]).length() / r.rest)
        .collect();
    let flags: Vec<bool> = ratios.iter().map(|&x| x < lo || x > hi).collect();
    for (s, e) in runs(&flags, GAP) {
        let worst = ratios[s..=e].iter().copied().fold(1.0f32, |w, x| {
            if (x - 1.0).abs() > (w - 1.0).abs() {
                x
            } else {
                w
            }
        });
        let mut p = blank(Kind::RigidDeformation, &r.name, (s, e));
        p.value = worst;
        p.limit = if worst < 1.0 { lo } else { hi };
        p.unit = format!("× its rest length {:.3} m", r.rest);
        p.against = format!(
            "real clips' range {:.2}–{:.2} × rest, widened by {RIGID_SLACK}",
            r.ratio.min, r.ratio.max
        );
        out.push(p);
    }
}

/// Horizontal facing of a pose: perpendicular to the hips and shoulders, +Z at rest.
pub fn facing(pose: &[Vec3; NUM_JOINTS]) -> Vec3 {
    let across = (pose[1] - pose[2]) + (pose[16] - pose[17]);
    let f = across.cross(Vec3::Y);
    Vec3::new(f.x, 0.0, f.z).normalize_or_zero()
}

fn facing_check(m: &Motion, out: &mut Vec<Problem>) {
    let n = m.len();
    if n < 5 {
        return;
    }
    // (angle in degrees, speed) at frames 2..n-2, from the pelvis over ±2 frames.
    let mut angle = vec![0.0f32; n];
    let mut backwards = vec![false; n];
    let mut sideways = vec![false; n];
    for t in 2..n - 2 {
        let d = m.frames[t + 2][0] - m.frames[t - 2][0];
        let v = Vec3::new(d.x, 0.0, d.z);
        let speed = v.length() * m.fps / 4.0;
        let f = facing(&m.frames[t]);
        if speed < FACING_SPEED || f == Vec3::ZERO {
            continue;
        }
        let cos = (v.normalize().dot(f)).clamp(-1.0, 1.0);
        let deg = cos.acos().to_degrees();
        angle[t] = deg;
        backwards[t] = deg > BACKWARDS_DEG;
        sideways[t] = deg > SIDEWAYS_DEG && deg <= BACKWARDS_DEG;
    }
    for (flags, part) in [
        (&backwards, "walking backwards"),
        (&sideways, "walking sideways"),
    ] {
        for (a, b) in runs(flags, GAP) {
            if b + 1 - a < FACING_FRAMES {
                continue;
            }
            let sum: f32 = (a..=b).filter(|&t| flags[t]).map(|t| angle[t]).sum();
            let count = (a..=b).filter(|&t| flags[t]).count().max(1);
            let mut p = blank(Kind::Facing, part, (a, b));
            p.value = sum / count as f32;
            p.limit = if part == "walking backwards" {
                BACKWARDS_DEG
            } else {
                SIDEWAYS_DEG
            };
            p.unit = "° between the path and the facing".into();
            p.against = format!(
                "travel above {FACING_SPEED} m/s for at least {:.1} s that the prompt does not ask for",
                FACING_FRAMES as f32 / m.fps
            );
            out.push(p);
        }
    }
}

fn overlap_check(a: &Motion, b: &Motion, pa: usize, pb: usize, out: &mut Vec<Problem>) {
    let n = a.len().min(b.len());
    let mut depth = vec![(0.0f32, 0usize, 0usize); n];
    for (t, d) in depth.iter_mut().enumerate() {
        let (fa, fb) = (&a.frames[t], &b.frames[t]);
        for (i, ca) in CAPSULES.iter().enumerate() {
            for (k, cb) in CAPSULES.iter().enumerate() {
                let dist = segment_distance(
                    fa[ca.joints[0]],
                    fa[ca.joints[1]],
                    fb[cb.joints[0]],
                    fb[cb.joints[1]],
                );
                let over = ca.radius + cb.radius - dist;
                if over > d.0 {
                    *d = (over, i, k);
                }
            }
        }
    }
    let flags: Vec<bool> = depth.iter().map(|d| d.0 > OVERLAP_DEPTH).collect();
    for (s, e) in runs(&flags, GAP) {
        let (over, i, k) = depth[s..=e]
            .iter()
            .copied()
            .fold((0.0, 0, 0), |w, x| if x.0 > w.0 { x } else { w });
        let mut p = blank(
            Kind::Interpenetration,
            &format!("{} ↔ person {pb}'s {}", CAPSULES[i].name, CAPSULES[k].name),
            (s, e),
        );
        p.person = pa;
        p.seconds = [s as f32 / a.fps, e as f32 / a.fps];
        p.value = over;
        p.limit = OVERLAP_DEPTH;
        p.unit = "m of overlap".into();
        p.against = format!(
            "body capsules of radius {:.3} and {:.3} m",
            CAPSULES[i].radius, CAPSULES[k].radius
        );
        out.push(p);
    }
}

/// Measures an envelope on real clips (each at `fps`); `source` says what they are.
pub fn measure_envelope<'a>(clips: impl Iterator<Item = &'a Motion>, source: &str) -> Envelope {
    let mut speed: Vec<Vec<f32>> = vec![Vec::new(); NUM_JOINTS];
    let mut accel: Vec<Vec<f32>> = vec![Vec::new(); NUM_JOINTS];
    let mut speed_peak: Vec<Vec<f32>> = vec![Vec::new(); NUM_JOINTS];
    let mut accel_peak: Vec<Vec<f32>> = vec![Vec::new(); NUM_JOINTS];
    let mut floor = Vec::new();
    let mut skating = Vec::new();
    let mut skating_moving = Vec::new();
    let rest = rest_pose();
    let rest_len: Vec<f32> = RIGID_PAIRS
        .iter()
        .map(|r| (rest[r.joints[0]] - rest[r.joints[1]]).length())
        .collect();
    let mut rigid: Vec<Vec<f32>> = vec![Vec::new(); RIGID_PAIRS.len()];
    let (mut count, mut frames, mut fps) = (0usize, 0usize, crate::skeleton::FPS);
    for m in clips {
        if m.is_empty() || !m.is_finite() {
            continue;
        }
        count += 1;
        frames += m.len();
        fps = m.fps;
        let f = &m.frames;
        for j in 0..NUM_JOINTS {
            let (s0, a0) = (speed[j].len(), accel[j].len());
            speed[j].extend(f.windows(2).map(|w| (w[1][j] - w[0][j]).length() * m.fps));
            accel[j].extend(
                f.windows(3)
                    .map(|w| (w[2][j] - 2.0 * w[1][j] + w[0][j]).length()),
            );
            if speed[j].len() > s0 {
                speed_peak[j].push(speed[j][s0..].iter().copied().fold(0.0, f32::max));
            }
            if accel[j].len() > a0 {
                accel_peak[j].push(accel[j][a0..].iter().copied().fold(0.0, f32::max));
            }
        }
        floor.extend(
            f.iter()
                .map(|p| p.iter().map(|v| v.y).fold(f32::INFINITY, f32::min)),
        );
        if m.len() >= 2 {
            let s = crate::metrics::per_motion::foot_skating_ratio(m);
            skating.push(s);
            if crate::metrics::per_motion::mean_root_speed(m) > MOVING_SPEED {
                skating_moving.push(s);
            }
        }
        for (k, r) in RIGID_PAIRS.iter().enumerate() {
            rigid[k].extend(
                f.iter()
                    .map(|p| (p[r.joints[0]] - p[r.joints[1]]).length() / rest_len[k]),
            );
        }
    }
    Envelope {
        version: crate::dataset::envelope::ENVELOPE_VERSION,
        source: format!("{source}: {count} clips, {frames} frames"),
        clips: count,
        frames,
        fps,
        speed: speed.iter_mut().map(Spread::of).collect(),
        accel: accel.iter_mut().map(Spread::of).collect(),
        speed_peak: speed_peak.iter_mut().map(Spread::of).collect(),
        accel_peak: accel_peak.iter_mut().map(Spread::of).collect(),
        floor: Spread::of(&mut floor),
        skating: Spread::of(&mut skating),
        skating_moving: Spread::of(&mut skating_moving),
        rigid: RIGID_PAIRS
            .iter()
            .zip(rigid.iter_mut())
            .zip(&rest_len)
            .map(|((r, v), &rest)| RigidRange {
                name: r.name.into(),
                joints: r.joints,
                rest,
                ratio: Spread::of(v),
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::Pose;

    /// A stick walk: the rest pose carried along `dir` at `speed` m/s, legs and arms
    /// swinging at 1 Hz, the standing foot's toe kept on the floor.
    pub(crate) fn walk(frames: usize, speed: f32, dir: Vec3, phase: f32) -> Motion {
        let rest = rest_pose();
        let lowest = rest.iter().map(|p| p.y).fold(f32::INFINITY, f32::min);
        let fps = 20.0;
        let poses = (0..frames)
            .map(|t| {
                let time = t as f32 / fps;
                let w = std::f32::consts::TAU * time + phase;
                let base = dir * speed * time + Vec3::new(0.0, -lowest, 0.0);
                let mut p: Pose = std::array::from_fn(|j| rest[j] + base);
                // Left leg swings with sin, right leg against it; arms opposite the legs.
                for (joints, sign) in [([4usize, 7, 10], 1.0f32), ([5, 8, 11], -1.0)] {
                    let s = sign * w.sin();
                    for (k, &j) in joints.iter().enumerate() {
                        let reach = [0.1, 0.2, 0.22][k];
                        p[j] += dir * (0.8 * reach * s);
                        if k > 0 {
                            p[j].y += 0.06 * (w.cos() * sign).max(0.0);
                        }
                    }
                }
                for (joints, sign) in [([18usize, 20], -1.0f32), ([19, 21], 1.0)] {
                    for (k, &j) in joints.iter().enumerate() {
                        p[j] += dir * (sign * w.sin() * [0.08, 0.15][k]);
                    }
                }
                p
            })
            .collect();
        Motion::new(poses)
    }

    fn envelope() -> Envelope {
        let clips: Vec<Motion> = [0.6f32, 0.9, 1.2, 1.5, 1.8]
            .iter()
            .flat_map(|&s| [0.0f32, 1.0, 2.0].map(|ph| walk(120, s, Vec3::Z, ph)))
            .collect();
        measure_envelope(clips.iter(), "synthetic walks")
    }

    fn kinds(r: &Report) -> Vec<Kind> {
        r.problems.iter().map(|p| p.kind).collect()
    }

    #[test]
    fn a_torso_twisted_on_its_hips_is_found() {
        let mut m = walk(40, 1.0, Vec3::Z, 0.0);
        for f in &mut m.frames[10..20] {
            // The shoulder girdle turned half a turn about the spine: collars swapped.
            for (l, r) in [(13, 14), (16, 17), (18, 19), (20, 21)] {
                f.swap(l, r);
            }
        }
        let r = check(&[m], &[None], &envelope());
        let p = r
            .problems
            .iter()
            .find(|p| p.part.starts_with("torso twist"))
            .expect("the twist is reported");
        assert_eq!(p.frames, [10, 19]);
        assert!(p.value > 170.0, "{}", p.value);
    }

    #[test]
    fn a_clean_walk_passes() {
        let env = envelope();
        let r = check(&[walk(100, 1.1, Vec3::Z, 0.5)], &[None], &env);
        assert!(r.ok, "{:#?}", r.problems);
        assert_eq!(r.skating.len(), 1);
        assert!(
            r.skating[0].contains("real clips moving > 0.5 m/s: mean"),
            "{}",
            r.skating[0]
        );
        // Two people side by side, 1.5 m apart, are fine too.
        let b = walk(100, 1.1, Vec3::Z, 0.5);
        let b = Motion::new(
            b.frames
                .iter()
                .map(|f| f.map(|p| p + Vec3::new(1.5, 0.0, 0.0)))
                .collect(),
        );
        let r = check(&[walk(100, 1.1, Vec3::Z, 0.5), b], &[None, None], &env);
        assert!(r.ok, "{:#?}", r.problems);
    }

    #[test]
    fn a_snap_is_found_and_located() {
        let env = envelope();
        let mut m = walk(100, 1.1, Vec3::Z, 0.5);
        // The head and neck jump 25 cm sideways for frames 60–61.
        for t in 60..62 {
            m.frames[t][15].x += 0.25;
            m.frames[t][12].x += 0.25;
        }
        let r = check(&[m], &[None], &env);
        assert!(!r.ok);
        let p = r
            .problems
            .iter()
            .find(|p| p.kind == Kind::Acceleration && p.part == "head")
            .expect("a snap of the head");
        assert!(p.frames[0] >= 59 && p.frames[1] <= 62, "{:?}", p.frames);
        assert!((p.seconds[0] - p.frames[0] as f32 / 20.0).abs() < 1e-6);
        assert!(p.value > p.limit && p.against.contains("acceleration that 99 % of real clips"));
        assert!(p.line().contains("person 1"), "{}", p.line());
    }

    #[test]
    fn floor_penetration_is_found() {
        let env = envelope();
        let mut m = walk(100, 1.1, Vec3::Z, 0.5);
        for f in &mut m.frames[40..50] {
            f[10].y = -0.05;
        }
        let r = check(&[m], &[None], &env);
        let p = r
            .problems
            .iter()
            .find(|p| p.kind == Kind::FloorPenetration)
            .expect("floor penetration");
        assert_eq!((p.frames, p.part.as_str()), ([40, 49], "left_foot"));
        assert!((p.value - 0.05).abs() < 1e-6);
        // 1.5 cm below is within the tolerance.
        let mut m = walk(100, 1.1, Vec3::Z, 0.5);
        for f in &mut m.frames {
            for p in f.iter_mut() {
                p.y -= 0.015;
            }
        }
        assert!(!kinds(&check(&[m], &[None], &env)).contains(&Kind::FloorPenetration));
    }

    #[test]
    fn squeezed_hips_are_found_though_bones_keep_their_length() {
        let env = envelope();
        let mut m = walk(100, 1.1, Vec3::Z, 0.5);
        for f in &mut m.frames {
            // Hips 1 cm apart: pelvis–hip bones kept by lowering them (a "V").
            let len = (f[1] - f[0]).length();
            let drop = (len * len - 0.005f32 * 0.005).sqrt();
            f[1] = f[0] + Vec3::new(0.005, -drop, 0.0);
            f[2] = f[0] + Vec3::new(-0.005, -drop, 0.0);
        }
        let r = check(&[m], &[None], &env);
        let p = r
            .problems
            .iter()
            .find(|p| p.kind == Kind::RigidDeformation && p.part.starts_with("hip width"))
            .expect("squeezed hips");
        assert_eq!(p.frames, [0, 99]);
        assert!(p.value < 0.1 && p.value < p.limit, "{p:?}");
    }

    #[test]
    fn two_people_overlapping_are_found() {
        let env = envelope();
        let a = walk(60, 1.0, Vec3::Z, 0.0);
        let mut b = a.clone();
        for (t, f) in b.frames.iter_mut().enumerate() {
            // 1 m to the side, then 8 cm from frame 30 on.
            let dx = if t < 30 { 1.0 } else { 0.08 };
            for p in f.iter_mut() {
                p.x += dx;
            }
        }
        let r = check(&[a, b], &[None, None], &env);
        let p = r
            .problems
            .iter()
            .find(|p| p.kind == Kind::Interpenetration)
            .expect("overlap");
        assert_eq!(p.person, 1);
        assert_eq!(p.frames, [30, 59]);
        assert!(p.part.contains("person 2"), "{}", p.part);
    }

    #[test]
    fn walking_backwards_is_found_unless_asked_for() {
        let env = envelope();
        // Facing +Z (hips and shoulders as at rest), travelling −Z.
        let back = walk(80, 1.0, -Vec3::Z, 0.0);
        assert!(facing(&back.frames[0]).dot(Vec3::Z) > 0.99);
        let r = check(std::slice::from_ref(&back), &[None], &env);
        let p = r
            .problems
            .iter()
            .find(|p| p.kind == Kind::Facing)
            .expect("backwards");
        assert_eq!(p.part, "walking backwards");
        assert!(p.frames[1] - p.frames[0] >= FACING_FRAMES);
        let asked = Some("a person walks backwards".to_string());
        assert!(!kinds(&check(&[back], &[asked], &env)).contains(&Kind::Facing));
        // Sideways: travelling +X while facing +Z.
        let side = walk(80, 1.0, Vec3::X, 0.0);
        let r = check(&[side], &[Some("a person walks".into())], &env);
        assert!(
            r.problems
                .iter()
                .any(|p| p.kind == Kind::Facing && p.part == "walking sideways"),
            "{:#?}",
            r.problems
        );
    }

    #[test]
    fn odd_input_does_not_panic() {
        let env = envelope();
        assert!(check(&[], &[], &env).ok);
        assert!(check(&[Motion::new(Vec::new())], &[], &env).ok);
        let one = Motion::new(vec![walk(1, 1.0, Vec3::Z, 0.0).frames[0]]);
        assert!(check(&[one], &[None], &env).ok);
        let mut m = walk(30, 1.0, Vec3::Z, 0.0);
        m.frames[7][3].y = f32::NAN;
        let r = check(&[m], &[None], &env);
        assert_eq!(kinds(&r), vec![Kind::Invalid]);
        assert_eq!(r.problems[0].frames, [7, 7]);
        // The report serialises (NaN as null) for meta.
        let v = r.to_json();
        assert_eq!(v["ok"], false);
    }

    #[test]
    fn a_bend_of_the_path_is_not_a_side_step() {
        assert!(prompt_allows_facing("a person walks to the left"));
        assert!(prompt_allows_facing("someone walks backwards"));
        assert!(!prompt_allows_facing(
            "a person walks in a circle to the right"
        ));
        assert!(!prompt_allows_facing(
            "a person walks and turns to the left"
        ));
        assert!(!prompt_allows_facing("a person walks forward"));
    }

    #[test]
    fn runs_join_small_gaps() {
        let f = |s: &str| s.chars().map(|c| c == '1').collect::<Vec<_>>();
        assert_eq!(runs(&f("0110010001"), 2), vec![(1, 5), (9, 9)]);
        assert_eq!(runs(&f("000"), 2), vec![]);
    }

    #[test]
    fn segment_distance_cases() {
        let d = segment_distance(
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(0.5, 1.0, 0.0),
            Vec3::new(0.5, 1.0, 1.0),
        );
        assert!((d - 1.0).abs() < 1e-6);
        let d = segment_distance(
            Vec3::ZERO,
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(3.0, 0.0, 0.0),
        );
        assert!((d - 2.0).abs() < 1e-6);
        let d = segment_distance(
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(0.5, -1.0, 0.0),
            Vec3::new(0.5, 1.0, 0.0),
        );
        assert!(d.abs() < 1e-6);
    }

    #[test]
    fn the_builtin_envelope_passes_the_clean_walk() {
        let env = Envelope::builtin();
        let r = check(&[walk(100, 1.1, Vec3::Z, 0.5)], &[None], &env);
        let serious: Vec<_> = r
            .problems
            .iter()
            .filter(|p| p.kind != Kind::FootSkating)
            .collect();
        assert!(serious.is_empty(), "{serious:#?}");
    }
}
