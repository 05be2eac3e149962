//! `mprog bench paraphrases` through the built binary, cheaply: a one-caption set, one
//! seed, two DDIM steps with the shipped model; a bad set's error; the measure list.

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

fn text(out: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&out.stdout).to_string(),
        String::from_utf8_lossy(&out.stderr).to_string(),
    )
}

#[test]
fn a_tiny_set_runs_in_both_conditionings_and_writes_its_table() {
    let dir = tempfile::tempdir().unwrap();
    let set = dir.path().join("set.toml");
    // One wording near the caption (read as written) and one far from every caption
    // (conditioned on its neighbours by default), so the literal column has one run of
    // its own and one "=".
    std::fs::write(
        &set,
        r#"
[[entry]]
caption = "a person runs forward"
wordings = ["someone is running forwards", "a figure hastens onward across the meadow"]
pace = "fast"
judges = [
  { measure = "speed", min = 2.2, word = "speed" },
  { measure = "forward", min = 0.0, word = "direction" },
]
"#,
    )
    .unwrap();
    let md = dir.path().join("table.md");
    let out = run(&[
        "bench",
        "paraphrases",
        "--set",
        set.to_str().unwrap(),
        "--seeds",
        "1",
        "--steps",
        "2",
        "-o",
        md.to_str().unwrap(),
    ]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    let table = std::fs::read_to_string(&md).unwrap();
    assert_eq!(table, stdout);
    for needle in [
        "Paraphrase bench: 1 captions and 2 wordings",
        "seeds 1, DDIM 2",
        "| nearest captions (`gen`'s default) |",
        "| literal (`--literal-prompt`) |",
        "| a person runs forward (fast) | speed: speed ≥ 2.2; direction: forward ≥ 0 |",
        "| **a person runs forward** (caption) | its own (1.00) | as written |",
        "| nearest seed 1 | literal seed 1 |",
    ] {
        assert!(table.contains(needle), "{needle} missing:\n{table}");
    }
    // A prompt read as written gives the same motion literally ("=", not a second run);
    // a prompt conditioned on its neighbours is generated again as written.
    let rows: Vec<&str> = table
        .lines()
        .filter(|l| {
            l.starts_with("| **a person runs forward**")
                || l.starts_with("| someone is running forwards |")
                || l.starts_with("| a figure hastens onward across the meadow |")
        })
        .collect();
    assert_eq!(rows.len(), 3, "{table}");
    let mut snapped = 0;
    for row in &rows {
        if row.contains("| as written |") {
            assert!(row.ends_with("| = |"), "{row}");
        } else {
            assert!(row.contains("| mean of "), "{row}");
            assert!(!row.ends_with("| = |"), "{row}");
            snapped += 1;
        }
    }
    // The far wording is snapped with the shipped model (best cosine well below 0.7).
    assert!(snapped >= 1, "{table}");
    // Progress on stderr: every prompt under nearest, the snapped ones again literally.
    let total = 3 + snapped;
    assert!(
        stderr.contains(&format!("[{total}/{total}] literal seed 1")),
        "{stderr}"
    );
}

#[test]
fn a_bad_set_is_refused_naming_the_file_and_the_entry() {
    let dir = tempfile::tempdir().unwrap();
    let set = dir.path().join("bad.toml");
    std::fs::write(
        &set,
        "[[entry]]\ncaption = \"a person jumps\"\nwordings = [\"someone jumps up\"]\njudges = [{ measure = \"hang_time\", min = 0.5 }]\n",
    )
    .unwrap();
    let out = run(&["bench", "paraphrases", "--set", set.to_str().unwrap()]);
    assert!(!out.status.success());
    let (_, stderr) = text(&out);
    assert!(stderr.contains("bad.toml"), "{stderr}");
    assert!(
        stderr.contains("entry 1 (\"a person jumps\", line 2)"),
        "{stderr}"
    );
    assert!(stderr.contains("unknown measure `hang_time`"), "{stderr}");
    let out = run(&["bench", "paraphrases", "--set", "/nonexistent/set.toml"]);
    assert!(!out.status.success());
    assert!(text(&out).1.contains("/nonexistent/set.toml"));
}

#[test]
fn measures_are_listed_without_a_model() {
    let out = run(&[
        "bench",
        "paraphrases",
        "--measures",
        "--bundle",
        "/nonexistent",
    ]);
    let (stdout, stderr) = text(&out);
    assert!(out.status.success(), "{stderr}");
    for m in [
        "`forward`",
        "`turn`",
        "`both_feet_up`",
        "`wave_swings`",
        "`torso_lean`",
    ] {
        assert!(stdout.contains(m), "{m} missing:\n{stdout}");
    }
}
