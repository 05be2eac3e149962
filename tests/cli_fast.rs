//! The shipped few-step model (`models/fast`, the default model consistency-distilled)
//! through the built binary: `gen` samples it in a few passes, `latent-fast` steers it,
//! and solvers or samplers that need the other kind of model say so by name.

use std::path::PathBuf;
use std::process::{Command, Output};

fn bin() -> Command {
    let bin = std::env::var_os("MPROG_TEST_BIN")
        .map_or_else(|| env!("CARGO_BIN_EXE_mprog").into(), PathBuf::from);
    let mut c = Command::new(bin);
    c.env("NO_COLOR", "1")
        .env_remove("MPROG_DEVICE")
        .env_remove("MPROG_MODEL")
        .env_remove("MPROG_FAST_MODEL")
        .current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

fn run(args: &[&str]) -> (bool, String, String) {
    let out: Output = bin().args(args).output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).to_string(),
        String::from_utf8_lossy(&out.stderr).to_string(),
    )
}

/// Joint positions `[frames, 22, 3]` of a written `.npy`.
fn joints(path: &std::path::Path) -> Vec<[f32; 3]> {
    let bytes = std::fs::read(path).unwrap();
    let header = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    bytes[10 + header..]
        .chunks_exact(12)
        .map(|c| {
            let f = |i: usize| f32::from_le_bytes(c[i..i + 4].try_into().unwrap());
            [f(0), f(4), f(8)]
        })
        .collect()
}

#[test]
fn the_few_step_model_walks_in_four_passes_and_is_deterministic() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.npy");
    let b = dir.path().join("b.npy");
    for out in [&a, &b] {
        let (ok, _, stderr) = run(&[
            "gen",
            "--model",
            "models/fast",
            "--text",
            "a person walks forward",
            "--seconds",
            "4",
            "--seed",
            "3",
            "--raw",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{stderr}");
    }
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let j = joints(&a);
    assert_eq!(j.len(), 80 * 22);
    let (first, last) = (j[0], j[79 * 22]);
    let travel = ((last[0] - first[0]).powi(2) + (last[2] - first[2]).powi(2)).sqrt();
    assert!(travel > 1.5, "a 4 s walk travels {travel} m");
    let meta = std::fs::read_to_string(dir.path().join("a.meta.json")).unwrap();
    assert!(meta.contains("Consistency"), "{meta}");
    assert!(meta.contains("\"guidance_scale\": 1.0"), "{meta}");
}

#[test]
fn latent_fast_steers_the_few_step_model() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.npy");
    let (ok, stdout, stderr) = run(&[
        "run",
        "programs/hsc1_hand_on_head.mprog",
        "--solver",
        "latent-fast",
        "--knob",
        "iterations=12",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    // | 8 | `…` | m² | unguided | latent-fast | plausibility |
    let row = stdout
        .lines()
        .find(|l| l.starts_with("| 8 |"))
        .unwrap_or_else(|| panic!("{stdout}"));
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    let unguided: f64 = cells[4].parse().unwrap();
    let steered: f64 = cells[5].parse().unwrap();
    assert!(
        steered < 0.5 * unguided,
        "12 iterations: {unguided} -> {steered}\n{stdout}"
    );
}

#[test]
fn each_kind_of_model_refuses_what_needs_the_other() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.npy");
    let out = out.to_str().unwrap();
    let prog = "programs/hsc1_hand_on_head.mprog";
    let (ok, _, stderr) = run(&["run", prog, "--model", "models/fast", "-o", out]);
    assert!(!ok);
    assert!(
        stderr.contains("cannot run on a few-step") && stderr.contains("latent-fast"),
        "{stderr}"
    );
    let (ok, _, stderr) = run(&[
        "run",
        prog,
        "--model",
        "models/default",
        "--solver",
        "latent-fast",
        "-o",
        out,
    ]);
    assert!(!ok);
    assert!(stderr.contains("models/fast"), "{stderr}");
    let (ok, _, stderr) = run(&[
        "gen",
        "--text",
        "a person walks",
        "--sampler",
        "lcm",
        "-o",
        out,
    ]);
    assert!(!ok);
    assert!(stderr.contains("consistency-distilled"), "{stderr}");
}
