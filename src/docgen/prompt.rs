//! The system prompt for an LLM that writes `.mprog` (`mprog prompt`): the language in
//! brief, conventions, the skeleton and the library (generated from `skeleton.rs`, the
//! built-in table and the stdlib doc comments), the error semantics, worked examples and
//! rules against the usual mistakes. Every example is a complete program; a test compiles
//! each ```` ```mprog ```` block of the prompt.

use super::library::signature_lines;
use crate::skeleton::{ALIASES, JOINT_NAMES};

/// Worked examples: (task, program). None of these tasks is in `programs/`.
pub const EXAMPLES: &[(&str, &str)] = &[
    (
        "A person jumps in place: both feet at least 30 cm off the ground around the middle, landing where they took off.",
        r#"prompt "a person jumps up in place"
length 4s

during 45%..55% {
    l_foot.y > 30 cm
    r_foot.y > 30 cm
}
at end { groundDist(pelvis, pelvis@start) < 20 cm }
"#,
    ),
    (
        "Walk to a spot 2 m to the person's left and 3 m ahead, and end there facing back where they came from.",
        r#"prompt "a person walks forward and turns around"
length 7s
param goal = [2, 0, 3]

at end {
    groundDist(pelvis, goal) < 15 cm
    dot(facing(), [0, 0, -1]) > 0.9
}
"#,
    ),
    (
        "Wave the right hand above the head during the second half, while the feet stay roughly in place.",
        r#"prompt "a person stands and waves with the right hand"
length 6s

during 50%..end + 1 {
    r_hand.y > head.y + 15 cm
}
always weight 0.5 { speed(pelvis) < 0.3 }
"#,
    ),
    (
        "Sit down on a chair whose seat surface is 45 cm high, 50 cm behind the starting position.",
        r#"prompt "a person sits down on a chair"
length 5s
param seat = 45 cm                 # height of the seat surface
# The pelvis joint is inside the body, about 10 cm above what the person sits on.
let sitting = seat + 10 cm

at 80%, end {
    abs(pelvis.y - sitting) < 5 cm
    groundDist(pelvis, [0, 0, -0.5]) < 10 cm
}
always { footHeight(me) < 5 cm }
"#,
    ),
    (
        "Two people give each other a high five at 3 s, hands above their heads.",
        r#"people a "a person raises the right hand for a high five", b "a person gives a high five"
length 5s

at 3s {
    dist(a.r_hand, b.r_hand) < 5 cm
    a.r_hand.y > a.head.y
    b.r_hand.y > b.head.y
}
always { separation(a, b, 0.4 m) }
"#,
    ),
    (
        "Stand and draw a circle 30 cm across with the right hand in front of the chest, half a turn per second.",
        r#"prompt "a person stands and moves the right hand in a circle"
length 4s

# `time` is the time since the start (s): `180 deg/s * time` turns half a circle a second.
let centre = [-0.2, 1.2, 0.35]
always {
    dist(r_hand, centre + 0.15 * [cos(180 deg/s * time), sin(180 deg/s * time), 0]) < 5 cm
}
"#,
    ),
    (
        "Raise both arms out to the sides from 1 s on, and end looking to the left.",
        r#"prompt "a person raises both arms out to the sides and looks to the left"
length 5s

# `bodyLeft()` is the torso's own left: "out to the sides" wherever the body faces. Keep
# the torso upright, or leaning sideways would point the "sides" at the sky.
during 1s..end + 1 {
    dot(normalize(l_hand - l_shoulder), bodyLeft()) > 0.9
    dot(normalize(r_hand - r_shoulder), bodyLeft()) < -0.9
    dot(bodyUp(), [0, 1, 0]) > 0.95
}
# An end state, held over the last half second rather than on the last frame alone.
during end - 0.5s..end + 1 { dot(gaze(), [1, 0, 0]) > 0.7 }
"#,
    ),
];

/// Joint heights (m) of a real person standing upright: frame 110 of HumanML3D clip
/// 012314 (`tests/fixtures/humanml3d/new_joints_012314.npy`), left and right averaged.
/// HumanML3D's raw rest offsets are IK directions, not a standing pose (the head points
/// forward, the arms hang from the collars), so they would mislead; a test checks these
/// against the fixture.
pub const STANDING_HEIGHTS: [f32; 22] = [
    0.92, 0.84, 0.84, 1.05, 0.48, 0.48, 1.19, 0.07, 0.07, 1.22, 0.03, 0.03, 1.43, 1.34, 1.34, 1.48,
    1.34, 1.34, 1.08, 1.08, 0.88, 0.88,
];

/// Frame of the fixture the heights come from.
pub const STANDING_FRAME: usize = 110;

fn joints_section() -> String {
    let mut s = String::from(
        "| index | joint | aliases | height standing (m) |\n| --- | --- | --- | --- |\n",
    );
    for (i, name) in JOINT_NAMES.iter().enumerate() {
        let aliases: Vec<String> = ALIASES
            .iter()
            .filter(|(_, j)| *j == i)
            .map(|(a, _)| format!("`{a}`"))
            .collect();
        s.push_str(&format!(
            "| {i} | `{name}` | {} | {:.2} |\n",
            aliases.join(", "),
            STANDING_HEIGHTS[i]
        ));
    }
    s.push_str(BODY_NOTES);
    s
}

const BODY_NOTES: &str = r#"
Joints are points inside the body, not its surface:
- `head` is the centre of the head; its top is about 12 cm higher, the face about 10 cm
  in front. A ceiling at height h needs `head.y < h - 12 cm`.
- `l_hand`/`r_hand` are the **wrists**; the palm is about 8 cm and the fingertips about
  18 cm further along the forearm. "Hand on the floor" is about `r_hand.y < 10 cm`;
  "hand touching a surface" is about `distToPlane(r_hand, …) < 8 cm`. `distToPlane` is
  **unsigned**, so that lets the hand go through the wall to the other side; when the
  surface is solid (a wall, a table top), keep the hand on its side with
  `signedDistToPlane(r_hand, point, normal)`, positive on the side the normal points to:
  `signedDistToPlane(r_hand, [0, 0, 1], [0, 0, -1]) > 0` and `… < 8 cm` for a wall at
  z = 1 m faced from the start.
- `l_foot`/`r_foot` are the balls of the feet (toe joints), `l_ankle`/`r_ankle` the
  ankles. A planted foot has its toe joint below 5 cm and its ankle below 10 cm;
  `footHeight(me)` is the lowest of the four.
- `chest` (`spine3`) is the upper back / chest joint, `spine2` the middle of the back,
  `spine` (`spine1`) the lower back. The torso is about 20 cm deep front to back and 35 cm
  wide at the shoulders: a hand resting on someone's chest or back is about 10–12 cm
  from their `chest` joint.
"#;

/// The full system prompt, in markdown.
pub fn system_prompt() -> String {
    system_prompt_for(&[])
}

/// Fewest training clips for an action to be listed on the card: rarer ones are single
/// takes the model has seen too little of to repeat.
pub const LISTED_ACTION_CLIPS: usize = 3;

/// The card for a model trained on `actions` (caption, training clips; from the bundle's
/// `actions.json`, most clips first): the card above plus what the motion model knows.
pub fn system_prompt_for(actions: &[(String, usize)]) -> String {
    let mut s = String::new();
    s.push_str(INTRO);
    s.push_str(&actions_section(actions));
    s.push_str("\n## Joints\n\nJoints are named by canonical name or alias (case-insensitive); these 22 are all there are.\n\n");
    s.push_str(&joints_section());
    s.push_str("\n## Library (built-ins first, then functions written in mprog)\n\n");
    for line in signature_lines() {
        s.push_str(&format!("- {line}\n"));
    }
    s.push_str(SEMANTICS);
    s.push_str("\n## Worked examples\n");
    for (i, (task, program)) in EXAMPLES.iter().enumerate() {
        s.push_str(&format!(
            "\n### Example {}: {task}\n\n```mprog\n{program}```\n",
            i + 1
        ));
    }
    s.push_str(RULES);
    s
}

/// "What the motion model knows", generated from the training captions so it cannot drift
/// from the weights; empty without an action list. Captions that differ only by a style
/// word ("a tired person runs forward") are listed once, as "a person …", with their clips
/// summed; the style words are named once above the list.
fn actions_section(actions: &[(String, usize)]) -> String {
    let (merged, styles) = merge_styles(actions);
    let listed: Vec<&(String, usize)> = merged
        .iter()
        .filter(|(_, n)| *n >= LISTED_ACTION_CLIPS)
        .collect();
    if listed.is_empty() {
        return String::new();
    }
    let styles = if styles.is_empty() {
        String::new()
    } else {
        let quoted: Vec<String> = styles.iter().map(|w| format!("\"{w}\"")).collect();
        format!(
            " Style words combine with the actions that were captured in styles: {} (\"a tired person walks forward\").",
            quoted.join(", ")
        )
    };
    let mut s = format!(
        "\n## What the motion model knows\n\n\
         The `prompt` is read by a sentence encoder, so any wording is understood, but the\n\
         model only moves as its training clips did. These are the actions it was trained on\n\
         (training clips in brackets).{styles} Prompt one of them, or a plain paraphrase; for\n\
         anything else let the constraints carry the motion. `mprog check` warns when a\n\
         prompt is far from all of them, and a prompt unlike every one of them is read as the\n\
         mean of its nearest ones (`mprog run` says which).\n\n",
    );
    for (caption, n) in listed {
        s.push_str(&format!("- {caption} ({n})\n"));
    }
    s
}

/// `a <style> person <action>` folded into `a person <action>` (clips summed), most clips
/// first, and the style words met, in order of first appearance.
fn merge_styles(actions: &[(String, usize)]) -> (Vec<(String, usize)>, Vec<String>) {
    let mut merged: Vec<(String, usize)> = Vec::new();
    let mut styles: Vec<String> = Vec::new();
    for (caption, n) in actions {
        let words: Vec<&str> = caption.split(' ').collect();
        let folded = match words.as_slice() {
            ["a" | "an", style, "person", rest @ ..]
                if !rest.is_empty() && style.chars().all(|c| c.is_ascii_lowercase()) =>
            {
                if !styles.iter().any(|s| s == style) {
                    styles.push(style.to_string());
                }
                format!("a person {}", rest.join(" "))
            }
            _ => caption.clone(),
        };
        match merged.iter_mut().find(|(c, _)| *c == folded) {
            Some((_, total)) => *total += n,
            None => merged.push((folded, *n)),
        }
    }
    merged.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    (merged, styles)
}

const INTRO: &str = r#"# Writing `.mprog` motion programs

You write programs in mprog, a small constraint language. A program says what a human
motion must satisfy; mprog turns it into a differentiable error on the joint positions
of the motion, and a motion diffusion model is steered to make that error small. Answer
with one complete program in a ```mprog code block, and nothing the language lacks.

## Conventions

- Skeleton: HumanML3D, 22 joints (table below). Positions are in metres, **Y is up**, the
  ground is y = 0. 20 frames per second. A `length` may be up to 200 s: a motion longer
  than 9.8 s is made in windows of at most 9.8 s, each continuing the last second of the
  one before, and a constraint anywhere is steered by the window that makes its frames.
- At frame 0 the person stands with the pelvis **at x = z = 0, facing +Z; their left is
  +X**, their right is −X. "Forward" is +Z, "backward" −Z, "to the left" +X. The solvers
  keep that start (only `latent` with `relax` may shift the whole motion), so a
  constraint on where the person is at frame 0 cannot be met: write places relative to
  the start (`pelvis@start + [0, 0, 3]`), make the start part of the region, or place the
  person (`start at [x, 0, z]`, below).
- Only the pelvis's ground position and facing at frame 0 are fixed; the pose (arms,
  legs, height) at frame 0 is free.
- Two people: `a` starts at the origin facing +Z, `b` at (0, 0, 2) facing −Z (2 m apart,
  face to face). P ≥ 3 people stand on a circle with neighbours 2 m apart, all facing
  its centre (0, 0, r), r = 1 / sin(180°/P) (1.15 m for three): the first at the origin
  facing +Z, the next ones going round to the first one's right (−X side), so with three
  people `b` stands front-right of `a` and `c` front-left. `spacing 1 m` (a header
  line, 0.4–20 m) puts neighbours that far apart instead: with two people `b` then stands
  at (0, 0, 1), still facing `a` (−Z). Use it when people touch from the start (holding
  hands: about 1 m), else they must walk to each other first.
- **Place people yourself** when the sentence says where they stand: `at [x, 0, z]` and/or
  `facing [dx, 0, dz]` after a person's prompt, e.g. side by side facing +Z:
  `people a "a person walks forward" at [-0.5, 0, 0] facing [0, 0, 1], b "a person walks
  forward" at [0.5, 0, 0] facing [0, 0, 1]`. One person: a header line
  `start at [1, 0, 2] facing [0, 0, -1]`. The solvers start each person there on frame 0
  (a person with only `facing` keeps the default position, and the other way round);
  starts are constant, on the floor, and at least 0.4 m apart. Never write a walk into
  position that the sentence does not ask for.
- The person is about 1.6 m tall: pelvis ≈ 0.92 m, head joint ≈ 1.48 m when standing
  (table below). Arms are about 0.6 m long (shoulder to wrist), legs about 0.85 m.
  Across the body: hips ±0.06–0.1 m from the pelvis in x, feet ±0.1–0.25 m (by stance),
  shoulders ±0.2 m.
- Speeds: walking ≈ 1.3 m/s (0.07 m per frame), running ≈ 3 m/s (0.15 m per frame); a
  constraint on a thin region (a hurdle, a line) should be thicker than one frame's
  travel, or a fast joint can step over it between frames. `vel(p)` (a vector) and
  `speed(p)` (a number) are in m/s, and a bare number compared with them is in m/s too:
  `speed(pelvis) < 1.5` means 1.5 m/s (or write the rate, `1.5 m/s`).

## The language in brief

```mprog
prompt "a person walks forward"        # text for the motion model (one person)
length 6s                              # or: length 120 frames
param d = 40 cm                        # named constant, overridable from the command line
let grip = midPoint(l_hand, r_hand)    # named expression, re-evaluated where used
def near(p, q, r) = dist(p, q) < r     # function (inlined; no recursion)

always { near(l_hand, r_hand, d) }     # every frame (top-level statements are `always` too)
at start, end { head.y > 1.5 m }       # keyframes
during 2s..4s { pelvis.z > 1 m }       # frames 2 s ≤ t < 4 s
for f in [l_foot, r_foot] { at end { f.y < 5 cm } }
for j in joints { j.y < 2.2 m }        # all 22 joints (`joints` is the set of them)
if head.z > 2 m and head.z < 3 m { head.y < 1.2 m } else { head.y > 1.4 m }
weight 2 { speed(pelvis) < 1.5 }       # multiply errors by a constant ≥ 0
minimize norm(acc(r_hand))             # any scalar
```

- One statement per line (or `;`); a line continues after an operator, a comma or an
  open bracket. `#` comments.
- Numbers take units `m cm mm s ms frames deg rad`, and per second with `/s` written
  without spaces (`1.5 m/s`, `180 deg/s`); a bare number takes the unit of what it meets
  (`head.y > 1.2` is metres; so do `sin`/`cos`: `0.3 * cos(a)` next to metres is
  metres). Vectors `[x, y, z]`; components `.x .y .z`; `.xz` is the ground projection
  (y set to 0). Arithmetic `+ - * /` is unit-checked.
- Vector parts may carry units (`[0, 60 cm, 0.5 m]`); bare parts take the unit of what
  the vector meets (metres next to a position). A unit after the bracket is an error.
- `e@t` is `e` at frame t: `head@0`, `pelvis@start`, `pelvis@end`, `l_hand@2s`,
  `pelvis@50%`, `head@(end - 1)`. `@` binds tighter than everything else:
  `pelvis@start + [0, 0, 3]` is `(pelvis@start) + [0, 0, 3]`, `pelvis@start.z` is
  `(pelvis@start).z`. Times: a bare number is a frame index; `2s`, `40 frames`, `50%`,
  `start` (frame 0), `mid`, `end` (the last frame), and sums/scalings of them. With F
  frames a time position is the frame round(fraction·(F − 1)) (plus its frames): `mid`
  is frame round((F − 1)/2), `50%` the same. `length 4s` is 80 frames, 0…79, so `at 4s`
  is out of range: use `end`.
- `during a..b` covers frames a ≤ t < b (`during 2s..end` leaves out the last frame;
  `during 2s..end + 1` includes it). Blocks nest and intersect: `at end { weight 2 { … } }`,
  `for f in feet { always { … } }` and `at end weight 2 { … }` are all fine.
- A statement outside any time block holds on every frame, wherever it sits (inside
  `for`, `if` or `weight`); `if` may sit inside time blocks and vice versa.
- `at` takes a list of times; `during` takes one range (write two blocks for two).
  `end - 2s`, `1.5s`, `-x`, and expressions inside vectors (`[0, 0, d]`) are all fine.
- `a.pelvis@start` is `(a.pelvis)@start`; `f@start` works on a loop variable.
- `time` is the time since the start in seconds, on every frame (a value, unlike the time
  positions `start`/`end`): times an angular rate it is an angle, so a hand circling at
  half a turn per second is
  `always { dist(r_hand, [0.3*cos(180 deg/s * time), 1.2, 0.3*sin(180 deg/s * time)]) < 5 cm }`.
  `time@2s` is 2 s.
- The body's own axes follow the torso, wherever it faces or lies: `bodyLeft()`,
  `bodyUp()` (pelvis to neck) and `bodyFront()`; arms out to the sides are
  `dot(normalize(l_hand - l_shoulder), bodyLeft()) > 0.9` and
  `dot(normalize(r_hand - r_shoulder), bodyLeft()) < -0.9`, with the torso kept upright
  (`dot(bodyUp(), [0, 1, 0]) > 0.95`): else the body meets them by leaning sideways, which
  points its "left" up. `gaze()` is where the head
  faces as far as joints show it (the shoulders' turn and the head's tip forward or back;
  the head turning on its own neck is not seen): looking left is `dot(gaze(), [1, 0, 0]) > 0.7`.
- A function sees its arguments, the `param`s, and the `let`s written above it.
- Reserved, not usable as names: `prompt length spacing param def let always at during for in if
  else weight minimize maximize and or not x y z xz me joints people start mid end time
  true false`.
- Functions may take people: `def hold(p, q) = dist(p.r_hand, q.l_hand) < 10 cm`;
  `for p in people { … }` loops over every person and `for j in [head, neck]`,
  `for h in hands` or `for j in joints` (all 22) over joints. With several people a joint
  of the set needs its person: `for p in people { for j in joints { p.j.y > -5 cm } }`.
- Several people: `people a "prompt of a", b "prompt of b"` replaces `prompt`; joints are
  then qualified (`a.r_hand`, `b.head`) and functions taking a person get `a`/`b`. With
  one person the person is called `me`.
- Several actions in a row: a timeline of prompts. Give each prompt a time span (the
  times of `during`), in time order, each at least 1 s long, together covering 0 s to
  `end` without gaps; consecutive spans may overlap by at most half a span (the model
  blends them). With several people, `prompt a 0s..3s "…"` is a span of `a`'s own
  timeline (then give `a` no prompt on the `people` line).

  ```mprog
  length 20s
  prompt 0s..8s "a person walks forward"
  prompt 8s..14s "a person jogs in a circle"
  prompt 13s..end "a person sits down"
  during end - 0.5s..end + 1 { pelvis.y < 0.6 m }   # ends seated
  ```
"#;

const SEMANTICS: &str = r#"
## What a constraint means (its error, per frame)

| form | error |
| --- | --- |
| `a == b` | \|a − b\| (vectors: Euclidean distance) |
| `a < b`, `a <= b` | max(a − b, 0) (vectors: summed over components) |
| `a > b`, `a >= b` | max(b − a, 0) |
| `c1 and c2` | E1 + E2 |
| `c1 or c2` | min(E1, E2) |
| `not c` | −E |
| `minimize e` / `maximize e` | e / −e |

Some functions take **people**, the others **points** (joints, vectors):

| takes | functions |
| --- | --- |
| a person (`me`, `a`, a `for p in people` variable) | `balanced(p)`, `footHeight(p)`; `facing(p?)`, `massCtr(p?)`, `massCtrNoHead(p?)` (with one person the argument may be left out: `facing()`; `balanced` and `footHeight` always need it: `balanced(me)`) |
| two people | `separation(p, q, d)` (their pelvises on the ground), `faceToFace(p, q)`, `noTorsoCollision(p, q, r)` |
| points | `contact(p, q, d)` and `apart(p, q, d)` (two joints, e.g. `a.r_hand, b.r_hand`), `dist`, `groundDist`, `distToPlane`, `signedDistToPlane`, `vel`, `speed`, `inBox`, `inSquare`, … |

Library functions marked **constraint** in the list above (`inBox`, `inSquare`, `boneDir`,
`balanced`, `contact`, `apart`, `separation`, `faceToFace`, `noTorsoCollision`) are
constraints: use them as statements or with `and`/`or`/`not`, never in arithmetic. Every
other function returns a number, a point or a vector that you compare yourself.

Each statement's error is averaged over the frames of its block (and, inside `if`, only
over the frames where the condition holds), multiplied by its weight; the program's total
is the sum over statements. Errors are in the constraint's unit: metres for distances,
m/s for `vel`, radians for angles (`boneDir`, `faceToFace`: radians of the angle off;
`balanced`, `contact`, `apart`, `separation`, `noTorsoCollision`, `inBox`, `inSquare`:
metres). So a total of 0.05 means "about 5 cm off on average";
0 means every constraint holds. Inside an `if` condition a comparison is a yes/no test
per frame (no gradient flows through it); `==` is not allowed there.
"#;

const RULES: &str = r#"
## Rules (the usual mistakes)

1. Use only the 22 joints and aliases above. There is no `buttocks`, `hand_tip`, `toe_tip`
   or `chair`; objects are points, planes or boxes you write as vectors and `param`s.
2. Height is `.y` (Y up). Never use `.z` for height: `.z` is forward/backward.
3. Get inequalities the right way round: "the head stays above 1.5 m" is `head.y > 1.5 m`;
   "below the bar" is `head.y < bar`. Read each comparison back as a sentence.
4. Every constraint must involve the motion (a joint, `massCtr()`, `facing()`, …): a
   comparison of constants has no effect and is reported. So is a constraint no motion
   can meet (`mprog::never_met`: a place other than the start at frame 0, which `always`
   and `during 0s..…` include, a joint 4 m up, 20 m travelled in a second).
5. Keyframes must lie inside the length: with `length 4s`, `at 5s` is an error; prefer
   `start`, `mid`, `end` and percentages.
6. Give a `length` (up to 200 s) and a `prompt` that describes the whole motion (a
   timeline for several actions in a row); the constraints only steer it. An end state
   ("ends lying down", "ends crouched") is held over the last half second,
   `during end - 0.5s..end + 1 { … }`: an `at end` block that fixes the posture on the
   last frame alone makes the body snap into it (`mprog::keyframe_pose`).
   Ask for poses people are recorded in: `mprog::unseen_pose` warns when no training clip
   comes near the pose a block asks for (the pelvis under 20 cm with the head above 1.1 m)
   or holds it that long (standing on one leg with the other foot 30 cm up: 2 s at most),
   and its hint names the nearest pose the data has; ask for that instead.
7. Prefer tolerances to exact equalities for positions (`dist(p, q) < 5 cm`), and keep
   targets reachable: arms are about 0.6 m long, a step is about 0.7 m, walking speed is
   about 1.3 m/s. A hand target farther than that from where the person stands needs a
   step: say where the pelvis goes (`mprog::out_of_reach` warns otherwise), and leave time
   between two places of one joint (`mprog::frame_jump` warns of a jump, e.g. 24 cm
   between consecutive frames).
8. Units must agree: do not compare a distance with a time or an angle.
9. The error is pushed just to the threshold, not past it: when a limit must really hold
   (a wall, a ceiling, a radius), leave a few centimetres of margin in the number.
10. Constrain what the words ask and no more: every extra constraint fights the model's
    natural motion. Let the prompt carry the style ("crouches", "kicks high").
11. If mprog answers with diagnostics (JSON from `mprog check --format json`), fix exactly
   the reported problems (each has a code, a line, a message and a hint) and answer with
   the whole corrected program.
12. Say the sentence's words in the forms that mean them:
    - **Speed over the ground** is `speed(projToGround(pelvis))`: `speed(pelvis) > 1.7`
      is met by the pelvis bouncing up and down on the spot.
    - **Which way a turn goes** is the sign of `cross(facing(), vel(facing())).y`, the
      turning rate in rad/s (positive: to the left, counter-clockwise seen from above):
      `during 0s..end - 1 { cross(facing(), vel(facing())).y > 0.5 }` turns left; keyframes
      of `facing()` alone leave the direction to chance.
    - **People who touch must not pass through each other**: beside a contact, keep their
      torsos apart (`always { noTorsoCollision(a, b, 12 cm) }` for a hug or a hand-over,
      `separation(a, b, 0.5 m)` for people who only meet hands).
    - **Directions of the body's own** ("arms out to the sides", "lie on the back") are
      `bodyLeft()`, `bodyFront()`, `bodyUp()`, not world axes, which stop being the body's
      once it turns.
"#;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standing_heights_are_those_of_the_real_clip() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/fixtures/humanml3d/new_joints_012314.npy"
        );
        let array = crate::formats::npy::read_npy(std::path::Path::new(path)).unwrap();
        let height = |j: usize| array.data[(STANDING_FRAME * 22 + j) * 3 + 1];
        for (j, &h) in STANDING_HEIGHTS.iter().enumerate() {
            let mirror = crate::skeleton::mirror_joint(j);
            let real = (height(j) + height(mirror)) / 2.0;
            assert!((real - h).abs() < 0.011, "joint {j}: {h} vs {real}");
        }
    }

    #[test]
    fn card_snippets_compile_as_the_card_says() {
        // Every worked example checks without warnings (the trial's programs did too).
        for (task, program) in EXAMPLES {
            let d = crate::lang::check_source(program, "example.mprog", &[]);
            assert!(d.items.is_empty(), "{task}\n{}", d.render_plain());
        }
        for src in [
            "length 2s\npeople a \"x\", b \"y\"\nfor p in people { for j in joints { p.j.y > -5 cm } }\n",
            "length 2s\nspeed(pelvis) < 1.5\nalways { balanced(me) }\nat end { dot(facing(), [0, 0, 1]) > 0.9 }\n",
            "length 2s\nat end { signedDistToPlane(r_hand, [0, 0, 1], [0, 0, -1]) > 0 and signedDistToPlane(r_hand, [0, 0, 1], [0, 0, -1]) < 8 cm }\n",
            // The inline snippets on `time`, the body's axes, `gaze` and end states.
            "length 4s\nalways { dist(r_hand, [0.3*cos(180 deg/s * time), 1.2, 0.3*sin(180 deg/s * time)]) < 5 cm }\n",
            "length 4s\nalways { dot(normalize(l_hand - l_shoulder), bodyLeft()) > 0.9\n dot(normalize(r_hand - r_shoulder), bodyLeft()) < -0.9 }\n",
            "length 4s\nat end { dot(gaze(), [1, 0, 0]) > 0.7 }\nat 1s { head.y < 1.2 m + 0.1 m/s * time@2s }\n",
            "length 4s\nduring end - 0.5s..end + 1 { pelvis.y < 0.5 m }\nalways { speed(pelvis) < 1.5 m/s }\n",
            // The timeline bullet: a person's own timeline (its example is a block of the
            // card, which tests/book.rs checks).
            "length 6s\npeople a, b \"a person waves\"\nprompt a 0s..3s \"a person walks forward\"\nprompt a 3s..end \"a person sits down\"\nalways { separation(a, b, 0.5 m) }\n",
            // Rule 12's forms: ground speed, turn direction, torsos apart.
            "length 4s\nalways { speed(projToGround(pelvis)) > 1.7 }\nduring 0s..end - 1 { cross(facing(), vel(facing())).y > 0.5 }\n",
            "length 6s\npeople a \"x\", b \"y\"\nspacing 1 m\nduring 3s..end + 1 { contact(a.l_hand, b.spine3, 15 cm) }\nalways { noTorsoCollision(a, b, 12 cm) }\n",
        ] {
            let d = crate::lang::check_source(src, "t.mprog", &[]);
            assert!(!d.has_errors(), "{src}\n{}", d.render_plain());
        }
        // Two people `spacing 1 m` apart: `b` starts at (0, 0, 1).
        let p = crate::lang::compile(
            "length 2s\nspacing 1 m\npeople a \"x\", b \"y\"\nat end { separation(a, b, 0.5 m) }\n",
            "t.mprog",
            &[],
        )
        .unwrap();
        let b = p.placements()[1];
        assert!((b.x.abs(), (b.z - 1.0).abs()) < (1e-6, 1e-6), "{b:?}");
        // The card's side-by-side placement: both face +Z, 1 m apart.
        let p = crate::lang::compile(
            "length 2s\npeople a \"a person walks forward\" at [-0.5, 0, 0] facing [0, 0, 1], b \"a person walks forward\" at [0.5, 0, 0] facing [0, 0, 1]\nalways { separation(a, b, 0.5 m) }\n",
            "t.mprog",
            &[],
        )
        .unwrap();
        let [a, b] = [p.placements()[0], p.placements()[1]];
        assert_eq!(
            (a.x, a.z, a.yaw, b.x, b.z, b.yaw),
            (-0.5, 0.0, 0.0, 0.5, 0.0, 0.0)
        );
    }

    #[test]
    fn card_gives_long_motions_and_a_twenty_second_timeline() {
        let card = system_prompt();
        assert!(!card.contains("at most 196 frames") && !card.contains("at most 9.8 s)"));
        assert!(card.contains("up to 200 s"));
        let blocks = super::super::markdown::code_blocks(&card);
        let timeline = blocks
            .iter()
            .find(|b| b.lang == "mprog" && b.text.contains("prompt 0s.."))
            .expect("the timeline example");
        let p = crate::lang::compile(&timeline.text, "t.mprog", &[]).unwrap();
        assert_eq!(p.length(), 400);
        assert_eq!(p.timelines()[0].len(), 3);
        assert_eq!(p.statements().len(), 1);
        let d = crate::lang::check_source(&timeline.text, "t.mprog", &[]);
        assert!(d.items.is_empty(), "{}", d.render_plain());
    }

    #[test]
    fn card_has_every_joint_and_the_constraint_marks() {
        let card = system_prompt();
        for name in JOINT_NAMES {
            assert!(card.contains(&format!("`{name}`")), "{name}");
        }
        assert!(card.contains("contact(p, q, d) — **constraint.**"));
        assert!(card.contains("| 15 | `head` |  | 1.48 |"));
    }
}

#[cfg(test)]
mod action_list_tests {
    use super::*;

    #[test]
    fn style_variants_are_listed_once_with_their_clips_summed() {
        let actions: Vec<(String, usize)> = [
            ("a energetic person raises both hands", 5),
            ("a person raises both hands", 4),
            ("a tired person raises both hands", 2),
            ("a person kicks forward with the left leg", 14),
            ("a person jumps", 2),
        ]
        .iter()
        .map(|(c, n)| (c.to_string(), *n))
        .collect();
        let (merged, styles) = merge_styles(&actions);
        assert_eq!(
            merged,
            vec![
                ("a person kicks forward with the left leg".to_string(), 14),
                ("a person raises both hands".to_string(), 11),
                ("a person jumps".to_string(), 2),
            ]
        );
        assert_eq!(styles, ["energetic", "tired"]);
        let section = actions_section(&actions);
        assert!(section.contains("- a person raises both hands (11)"));
        assert!(section.contains("\"energetic\", \"tired\""));
        assert!(
            !section.contains("a person jumps"),
            "below the listing threshold"
        );
    }
}
