//! The arguments of each tool, parsed from a request's JSON with the limits of the
//! command line: a wrong shape is the caller's mistake and becomes a protocol error
//! (invalid params) naming the field, never a panic.

use serde_json::{Map, Value};

/// Longest program text accepted (the language's own limit, checked here before parsing).
pub const MAX_SOURCE: usize = 256 * 1024;
/// Most outputs one run may write.
pub const MAX_OUTPUTS: usize = 16;
/// Most knob and parameter settings in one request.
pub const MAX_SETTINGS: usize = 32;

/// `run`'s arguments.
#[derive(Clone, Debug, PartialEq)]
pub struct RunArgs {
    pub source: String,
    pub solver: String,
    pub seed: u64,
    pub knobs: Vec<(String, f64)>,
    pub set: Vec<(String, f64)>,
    /// Relative paths in the output folder.
    pub outputs: Vec<String>,
    /// Also run the unguided sample, for the comparison column.
    pub baseline: bool,
    /// The user's rig (`.bvh` or skinned `.glb`), a relative path in the output folder.
    pub rig: Option<String>,
    /// Its mapping file (TOML), likewise.
    pub rig_map: Option<String>,
}

/// Reads a tool call's arguments (absent: an empty object).
pub fn object(args: Option<&Map<String, Value>>) -> Map<String, Value> {
    args.cloned().unwrap_or_default()
}

fn string(args: &Map<String, Value>, key: &str, max: usize) -> Result<Option<String>, String> {
    match args.get(key) {
        None | Some(Value::Null) => Ok(None),
        Some(Value::String(s)) if s.len() <= max => Ok(Some(s.clone())),
        Some(Value::String(s)) => Err(format!("`{key}` is {} bytes; at most {max}", s.len())),
        Some(other) => Err(format!("`{key}` must be a string, not {}", kind(other))),
    }
}

fn kind(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// The program text every program tool needs.
pub fn source(args: &Map<String, Value>) -> Result<String, String> {
    string(args, "source", MAX_SOURCE)?
        .ok_or_else(|| "`source` (the program text) is missing".into())
}

/// `score`'s motion file, relative to the output folder.
pub fn motion(args: &Map<String, Value>) -> Result<String, String> {
    string(args, "motion", 1024)?
        .ok_or_else(|| "`motion` (a motion file in the output folder) is missing".into())
}

/// `{name: number}` settings (`knobs`, `set`).
pub fn settings(args: &Map<String, Value>, key: &str) -> Result<Vec<(String, f64)>, String> {
    match args.get(key) {
        None | Some(Value::Null) => Ok(Vec::new()),
        Some(Value::Object(m)) if m.len() <= MAX_SETTINGS => m
            .iter()
            .map(|(k, v)| match v.as_f64() {
                Some(x) if x.is_finite() && k.len() <= 64 => Ok((k.clone(), x)),
                _ => Err(format!("`{key}.{k}` must be a finite number")),
            })
            .collect(),
        Some(Value::Object(_)) => Err(format!("`{key}` has more than {MAX_SETTINGS} entries")),
        Some(other) => Err(format!(
            "`{key}` must be an object of numbers, not {}",
            kind(other)
        )),
    }
}

/// `run`'s arguments.
pub fn run(args: &Map<String, Value>) -> Result<RunArgs, String> {
    let seed = match args.get("seed") {
        None | Some(Value::Null) => 1,
        Some(v) => v
            .as_u64()
            .ok_or_else(|| format!("`seed` must be a whole number ≥ 0, not {v}"))?,
    };
    let outputs = match args.get("output") {
        None | Some(Value::Null) => vec!["run.json".to_string()],
        Some(Value::String(s)) => vec![s.clone()],
        Some(Value::Array(a)) if !a.is_empty() && a.len() <= MAX_OUTPUTS => a
            .iter()
            .map(|v| {
                v.as_str()
                    .map(str::to_string)
                    .ok_or_else(|| format!("`output` entries must be strings, not {}", kind(v)))
            })
            .collect::<Result<_, _>>()?,
        Some(Value::Array(_)) => {
            return Err(format!("`output` must list 1 to {MAX_OUTPUTS} files"));
        }
        Some(other) => {
            return Err(format!(
                "`output` must be a file name or a list of them, not {}",
                kind(other)
            ));
        }
    };
    let baseline = match args.get("baseline") {
        None | Some(Value::Null) => true,
        Some(Value::Bool(b)) => *b,
        Some(other) => return Err(format!("`baseline` must be a boolean, not {}", kind(other))),
    };
    let rig = string(args, "rig", 1024)?;
    let rig_map = string(args, "rig_map", 1024)?;
    if rig_map.is_some() && rig.is_none() {
        return Err("`rig_map` needs `rig`: the mapping file names the rig's joints".into());
    }
    Ok(RunArgs {
        rig,
        rig_map,
        source: source(args)?,
        solver: string(args, "solver", 64)?.unwrap_or_else(|| "guide".into()),
        seed,
        knobs: settings(args, "knobs")?,
        set: settings(args, "set")?,
        outputs,
        baseline,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn obj(v: Value) -> Map<String, Value> {
        v.as_object().unwrap().clone()
    }

    #[test]
    fn run_arguments_have_defaults_and_limits() {
        let a = run(&obj(json!({"source": "x"}))).unwrap();
        assert_eq!((a.solver.as_str(), a.seed, a.baseline), ("guide", 1, true));
        assert_eq!(a.outputs, ["run.json"]);
        let a = run(&obj(
            json!({"source": "x", "knobs": {"steps": 5}, "output": ["a.bvh", "a.png"]}),
        ))
        .unwrap();
        assert_eq!(a.knobs, [("steps".to_string(), 5.0)]);
        assert_eq!(a.outputs.len(), 2);
        let a = run(&obj(
            json!({"source": "x", "rig": "hero.glb", "rig_map": "m.toml"}),
        ))
        .unwrap();
        assert_eq!(
            (a.rig.as_deref(), a.rig_map.as_deref()),
            (Some("hero.glb"), Some("m.toml"))
        );
        for bad in [
            json!({}),
            json!({"source": 3}),
            json!({"source": "x", "seed": -1}),
            json!({"source": "x", "seed": "1"}),
            json!({"source": "x", "knobs": {"steps": "many"}}),
            json!({"source": "x", "knobs": [1]}),
            json!({"source": "x", "output": []}),
            json!({"source": "x", "output": [1]}),
            json!({"source": "x", "baseline": "no"}),
            json!({"source": "x", "rig": 3}),
            json!({"source": "x", "rig_map": "map.toml"}),
        ] {
            assert!(run(&obj(bad.clone())).is_err(), "{bad}");
        }
        let big = "x".repeat(MAX_SOURCE + 1);
        assert!(source(&obj(json!({ "source": big }))).is_err());
    }
}
