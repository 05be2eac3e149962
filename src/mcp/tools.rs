//! What the server offers: its tools with their JSON input schemas, and the prompt card
//! as a prompt and a resource.

use rmcp::model::{JsonObject, Tool};
use serde_json::{Value, json};

/// URI of the prompt card resource.
pub const CARD_URI: &str = "mprog://prompt-card";
/// URI of the library reference resource.
pub const LIBRARY_URI: &str = "mprog://library";
/// Name of the prompt card prompt.
pub const CARD_PROMPT: &str = "write-mprog";

fn schema(v: Value) -> JsonObject {
    v.as_object().cloned().unwrap_or_default()
}

fn source_property() -> Value {
    json!({"type": "string", "description": "the .mprog program text (at most 256 kB)"})
}

fn set_property() -> Value {
    json!({"type": "object", "additionalProperties": {"type": "number"},
           "description": "parameter overrides, in the unit of each default: {\"diameter\": 0.5}"})
}

/// The tools, in the order they are listed.
pub fn tools() -> Vec<Tool> {
    vec![
        Tool::new(
            "check",
            "Parse and type-check an mprog program. Returns {ok, diagnostics}: each with code, \
             severity, message, hint, line, column (1-based) and the source snippet: the same \
             as `mprog check --format json`. Warnings flag constraints no motion can meet, and \
             poses no training clip comes near or holds that long (`mprog::unseen_pose`: its \
             hint names the nearest pose the data has; ask for that instead).",
            schema(json!({"type": "object", "required": ["source"],
                "properties": {"source": source_property(), "set": set_property()}})),
        ),
        Tool::new(
            "score",
            "A program's error on a motion file in the server's output folder (.json, .npy, \
             .bvh), per statement: 0 means met.",
            schema(json!({"type": "object", "required": ["source", "motion"],
                "properties": {"source": source_property(), "set": set_property(),
                    "motion": {"type": "string", "description": "a file in the output folder, by relative path, e.g. `walk.json`"}}})),
        ),
        Tool::new(
            "run",
            "Generate a motion with the model, steered by the program. Returns each statement's \
             error next to the unguided sample's and whether it was met plausibly (\"met\", \
             \"met by a snap at 5.85–5.95 s\", \"not met\"), the plausibility report \
             (`plausibility`: ok, and each problem with its person, kind, body part, frames, \
             seconds, value, limit, what the limit is measured against and the statements \
             active there: repair those), the poses no training clip comes near \
             (`coverage`: ok, and each `mprog::unseen_pose` warning, said before solving), \
             the files written (relative to the output folder) \
             and a PNG strip of the motion. Runs are one at a time and stopped at the \
             server's time limit; for a quick look pass knobs such as {\"steps\": 10}.",
            schema(json!({"type": "object", "required": ["source"],
                "properties": {
                    "source": source_property(),
                    "set": set_property(),
                    "solver": {"type": "string", "description": "guide (default), latent, ik, ik-reg, lbfgs, plain"},
                    "seed": {"type": "integer", "minimum": 0, "description": "default 1"},
                    "knobs": {"type": "object", "additionalProperties": {"type": "number"},
                              "description": "solver settings, e.g. {\"steps\": 10}"},
                    "output": {"oneOf": [{"type": "string"}, {"type": "array", "items": {"type": "string"}, "minItems": 1, "maxItems": 16}],
                               "description": "files to write inside the output folder, by relative path; the extension picks the kind (.bvh .npy .json .gif .png .html .glb); default run.json"},
                    "baseline": {"type": "boolean", "description": "also sample without guidance, for the comparison column (default true)"},
                    "rig": {"type": "string", "description": "your character, a file you put in the output folder (relative path): a .bvh of its skeleton or a skinned .glb; .bvh and .glb outputs are on it (a .glb output is that file, mesh and all, animated)"},
                    "rig_map": {"type": "string", "description": "with rig: a TOML file in the output folder naming rig joints mprog does not recognise, lines such as left_knee = \"Knee_L\""}}})),
        ),
        Tool::new(
            "joints",
            "The skeleton's 22 joints: index, name and aliases, and the conventions (metres, Y \
             up, 20 fps, start at x = z = 0 facing +Z).",
            schema(json!({"type": "object", "properties": {}})),
        ),
        Tool::new(
            "library",
            "The library reference: every builtin and standard-library function with its \
             signature, meaning and an example.",
            schema(json!({"type": "object", "properties": {}})),
        ),
    ]
}
