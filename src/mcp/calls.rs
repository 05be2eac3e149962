//! The tools that answer at once: `check`, `score`, `joints` and `library`. Each returns
//! JSON; a program with errors is an answer (its diagnostics), not a failure.

use super::paths::OutDir;
use crate::formats::{LoadedMotion, read_motion};
use crate::motion::Motion;
use serde_json::{Value, json};

/// The name programs from a request are reported under.
pub const SOURCE_NAME: &str = "program.mprog";

/// `check`: what `mprog check --format json` prints for the program (with the model's
/// far-prompt and unseen-pose warnings when the server was given what they need).
pub fn check(
    source: &str,
    set: &[(String, f64)],
    far_prompts: Option<&crate::lang::PromptReport>,
    coverage: Option<&crate::coverage::Coverage>,
) -> Value {
    let mut diags = crate::lang::check_source(source, SOURCE_NAME, set);
    if let Some(report) = far_prompts {
        diags = crate::lang::with_far_prompts(diags, source, report);
    }
    if let Some(c) = coverage {
        diags = crate::lang::with_unseen_poses(diags, source, set, c);
    }
    json!({
        "file": SOURCE_NAME,
        "ok": !diags.has_errors(),
        "diagnostics": diags.to_json(),
    })
}

/// `score`: the program's error on a motion file in the output folder, per statement.
/// Err is a message for the caller (a program with errors, an unreadable file).
pub fn score(
    out: &OutDir,
    source: &str,
    motion: &str,
    set: &[(String, f64)],
) -> Result<Value, Value> {
    let program = crate::lang::compile(source, SOURCE_NAME, set).map_err(|d| {
        json!({"error": "the program has errors", "file": SOURCE_NAME, "ok": false,
               "diagnostics": d.to_json()})
    })?;
    let fail = |m: String| json!({ "error": m });
    let path = out.for_reading(motion).map_err(fail)?;
    let people: Vec<Motion> = match read_motion(&path).map_err(|e| fail(e.to_string()))? {
        LoadedMotion::Joints { people, .. } => people.into_iter().map(|p| p.motion).collect(),
        LoadedMotion::Features(a) => vec![
            crate::features::recover_from_ric(&a.data)
                .map_err(|e| fail(format!("`{motion}`: {e}")))?,
        ],
    };
    let wanted = program.people().len().max(1);
    if people.len() != wanted {
        return Err(fail(format!(
            "the program has {wanted} people but `{motion}` holds {}",
            people.len()
        )));
    }
    let device = crate::backend::device_from_env().map_err(fail)?;
    let joints = crate::view::program::people_tensor(&people, &device);
    let e = program
        .try_evaluate(joints)
        .map_err(|e| fail(e.to_string()))?;
    let per: Vec<f32> = e
        .per_statement
        .into_data()
        .convert::<f32>()
        .try_into_vec::<f32>()
        .map_err(|e| fail(format!("{e:?}")))?;
    let statements: Vec<Value> = program
        .statements()
        .iter()
        .zip(&per)
        .map(|(s, e)| json!({"line": s.line, "statement": statement_text(&s.label), "unit": s.unit, "error": e}))
        .collect();
    Ok(json!({
        "motion": motion,
        "frames": people[0].len(),
        "statements": statements,
        "total": per.iter().sum::<f32>(),
    }))
}

/// `line 3: head.y > 1 m` → `head.y > 1 m`.
pub fn statement_text(label: &str) -> &str {
    label.split_once(": ").map_or(label, |(_, t)| t).trim()
}

/// `joints`: the skeleton's joints with their indices and aliases.
pub fn joints() -> Value {
    let joints: Vec<Value> = crate::skeleton::JOINT_NAMES
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let aliases: Vec<&str> = crate::skeleton::ALIASES
                .iter()
                .filter(|(_, j)| *j == i)
                .map(|(a, _)| *a)
                .collect();
            json!({"index": i, "name": name, "aliases": aliases})
        })
        .collect();
    json!({
        "conventions": "metres, Y up, 20 fps; at frame 0 the person stands at x = z = 0 facing +Z, their left at +X",
        "joints": joints,
    })
}

/// `library`: the library reference (builtins and the standard library), as markdown.
pub fn library() -> String {
    crate::docgen::library::stdlib_reference()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_reports_located_diagnostics() {
        let v = check("length 4s\nalways { r_hnad.y > 1 m }\n", &[], None, None);
        assert_eq!(v["ok"], false);
        let d = &v["diagnostics"][0];
        assert_eq!(d["code"], crate::lang::codes::UNKNOWN_JOINT);
        assert_eq!(
            (d["line"].as_u64(), d["column"].as_u64()),
            (Some(2), Some(10))
        );
        assert!(d["hint"].as_str().unwrap().contains("r_hand"));
        assert_eq!(
            check("length 4s\nalways { head.y > 1 m }\n", &[], None, None)["ok"],
            true
        );
    }

    #[test]
    fn score_reads_only_inside_the_output_folder() {
        let dir = tempfile::tempdir().unwrap();
        let out = OutDir::new(&dir.path().join("out")).unwrap();
        let motion = Motion::new(vec![crate::skeleton::rest_pose(); 10]);
        let job = crate::formats::OutputJob {
            people: std::slice::from_ref(&motion),
            meta: &crate::motion::Meta::new(),
            title: "",
            bvh: &Default::default(),
            rig: None,
        };
        crate::formats::write_outputs(&[out.root().join("m.json")], &job).unwrap();
        let src = "length 10 frames\nalways { head.y > 3 m }\n";
        let v = score(&out, src, "m.json", &[]).unwrap();
        assert_eq!(v["statements"][0]["line"], 2);
        assert!(v["total"].as_f64().unwrap() > 1.0, "{v}");
        let e = score(&out, src, "../m.json", &[]).unwrap_err();
        assert!(
            e["error"].as_str().unwrap().starts_with("refused path"),
            "{e}"
        );
        let e = score(&out, "length 1s\nalways { hed.y > 1 m }", "m.json", &[]).unwrap_err();
        assert_eq!(
            e["diagnostics"][0]["code"],
            crate::lang::codes::UNKNOWN_JOINT,
            "{e}"
        );
    }

    #[test]
    fn check_warns_of_a_pose_no_training_clip_holds() {
        let cov = crate::coverage::Coverage::builtin();
        let src = "length 8s\nduring 1s..6s { l_foot.y > 30 cm\n r_foot.y < 5 cm }\n";
        let v = check(src, &[], None, Some(&cov));
        assert_eq!(v["ok"], true, "a warning, not an error");
        let d = &v["diagnostics"][0];
        assert_eq!(d["code"], crate::lang::codes::UNSEEN_POSE);
        assert!(
            d["hint"]
                .as_str()
                .unwrap()
                .contains("the longest the training data holds it")
        );
        let without = check(src, &[], None, None);
        assert!(without["diagnostics"].as_array().unwrap().is_empty());
    }

    #[test]
    fn check_warns_on_a_prompt_far_from_the_models_captions() {
        // What the model says of a prompt: the lines `run` would print before generating.
        let report = |prompt: &str| -> Vec<String> {
            if prompt.contains("violin") {
                vec!["the prompt is far from every caption the model was trained on (cosine 0.31 < 0.5); nearest known: \"a person waves\"".to_string()]
            } else {
                Vec::new()
            }
        };
        let far = check(
            "prompt \"a person plays the violin\"\nlength 2s\nat end { head.y > 1 m }\n",
            &[],
            Some(&report),
            None,
        );
        let d = &far["diagnostics"][0];
        assert_eq!(d["code"], crate::lang::codes::FAR_PROMPT);
        assert_eq!(d["severity"], "warning");
        assert!(
            d["hint"]
                .as_str()
                .unwrap()
                .contains("nearest known: \"a person waves\"")
        );
        assert_eq!(far["ok"], true, "a warning, not an error");
        let near = check(
            "prompt \"a person walks\"\nlength 2s\nat end { head.y > 1 m }\n",
            &[],
            Some(&report),
            None,
        );
        let far_prompts = near["diagnostics"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|d| d["code"] == crate::lang::codes::FAR_PROMPT)
            .count();
        assert_eq!(far_prompts, 0, "{near}");
    }
}
