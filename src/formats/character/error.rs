//! Errors of retargeting onto a user's rig: what is wrong ([`RigErrorKind`]) and where
//! ([`RigError`]: the rig or mapping file and, when it applies, the 1-based line), displayed
//! `rig.bvh:12: …` as compilers do. The rig is untrusted input: every way it can fail to
//! map is one of these, never a panic.

use crate::formats::bvh::error::Location;

/// An error about a rig, a mapping file or a motion put on a rig.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}: {kind}", Location(origin, *line))]
pub struct RigError {
    /// The rig or mapping file (or the output, for a motion that cannot be put on it).
    pub origin: String,
    /// 1-based line, when the error belongs to one.
    pub line: Option<usize>,
    /// What is wrong.
    pub kind: RigErrorKind,
}

/// A HumanML3D joint the rig lacks, and the rig joints that might be it.
#[derive(Debug, Clone, PartialEq)]
pub struct Missing {
    /// The HumanML3D joint name.
    pub joint: &'static str,
    /// Rig joints whose names come closest: (name, line).
    pub candidates: Vec<(String, usize)>,
}

/// What is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RigErrorKind {
    #[error("cannot read the rig: {0}")]
    Io(String),
    #[error("{0}")]
    Parse(String),
    #[error(
        "a rig must be a .bvh file or a skinned .glb (found `.{0}`); export the character's armature as BVH (Blender: File > Export > Motion Capture (.bvh)) or the character as glTF Binary (.glb)"
    )]
    NotBvh(String),
    #[error("cannot read the .glb rig: {0}")]
    Glb(String),
    #[error("the hierarchy is over {limit} bytes; a character's rig is far smaller")]
    TooLarge { limit: u64 },
    #[error("{}", missing_message(.missing, .mapped_by))]
    Missing {
        missing: Vec<Missing>,
        mapped_by: String,
    },
    #[error(
        "`{rig_joint}` ({joint}) is not below `{above_rig}` ({above}) in the rig's hierarchy, so it cannot follow it; fix the mapping with --rig-map"
    )]
    NotBelow {
        joint: &'static str,
        rig_joint: String,
        above: &'static str,
        above_rig: String,
    },
    #[error(
        "the bone from `{from}` to `{to}` has zero length in the rest pose, so it has no direction to turn"
    )]
    ZeroBone { from: String, to: String },
    #[error(
        "joint `{joint}` ({as_joint}) must turn but its channels `{channels}` are not three rotations (Xrotation, Yrotation, Zrotation in some order)"
    )]
    Channels {
        joint: String,
        as_joint: &'static str,
        channels: String,
    },
    #[error(
        "nothing can move the body: neither `{pelvis}` nor a joint above it has Xposition, Yposition and Zposition channels"
    )]
    NoTranslation { pelvis: String },
    #[error(
        "the rest pose is not upright: the head is not above the feet along +Y or +Z (feet to head points along ({:.2}, {:.2}, {:.2}))",
        .0[0], .0[1], .0[2]
    )]
    NotUpright([f32; 3]),
    #[error("the rest pose has a joint at a non-finite position (`{0}`)")]
    NonFinite(String),
    #[error("invalid mapping file: {0}")]
    MapSyntax(String),
    #[error("`{key}` is not a HumanML3D joint{}", did_you_mean(.suggestions))]
    MapUnknownJoint {
        key: String,
        suggestions: Vec<String>,
    },
    #[error("`{key} = \"{value}\"`: the rig has no joint `{value}`{}", did_you_mean(.suggestions))]
    MapUnknownRigJoint {
        key: String,
        value: String,
        suggestions: Vec<String>,
    },
    #[error("`{key}` must be a rig joint name in quotes, e.g. {key} = \"LeftUpLeg\"")]
    MapNotString { key: String },
    #[error("`{value}` is given to both {first} and {second}")]
    MapTwice {
        value: String,
        first: &'static str,
        second: &'static str,
    },
    #[error("cannot put this motion on the rig: {0}")]
    Motion(String),
    #[error(
        "--bvh-units and --bvh-axes do not apply to a rig's output: it keeps the rig's own units and axes"
    )]
    ExportOptions,
}

fn did_you_mean(suggestions: &[String]) -> String {
    match suggestions {
        [] => String::new(),
        [one] => format!("; did you mean `{one}`?"),
        many => format!(
            "; did you mean one of {}?",
            many.iter()
                .map(|s| format!("`{s}`"))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

fn missing_message(missing: &[Missing], mapped_by: &str) -> String {
    let names: Vec<&str> = missing.iter().map(|m| m.joint).collect();
    let (family, rest) = match mapped_by.split_once(' ') {
        Some((f, r)) => (f, format!(" {r}")),
        None => (mapped_by, String::new()),
    };
    let how = match family {
        "name-matched" => format!("by name{rest}"),
        table => format!("by the {table} table{rest}"),
    };
    let mut out = format!(
        "cannot retarget onto this rig: no joint for {} (joints mapped {how}; mprog knows Mixamo names with or without `mixamorig:`, the BVH rigs it reads, SMPL, Biped, Blender .L/.R)",
        names.join(", ")
    );
    for m in missing {
        if m.candidates.is_empty() {
            out.push_str(&format!("\n  {}: no rig joint comes close", m.joint));
        } else {
            let c: Vec<String> = m
                .candidates
                .iter()
                .map(|(name, line)| match line {
                    0 => format!("`{name}`"),
                    line => format!("`{name}` (line {line})"),
                })
                .collect();
            out.push_str(&format!("\n  {}: perhaps {}", m.joint, c.join(" or ")));
        }
    }
    out.push_str("\n  help: name them in a TOML file passed with --rig-map, one line each:");
    for m in missing {
        let example = m.candidates.first().map_or("<rig joint>", |(n, _)| n);
        out.push_str(&format!(
            "\n    {} = \"{}\"",
            m.joint,
            example.replace('"', "\\\"")
        ));
    }
    out
}

impl RigError {
    /// An error at a line of `origin` (line 0: a rig without lines, a `.glb`).
    pub fn at(origin: &str, line: usize, kind: RigErrorKind) -> Self {
        RigError {
            origin: origin.to_string(),
            line: (line > 0).then_some(line),
            kind,
        }
    }

    /// An error about the whole of `origin`.
    pub fn whole(origin: &str, kind: RigErrorKind) -> Self {
        RigError {
            origin: origin.to_string(),
            line: None,
            kind,
        }
    }
}
