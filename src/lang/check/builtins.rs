//! The table of built-in (Rust) functions: names, arities and documentation. Their
//! meaning is implemented in `calls.rs` (numeric ones in `numeric.rs`); library functions written in mprog live in
//! `stdlib/*.mprog`.

/// One built-in function.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BuiltinDoc {
    /// Name.
    pub name: &'static str,
    /// Parameter list as shown in docs.
    pub signature: &'static str,
    /// Fewest arguments.
    pub min_args: usize,
    /// Most arguments.
    pub max_args: usize,
    /// What it computes.
    pub doc: &'static str,
    /// A statement using it.
    pub example: &'static str,
}

const fn b(
    name: &'static str,
    signature: &'static str,
    min_args: usize,
    max_args: usize,
    doc: &'static str,
    example: &'static str,
) -> BuiltinDoc {
    BuiltinDoc {
        name,
        signature,
        min_args,
        max_args,
        doc,
        example,
    }
}

/// Every built-in, alphabetically.
pub const BUILTINS: &[BuiltinDoc] = &[
    b(
        "abs",
        "abs(x)",
        1,
        1,
        "Absolute value (elementwise).",
        "abs(pelvis.x) < 0.1 m",
    ),
    b(
        "acc",
        "acc(x)",
        1,
        1,
        "Acceleration: second time difference of x times fps² (per s²); the last two frames repeat the last value.",
        "norm(acc(r_hand)) < 20",
    ),
    b(
        "atan2",
        "atan2(y, x)",
        2,
        2,
        "Angle of (x, y) in radians.",
        "atan2(facing().x, facing().z) < 30 deg",
    ),
    b(
        "bodyFront",
        "bodyFront(person?)",
        0,
        1,
        "Unit vector out of the front of the torso, in 3-D (it tilts with the torso, unlike `facing`): bodyLeft × bodyUp. Standing it is `facing()`; lying on the back it points up.",
        "at end { dot(bodyFront(), [0, 1, 0]) > 0.9 }",
    ),
    b(
        "bodyLeft",
        "bodyLeft(person?)",
        0,
        1,
        "Unit vector to the torso's own left: the right-to-left direction of the hips and of the shoulders (each normalised, summed), made perpendicular to bodyUp. Standing facing +Z it is +X.",
        "always { dot(normalize(l_hand - l_shoulder), bodyLeft()) > 0.8 }",
    ),
    b(
        "bodyUp",
        "bodyUp(person?)",
        0,
        1,
        "Unit vector along the spine, pelvis to neck: +Y standing upright, horizontal lying down. With bodyLeft and bodyFront it makes a right-handed frame (left × up = front).",
        "at end { dot(bodyUp(), [0, 1, 0]) < 0.3 }",
    ),
    b(
        "clamp",
        "clamp(x, lo, hi)",
        3,
        3,
        "x limited to [lo, hi].",
        "clamp(head.y, 0, 2) > 1",
    ),
    b(
        "cos",
        "cos(a)",
        1,
        1,
        "Cosine of an angle: a plain number, which takes the unit of what it meets (`0.3 * cos(a)` next to metres is metres).",
        "cos(angle(bone(l_elbow), [1,0,0])) > 0.9",
    ),
    b(
        "cross",
        "cross(u, v)",
        2,
        2,
        "Cross product of two vectors.",
        "norm(cross(r_hand - pelvis, [0,1,0])) < 0.1 m",
    ),
    b(
        "dot",
        "dot(u, v)",
        2,
        2,
        "Dot product of two vectors.",
        "dot(facing(), [0,0,1]) > 0.9",
    ),
    b(
        "facing",
        "facing(person?)",
        0,
        1,
        "Horizontal unit vector the body faces, from the hips and shoulders (forward = up × (right − left)).",
        "dot(facing(), [1,0,0]) > 0.9",
    ),
    b(
        "gaze",
        "gaze(person?)",
        0,
        1,
        "Where the head faces, from what the 22 joints carry: perpendicular to the shoulder line and tilted with the neck-to-head bone (tipping the head forward looks down, back looks up), raised 25° so an upright head looks level. The skeleton has no face joints, so turning the head on its own neck (yaw) is not seen: looking left or over a shoulder is measured by the shoulders turning, and a head tilted sideways counts as level.",
        "during 2s..3s { dot(gaze(), [1, 0, 0]) > 0.7 }",
    ),
    b(
        "massCtr",
        "massCtr(person?)",
        0,
        1,
        "Centre of mass from PMG's segment masses (head included).",
        "massCtr().y > 0.8 m",
    ),
    b(
        "massCtrNoHead",
        "massCtrNoHead(person?)",
        0,
        1,
        "Centre of mass without the head segment (PMG's fixhead variant).",
        "massCtrNoHead().y > 0.8 m",
    ),
    b(
        "max",
        "max(a, b)",
        2,
        2,
        "Larger of two values (elementwise).",
        "max(l_hand.y, r_hand.y) > 1.8 m",
    ),
    b(
        "min",
        "min(a, b)",
        2,
        2,
        "Smaller of two values (elementwise).",
        "min(l_foot.y, r_foot.y) < 0.05 m",
    ),
    b(
        "norm",
        "norm(v)",
        1,
        1,
        "Euclidean length of a vector (√(Σv² + 1e-12), so its gradient stays finite at 0).",
        "norm(l_hand - r_hand) == 0.4 m",
    ),
    b(
        "normalize",
        "normalize(v)",
        1,
        1,
        "v divided by its length.",
        "dot(normalize(bone(l_elbow)), [1,0,0]) > 0.9",
    ),
    b(
        "parent",
        "parent(joint)",
        1,
        1,
        "The parent joint in the skeleton (pelvis is its own parent).",
        "norm(l_elbow - parent(l_elbow)) > 0.2 m",
    ),
    b(
        "sin",
        "sin(a)",
        1,
        1,
        "Sine of an angle: a plain number, like `cos`.",
        "sin(30 deg) * 1 m < head.y",
    ),
    b(
        "sq",
        "sq(x)",
        1,
        1,
        "x squared (elementwise); PMG's squared-error losses use it.",
        "minimize sq(head.y - 1.5 m)",
    ),
    b(
        "sqrt",
        "sqrt(x)",
        1,
        1,
        "Square root (of max(x, 0) + 1e-12).",
        "sqrt(dot(r_hand, r_hand)) < 2 m",
    ),
    b(
        "supportDist",
        "supportDist(point, person?)",
        1,
        2,
        "Signed ground distance from the point's projection to the support polygon (convex hull of both ankles and toes): positive outside, negative inside.",
        "supportDist(massCtr()) < 0",
    ),
    b(
        "vec",
        "vec(x, y, z)",
        3,
        3,
        "A vector from three scalars (same as [x, y, z]).",
        "r_hand == vec(pelvis.x, 1.5 m, pelvis.z)",
    ),
    b(
        "vel",
        "vel(x)",
        1,
        1,
        "Velocity: time difference x[t+1] − x[t] times fps (per second); the last frame repeats the last difference.",
        "norm(vel(pelvis)) < 1.5",
    ),
];

/// The built-in called `name`.
pub fn find(name: &str) -> Option<&'static BuiltinDoc> {
    BUILTINS.iter().find(|b| b.name == name)
}
