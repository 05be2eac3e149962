//! The system prompt for an LLM that writes `.mprog` (`mprog prompt`): the language in
//! brief, conventions, the skeleton and the library (generated from `skeleton.rs`, the
//! built-in table and the stdlib doc comments), the error semantics, worked examples and
//! rules against the usual mistakes. Every example is a complete program; a test compiles
//! each ```` ```mprog ```` block of the prompt.

use super::library::signature_lines;
use crate::skeleton::{ALIASES, JOINT_NAMES, rest_pose};

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

during 50%..end {
    r_hand.y > head.y + 10 cm
}
always weight 0.5 { speed(pelvis) < 0.3 }
"#,
    ),
    (
        "Sit down on a chair whose seat is 45 cm high, 50 cm behind the starting position.",
        r#"prompt "a person sits down on a chair"
length 5s
param seat = 45 cm

at 80%, end {
    abs(pelvis.y - seat - 10 cm) < 5 cm
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
];

fn joints_section() -> String {
    let rest = rest_pose();
    let mut s =
        String::from("| index | joint | aliases | rest height (m) |\n| --- | --- | --- | --- |\n");
    for (i, name) in JOINT_NAMES.iter().enumerate() {
        let aliases: Vec<String> = ALIASES
            .iter()
            .filter(|(_, j)| *j == i)
            .map(|(a, _)| format!("`{a}`"))
            .collect();
        s.push_str(&format!(
            "| {i} | `{name}` | {} | {:.2} |\n",
            aliases.join(", "),
            rest[i].y
        ));
    }
    s
}

/// The full system prompt, in markdown.
pub fn system_prompt() -> String {
    let mut s = String::new();
    s.push_str(INTRO);
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

const INTRO: &str = r#"# Writing `.mprog` motion programs

You write programs in mprog, a small constraint language. A program says what a human
motion must satisfy; mprog turns it into a differentiable error on the joint positions
of the motion, and a motion diffusion model is steered to make that error small. Answer
with one complete program in a ```mprog code block, and nothing the language lacks.

## Conventions

- Skeleton: HumanML3D, 22 joints (table below). Positions are in metres, **Y is up**, the
  ground is y = 0. 20 frames per second; a motion is at most 196 frames (9.8 s).
- At frame 0 the person stands near the origin **facing +Z; their left is +X**, their
  right is −X. "Forward" is +Z, "backward" −Z, "to the left" +X.
- A standing adult: pelvis ≈ 0.95 m, head ≈ 1.6 m high (rest heights in the table).

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
if head.z > 2 m and head.z < 3 m { head.y < 1.2 m } else { head.y > 1.4 m }
weight 2 { speed(pelvis) < 1.5 }       # multiply errors by a constant ≥ 0
minimize norm(acc(r_hand))             # any scalar
```

- One statement per line (or `;`); a line continues after an operator, a comma or an
  open bracket. `#` comments.
- Numbers take units `m cm mm s ms frames deg rad`; a bare number takes the unit of what
  it meets (`head.y > 1.2` is metres). Vectors `[x, y, z]`; components `.x .y .z`;
  `.xz` is the ground projection (y set to 0). Arithmetic `+ - * /` is unit-checked.
- `e@t` is `e` at frame t: `head@0`, `pelvis@start`, `pelvis@end`, `l_hand@2s`,
  `pelvis@50%`, `head@(end - 1)`. Times: a bare number is a frame index; `2s`, `40 frames`,
  `50%` (of the last frame), `start`, `mid`, `end`, and sums/scalings of them.
- Several people: `people a "prompt of a", b "prompt of b"` replaces `prompt`; joints are
  then qualified (`a.r_hand`, `b.head`) and functions taking a person get `a`/`b`. With
  one person the person is called `me`.
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

Each statement's error is averaged over the frames of its block (and, inside `if`, only
over the frames where the condition holds), multiplied by its weight; the program's total
is the sum over statements. Errors are in the constraint's unit: metres for distances,
m/s for `vel`, radians for angles. So a total of 0.05 means "about 5 cm off on average";
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
   comparison of constants has no effect and is reported.
5. Keyframes must lie inside the length: with `length 4s`, `at 5s` is an error; prefer
   `start`, `mid`, `end` and percentages.
6. Give a `length` (at most 9.8 s) and a `prompt` that describes the whole motion; the
   constraints only steer it.
7. Prefer tolerances to exact equalities for positions (`dist(p, q) < 5 cm`), and keep
   targets reachable: arms are about 0.6 m long, a step is about 0.7 m, walking speed is
   about 1.3 m/s.
8. Units must agree: do not compare a distance with a time or an angle.
9. If mprog answers with diagnostics (JSON from `mprog check --format json`), fix exactly
   the reported problems (each has a code, a line, a message and a hint) and answer with
   the whole corrected program.
"#;
