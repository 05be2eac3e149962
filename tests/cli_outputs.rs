//! The `mprog` binary's output options as a user runs them: `convert` with
//! `--bvh-fps/--bvh-axes/--bvh-units`, `.npy` outputs with their `.meta.json` sidecar (and
//! the meta coming back when the `.npy` is read), and `view` writing one HTML page.

mod common;

use common::golden;
use mprog::formats::json::write_json;
use mprog::formats::{LoadedMotion, Meta, Person, read_motion, sidecar_path};
use serde_json::json;
use std::path::Path;
use std::process::{Command, Output};

fn mprog(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mprog"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("mprog runs")
}

fn ok(out: &Output) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "mprog failed: {stderr}");
    stderr
}

/// A `.json` of the golden clip with reproduction meta and a viewer overlay.
fn input(dir: &Path) -> Meta {
    let (_, joints) = golden();
    let meta: Meta = json!({
        "seed": 7,
        "program": "person a\nkeep a.pelvis.y > 0.5",
        "weights": "mprog-small@1234abcd",
        "overlays": [{"kind": "horizontal_plane", "height": 0.5}]
    })
    .as_object()
    .unwrap()
    .clone();
    let people = [Person {
        name: "a".into(),
        motion: joints,
    }];
    write_json(&dir.join("in.json"), &people, &meta).unwrap();
    meta
}

#[test]
fn convert_with_bvh_flags_and_npy_sidecar() {
    let dir = tempfile::tempdir().unwrap();
    let meta = input(dir.path());
    let args = [
        "convert",
        "in.json",
        "-o",
        "out.bvh",
        "out.npy",
        "--bvh-fps",
        "30",
        "--bvh-axes",
        "blender-z-up",
        "--bvh-units",
        "cm",
    ];
    let stderr = ok(&mprog(&args, dir.path()));
    assert!(stderr.contains("out.meta.json"), "{stderr}");

    let bvh = std::fs::read_to_string(dir.path().join("out.bvh")).unwrap();
    let header: String = bvh.lines().take(3).collect::<Vec<_>>().join("\n");
    for word in [
        "centimetres",
        "Z up (Blender)",
        "30 fps (resampled from 20 fps)",
    ] {
        assert!(header.contains(word), "{word} missing from {header}");
    }
    assert!(bvh.contains("Frames: 254\nFrame Time: 0.03333333\n"));

    // The .npy keeps mprog's 20 fps; its sidecar carries the meta, which comes back on read.
    let side = sidecar_path(&dir.path().join("out.npy"));
    assert!(side.ends_with("out.meta.json"));
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&side).unwrap()).unwrap();
    assert_eq!(doc["describes"], "out.npy");
    assert_eq!(doc["meta"]["seed"], 7);
    assert_eq!(doc["meta"]["fps"], 20.0);
    let LoadedMotion::Joints { people, meta: back } =
        read_motion(&dir.path().join("out.npy")).unwrap()
    else {
        panic!("joints expected");
    };
    assert_eq!(people[0].motion.len(), 170);
    for key in ["seed", "program", "weights", "overlays"] {
        assert_eq!(back[key], meta[key], "{key}");
    }
}

#[test]
fn bad_export_flags_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    input(dir.path());
    let out = mprog(
        &["convert", "in.json", "-o", "x.bvh", "--bvh-fps", "0"],
        dir.path(),
    );
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("the frame rate must be above 0"));
    let out = mprog(
        &["convert", "in.json", "-o", "x.bvh", "--bvh-axes", "z-up"],
        dir.path(),
    );
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("blender-z-up"));
    // BVH flags without a BVH output would do nothing: refused, nothing written.
    let out = mprog(
        &["convert", "in.json", "-o", "x.npy", "--bvh-units", "cm"],
        dir.path(),
    );
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("only affect .bvh outputs"));
    assert!(!dir.path().join("x.npy").exists());
}

#[test]
fn view_writes_one_self_contained_page() {
    let dir = tempfile::tempdir().unwrap();
    input(dir.path());
    let stderr = ok(&mprog(
        &[
            "view",
            "in.json",
            "-o",
            "v.html",
            "--title",
            "golden <clip>",
        ],
        dir.path(),
    ));
    assert!(stderr.contains("170 frames"), "{stderr}");
    let html = std::fs::read_to_string(dir.path().join("v.html")).unwrap();
    assert!(html.contains("<title>golden &lt;clip&gt;</title>"));
    assert!(html.contains(r#""kind":"horizontal_plane""#));
    assert!(!html.contains("http://") && !html.contains("https://"));
    // `convert … -o x.html` writes the same page, and a non-HTML view output is refused.
    ok(&mprog(&["convert", "in.json", "-o", "c.html"], dir.path()));
    assert!(dir.path().join("c.html").exists());
    let out = mprog(&["view", "in.json", "-o", "v.png"], dir.path());
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("writes an HTML page"));
}

#[test]
fn two_people_to_bvh_write_one_file_each() {
    let dir = tempfile::tempdir().unwrap();
    let (_, joints) = golden();
    let people = [
        Person {
            name: "a".into(),
            motion: joints.clone(),
        },
        Person {
            name: "b".into(),
            motion: joints,
        },
    ];
    write_json(&dir.path().join("two.json"), &people, &Meta::new()).unwrap();
    let stderr = ok(&mprog(
        &["convert", "two.json", "-o", "pair.bvh"],
        dir.path(),
    ));
    for name in ["pair_p1.bvh", "pair_p2.bvh"] {
        assert!(stderr.contains(name), "{stderr}");
        let bvh = std::fs::read_to_string(dir.path().join(name)).unwrap();
        assert!(
            bvh.starts_with("HIERARCHY") || bvh.contains("HIERARCHY"),
            "{name}"
        );
    }
    assert!(!dir.path().join("pair.bvh").exists());
}
