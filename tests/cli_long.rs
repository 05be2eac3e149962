//! Long motions and prompt timelines through the built binary, with the shipped model and
//! short chains: `gen` past the model's 9.8 s, a timeline program whose constraints sit in
//! its first and last windows, the windows in the meta, and refusals.

use std::path::PathBuf;
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

/// `mprog run PROG -o JSON` with a short chain (20 steps, 4 late steps of 30 iterations).
fn run_short(prog: &std::path::Path, json: &std::path::Path) -> Output {
    run(&[
        "run",
        prog.to_str().unwrap(),
        "--no-baseline",
        "--knob",
        "steps=20",
        "--knob",
        "late_steps=4",
        "--knob",
        "k_late=30",
        "-o",
        json.to_str().unwrap(),
    ])
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).to_string()
}

/// `[frames, 22, 3]` of a `.json` output's first person, and its meta.
fn read_json(path: &std::path::Path) -> (Vec<[[f32; 3]; 22]>, serde_json::Value) {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let person = &v["people"][0];
    let frames = person["frames"]
        .as_array()
        .or_else(|| person["positions"].as_array())
        .expect("frames")
        .iter()
        .map(|f| {
            let joints = f.as_array().unwrap();
            std::array::from_fn(|j| {
                let p = joints[j].as_array().unwrap();
                std::array::from_fn(|k| p[k].as_f64().unwrap() as f32)
            })
        })
        .collect();
    (frames, v["meta"].clone())
}

/// Largest torso (pelvis, chest, head) acceleration in m/frame² over `frames`.
fn torso_accel(m: &[[[f32; 3]; 22]], frames: std::ops::Range<usize>) -> f32 {
    let mut worst = 0.0f32;
    for t in frames.start.max(1)..frames.end.min(m.len() - 1) {
        for j in [0, 9, 15] {
            let a: f32 = (0..3)
                .map(|k| (m[t + 1][j][k] - 2.0 * m[t][j][k] + m[t - 1][j][k]).powi(2))
                .sum::<f32>()
                .sqrt();
            worst = worst.max(a);
        }
    }
    worst
}

#[test]
fn gen_makes_a_motion_longer_than_the_model_in_windows_without_seams() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("walk.json");
    let out = run(&[
        "gen",
        "--text",
        "a person walks forward",
        "--seconds",
        "14",
        "--steps",
        "20",
        "-o",
        json.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("made in windows"), "{}", stderr(&out));
    let (m, meta) = read_json(&json);
    assert_eq!(m.len(), 280);
    let windows = meta["windows"].as_array().expect("windows in the meta");
    // Windows as long as a walk's clips (7.6 s, context and blend included): three.
    assert_eq!(windows.len(), 3);
    // It walks on across the seams, and no seam is rougher than the walk itself.
    let travel = ((m[279][0][0] - m[0][0][0]).powi(2) + (m[279][0][2] - m[0][0][2]).powi(2)).sqrt();
    assert!(travel > 5.0, "walked {travel} m in 14 s");
    let frame = |w: &serde_json::Value, k: usize| w[k].as_u64().unwrap() as usize;
    let seams: Vec<(usize, usize)> = windows[1..]
        .iter()
        .map(|w| (frame(w, 0), frame(w, 1) + 10))
        .collect();
    let mut inside = 0.0f32;
    let mut from = 0;
    for &(start, end) in &seams {
        inside = inside.max(torso_accel(&m, from..start));
        from = end;
    }
    inside = inside.max(torso_accel(&m, from..280));
    for &(start, end) in &seams {
        let seam = torso_accel(&m, start..end);
        assert!(seam <= inside.max(0.08), "seam {seam} vs inside {inside}");
    }
}

#[test]
fn a_timeline_program_meets_constraints_in_its_first_and_last_windows() {
    let dir = tempfile::tempdir().unwrap();
    let prog = dir.path().join("t.mprog");
    std::fs::write(
        &prog,
        "length 12s\n\
         prompt 0s..6s \"a person walks forward\"\n\
         prompt 6s..end \"a person waves both hands\"\n\
         at 2s { pelvis.y > 0.5 m }\n\
         at 11s { r_wrist.y > head.y }\n",
    )
    .unwrap();
    let json = dir.path().join("t.json");
    let out = run_short(&prog, &json);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    // The walk and the wave each in windows of their own clips' length.
    assert!(err.contains("in 4 windows"), "{err}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let (m, meta) = read_json(&json);
    assert_eq!(m.len(), 240);
    assert!(
        m[220][21][1] > m[220][15][1],
        "right wrist above the head at 11 s\n{stdout}"
    );
    let timeline = meta["timeline"][0]
        .as_array()
        .expect("timeline in the meta");
    assert_eq!(timeline.len(), 2);
    assert_eq!(timeline[1]["prompt"], "a person waves both hands");
    assert_eq!(meta["windows"].as_array().unwrap().len(), 4);
}

#[test]
fn long_requests_that_cannot_be_made_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let npy = dir.path().join("x.npy");
    let out = run(&[
        "gen",
        "--text",
        "a person walks forward",
        "--seconds",
        "400",
        "-o",
        npy.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("the longest motion mprog makes"),
        "{}",
        stderr(&out)
    );
    let out = run(&[
        "gen",
        "--text",
        "a person walks forward",
        "--seconds",
        "12",
        "--mirror-average",
        "-o",
        npy.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("mirror-average"), "{}", stderr(&out));
    let prog = dir.path().join("p.mprog");
    std::fs::write(
        &prog,
        "length 12s\nprompt \"a person walks forward\"\nat end { pelvis.z > 3 m }\n",
    )
    .unwrap();
    let out = run(&[
        "run",
        prog.to_str().unwrap(),
        "--solver",
        "ik",
        "-o",
        npy.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("cannot make a motion in windows"),
        "{}",
        stderr(&out)
    );
    assert!(!npy.exists(), "nothing written on failure");
}

#[test]
fn a_timeline_alone_is_a_program() {
    let dir = tempfile::tempdir().unwrap();
    let prog = dir.path().join("t.mprog");
    std::fs::write(
        &prog,
        "length 11s\n\
         prompt 0s..6s \"a person walks forward\"\n\
         prompt 6s..end \"a person waves the right hand\"\n",
    )
    .unwrap();
    let out = run(&["check", prog.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let json = dir.path().join("t.json");
    let out = run_short(&prog, &json);
    assert!(out.status.success(), "{}", stderr(&out));
    let (m, meta) = read_json(&json);
    assert_eq!(m.len(), 220);
    assert_eq!(meta["timeline"][0].as_array().unwrap().len(), 2);
    // An empty program without a timeline is still refused.
    std::fs::write(&prog, "prompt \"a person walks forward\"\n").unwrap();
    let out = run(&["check", prog.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("empty_program")
            || String::from_utf8_lossy(&out.stdout).contains("empty_program")
    );
}
