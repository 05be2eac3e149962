//! `mprog run` and `mprog bench tasks` through the built binary, with the shipped model and
//! short chains: solver knobs, the warning for statements the unguided motion already
//! satisfies, and what is saved next to the output.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The binary under test: cargo's, or `$MPROG_TEST_BIN` (see `tests/adversarial.rs`).
fn bin() -> Command {
    let bin = std::env::var_os("MPROG_TEST_BIN")
        .map_or_else(|| env!("CARGO_BIN_EXE_mprog").into(), PathBuf::from);
    let mut c = Command::new(bin);
    c.env("NO_COLOR", "1")
        .env_remove("MPROG_DEVICE")
        .current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().unwrap()
}

fn text(out: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&out.stdout).to_string(),
        String::from_utf8_lossy(&out.stderr).to_string(),
    )
}

fn program(dir: &Path, body: &str) -> String {
    let p = dir.join("p.mprog");
    std::fs::write(&p, body).unwrap();
    p.display().to_string()
}

#[test]
fn knobs_reach_the_solver_and_the_saved_meta() {
    let dir = tempfile::tempdir().unwrap();
    let prog = program(
        dir.path(),
        "prompt \"a person walks forward\"\nlength 1s\nhead.y > -5 m\nat end { pelvis.z > 5 m }\n",
    );
    let json = dir.path().join("out.json");
    let out = run(&[
        "run",
        &prog,
        "--solver",
        "guide",
        "--knob",
        "steps=10",
        "--knob",
        "k_late=20",
        "--knob",
        "late_steps=2",
        "-o",
        json.to_str().unwrap(),
    ]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("| **total** |"), "{stdout}");
    assert!(
        stderr.contains("line 3: already satisfied on every frame by the unguided motion"),
        "{stderr}"
    );
    assert!(!stderr.contains("line 4: already"), "{stderr}");
    assert!(
        stderr.contains("body: bone lengths within") && stderr.contains("foot skating"),
        "{stderr}"
    );
    let meta = std::fs::read_to_string(&json).unwrap();
    assert!(
        meta.contains("\"knobs\"") && meta.contains("k_late"),
        "{meta}"
    );
    assert!(
        meta.contains("steps: 10"),
        "the solver's settings are saved: {meta}"
    );
    // The shipped bundle has a realism ControlNet: the output names it beside the weights.
    let shipped = mprog::model::weights::default_model_dir();
    let manifest = std::fs::read_to_string(shipped.join("manifest.json")).unwrap();
    if shipped.join(mprog::model::control::CONTROL_FILE).exists() {
        let manifest: serde_json::Value = serde_json::from_str(&manifest).unwrap();
        let id = manifest["control_id"].as_str();
        assert!(id.is_some(), "the manifest names the ControlNet");
        let saved: serde_json::Value = serde_json::from_str(&meta).unwrap();
        assert_eq!(saved["meta"]["control_id"].as_str(), id);
    }

    let out = run(&[
        "run",
        &prog,
        "--solver",
        "latent",
        "--knob",
        "k_late=3",
        "-o",
        json.to_str().unwrap(),
    ]);
    let (_, stderr) = text(&out);
    assert!(!out.status.success());
    assert!(
        stderr.contains("no knob `k_late`") && stderr.contains("iterations"),
        "{stderr}"
    );
}

/// Every run carries a plausibility report: a column in the table, the report after it,
/// `meta.plausibility` and the `--report` JSON; `--strict` turns an implausible result
/// into a failure and still writes the outputs.
#[test]
fn runs_report_plausibility_and_strict_fails_on_problems() {
    let dir = tempfile::tempdir().unwrap();
    let prog = program(
        dir.path(),
        "prompt \"a person walks forward\"\nlength 1s\nat 0.5s { l_hand.y > 2.5 m }\n",
    );
    let json = dir.path().join("out.json");
    let report = dir.path().join("report.json");
    let args = |strict: bool| {
        let mut a = vec![
            "run".to_string(),
            prog.clone(),
            "--no-baseline".into(),
            "--knob".into(),
            "steps=10".into(),
            "--report".into(),
            report.display().to_string(),
            "-o".into(),
            json.display().to_string(),
        ];
        if strict {
            a.push("--strict".into());
        }
        a
    };
    let out = bin().args(args(false)).output().unwrap();
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("| plausibility |"), "{stdout}");
    assert!(stdout.contains("plausibility: "), "{stdout}");
    assert!(
        stderr.contains("foot skating") && stderr.contains("(real clips: mean"),
        "the skating figure says what it is measured against: {stderr}"
    );
    let saved: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let p = &saved["meta"]["plausibility"];
    let ok = p["ok"].as_bool().expect("meta.plausibility.ok");
    assert!(p["problems"].is_array(), "{p}");
    assert_eq!(ok, p["problems"].as_array().unwrap().is_empty());
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(r["plausibility"]["ok"].as_bool(), Some(ok));
    let column = r["statements"][0]["plausibility"].as_str().unwrap();
    assert!(
        column.starts_with("met") || column.starts_with("not met"),
        "{column}"
    );
    for problem in p["problems"].as_array().unwrap() {
        assert!(problem["frames"][1].as_u64() >= problem["frames"][0].as_u64());
        assert!(problem["against"].as_str().is_some_and(|s| !s.is_empty()));
    }
    // The same run, deterministic, with --strict: fails exactly when it was implausible,
    // and writes the outputs either way.
    std::fs::remove_file(&json).unwrap();
    let out = bin().args(args(true)).output().unwrap();
    assert_eq!(out.status.success(), ok, "{}", text(&out).1);
    assert!(json.exists(), "--strict still writes the outputs");
    if !ok {
        assert!(text(&out).1.contains("implausible result (--strict)"));
    }
}

#[test]
fn quick_task_bench_writes_a_table_for_the_chosen_solvers() {
    let dir = tempfile::tempdir().unwrap();
    let md = dir.path().join("tasks.md");
    let out = run(&[
        "bench",
        "tasks",
        "--quick",
        "--solvers",
        "plain,guide",
        "--knob",
        "guide.steps=10",
        "--knob",
        "guide.k_late=10",
        "--knob",
        "plain.steps=10",
        "--data",
        "/nonexistent",
        "-o",
        md.to_str().unwrap(),
    ]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("keyframe control and realism skipped"),
        "{stderr}"
    );
    let table = std::fs::read_to_string(&md).unwrap();
    assert_eq!(table, stdout);
    for needle in [
        "## PMG tasks",
        "## Two-person contact",
        "| bones (m) |",
        "| plausible |",
        "| guide |",
        "| plain |",
        "HSC-1",
        "handshake",
    ] {
        assert!(table.contains(needle), "{needle} missing:\n{table}");
    }
    assert!(!table.contains("| latent |"));
    let out = run(&[
        "bench",
        "tasks",
        "--quick",
        "--solvers",
        "guide",
        "--knob",
        "latent.iterations=3",
    ]);
    assert!(!out.status.success());
    assert!(text(&out).1.contains("not in this run"));
}

#[test]
fn spacing_sets_where_the_people_start() {
    let dir = tempfile::tempdir().unwrap();
    let prog = program(
        dir.path(),
        "people a \"a person waves\", b \"a person waves\"\nspacing 1.2 m\nlength 1s\nalways { separation(a, b, 0.5 m) }\n",
    );
    let npy = dir.path().join("out.npy");
    let out = run(&[
        "run",
        &prog,
        "--solver",
        "plain",
        "--knob",
        "steps=5",
        "--no-baseline",
        "-o",
        npy.to_str().unwrap(),
    ]);
    let (_, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    let array = mprog::formats::npy::read_npy(&npy).unwrap();
    assert_eq!(array.shape, vec![2, 20, 22, 3]);
    // Pelvis (joint 0) of each person at frame 0: the solvers pin it to the placement.
    let pelvis = |p: usize| {
        let i = p * 20 * 22 * 3;
        (array.data[i], array.data[i + 2])
    };
    let ((ax, az), (bx, bz)) = (pelvis(0), pelvis(1));
    let d = ((ax - bx).powi(2) + (az - bz).powi(2)).sqrt();
    assert!((d - 1.2).abs() < 0.02, "start distance {d}");
}

#[test]
fn gen_says_how_it_read_the_prompt() {
    // The shipped model reads sentences: a prompt far from every training caption is
    // conditioned on its nearest captions, and `gen` names them.
    let dir = tempfile::tempdir().unwrap();
    let npy = dir.path().join("out.npy");
    let generate = |extra: &[&str]| {
        let mut args = vec![
            "gen",
            "--text",
            "a man walked forwards, moonwalking",
            "--frames",
            "10",
            "--steps",
            "2",
            "-o",
            npy.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let out = run(&args);
        let (_, stderr) = text(&out);
        assert!(out.status.success(), "{stderr}");
        stderr
    };
    let stderr = generate(&[]);
    assert!(
        stderr.contains("the model has not read a caption like this")
            && stderr.contains("nearest captions, \"")
            && stderr.contains("--literal-prompt reads it as written"),
        "{stderr}"
    );
    assert!(!generate(&["--literal-prompt"]).contains("nearest captions"));
    // Every motion gets its plausibility report, printed and in the sidecar's meta.
    assert!(
        stderr.contains("plausibility: ")
            && stderr.contains("foot skating")
            && stderr.contains("real clips"),
        "{stderr}"
    );
    let sidecar: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("out.meta.json")).unwrap())
            .unwrap();
    assert!(
        sidecar["meta"]["plausibility"]["ok"].is_boolean(),
        "{sidecar}"
    );
}

#[test]
fn eval_refuses_an_unknown_sampler_before_loading_anything() {
    let out = run(&[
        "eval",
        "--data",
        "/nonexistent",
        "--sampler",
        "euler",
        "--steps",
        "20",
    ]);
    assert!(!out.status.success());
    let (_, stderr) = text(&out);
    assert!(stderr.contains("unknown sampler `euler`"), "{stderr}");
    let out = run(&["eval", "--data", "/nonexistent", "--steps", "0"]);
    assert!(text(&out).1.contains("--steps ≥ 1"));
}

#[test]
fn a_guidance_scale_that_is_not_a_sane_number_is_refused_by_name() {
    for bad in ["nan", "-3", "inf", "1e9", "two"] {
        for cmd in [
            &["gen", "--text", "a person walks", "-o", "/tmp/never.npy"][..],
            &["bench", "actions"][..],
            &["eval", "--data", "/nonexistent"][..],
        ] {
            let mut args = cmd.to_vec();
            args.extend(["--guidance", bad]);
            let out = run(&args);
            assert!(!out.status.success(), "{args:?}");
            let (_, stderr) = text(&out);
            assert!(stderr.contains("--guidance"), "{args:?}: {stderr}");
            assert!(
                stderr.contains("must lie in 0..=20") || stderr.contains("is not a number"),
                "{args:?}: {stderr}"
            );
        }
    }
}

#[test]
fn a_bundle_with_a_controlnet_adds_guide_without_realism_to_the_task_table() {
    use burn::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("model");
    std::fs::create_dir_all(&model).unwrap();
    let shipped = mprog::model::weights::default_model_dir();
    for entry in std::fs::read_dir(&shipped).unwrap() {
        let p = entry.unwrap().path();
        if p.is_file() {
            std::fs::copy(&p, model.join(p.file_name().unwrap())).unwrap();
        }
    }
    let device = Device::flex();
    let bundle = mprog::model::ModelBundle::load(&model, &device).unwrap();
    // Zero-initialised: a no-op, enough to make the run measure both rows.
    mprog::model::control::ControlNet::from_base(&bundle.model, &device)
        .save(&model, true)
        .unwrap();
    let md = dir.path().join("tasks.md");
    let out = run(&[
        "bench",
        "tasks",
        "--quick",
        "--model",
        model.to_str().unwrap(),
        "--solvers",
        "guide",
        "--knob",
        "guide.steps=10",
        "--knob",
        "guide.k_late=10",
        "--family",
        "pmg",
        "--tasks",
        "hsi-3",
        "--data",
        "/nonexistent",
        "-o",
        md.to_str().unwrap(),
    ]);
    let (_, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    let table = std::fs::read_to_string(&md).unwrap();
    assert!(table.contains("| guide |"), "{table}");
    assert!(table.contains("| guide, realism 0 |"), "{table}");
    assert!(
        table.contains("HSI-3") && !table.contains("HSC-1"),
        "--tasks keeps HSI-3 alone: {table}"
    );
    // A task name the run does not have is refused, with the names it has.
    let out = run(&[
        "bench",
        "tasks",
        "--quick",
        "--model",
        model.to_str().unwrap(),
        "--tasks",
        "HSI-9",
        "--data",
        "/nonexistent",
    ]);
    let (_, stderr) = text(&out);
    assert!(!out.status.success());
    assert!(
        stderr.contains("no task named `HSI-9`") && stderr.contains("HSC-1"),
        "{stderr}"
    );
}

/// A pose no training clip comes near is said before solving, on stderr as `check` says
/// it, and kept in `meta.coverage` and the `--report` JSON (what the MCP `run` returns).
#[test]
fn runs_say_when_a_pose_is_not_in_the_training_data() {
    let dir = tempfile::tempdir().unwrap();
    let prog = program(
        dir.path(),
        "prompt \"a person sits down on the floor\"\nlength 1s\nat 0.5s { pelvis.y < 20 cm\n head.y > 1.1 m }\n",
    );
    let json = dir.path().join("out.json");
    let report = dir.path().join("report.json");
    let out = run(&[
        "run",
        &prog,
        "--no-baseline",
        "--knob",
        "steps=10",
        "--report",
        &report.display().to_string(),
        "-o",
        &json.display().to_string(),
    ]);
    let (_, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("no training pose comes near `pelvis.y < 20 cm` and `head.y > 1.1 m`"),
        "{stderr}"
    );
    let saved: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let c = &saved["meta"]["coverage"];
    assert_eq!(c["ok"], false, "{c}");
    assert_eq!(c["unseen"][0]["code"], "mprog::unseen_pose", "{c}");
    assert_eq!(c["unseen"][0]["line"], 3, "{c}");
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(&r["coverage"], c);
}
