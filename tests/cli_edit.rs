//! `mprog run --from take`: editing a take through the built binary with the shipped
//! model. Strength 0 returns the take where it stood, with its provenance in the meta;
//! kept frames come back exactly; every bad take, window or strength is a clear error
//! and leaves no output file.

mod common;

use common::{max_joint_error, synthetic_walk};
use mprog::formats::{LoadedMotion, Meta, read_motion, write_motion};
use mprog::motion::Motion;
use mprog::solve::Take;
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

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).to_string()
}

const WALK: &str = "prompt \"a person walks forward\"\nlength 40 frames\nduring 50%..100% { dist(l_hand, head) < 15 cm }\n";

fn program(dir: &Path, body: &str) -> String {
    let p = dir.join("p.mprog");
    std::fs::write(&p, body).unwrap();
    p.display().to_string()
}

/// A take of `frames` frames standing at (1, ·, 2), written as JSON.
fn take(dir: &Path, name: &str, frames: usize, people: usize) -> (String, Vec<Motion>) {
    let walk = synthetic_walk(frames);
    let moved = Motion::new(
        walk.frames
            .iter()
            .map(|p| p.map(|v| v + glam::Vec3::new(1.0, 0.0, 2.0)))
            .collect(),
    );
    let all = vec![moved; people];
    let path = dir.join(name);
    write_motion(&path, &all, &Meta::new()).unwrap();
    (path.display().to_string(), all)
}

fn people_of(path: &Path) -> (Vec<Motion>, Meta) {
    match read_motion(path).unwrap() {
        LoadedMotion::Joints { people, meta } => {
            (people.into_iter().map(|p| p.motion).collect(), meta)
        }
        LoadedMotion::Features(_) => panic!("joints expected"),
    }
}

#[test]
fn strength_zero_returns_the_take_with_its_provenance() {
    let dir = tempfile::tempdir().unwrap();
    let prog = program(dir.path(), WALK);
    let (take_path, people) = take(dir.path(), "take.json", 41, 1);
    let out_path = dir.path().join("out.json");
    let out = run(&[
        "run",
        &prog,
        "--from",
        &take_path,
        "--strength",
        "0",
        "--no-baseline",
        "-o",
        out_path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (got, meta) = people_of(&out_path);
    let want = Take::encode(&people).unwrap().motions().unwrap();
    assert_eq!(got[0].len(), 40, "a take of 41 frames gives 40");
    assert!(max_joint_error(&got[0], &want[0]) < 1e-4);
    // Where the take stood (its frame-0 root), not at the origin.
    assert!((got[0].frames[0][0].x - people[0].frames[0][0].x).abs() < 1e-3);
    assert!((got[0].frames[0][0].z - people[0].frames[0][0].z).abs() < 1e-3);
    let edit = meta["edit"].as_object().expect("edit provenance");
    assert_eq!(edit["take"], take_path.as_str());
    assert_eq!(edit["take_sha256"].as_str().unwrap().len(), 64);
    assert_eq!(edit["strength"], 0.0);
    assert_eq!(edit["edited_frames"], serde_json::json!([[0, 40]]));
}

#[test]
fn kept_frames_come_back_and_the_rest_is_edited() {
    let dir = tempfile::tempdir().unwrap();
    let prog = program(dir.path(), WALK);
    let (take_path, people) = take(dir.path(), "take.json", 41, 1);
    let out_path = dir.path().join("out.json");
    let out = run(&[
        "run",
        &prog,
        "--from",
        &take_path,
        "--strength",
        "1",
        "--keep",
        "..20",
        "--knob",
        "steps=10",
        "--knob",
        "k_late=20",
        "--knob",
        "late_steps=2",
        "--no-baseline",
        "-o",
        out_path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (got, meta) = people_of(&out_path);
    let want = &Take::encode(&people).unwrap().motions().unwrap()[0];
    let first = |m: &Motion, a: usize, b: usize| Motion::new(m.frames[a..b].to_vec());
    assert!(max_joint_error(&first(&got[0], 0, 20), &first(want, 0, 20)) < 1e-3);
    assert!(max_joint_error(&first(&got[0], 26, 40), &first(want, 26, 40)) > 0.05);
    let edit = meta["edit"].as_object().unwrap();
    assert_eq!(edit["kept_frames"], serde_json::json!([[0, 20]]));
    assert_eq!(edit["edited_frames"], serde_json::json!([[20, 40]]));
}

#[test]
fn untouched_time_is_held_unless_free_time() {
    // WALK reads frames 20..39 of 40 (`during 50%..100%`): frames 0..10 are held, 10..20
    // ease into the edit (the default margin, 10 frames).
    let dir = tempfile::tempdir().unwrap();
    let prog = program(dir.path(), WALK);
    let (take_path, people) = take(dir.path(), "take.json", 41, 1);
    let want = &Take::encode(&people).unwrap().motions().unwrap()[0];
    let first = |m: &Motion| Motion::new(m.frames[..10].to_vec());
    let edit = |extra: &[&str], name: &str| {
        let out_path = dir.path().join(name);
        let mut args = vec![
            "run",
            &prog,
            "--from",
            &take_path,
            "--strength",
            "1",
            "--knob",
            "steps=10",
            "--knob",
            "k_late=20",
            "--knob",
            "late_steps=2",
            "--no-baseline",
            "-o",
            out_path.to_str().unwrap(),
        ];
        args.extend(extra);
        let out = run(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        let (got, meta) = people_of(&out_path);
        (got.into_iter().next().unwrap(), meta, stderr(&out))
    };
    let (held, meta, err) = edit(&[], "held.json");
    assert!(
        err.contains("untouched time held to the take: frames 0..10 (0.00–0.50 s) of 40")
            && err.contains("the 10 frames (0.50 s)"),
        "{err}"
    );
    let gap = max_joint_error(&first(&held), &first(want));
    assert!(gap < 0.02, "untouched time moved {gap} m");
    let e = meta["edit"].as_object().unwrap();
    assert_eq!(e["held_time"], serde_json::json!([[0, 10]]));
    assert_eq!(e["time_margin"], 10);
    // `--free-time`: every frame is the edit's again, as before untouched time was held.
    let (free, meta, err) = edit(&["--free-time"], "free.json");
    assert!(err.contains("every frame free"), "{err}");
    let gap = max_joint_error(&first(&free), &first(want));
    assert!(
        gap > 0.02,
        "with --free-time the first frames moved only {gap} m"
    );
    assert_eq!(meta["edit"]["held_time"], serde_json::json!([]));
    // A wider margin holds fewer frames.
    let (_, meta, _) = edit(&["--time-margin", "15"], "wide.json");
    assert_eq!(meta["edit"]["held_time"], serde_json::json!([[0, 5]]));
}

/// A take longer than the model makes (15 s) is edited in windows: the time the program
/// does not read stays the take's.
#[test]
fn a_take_longer_than_the_model_is_edited_in_windows() {
    let dir = tempfile::tempdir().unwrap();
    let prog = program(dir.path(), WALK);
    let (take_path, people) = take(dir.path(), "long.json", 300, 1);
    let want = &Take::encode(&people).unwrap().motions().unwrap()[0];
    let out_path = dir.path().join("out.json");
    let out = run(&[
        "run",
        &prog,
        "--from",
        &take_path,
        "--knob",
        "steps=10",
        "--knob",
        "k_late=20",
        "--knob",
        "late_steps=2",
        "--no-baseline",
        "-o",
        out_path.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("in 2 windows"), "{err}");
    // WALK reads 50%..100% of 299 frames: 0..139 are held, 139..149 ease in.
    assert!(
        err.contains("untouched time held to the take: frames 0..139"),
        "{err}"
    );
    let (got, _) = people_of(&out_path);
    assert_eq!(got[0].len(), 299);
    let first = |m: &Motion| Motion::new(m.frames[..139].to_vec());
    let gap = max_joint_error(&first(&got[0]), &first(want));
    assert!(gap < 0.02, "untouched time moved {gap} m");
}

#[test]
fn bad_takes_windows_and_strengths_are_clear_errors_with_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let prog = program(dir.path(), WALK);
    let two = {
        let p = dir.path().join("two.mprog");
        std::fs::write(
            &p,
            "people a \"a person walks forward\", b \"a person waves\"\nlength 40 frames\ndist(a.r_hand, b.r_hand) < 1 m\n",
        )
        .unwrap();
        p.display().to_string()
    };
    let (one, _) = take(dir.path(), "one.json", 41, 1);
    let (long, _) = take(dir.path(), "long.json", 300, 1);
    let (too_long, _) = take(dir.path(), "too_long.json", 4002, 1);
    let missing = dir.path().join("missing.bvh").display().to_string();
    let garbage = dir.path().join("garbage.bvh");
    std::fs::write(&garbage, "not a bvh").unwrap();
    let garbage = garbage.display().to_string();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec![&prog, "--from", &missing], "cannot read the take"),
        (vec![&prog, "--from", &garbage], "cannot read the take"),
        (
            vec![&two, "--from", &one],
            "holds 1 person; the program has 2",
        ),
        (
            vec![&prog, "--from", &one, "--strength", "1.5"],
            "outside 0…1",
        ),
        (
            vec![&prog, "--from", &one, "--strength", "-0.2"],
            "outside 0…1",
        ),
        (
            vec![&prog, "--from", &one, "--keep", "30..50"],
            "outside the take",
        ),
        (
            vec![&prog, "--from", &one, "--edit", "10..41"],
            "outside the take",
        ),
        (
            vec![&prog, "--from", &too_long],
            "gives 4001 frames; a motion is at",
        ),
        (
            vec![&prog, "--from", &long, "--to", &one, "--context", "20"],
            "in-between",
        ),
        (
            vec![&prog, "--from", &long, "--take-frames", "250..400"],
            "outside the take",
        ),
        (
            vec![&prog, "--from", &one, "--to", &one, "--context", "20"],
            "leaves no gap",
        ),
        (
            vec![&prog, "--from", &one, "--solver", "ik"],
            "cannot edit a take",
        ),
        (vec![&prog, "--strength", "0.5"], "--from"),
        (
            vec![&prog, "--from", &one, "--resample", "500"],
            "more than 20 rounds",
        ),
    ];
    for (args, want) in cases {
        let out_path = dir.path().join("out.json");
        let mut all = vec!["run"];
        all.extend(args.iter().copied());
        all.extend(["--no-baseline", "-o", out_path.to_str().unwrap()]);
        let out = run(&all);
        let err = stderr(&out);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(err.contains(want), "{args:?}: wanted `{want}` in\n{err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(!out_path.exists(), "{args:?} left an output");
    }
}
