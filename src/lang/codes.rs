//! Every diagnostic code, in one place: the checker, the CLI, the REPL and the MCP server
//! use these constants, and `tests/book.rs` checks that each one is on the book's
//! diagnostics page (`book/src/reference/diagnostics.md`).

/// A function called with the wrong number of arguments.
pub const ARITY: &str = "mprog::arity";
/// A `length` that is not a positive, absolute duration.
pub const BAD_LENGTH: &str = "mprog::bad_length";
/// A vector literal without exactly 3 numbers.
pub const BAD_LIST: &str = "mprog::bad_list";
/// A number that is not finite or cannot be read.
pub const BAD_NUMBER: &str = "mprog::bad_number";
/// A `--set` value that cannot replace the parameter (a vector, a unit clash).
pub const BAD_OVERRIDE: &str = "mprog::bad_override";
/// A `spacing` outside 0.4–20 m.
pub const BAD_SPACING: &str = "mprog::bad_spacing";
/// A start placement (`at [x, 0, z]`, `facing [dx, 0, dz]`) that is not a constant point on
/// the floor or horizontal direction, or that puts two people inside each other.
pub const BAD_START: &str = "mprog::bad_start";
/// A timeline of prompts (`prompt 0s..8s "…"`) with a span that is empty, shorter than
/// 1 s or past the length, spans out of time order, a gap, an overlap that is no blend, an
/// empty text, or a person given both a whole-motion prompt and a timeline.
pub const BAD_TIMELINE: &str = "mprog::bad_timeline";
/// A negative or non-constant `weight`.
pub const BAD_WEIGHT: &str = "mprog::bad_weight";
/// `a < b < c`: write two constraints.
pub const CHAINED_COMPARISON: &str = "mprog::chained_comparison";
/// Division by a constant zero.
pub const DIVISION_BY_ZERO: &str = "mprog::division_by_zero";
/// A header line (`prompt`, `length`, `spacing`, `people`) or a definition given twice.
pub const DUPLICATE: &str = "mprog::duplicate";
/// A function whose body computes nothing.
pub const EMPTY_FUNCTION: &str = "mprog::empty_function";
/// A program with no constraint (warning).
pub const EMPTY_PROGRAM: &str = "mprog::empty_program";
/// `=` between measured values, almost never exactly true: use `dist(…) < tolerance`.
pub const EXACT_EQUALITY: &str = "mprog::exact_equality";
/// A prompt the model does not read as written: far from every caption it was trained on, or
/// read through its nearest captions (warning; needs a sentence-encoder model).
pub const FAR_PROMPT: &str = "mprog::far_prompt";
/// Two places for one joint that it can only travel between faster than 4 m/s (warning).
pub const FRAME_JUMP: &str = "mprog::frame_jump";
/// A single-frame `at` on the last 0.25 s (`at end`) that fixes the body's posture: the
/// absolute height of the pelvis, spine, neck, head or centre of mass, or of two or more
/// joints other than the feet (warning; hold the end state over a `during` window).
pub const KEYFRAME_POSE: &str = "mprog::keyframe_pose";
/// `%` outside a time position.
pub const MISPLACED_PERCENT: &str = "mprog::misplaced_percent";
/// A time position (`start`, `end`, `2s`) used as a value.
pub const MISPLACED_TIME: &str = "mprog::misplaced_time";
/// No `length` line; 196 frames are used (warning).
pub const MISSING_LENGTH: &str = "mprog::missing_length";
/// A per-person function (`com`, `balanced`, …) in a several-person program without saying whose.
pub const NEEDS_PERSON: &str = "mprog::needs_person";
/// No motion can meet the constraint; the hint names the cause (warning).
pub const NEVER_MET: &str = "mprog::never_met";
/// A constraint that does not depend on the motion (warning).
pub const NO_MOTION: &str = "mprog::no_motion";
/// An `if` whose condition is not a comparison.
pub const NOT_A_CONDITION: &str = "mprog::not_a_condition";
/// A statement that is a value, not a constraint.
pub const NOT_A_CONSTRAINT: &str = "mprog::not_a_constraint";
/// `for` over something that is not a list of joints or people.
pub const NOT_A_SET: &str = "mprog::not_a_set";
/// A time block or `@` given something that is not a time position.
pub const NOT_A_TIME: &str = "mprog::not_a_time";
/// A `param` whose value depends on the motion.
pub const NOT_CONSTANT: &str = "mprog::not_constant";
/// A number beyond 32-bit floats.
pub const NUMBER_OUT_OF_RANGE: &str = "mprog::number_out_of_range";
/// A keyframe place out of reach without a step when nothing moves the pelvis (warning).
pub const OUT_OF_REACH: &str = "mprog::out_of_reach";
/// A function that calls itself, directly or not.
pub const RECURSION: &str = "mprog::recursion";
/// A keyword or joint name used as a name.
pub const RESERVED_NAME: &str = "mprog::reserved_name";
/// `spacing` in a one-person program.
pub const SPACING_NEEDS_PEOPLE: &str = "mprog::spacing_needs_people";
/// Text the grammar does not accept.
pub const SYNTAX: &str = "mprog::syntax";
/// A frame outside the motion.
pub const TIME_OUT_OF_RANGE: &str = "mprog::time_out_of_range";
/// A program that expands to more tensor operations than the limit.
pub const TOO_COSTLY: &str = "mprog::too_costly";
/// Brackets nested deeper than the limit.
pub const TOO_DEEP: &str = "mprog::too_deep";
/// A program longer than the byte limit.
pub const TOO_LARGE: &str = "mprog::too_large";
/// A value of the wrong kind (point, number, angle, person, …).
pub const TYPE_MISMATCH: &str = "mprog::type_mismatch";
/// A unit clash (metres against seconds, angles against distances).
pub const UNIT_MISMATCH: &str = "mprog::unit_mismatch";
/// A component other than `.x .y .z .xz`.
pub const UNKNOWN_COMPONENT: &str = "mprog::unknown_component";
/// A function the library does not have (the hint suggests a near name).
pub const UNKNOWN_FUNCTION: &str = "mprog::unknown_function";
/// A joint name that is not one of the 22 or their aliases.
pub const UNKNOWN_JOINT: &str = "mprog::unknown_joint";
/// A name that is not defined.
pub const UNKNOWN_NAME: &str = "mprog::unknown_name";
/// A `--set` name that is no parameter of the program.
pub const UNKNOWN_PARAM: &str = "mprog::unknown_param";
/// A person the `people` line does not declare.
pub const UNKNOWN_PERSON: &str = "mprog::unknown_person";
/// A pose no training clip comes near, or one held longer than any clip holds it; the
/// hint names the nearest pose the data has (warning; needs the model's coverage set).
pub const UNSEEN_POSE: &str = "mprog::unseen_pose";

/// Every code with what it means, for the book and its test.
pub const ALL: &[(&str, &str)] = &[
    (
        ARITY,
        "a function called with the wrong number of arguments",
    ),
    (
        BAD_LENGTH,
        "a `length` that is not a positive, absolute duration",
    ),
    (BAD_LIST, "a vector literal without exactly 3 numbers"),
    (BAD_NUMBER, "a number that is not finite or cannot be read"),
    (
        BAD_OVERRIDE,
        "a `--set` value that cannot replace the parameter (a vector, a unit clash)",
    ),
    (BAD_SPACING, "a `spacing` outside 0.4–20 m"),
    (
        BAD_START,
        "a start placement (`at [x, 0, z]`, `facing [dx, 0, dz]`) that is not a constant point on the floor or horizontal direction, or that puts two people inside each other",
    ),
    (
        BAD_TIMELINE,
        "a timeline of prompts (`prompt 0s..8s \"…\"`) with a span that is empty, shorter than 1 s or past the length, spans out of time order, a gap, an overlap that is no blend, an empty text, or a person given both a whole-motion prompt and a timeline",
    ),
    (BAD_WEIGHT, "a negative or non-constant `weight`"),
    (CHAINED_COMPARISON, "`a < b < c`: write two constraints"),
    (DIVISION_BY_ZERO, "division by a constant zero"),
    (
        DUPLICATE,
        "a header line (`prompt`, `length`, `spacing`, `people`) or a definition given twice",
    ),
    (EMPTY_FUNCTION, "a function whose body computes nothing"),
    (EMPTY_PROGRAM, "a program with no constraint (warning)"),
    (
        EXACT_EQUALITY,
        "`=` between measured values, almost never exactly true: use `dist(…) < tolerance`",
    ),
    (
        FAR_PROMPT,
        "a prompt the model does not read as written: far from every caption it was trained on, or read through its nearest captions (warning; needs a sentence-encoder model)",
    ),
    (
        FRAME_JUMP,
        "two places for one joint that it can only travel between faster than 4 m/s (warning)",
    ),
    (
        KEYFRAME_POSE,
        "a single-frame `at` on the last 0.25 s (`at end`) that fixes the body's posture: the absolute height of the pelvis, spine, neck, head or centre of mass, or of two or more joints other than the feet, which the motion would snap into on its last frame (warning; hold the end state over a `during` window)",
    ),
    (MISPLACED_PERCENT, "`%` outside a time position"),
    (
        MISPLACED_TIME,
        "a time position (`start`, `end`, `2s`) used as a value",
    ),
    (
        MISSING_LENGTH,
        "no `length` line; 196 frames are used (warning)",
    ),
    (
        NEEDS_PERSON,
        "a per-person function (`com`, `balanced`, …) in a several-person program without saying whose",
    ),
    (
        NEVER_MET,
        "no motion can meet the constraint; the hint names the cause (warning)",
    ),
    (
        NO_MOTION,
        "a constraint that does not depend on the motion (warning)",
    ),
    (
        NOT_A_CONDITION,
        "an `if` whose condition is not a comparison",
    ),
    (
        NOT_A_CONSTRAINT,
        "a statement that is a value, not a constraint",
    ),
    (
        NOT_A_SET,
        "`for` over something that is not a list of joints or people",
    ),
    (
        NOT_A_TIME,
        "a time block or `@` given something that is not a time position",
    ),
    (NOT_CONSTANT, "a `param` whose value depends on the motion"),
    (NUMBER_OUT_OF_RANGE, "a number beyond 32-bit floats"),
    (
        OUT_OF_REACH,
        "a keyframe place out of reach without a step when nothing moves the pelvis (warning)",
    ),
    (RECURSION, "a function that calls itself, directly or not"),
    (RESERVED_NAME, "a keyword or joint name used as a name"),
    (SPACING_NEEDS_PEOPLE, "`spacing` in a one-person program"),
    (SYNTAX, "text the grammar does not accept"),
    (TIME_OUT_OF_RANGE, "a frame outside the motion"),
    (
        TOO_COSTLY,
        "a program that expands to more tensor operations than the limit",
    ),
    (TOO_DEEP, "brackets nested deeper than the limit"),
    (TOO_LARGE, "a program longer than the byte limit"),
    (
        TYPE_MISMATCH,
        "a value of the wrong kind (point, number, angle, person, …)",
    ),
    (
        UNIT_MISMATCH,
        "a unit clash (metres against seconds, angles against distances)",
    ),
    (UNKNOWN_COMPONENT, "a component other than `.x .y .z .xz`"),
    (
        UNKNOWN_FUNCTION,
        "a function the library does not have (the hint suggests a near name)",
    ),
    (
        UNKNOWN_JOINT,
        "a joint name that is not one of the 22 or their aliases",
    ),
    (UNKNOWN_NAME, "a name that is not defined"),
    (
        UNKNOWN_PARAM,
        "a `--set` name that is no parameter of the program",
    ),
    (
        UNKNOWN_PERSON,
        "a person the `people` line does not declare",
    ),
    (
        UNSEEN_POSE,
        "a pose no training clip comes near (summed error over 0.15 m), or one held longer than any clip holds it; the hint names the nearest pose the data has (warning; needs the model's coverage set)",
    ),
];
