//! Every rig of the CMU and HDM05 archives, on the small fixtures in
//! `tests/fixtures/rigs/` (first frames of real files; see its README): the rig table
//! chosen, scale from the leg, the cgspeed T-pose dropped, a standing human in metres;
//! a malformed file of each rig gives a located error and `mprog convert` writes nothing.

use mprog::formats::asf::{import_amc_beside_asf, import_asf_amc};
use mprog::formats::bvh::{BvhImport, BvhImportOptions, import_bvh, import_bvh_str};
use std::path::{Path, PathBuf};
use std::process::Command;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/rigs")
        .join(name)
}

fn import(name: &str) -> BvhImport {
    import_bvh(&fixture(name), &BvhImportOptions::default()).unwrap()
}

/// Pelvis and head heights of frame 0 above the lower foot joint, leg length (metres).
fn body(out: &BvhImport) -> (f32, f32, f32) {
    let p = &out.motion.frames[0];
    let floor = [7, 8, 10, 11]
        .iter()
        .map(|&j| p[j].y)
        .fold(f32::MAX, f32::min);
    let leg = mprog::formats::bvh::units::leg_length(p);
    (p[0].y - floor, p[15].y - floor, leg)
}

fn assert_human(name: &str, out: &BvhImport) {
    let (pelvis, head, leg) = body(out);
    // DeepMimic's humanoid is small (head joint 1.3 m) and the kick starts crouched.
    assert!((0.7..1.1).contains(&pelvis), "{name}: pelvis {pelvis}");
    assert!((1.25..1.9).contains(&head), "{name}: head {head}");
    assert!((0.7..0.95).contains(&leg), "{name}: leg {leg}");
}

#[test]
fn cgspeed_31_is_full_size_without_its_tpose() {
    let out = import("cmu_cgspeed_31_01_01.bvh");
    assert_eq!(out.joint_map.rig, "cmu-cgspeed-31");
    // CMU units are 1/0.45 inch = 0.0564 m: the leg gives it to 3 %.
    assert!(
        (out.unit_scale - 0.0564).abs() < 0.0017,
        "{}",
        out.unit_scale
    );
    assert!(
        out.warnings.iter().any(|w| w.contains("T-pose")),
        "{:?}",
        out.warnings
    );
    // 24 frames after the T-pose at 120 fps → 4 at 20 fps.
    assert_eq!(out.motion.frames.len(), 4);
    assert_human("cgspeed-31", &out);
    // The first kept frame is the motion's.
    assert!(!mprog::formats::bvh::tpose::is_tpose(&out.motion.frames[0]));
}

#[test]
fn cgspeed_daz_still_imports() {
    let out = import("cmu_cgspeed_daz_12_01.bvh");
    assert_eq!(out.joint_map.rig, "name-matched");
    assert_human("daz", &out);
}

#[test]
fn hdm05_asf_names() {
    let out = import("HDM_bd_squat1Reps_001_120.bvh");
    assert_eq!(out.joint_map.rig, "cmu-asf");
    assert_eq!(out.unit_scale, 1.0);
    assert_eq!(out.source_fps, 120.0);
    assert_human("hdm05", &out);
}

#[test]
fn deepmimic_13_and_15_joints() {
    let out = import("cmu_deepmimic13_02_01.bvh");
    assert_eq!(out.joint_map.rig, "deepmimic");
    assert_eq!(out.unit_scale, 1.0);
    assert_human("deepmimic-13", &out);
    let out15 = import("humanoid3d_kick.bvh");
    assert_eq!(out15.joint_map.rig, "deepmimic");
    assert!(
        out15
            .warnings
            .iter()
            .any(|w| w.contains("End Site of `neck`")),
        "{:?}",
        out15.warnings
    );
    assert_human("deepmimic-15", &out15);
}

#[test]
fn asf_amc_pair() {
    let amc = fixture("asf/HDM_tt_squat1Reps_001_120.amc");
    let out = import_amc_beside_asf(&amc, &BvhImportOptions::default()).unwrap();
    let same = import_asf_amc(
        &fixture("asf/HDM_tt.asf"),
        &amc,
        &BvhImportOptions::default(),
    )
    .unwrap();
    assert_eq!(out.motion, same.motion);
    assert_eq!(out.joint_map.rig, "cmu-asf");
    assert_eq!(out.motion.frames.len(), 22);
}

/// Breaks one frame line of a fixture: its third value becomes `x`.
fn broken(name: &str) -> (String, usize) {
    let text = std::fs::read_to_string(fixture(name)).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let at = lines.iter().position(|l| l.trim() == "MOTION").unwrap() + 4;
    let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    let mut words: Vec<&str> = lines[at].split_whitespace().collect();
    words[2] = "x";
    out[at] = words.join(" ");
    (out.join("\n"), at + 1)
}

#[test]
fn malformed_files_of_every_rig_are_located() {
    for name in [
        "cmu_cgspeed_31_01_01.bvh",
        "cmu_cgspeed_daz_12_01.bvh",
        "cmu_deepmimic13_02_01.bvh",
        "HDM_bd_squat1Reps_001_120.bvh",
        "humanoid3d_kick.bvh",
    ] {
        let (text, line) = broken(name);
        let e = import_bvh_str(name, &text, &BvhImportOptions::default()).unwrap_err();
        assert_eq!(e.line, Some(line), "{name}: {e}");
        assert!(
            e.to_string()
                .starts_with(&format!("{name}:{line}: invalid number `x`")),
            "{e}"
        );
        // A truncated file: the frames it lacks.
        let cut = text.lines().take(line - 1).collect::<Vec<_>>().join("\n");
        let e = import_bvh_str(name, &cut, &BvhImportOptions::default()).unwrap_err();
        assert!(e.to_string().contains("the file ends after"), "{name}: {e}");
    }
}

#[test]
fn convert_writes_nothing_for_a_malformed_file() {
    let dir = tempfile::tempdir().unwrap();
    let (text, line) = broken("HDM_bd_squat1Reps_001_120.bvh");
    let input = dir.path().join("bad.bvh");
    std::fs::write(&input, text).unwrap();
    let out = dir.path().join("bad.json");
    let run = Command::new(env!("CARGO_BIN_EXE_mprog"))
        .args([
            "convert",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(!run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.contains(&format!("bad.bvh:{line}")), "{stderr}");
    assert!(!out.exists());
    // The same for a malformed AMC.
    let amc = dir.path().join("HDM_tt_squat1Reps_001_120.amc");
    let good = std::fs::read_to_string(fixture("asf/HDM_tt_squat1Reps_001_120.amc")).unwrap();
    std::fs::write(&amc, good.replacen("rradius 40", "rradius 40 1", 1)).unwrap();
    std::fs::copy(fixture("asf/HDM_tt.asf"), dir.path().join("HDM_tt.asf")).unwrap();
    let out = dir.path().join("amc.json");
    let run = Command::new(env!("CARGO_BIN_EXE_mprog"))
        .args([
            "convert",
            amc.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(!run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("amc:14") && stderr.contains("rradius"),
        "{stderr}"
    );
    assert!(!out.exists());
}
