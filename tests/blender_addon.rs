//! The Blender add-on (`integrations/blender/mprog_blender/`), enabled headless in Blender's
//! own Python from a zip, generates 4 s of "a person walks forward" onto the active
//! armature (the Mixamo-named test rig, placed, turned and scaled): a new action of at least
//! 70 frames in which the hips move, every bone where Blender's own import of the same
//! motion puts it; a program with a typo is refused with its diagnostic at its line.
//! In Blender's interface (a virtual X server), the panel draws, *Generate motion* runs in
//! the background to a new action, and Esc stops a run.
//! Needs Blender (3.4: `apt-get install blender python3-numpy`, and `xvfb` for the panel)
//! and the shipped model: `cargo test --test blender_addon -- --ignored --nocapture`.

use std::process::Command;

/// Runs an add-on test script with `launcher` (Blender, or Blender under `xvfb-run`) on
/// the test rig, prints its report lines (those starting with `tag`) and asserts an OK.
fn run_script(mut launcher: Command, script: &str, tag: &str) {
    let root = env!("CARGO_MANIFEST_DIR");
    let scripts = tempfile::tempdir().unwrap();
    let out = launcher
        .arg(format!("{root}/integrations/blender/tests/{script}"))
        .arg("--")
        .arg(format!("{root}/tests/fixtures/rigs/mixamo_tall.bvh"))
        .env("MPROG_BIN", env!("CARGO_BIN_EXE_mprog"))
        .env("BLENDER_USER_SCRIPTS", scripts.path())
        .current_dir(root)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let report: Vec<&str> = stdout.lines().filter(|l| l.starts_with(tag)).collect();
    println!("{}", report.join("\n"));
    assert!(
        out.status.success() && report.iter().any(|l| l.contains(": OK")),
        "{script} failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Whether `tool` is on PATH.
fn have(tool: &str) -> bool {
    Command::new("sh")
        .args(["-c", &format!("command -v {tool}")])
        .output()
        .is_ok_and(|o| o.status.success())
}

#[test]
#[ignore = "needs Blender and the shipped model; run by hand"]
fn the_addon_generates_onto_the_active_armature() {
    if !have("blender") {
        println!("SKIPPED: blender is not installed");
        return;
    }
    let mut blender = Command::new("blender");
    blender.args(["-b", "--factory-startup", "--python"]);
    run_script(blender, "test_addon.py", "mprog_blender_test");
}

#[test]
#[ignore = "needs Blender, xvfb-run and the shipped model; run by hand"]
fn the_panel_runs_in_the_background_and_esc_stops_it() {
    if !have("blender") || !have("xvfb-run") {
        println!("SKIPPED: blender or xvfb-run is not installed");
        return;
    }
    let mut xvfb = Command::new("xvfb-run");
    xvfb.args(["-a", "-s", "-screen 0 1280x720x24"]).args([
        "blender",
        "--factory-startup",
        "--enable-event-simulate",
        "--python",
    ]);
    run_script(xvfb, "test_panel.py", "mprog_blender_panel");
}
