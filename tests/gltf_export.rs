//! glTF export through the output table: `mprog convert` writes a `.glb` of the golden
//! clip, and (ignored, needs Blender) Blender's own glTF importer puts every joint within
//! 1 cm of the clip. The read-back with forward kinematics written here is the unit test
//! in `src/formats/gltf/tests.rs`.

mod common;

use common::golden;
use mprog::motion::Motion;
use std::process::Command;

/// Writes `[frames, 22, 3]` positions (Y up, metres) as a float32 `.npy`.
fn write_npy(path: &std::path::Path, m: &Motion) {
    mprog::formats::npy::write_joints_npy(path, std::slice::from_ref(m)).unwrap();
}

#[test]
fn convert_writes_a_glb_through_the_output_table() {
    let (_, joints) = golden();
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("clip.npy");
    write_npy(&input, &joints);
    let glb = dir.path().join("clip.glb");
    let out = Command::new(env!("CARGO_BIN_EXE_mprog"))
        .arg("convert")
        .arg(&input)
        .arg("-o")
        .arg(&glb)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(&glb).unwrap();
    assert_eq!(&bytes[..4], b"glTF");
    assert_eq!(u32::from_le_bytes(bytes[4..8].try_into().unwrap()), 2);
    let help = Command::new(env!("CARGO_BIN_EXE_mprog"))
        .args(["convert", "--help"])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&help.stdout).contains(".glb"));
}

/// Blender imports our glTF and its joint empties sit within 1 cm of the input:
/// `cargo test --test gltf_export -- --ignored --nocapture blender`.
#[test]
#[ignore = "needs Blender (apt-get install blender python3-numpy); run by hand"]
fn blender_imports_the_glb_where_we_expect() {
    if Command::new("blender").arg("--version").output().is_err() {
        println!("SKIPPED: blender is not installed");
        return;
    }
    let (_, joints) = golden();
    let dir = tempfile::tempdir().unwrap();
    let expected = dir.path().join("expected.npy");
    write_npy(&expected, &joints);
    let glb = dir.path().join("clip.glb");
    std::fs::write(&glb, mprog::formats::gltf::glb_bytes(&[joints]).unwrap()).unwrap();
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/blender_gltf_check.py");
    let out = Command::new("blender")
        .args(["-b", "--factory-startup", "--python", script, "--"])
        .arg(&glb)
        .arg(&expected)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let report: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("blender_gltf_check"))
        .collect();
    println!("{}", report.join("\n"));
    assert!(
        out.status.success() && report.iter().any(|l| l.contains("OK")),
        "blender check failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
