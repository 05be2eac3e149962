//! Adversarial inputs: every bad file, program, bundle or command line is answered by a
//! clear error that names the place (file, line, field), never by a panic, and commands
//! that fail leave no output file behind.
//!
//! Library cases call the readers directly; CLI cases run the built `mprog` binary in a
//! temporary folder. Fixture files live in `tests/fixtures/adversarial/` (the fuzzing
//! findings among them are named after what they trigger).

use burn::tensor::{Device, Tensor, TensorData};
use mprog::formats::bvh::{BvhImportOptions, ParseLimits, import_bvh, import_bvh_bytes};
use mprog::formats::json::read_json_str;
use mprog::formats::npy::{classify, read_npy_bytes};
use mprog::formats::{LoadedMotion, read_motion};
use mprog::lang::{EvalError, MAX_EVAL_ELEMENTS, check_source, compile};
use mprog::model::prompt::PromptEncoder;
use mprog::model::text::Vocabulary;
use mprog::model::weights::Manifest;
use mprog::model::{Mdm, ModelBundle, ModelConfig};
use mprog::skeleton::{JOINT_NAMES, NUM_JOINTS};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

// ---------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/adversarial")
        .join(name)
}

fn bandai_like() -> String {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/bandai_like.bvh");
    std::fs::read_to_string(p).unwrap()
}

/// Runs `f` on a thread with a 2 MiB stack (the default of test threads): deep-nesting
/// cases must not need more, and a panic fails with the input's description.
fn no_panic<T: Send + 'static>(what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    std::thread::Builder::new()
        .stack_size(2 << 20)
        .spawn(f)
        .unwrap()
        .join()
        .unwrap_or_else(|_| panic!("{what}: panicked"))
}

/// Asserts that `message` contains every needle.
#[track_caller]
fn assert_mentions(message: &str, needles: &[&str]) {
    for n in needles {
        assert!(
            message.contains(n),
            "expected `{n}` in the message:\n{}",
            short(message)
        );
    }
}

/// The first 2000 characters, for failure messages about huge inputs.
fn short(text: &str) -> String {
    text.chars().take(2000).collect()
}

/// BVH text → the error message (the import must fail).
fn bvh_error(origin: &str, text: &str) -> String {
    let (o, t) = (origin.to_string(), text.as_bytes().to_vec());
    no_panic(origin, move || {
        import_bvh_bytes(&o, &t, &BvhImportOptions::default())
            .map(|_| ())
            .expect_err("import should fail")
            .to_string()
    })
}

/// The bandai-like fixture with the MOTION header and frame lines replaced.
fn bvh_with_motion(motion: &str) -> String {
    let text = bandai_like();
    let at = text.find("MOTION").unwrap();
    format!("{}MOTION\n{motion}", &text[..at])
}

/// An `.npy` file: header for `descr` and `shape`, then `payload`.
fn npy(descr: &str, shape: &[usize], payload: &[u8]) -> Vec<u8> {
    let dims: String = shape.iter().map(|d| format!("{d}, ")).collect();
    let header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': ({dims}), }}");
    let mut h = header.into_bytes();
    let pad = 64 - (10 + h.len() + 1) % 64;
    h.extend(std::iter::repeat_n(b' ', pad));
    h.push(b'\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend((h.len() as u16).to_le_bytes());
    out.extend(h);
    out.extend(payload);
    out
}

fn f32_bytes(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

fn npy_error(bytes: Vec<u8>) -> String {
    no_panic("npy", move || match read_npy_bytes("bad.npy", &bytes) {
        Err(e) => e.to_string(),
        Ok(array) => classify("bad.npy", array)
            .map(|_| ())
            .expect_err("the array should be refused")
            .to_string(),
    })
}

/// A valid motion document as a JSON value (two frames of one person).
fn json_doc() -> serde_json::Value {
    let pose: Vec<[f32; 3]> = (0..NUM_JOINTS)
        .map(|j| [0.0, 0.9 + 0.01 * j as f32, 0.0])
        .collect();
    serde_json::json!({
        "format": "mprog-motion",
        "version": 1,
        "fps": 20.0,
        "skeleton": "humanml3d-22",
        "joint_names": JOINT_NAMES,
        "up": "+y",
        "units": "m",
        "people": [{"name": "a", "frames": [pose.clone(), pose]}],
    })
}

fn json_error(text: String) -> String {
    no_panic("json", move || {
        read_json_str("bad.json", &text)
            .map(|_| ())
            .expect_err("the document should be refused")
            .to_string()
    })
}

/// Checks `src`; asserts an error whose code contains `code` on 1-based `line`.
#[track_caller]
fn program_error(src: &str, code: &str, line: usize) {
    let owned = src.to_string();
    let diags = no_panic("program", move || check_source(&owned, "adv.mprog", &[]));
    let json = diags.to_json();
    assert!(
        json.iter()
            .any(|d| d.code.contains(code) && d.line == line && !d.message.is_empty()),
        "expected {code} on line {line}, got:\n{}",
        short(&diags.render_plain())
    );
}

/// A joints tensor `[batch, people, frames, 22, 3]` of a standing person.
fn joints(batch: usize, people: usize, frames: usize) -> Tensor<5> {
    let rest = mprog::skeleton::rest_pose();
    let data: Vec<f32> = (0..batch * people * frames)
        .flat_map(|_| rest.iter().flat_map(|v| [v.x, v.y, v.z]))
        .collect();
    Tensor::from_data(
        TensorData::new(data, [batch, people, frames, NUM_JOINTS, 3]),
        &Device::flex(),
    )
}

fn tiny_config() -> ModelConfig {
    ModelConfig {
        features: 263,
        d_model: 16,
        layers: 1,
        heads: 2,
        d_ff: 32,
        dropout: 0.0,
        d_text: 8,
        text_encoder: Default::default(),
        max_frames: 40,
        input_skip: false,
        skip_taps: 1,
        skip_taps_below: None,
        side_input: false,
        text_control: None,
    }
}

/// Saves a tiny random bundle in `dir` (f32 weights).
fn tiny_bundle(dir: &Path) {
    let device = Device::flex();
    let config = tiny_config();
    let vocab = Vocabulary::from_captions(["a person walks forward", "a person waves"], 8);
    let model = Mdm::new(&config, vocab.len(), &device);
    let bundle = ModelBundle {
        config,
        text: PromptEncoder::Words(vocab),
        mean: vec![0.0; 263],
        std: vec![1.0; 263],
        model,
        manifest: Manifest {
            version: mprog::model::weights::BUNDLE_VERSION,
            weights_id: "tiny-test".into(),
            steps: 0,
            train_seconds: 0.0,
            half_precision: false,
            text_encoder_id: None,
            control_id: None,
            consistency: None,
        },
    };
    bundle.save(dir).unwrap();
}

fn load_error(dir: &Path) -> String {
    let d = dir.to_path_buf();
    no_panic("bundle", move || {
        ModelBundle::load(&d, &Device::flex())
            .map(|_| ())
            .expect_err("the bundle should be refused")
            .to_string()
    })
}

/// The `mprog` binary under test: cargo's, or `$MPROG_TEST_BIN` (for worktrees that share
/// a target folder, where `target/debug/mprog` may come from another checkout).
fn binary() -> PathBuf {
    std::env::var_os("MPROG_TEST_BIN")
        .map_or_else(|| env!("CARGO_BIN_EXE_mprog").into(), PathBuf::from)
}

/// Runs the binary in `dir`.
fn mprog(dir: &Path, args: &[&str]) -> Output {
    Command::new(binary())
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .env_remove("MPROG_MODEL")
        .output()
        .unwrap()
}

/// Asserts that the command failed with a message (on stderr, or stdout for `check`)
/// naming `needles`, without a panic.
#[track_caller]
fn assert_cli_error(out: &Output, needles: &[&str]) -> String {
    let stderr =
        String::from_utf8_lossy(&out.stderr).to_string() + &String::from_utf8_lossy(&out.stdout);
    assert!(!out.status.success(), "should fail; stderr:\n{stderr}");
    assert_ne!(out.status.code(), Some(101), "panicked:\n{stderr}");
    assert!(!stderr.contains("panicked"), "panicked:\n{stderr}");
    assert_mentions(&stderr, needles);
    stderr
}

/// Files in `dir` (recursively) other than `keep`.
fn files_except(dir: &Path, keep: &[&str]) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().to_string_lossy().to_string();
                if !keep.contains(&rel.as_str()) {
                    out.push(rel);
                }
            }
        }
    }
    out
}

#[track_caller]
fn assert_no_outputs(dir: &Path, inputs: &[&str]) {
    let extra = files_except(dir, inputs);
    assert!(extra.is_empty(), "partial outputs left behind: {extra:?}");
}

// ---------------------------------------------------------------------------------------
// BVH
// ---------------------------------------------------------------------------------------

#[test]
fn bvh_empty_file() {
    let m = bvh_error("empty.bvh", "");
    assert_mentions(&m, &["empty.bvh:1", "HIERARCHY", "end of file"]);
}

#[test]
fn bvh_binary_data() {
    let bytes = b"HIERARCHY\nROOT a\n{\x00\x01\x02".to_vec();
    let m = no_panic("binary", move || {
        import_bvh_bytes("bin.bvh", &bytes, &BvhImportOptions::default())
            .unwrap_err()
            .to_string()
    });
    assert_mentions(&m, &["bin.bvh:3", "binary"]);
}

#[test]
fn bvh_not_utf8() {
    let mut bytes = bandai_like().into_bytes();
    bytes.splice(40..40, [0xff, 0xfe]);
    let m = no_panic("latin1", move || {
        import_bvh_bytes("latin1.bvh", &bytes, &BvhImportOptions::default())
            .unwrap_err()
            .to_string()
    });
    assert_mentions(&m, &["latin1.bvh:", "UTF-8"]);
}

#[test]
fn bvh_truncated_in_the_hierarchy() {
    let text = bandai_like();
    let cut: String = text.lines().take(20).collect::<Vec<_>>().join("\n");
    let m = bvh_error("cut.bvh", &cut);
    assert_mentions(&m, &["cut.bvh:20", "never closed"]);
}

#[test]
fn bvh_truncated_in_the_motion() {
    let text = bandai_like();
    let cut: String = text.lines().take(136).collect::<Vec<_>>().join("\n");
    let m = bvh_error("cut.bvh", &cut);
    assert_mentions(&m, &["cut.bvh:136", "2 of the 4 frames"]);
}

#[test]
fn bvh_truncated_mid_line() {
    let text = bandai_like();
    let at = text.rfind('\n').unwrap() - 40;
    let m = bvh_error("cut.bvh", &text[..at]);
    assert_mentions(&m, &["cut.bvh:138", "values, expected 132"]);
}

#[test]
fn bvh_missing_channels() {
    let m = no_panic("missing channels", || {
        import_bvh(
            &fixture("missing_channels.bvh"),
            &BvhImportOptions::default(),
        )
        .unwrap_err()
        .to_string()
    });
    assert_mentions(&m, &["missing_channels.bvh:10", "`Spine` has no CHANNELS"]);
}

#[test]
fn bvh_channel_count_disagrees() {
    let text = bandai_like().replacen(
        "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
        "CHANNELS 6 Xposition Yposition Zposition",
        1,
    );
    assert_mentions(
        &bvh_error("c.bvh", &text),
        &["c.bvh:5", "declares 6 channels but lists 3"],
    );
}

#[test]
fn bvh_unknown_channel_name() {
    let text = bandai_like().replacen("Zrotation", "Wrotation", 1);
    assert_mentions(
        &bvh_error("w.bvh", &text),
        &["w.bvh:5", "unknown channel `Wrotation`"],
    );
}

#[test]
fn bvh_nan_value() {
    let m = no_panic("nan", || {
        import_bvh(&fixture("nan_value.bvh"), &BvhImportOptions::default())
            .unwrap_err()
            .to_string()
    });
    assert_mentions(&m, &["nan_value.bvh:136", "`nan`", "not a finite number"]);
}

#[test]
fn bvh_infinite_value() {
    let frame = vec!["0"; 132].join(" ");
    let bad = format!("1e39 {}", vec!["0"; 131].join(" "));
    let text = bvh_with_motion(&format!("Frames: 2\nFrame Time: 0.05\n{frame}\n{bad}\n"));
    assert_mentions(&bvh_error("inf.bvh", &text), &["inf.bvh:136", "1e39"]);
}

#[test]
fn bvh_values_that_overflow_along_the_skeleton() {
    // Finding: 3e38 on two chained position channels gave ∞ joint positions, written
    // to JSON as `null` and to .npy as inf.
    let text = bandai_like();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let first = lines.iter().position(|l| l == "MOTION").unwrap() + 3;
    for line in &mut lines[first..first + 4] {
        let mut v: Vec<&str> = line.split(' ').collect();
        v[7] = "3e38";
        v[13] = "3e38";
        *line = v.join(" ");
    }
    let m = bvh_error("big.bvh", &lines.join("\n"));
    assert_mentions(&m, &["big.bvh", "frame 1 of the file", "not finite"]);
}

#[test]
fn bvh_zero_frames() {
    let m = no_panic("zero frames", || {
        import_bvh(&fixture("zero_frames.bvh"), &BvhImportOptions::default())
            .unwrap_err()
            .to_string()
    });
    assert_mentions(&m, &["zero_frames.bvh:133", "Frames: 0"]);
}

#[test]
fn bvh_unknown_skeleton() {
    let m = no_panic("unknown skeleton", || {
        import_bvh(
            &fixture("unknown_skeleton.bvh"),
            &BvhImportOptions::default(),
        )
        .unwrap_err()
        .to_string()
    });
    assert_mentions(
        &m,
        &[
            "unknown_skeleton.bvh",
            "cannot map the skeleton",
            "Base",
            "Arm",
        ],
    );
}

#[test]
fn bvh_missing_motion_section() {
    let text = bandai_like();
    let at = text.find("MOTION").unwrap();
    assert_mentions(
        &bvh_error("h.bvh", &text[..at]),
        &["h.bvh:", "no MOTION section"],
    );
}

#[test]
fn bvh_bad_frame_times() {
    for (time, line) in [("0", 134), ("-0.1", 134), ("nan", 134), ("soon", 134)] {
        let frame = vec!["0"; 132].join(" ");
        let text = bvh_with_motion(&format!("Frames: 1\nFrame Time: {time}\n{frame}\n"));
        let m = bvh_error("t.bvh", &text);
        assert_mentions(&m, &[&format!("t.bvh:{line}"), "Frame Time", time]);
    }
}

#[test]
fn bvh_huge_frame_time_is_refused_before_resampling() {
    // Fuzzing finding: 1e30 s per frame made the resampler allocate ~1e31 frames.
    let m = no_panic("huge frame time", || {
        import_bvh(
            &fixture("huge_frame_time.bvh"),
            &BvhImportOptions::default(),
        )
        .unwrap_err()
        .to_string()
    });
    assert_mentions(&m, &["huge_frame_time.bvh", "frames after resampling"]);
}

#[test]
fn bvh_frames_claim_beyond_the_limit() {
    let text = bvh_with_motion("Frames: 99999999999999\nFrame Time: 0.05\n0\n");
    assert_mentions(
        &bvh_error("big.bvh", &text),
        &["big.bvh:133", "over the limit"],
    );
}

#[test]
fn bvh_frame_count_not_a_number() {
    for bad in ["-3", "four", "1.5"] {
        let text = bvh_with_motion(&format!("Frames: {bad}\nFrame Time: 0.05\n"));
        assert_mentions(&bvh_error("f.bvh", &text), &["f.bvh:133", bad]);
    }
}

#[test]
fn bvh_more_frame_lines_than_declared() {
    let frame = vec!["0"; 132].join(" ");
    let text = bvh_with_motion(&format!("Frames: 1\nFrame Time: 0.05\n{frame}\n{frame}\n"));
    assert_mentions(
        &bvh_error("x.bvh", &text),
        &["x.bvh:136", "more frame lines"],
    );
}

#[test]
fn bvh_deep_nesting_does_not_overflow_the_stack() {
    let depth = 100_000;
    let mut text = String::from("HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n");
    for i in 0..depth {
        text.push_str(&format!(
            "JOINT j{i}\n{{\nOFFSET 0 1 0\nCHANNELS 1 Xrotation\n"
        ));
    }
    let m = bvh_error("deep.bvh", &text);
    assert_mentions(&m, &["deep.bvh:", "nested more than 256 levels"]);
}

#[test]
fn bvh_duplicate_offset() {
    let text = bandai_like().replacen("OFFSET 0 95 0", "OFFSET 0 95 0\n\t\tOFFSET 1 2 3", 1);
    assert_mentions(&bvh_error("d.bvh", &text), &["d.bvh:9", "second OFFSET"]);
}

#[test]
fn bvh_file_over_the_size_limit() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("big.bvh");
    std::fs::write(&path, vec![b' '; (1 << 20) + 10]).unwrap();
    let opts = BvhImportOptions {
        limits: ParseLimits { max_values: 10 },
        ..BvhImportOptions::default()
    };
    let m = import_bvh(&path, &opts).unwrap_err().to_string();
    assert_mentions(&m, &["big.bvh", "over the limit of 1048576 bytes"]);
}

// ---------------------------------------------------------------------------------------
// .npy
// ---------------------------------------------------------------------------------------

#[test]
fn npy_empty_file() {
    assert_mentions(
        &npy_error(Vec::new()),
        &["bad.npy", "not a valid .npy file"],
    );
}

#[test]
fn npy_not_an_npy_file() {
    let m = npy_error(b"frame,joint,x,y,z\n0,0,1,2,3\n".to_vec());
    assert_mentions(&m, &["bad.npy", "not a valid .npy file"]);
}

#[test]
fn npy_truncated_header() {
    let full = npy("<f4", &[1, 22, 3], &f32_bytes(&[0.0; 66]));
    assert_mentions(
        &npy_error(full[..30].to_vec()),
        &["bad.npy", "not a valid .npy file"],
    );
}

#[test]
fn npy_integer_dtype() {
    let bytes = std::fs::read(fixture("int32_joints.npy")).unwrap();
    assert_mentions(
        &npy_error(bytes),
        &["bad.npy", "unsupported dtype `<i4`", "float32"],
    );
}

#[test]
fn npy_half_float_and_bool_dtypes() {
    assert_mentions(
        &npy_error(npy("<f2", &[1, 22, 3], &[0; 132])),
        &["dtype `<f2`"],
    );
    assert_mentions(
        &npy_error(npy("|b1", &[1, 22, 3], &[0; 66])),
        &["dtype `|b1`"],
    );
}

#[test]
fn npy_wrong_shape() {
    let bytes = std::fs::read(fixture("wrong_shape.npy")).unwrap();
    assert_mentions(
        &npy_error(bytes),
        &["bad.npy", "[2, 21, 3]", "[frames, 22, 3]"],
    );
}

#[test]
fn npy_one_dimensional_and_empty_shapes() {
    let m = npy_error(npy("<f4", &[66], &f32_bytes(&[0.0; 66])));
    assert_mentions(&m, &["shape [66]"]);
    let m = npy_error(npy("<f4", &[0, 22, 3], &[]));
    assert_mentions(&m, &["shape [0, 22, 3]"]);
}

#[test]
fn npy_features_of_the_wrong_width() {
    let m = npy_error(npy("<f4", &[2, 262], &f32_bytes(&[0.0; 524])));
    assert_mentions(&m, &["[2, 262]", "[frames, 263] features"]);
}

#[test]
fn npy_truncated_data() {
    let bytes = std::fs::read(fixture("truncated.npy")).unwrap();
    assert_mentions(
        &npy_error(bytes),
        &["truncated", "needs 1056 bytes", "has 400"],
    );
}

#[test]
fn npy_nan_value_names_its_index() {
    let bytes = std::fs::read(fixture("nan_joints.npy")).unwrap();
    assert_mentions(
        &npy_error(bytes),
        &["bad.npy", "index [1, 1, 1]", "not finite"],
    );
}

#[test]
fn npy_deeply_nested_header_does_not_overflow_the_stack() {
    // The header is a Python literal: nest it as deep as a version-1 header allows.
    let depth = 30_000;
    let header = format!(
        "{{'descr': '<f4', 'fortran_order': False, 'shape': {}1{}, }}",
        "[".repeat(depth),
        "]".repeat(depth)
    );
    let mut h = header.into_bytes();
    h.push(b'\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend((h.len() as u16).to_le_bytes());
    bytes.extend(h);
    assert_mentions(&npy_error(bytes), &["bad.npy", "not a valid .npy file"]);
}

#[test]
fn npy_backtracking_header_is_refused_quickly() {
    // Fuzzing finding (npy target, timeout): unclosed `[` in the header made the header
    // parser backtrack for 15 s.
    let bytes = std::fs::read(
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures/fuzz/npy/backtracking-header.npy"),
    )
    .unwrap();
    let started = std::time::Instant::now();
    assert_mentions(&npy_error(bytes), &["bad.npy", "brackets"]);
    assert!(started.elapsed().as_secs() < 2, "{:?}", started.elapsed());
}

#[test]
fn npy_absurd_shape() {
    let m = npy_error(npy("<f4", &[1 << 40, 22, 3], &[]));
    assert_mentions(&m, &["bad.npy", "over the limit"]);
}

// ---------------------------------------------------------------------------------------
// .json
// ---------------------------------------------------------------------------------------

#[test]
fn json_empty_file() {
    assert_mentions(&json_error(String::new()), &["bad.json:1:0", "EOF"]);
}

#[test]
fn json_syntax_error_names_line_and_column() {
    let text = "{\n  \"format\": \"mprog-motion\",\n  \"version\": 1,,\n}";
    assert_mentions(&json_error(text.into()), &["bad.json:3:16"]);
}

#[test]
fn json_wrong_version() {
    let text = std::fs::read_to_string(fixture("bad_version.json")).unwrap();
    assert_mentions(
        &json_error(text),
        &["bad.json", "version 2 is not supported"],
    );
}

#[test]
fn json_wrong_joint_count_names_person_and_frame() {
    let mut doc = json_doc();
    doc["people"][0]["frames"][1]
        .as_array_mut()
        .unwrap()
        .truncate(21);
    let m = json_error(doc.to_string());
    assert_mentions(&m, &["person 0 (\"a\") frame 1 has 21 joints"]);
}

#[test]
fn json_non_numbers_and_overflowing_numbers() {
    let text = json_doc().to_string().replacen("0.9", "null", 1);
    assert_mentions(&json_error(text), &["bad.json:1:"]);
    let text = json_doc().to_string().replacen("0.9", "1e999", 1);
    assert_mentions(&json_error(text), &["bad.json:1:", "out of range"]);
}

#[test]
fn json_bad_fps() {
    for fps in ["0", "-20"] {
        let text = json_doc()
            .to_string()
            .replace("\"fps\":20.0", &format!("\"fps\":{fps}"));
        assert_mentions(&json_error(text), &["bad.json", "`fps` must be positive"]);
    }
}

#[test]
fn json_tiny_fps_is_refused_before_resampling() {
    // Fuzzing finding: fps 1e-30 made two frames last 1e30 s and resampling to 20 fps
    // tried to allocate ~usize::MAX frames.
    let path = fixture("tiny_fps.json");
    let m = no_panic("tiny fps", move || {
        read_motion(&path).map(|_| ()).unwrap_err().to_string()
    });
    assert_mentions(&m, &["tiny_fps.json", "fps", "too long"]);
}

#[test]
fn json_no_people_and_no_frames() {
    let mut doc = json_doc();
    doc["people"] = serde_json::json!([]);
    assert_mentions(&json_error(doc.to_string()), &["`people` is empty"]);
    let mut doc = json_doc();
    doc["people"][0]["frames"] = serde_json::json!([]);
    assert_mentions(
        &json_error(doc.to_string()),
        &["person 0 (\"a\") has no frames"],
    );
}

#[test]
fn json_unknown_units_and_skeleton() {
    let mut doc = json_doc();
    doc["units"] = "inch".into();
    assert_mentions(&json_error(doc.to_string()), &["`units` is \"inch\""]);
    let mut doc = json_doc();
    doc["skeleton"] = "smpl-24".into();
    assert_mentions(&json_error(doc.to_string()), &["`skeleton` is \"smpl-24\""]);
}

#[test]
fn json_deeply_nested_meta_does_not_overflow_the_stack() {
    let mut doc = json_doc().to_string();
    doc.pop();
    let nested = format!("{}1{}", "[".repeat(100_000), "]".repeat(100_000));
    let text = format!("{doc},\"meta\":{{\"x\":{nested}}}}}");
    assert_mentions(&json_error(text), &["bad.json:1:", "recursion limit"]);
}

// ---------------------------------------------------------------------------------------
// Programs
// ---------------------------------------------------------------------------------------

#[test]
fn program_absurd_literals() {
    // Constants are f32 at evaluation: overflowing literals and folded products are refused.
    program_error(
        "length 4s\nalways {\n  head.y > 1e308 m\n}\n",
        "number_out_of_range",
        3,
    );
    program_error(
        "length 4s\nalways { head.y > 1e30 m * 1e30 }\n",
        "number_out_of_range",
        2,
    );
    program_error("length 4s\nalways { head.y > 1e400 }\n", "", 2);
    // Large but finite literals evaluate to finite errors.
    let p = compile("length 4s\nalways { head.y > 1e18 m }\n", "big.mprog", &[]).unwrap();
    let e = p.try_evaluate(joints(1, 1, 8)).unwrap();
    let total = e.total.into_data().try_into_vec::<f32>().unwrap()[0];
    assert!(total.is_finite(), "{total}");
}

#[test]
fn program_nan_literal() {
    program_error("length 4s\nalways { head.y > NaN }\n", "unknown", 2);
}

#[test]
fn program_huge_loops() {
    let src = "length 9s\nfor a in joints { for b in joints { for c in joints {\n  always { dist(a, b) > dist(b, c) }\n} } }\n";
    let diags = check_source(src, "loops.mprog", &[]);
    assert!(diags.has_errors());
    assert_mentions(&diags.render_plain(), &["too_costly"]);
}

#[test]
fn program_unbounded_recursion_through_def() {
    program_error(
        "length 4s\ndef f(x) = f(x) + 1 m\nalways { f(head.y) > 1 m }\n",
        "",
        2,
    );
}

#[test]
fn program_mutual_recursion_through_def() {
    let src = "length 4s\ndef f(x) = g(x)\ndef g(x) = f(x)\nalways { f(head.y) > 1 m }\n";
    let diags = check_source(src, "rec.mprog", &[]);
    assert!(diags.has_errors(), "{}", diags.render_plain());
    assert!(diags.to_json().iter().any(|d| (2..=4).contains(&d.line)));
}

#[test]
fn program_keyframe_beyond_the_end() {
    program_error(
        "length 4s\nat 9s { head.y > 1 m }\n",
        "time_out_of_range",
        2,
    );
}

#[test]
fn program_unicode_identifiers() {
    // Non-ASCII letters are not identifiers: a syntax error on the line, not a panic.
    program_error(
        "length 4s\nlet höhe = 1 m\nalways { head.y > höhe }\n",
        "",
        2,
    );
    program_error("length 4s\nalways { 头.y > 1 m }\n", "", 2);
}

#[test]
fn program_person_referencing_a_missing_person() {
    program_error(
        "length 4s\npeople a, b\nalways { c.head.y > a.head.y }\n",
        "unknown",
        3,
    );
}

#[test]
fn program_overlong_input() {
    let src = format!("length 4s\n{}", "always { head.y > 1 m }\n".repeat(12_000));
    let diags = check_source(&src, "long.mprog", &[]);
    assert_mentions(&diags.render_plain(), &["the limit is 262144"]);
}

#[test]
fn program_deep_parentheses_do_not_overflow_the_stack() {
    let depth = 100_000; // 200 kB, under the 256 kB source limit
    let src = format!(
        "length 4s\nalways {{ head.y > {}1 m{} }}\n",
        "(".repeat(depth),
        ")".repeat(depth)
    );
    program_error(&src, "", 2);
}

#[test]
fn program_long_chains_do_not_overflow_the_stack() {
    // Chains without brackets: postfix, member, keyword and binary-operator chains.
    let n = 40_000;
    let cases = [
        format!("length 4s\nalways {{ head{} > 1 m }}\n", "@1s".repeat(n)),
        format!("length 4s\nalways {{ head{} > 1 m }}\n", ".y".repeat(n)),
        format!(
            "length 4s\nalways {{ head.y > 1 m{} }}\n",
            " and head.y > 1 m".repeat(n / 8)
        ),
        format!("length 4s\nalways {{ 1 m{} }}\n", " < head.y".repeat(n / 4)),
        format!("length 4s\nalways {{ head.y > 1 m{} }}\n", " * 1".repeat(n)),
        format!("length 4s\nalways {{ head.y > {}1 m }}\n", "-".repeat(n)),
        format!(
            "length 4s\n{}always {{ head.y > 1 m }}\n",
            "weight 2 ".repeat(n / 4)
        ),
        format!("length 4s\n{}head.y > 1 m\n", "at 1s ".repeat(n / 4)),
    ];
    for (i, src) in cases.into_iter().enumerate() {
        let diags = no_panic(&format!("chain {i}"), move || {
            check_source(&src, "chain.mprog", &[])
        });
        // Whatever the verdict, an error must point into the program.
        for d in diags.to_json() {
            assert!(d.line >= 1 && d.line <= 3, "chain {i}: {}", d.message);
        }
    }
}

#[test]
fn program_absurd_length() {
    program_error("length 1e308 s\nalways { head.y > 1 m }\n", "", 1);
    program_error("length 0 frames\nalways { head.y > 1 m }\n", "", 1);
}

#[test]
fn program_nan_and_infinite_parameter_overrides() {
    let src = "length 4s\nparam d = 40 cm\nalways { dist(l_hand, r_hand) == d }\n";
    for v in [f64::NAN, f64::INFINITY, 1e308] {
        let diags = check_source(src, "p.mprog", &[("d".into(), v)]);
        assert!(
            diags.has_errors(),
            "override {v} accepted:\n{}",
            diags.render_plain()
        );
        assert_mentions(&diags.render_plain(), &["d"]);
    }
}

#[test]
fn program_division_by_zero() {
    program_error("length 4s\nalways { head.y / 0 m > 1 }\n", "", 2);
}

#[test]
fn program_evaluation_too_costly_is_refused_with_the_estimate() {
    let p = compile(
        "length 4s\nfor j in joints { always { dist(j, head) > 10 cm } }\n",
        "costly.mprog",
        &[],
    )
    .unwrap();
    let frames = 50_000;
    let estimate = p.ir().cost_estimate_at(frames).elements(64);
    assert!(estimate > MAX_EVAL_ELEMENTS);
    // The refusal comes before any tensor work: the joints tensor is tiny on purpose
    // except for its frame count, so a real evaluation would take minutes.
    let err = p
        .try_evaluate(joints(64, 1, frames))
        .map(|_| ())
        .unwrap_err();
    assert!(matches!(err, EvalError::TooCostly { .. }), "{err}");
    assert_mentions(
        &err.to_string(),
        &[
            "costly.mprog",
            "64 motion(s) of 50000 frames",
            &estimate.to_string(),
            "limit",
        ],
    );
    // Under a smaller explicit limit even a short motion is refused; above it, it runs.
    let small = p.try_evaluate_with_limit(joints(1, 1, 10), 10).map(|_| ());
    assert!(matches!(small, Err(EvalError::TooCostly { limit: 10, .. })));
    assert!(p.try_evaluate(joints(1, 1, 10)).is_ok());
}

#[test]
fn program_evaluated_on_the_wrong_people() {
    let p = compile(
        "length 4s\npeople a, b\nalways { dist(a.head, b.head) > 1 m }\n",
        "two.mprog",
        &[],
    )
    .unwrap();
    let err = p.try_evaluate(joints(1, 1, 5)).map(|_| ()).unwrap_err();
    assert_mentions(
        &err.to_string(),
        &["[1, 1, 5, 22, 3]", "expected [batch, 2,"],
    );
}

// ---------------------------------------------------------------------------------------
// Model bundles
// ---------------------------------------------------------------------------------------

#[test]
fn bundle_missing_folder() {
    let dir = tempfile::tempdir().unwrap();
    let m = load_error(&dir.path().join("nowhere"));
    assert_mentions(&m, &["nowhere/manifest.json", "cannot read"]);
}

#[test]
fn bundle_wrong_version() {
    let dir = tempfile::tempdir().unwrap();
    tiny_bundle(dir.path());
    let p = dir.path().join("manifest.json");
    let text = std::fs::read_to_string(&p)
        .unwrap()
        .replace("\"version\": 1", "\"version\": 7");
    std::fs::write(&p, text).unwrap();
    assert_mentions(
        &load_error(dir.path()),
        &["manifest.json", "version 7", "reads version 1"],
    );
}

#[test]
fn bundle_garbage_manifest() {
    let dir = tempfile::tempdir().unwrap();
    tiny_bundle(dir.path());
    std::fs::write(dir.path().join("manifest.json"), b"\x00\x01not json").unwrap();
    assert_mentions(&load_error(dir.path()), &["manifest.json"]);
}

#[test]
fn bundle_config_of_another_shape() {
    let dir = tempfile::tempdir().unwrap();
    tiny_bundle(dir.path());
    let p = dir.path().join("config.toml");
    let text = std::fs::read_to_string(&p)
        .unwrap()
        .replace("d_model = 16", "d_model = 24");
    std::fs::write(&p, text).unwrap();
    assert_mentions(
        &load_error(dir.path()),
        &["model.safetensors", "do not fit"],
    );
}

#[test]
fn bundle_config_asking_for_an_input_skip_the_weights_lack() {
    let dir = tempfile::tempdir().unwrap();
    tiny_bundle(dir.path());
    let p = dir.path().join("config.toml");
    let mut text = std::fs::read_to_string(&p).unwrap();
    text.push_str("input_skip = true\n");
    std::fs::write(&p, text).unwrap();
    assert_mentions(
        &load_error(dir.path()),
        &["model.safetensors", "do not fit", "missing"],
    );
}

#[test]
fn bundle_config_with_unknown_field() {
    let dir = tempfile::tempdir().unwrap();
    tiny_bundle(dir.path());
    let p = dir.path().join("config.toml");
    let text = std::fs::read_to_string(&p).unwrap() + "colour = \"blue\"\n";
    std::fs::write(&p, text).unwrap();
    assert_mentions(&load_error(dir.path()), &["config.toml", "colour"]);
}

#[test]
fn bundle_truncated_weights() {
    let dir = tempfile::tempdir().unwrap();
    tiny_bundle(dir.path());
    let p = dir.path().join("model.safetensors");
    let bytes = std::fs::read(&p).unwrap();
    std::fs::write(&p, &bytes[..bytes.len() / 2]).unwrap();
    assert_mentions(&load_error(dir.path()), &["model.safetensors"]);
}

#[test]
fn bundle_empty_and_garbage_weights() {
    let dir = tempfile::tempdir().unwrap();
    tiny_bundle(dir.path());
    let p = dir.path().join("model.safetensors");
    std::fs::write(&p, b"").unwrap();
    assert_mentions(&load_error(dir.path()), &["model.safetensors"]);
    std::fs::write(&p, [0xffu8; 64]).unwrap();
    assert_mentions(&load_error(dir.path()), &["model.safetensors"]);
}

#[test]
fn bundle_weights_precision_mismatch() {
    let dir = tempfile::tempdir().unwrap();
    tiny_bundle(dir.path());
    let p = dir.path().join("manifest.json");
    let text = std::fs::read_to_string(&p)
        .unwrap()
        .replace("\"half_precision\": false", "\"half_precision\": true");
    std::fs::write(&p, text).unwrap();
    let d = dir.path().to_path_buf();
    // Either refused with the file named, or loaded (the adapter reads f32 as is).
    let result = no_panic("precision", move || {
        ModelBundle::load(&d, &Device::flex())
            .map(|_| ())
            .map_err(|e| e.to_string())
    });
    if let Err(m) = result {
        assert_mentions(&m, &["model.safetensors"]);
    }
}

#[test]
fn bundle_statistics_of_the_wrong_length() {
    let dir = tempfile::tempdir().unwrap();
    tiny_bundle(dir.path());
    mprog::dataset::store::write_f32_npy(&dir.path().join("mean.npy"), &[5], &[0.0; 5]).unwrap();
    assert_mentions(
        &load_error(dir.path()),
        &["mean.npy", "5 values", "263 features"],
    );
}

#[test]
fn bundle_missing_vocabulary() {
    let dir = tempfile::tempdir().unwrap();
    tiny_bundle(dir.path());
    std::fs::remove_file(dir.path().join("vocab.json")).unwrap();
    assert_mentions(&load_error(dir.path()), &["vocab.json", "cannot read"]);
}

// ---------------------------------------------------------------------------------------
// Motion files through `read_motion`
// ---------------------------------------------------------------------------------------

#[test]
fn read_motion_unknown_extension_and_missing_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("walk.fbx");
    std::fs::write(&p, b"Kaydara FBX Binary").unwrap();
    let m = read_motion(&p).map(|_| ()).unwrap_err().to_string();
    assert_mentions(&m, &["walk.fbx", "cannot read `.fbx` files"]);
    let m = read_motion(&dir.path().join("gone.npy"))
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert_mentions(&m, &["gone.npy", "cannot read"]);
}

#[test]
fn read_motion_npy_people_axis() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("two.npy");
    std::fs::write(&p, npy("<f4", &[2, 3, 22, 3], &f32_bytes(&[0.5; 396]))).unwrap();
    match read_motion(&p).unwrap() {
        LoadedMotion::Joints { people, .. } => assert_eq!(people.len(), 2),
        other => panic!("{other:?}"),
    }
}

// ---------------------------------------------------------------------------------------
// The command line: errors name the file, nothing is written
// ---------------------------------------------------------------------------------------

fn copy_fixture(dir: &Path, name: &str) {
    std::fs::copy(fixture(name), dir.join(name)).unwrap();
}

#[test]
fn cli_convert_missing_input() {
    let dir = tempfile::tempdir().unwrap();
    let out = mprog(dir.path(), &["convert", "nothing.bvh", "-o", "out.npy"]);
    assert_cli_error(&out, &["nothing.bvh"]);
    assert_no_outputs(dir.path(), &[]);
}

#[test]
fn cli_convert_empty_bvh() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("empty.bvh"), b"").unwrap();
    let out = mprog(
        dir.path(),
        &["convert", "empty.bvh", "-o", "out.npy", "out.json"],
    );
    assert_cli_error(&out, &["empty.bvh:1"]);
    assert_no_outputs(dir.path(), &["empty.bvh"]);
}

#[test]
fn cli_convert_nan_bvh() {
    let dir = tempfile::tempdir().unwrap();
    copy_fixture(dir.path(), "nan_value.bvh");
    let out = mprog(dir.path(), &["convert", "nan_value.bvh", "-o", "out.npy"]);
    assert_cli_error(&out, &["nan_value.bvh:136"]);
    assert_no_outputs(dir.path(), &["nan_value.bvh"]);
}

#[test]
fn cli_convert_int_npy() {
    let dir = tempfile::tempdir().unwrap();
    copy_fixture(dir.path(), "int32_joints.npy");
    let out = mprog(
        dir.path(),
        &["convert", "int32_joints.npy", "-o", "out.json"],
    );
    assert_cli_error(&out, &["int32_joints.npy", "<i4"]);
    assert_no_outputs(dir.path(), &["int32_joints.npy"]);
}

#[test]
fn cli_convert_binary_json() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("noise.json"),
        [0x89u8, b'P', b'N', b'G', 0, 0xff],
    )
    .unwrap();
    let out = mprog(dir.path(), &["convert", "noise.json", "-o", "out.npy"]);
    assert_cli_error(&out, &["noise.json"]);
    assert_no_outputs(dir.path(), &["noise.json"]);
}

#[test]
fn cli_convert_tiny_fps_json() {
    let dir = tempfile::tempdir().unwrap();
    copy_fixture(dir.path(), "tiny_fps.json");
    let out = mprog(dir.path(), &["convert", "tiny_fps.json", "-o", "out.npy"]);
    assert_cli_error(&out, &["tiny_fps.json", "too long"]);
    assert_no_outputs(dir.path(), &["tiny_fps.json"]);
}

#[test]
fn cli_convert_with_one_bad_output_writes_none() {
    // Finding: outputs were written one by one, so `-o a.npy b.xyz` left a.npy behind.
    let dir = tempfile::tempdir().unwrap();
    copy_fixture(dir.path(), "dataset-1_walk_normal_001.bvh");
    let out = mprog(
        dir.path(),
        &[
            "convert",
            "dataset-1_walk_normal_001.bvh",
            "-o",
            "a.npy",
            "b.xyz",
        ],
    );
    assert_cli_error(&out, &["b.xyz", "unknown extension"]);
    assert_no_outputs(dir.path(), &["dataset-1_walk_normal_001.bvh"]);
}

#[test]
fn cli_convert_two_degenerate_people_to_bvh_writes_none() {
    // Two people (one BVH each), every joint at one point: no facing direction, so BVH
    // export refuses, and the JSON asked for first must not be left behind either.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("two.npy"),
        npy("<f4", &[2, 3, 22, 3], &f32_bytes(&[0.5; 396])),
    )
    .unwrap();
    let out = mprog(dir.path(), &["convert", "two.npy", "-o", "a.json", "b.bvh"]);
    assert_cli_error(&out, &["b_p1.bvh", "facing", "nothing was written"]);
    assert_no_outputs(dir.path(), &["two.npy"]);
}

#[test]
fn cli_convert_overflowing_features_writes_nothing() {
    // Finite but absurd HumanML3D features recover to non-finite joints.
    let dir = tempfile::tempdir().unwrap();
    let feats = npy("<f4", &[3, 263], &f32_bytes(&[3e38; 3 * 263]));
    std::fs::write(dir.path().join("feats.npy"), feats).unwrap();
    let out = mprog(
        dir.path(),
        &["convert", "feats.npy", "-o", "out.json", "out.npy"],
    );
    assert_cli_error(&out, &["out.json", "non-finite"]);
    assert_no_outputs(dir.path(), &["feats.npy"]);
}

#[test]
fn cli_check_binary_and_missing_programs() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bin.mprog"), [0u8, 159, 146, 150]).unwrap();
    let out = mprog(dir.path(), &["check", "bin.mprog"]);
    assert_cli_error(&out, &["bin.mprog"]);
    let out = mprog(dir.path(), &["check", "gone.mprog"]);
    assert_cli_error(&out, &["gone.mprog"]);
    assert_no_outputs(dir.path(), &["bin.mprog"]);
}

#[test]
fn cli_check_nan_override() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("p.mprog"),
        "length 4s\nparam d = 40 cm\nalways { dist(l_hand, r_hand) == d }\n",
    )
    .unwrap();
    let out = mprog(dir.path(), &["check", "p.mprog", "--set", "d=NaN"]);
    assert_cli_error(&out, &["d"]);
}

#[test]
fn cli_gen_with_corrupt_bundles_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("model");
    tiny_bundle(&model);
    let p = model.join("manifest.json");
    let good = std::fs::read_to_string(&p).unwrap();
    std::fs::write(&p, good.replace("\"version\": 1", "\"version\": 9")).unwrap();
    let args = [
        "gen",
        "--model",
        "model",
        "--text",
        "a person walks",
        "--frames",
        "10",
        "-o",
        "o.npy",
    ];
    let out = mprog(dir.path(), &args);
    assert_cli_error(&out, &["manifest.json", "version 9"]);
    std::fs::write(&p, &good).unwrap();
    std::fs::write(model.join("model.safetensors"), b"garbage").unwrap();
    let out = mprog(dir.path(), &args);
    assert_cli_error(&out, &["model.safetensors"]);
    let inputs: Vec<String> = files_except(dir.path(), &[]);
    assert!(inputs.iter().all(|f| f.starts_with("model/")), "{inputs:?}");
}

#[test]
fn cli_gen_bad_lengths_and_sampler_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    tiny_bundle(&dir.path().join("model"));
    let base = [
        "gen",
        "--model",
        "model",
        "--text",
        "a person walks",
        "-o",
        "o.npy",
    ];
    for extra in [
        &["--frames", "0"][..],
        &["--frames", "100000"],
        &["--seconds", "NaN"],
        &["--seconds=-3"],
        &["--frames", "10", "--sampler", "euler"],
    ] {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        let out = mprog(dir.path(), &args);
        let stderr = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(!out.status.success(), "{extra:?} should fail:\n{stderr}");
        assert!(!stderr.contains("panicked"), "{extra:?}:\n{stderr}");
        assert!(
            stderr.contains("frames") || stderr.contains("sampler"),
            "{extra:?}: unclear message:\n{stderr}"
        );
        assert!(!dir.path().join("o.npy").exists());
    }
}

#[test]
fn cli_train_with_missing_data_leaves_no_run() {
    // Finding: the run's config.toml was written before the data was read, so a retry
    // said "already holds a training run".
    let dir = tempfile::tempdir().unwrap();
    let config = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models/train-default.toml");
    let out = mprog(
        dir.path(),
        &[
            "train",
            "--data",
            "nodata",
            "--config",
            config.to_str().unwrap(),
            "--out",
            "run",
        ],
    );
    assert_cli_error(&out, &["nodata"]);
    assert!(
        !dir.path().join("run").exists(),
        "a run folder was left behind"
    );
}

#[test]
fn cli_train_with_bad_config_leaves_no_run() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("train.toml"), "batch_size = \"many\"\n").unwrap();
    let out = mprog(
        dir.path(),
        &[
            "train",
            "--data",
            "nodata",
            "--config",
            "train.toml",
            "--out",
            "run",
        ],
    );
    assert_cli_error(&out, &["train.toml"]);
    assert!(!dir.path().join("run").exists());
}

#[test]
fn cli_data_build_from_an_empty_folder() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("raw")).unwrap();
    let out = mprog(
        dir.path(),
        &["data", "build", "--bvh", "raw", "--out", "set"],
    );
    assert_cli_error(&out, &["no .bvh files", "raw"]);
    assert!(!dir.path().join("set").exists());
}

#[test]
fn cli_data_build_from_only_bad_files() {
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("raw");
    std::fs::create_dir(&raw).unwrap();
    std::fs::write(raw.join("dataset-1_walk_normal_001.bvh"), b"HIERARCHY\n").unwrap();
    let out = mprog(
        dir.path(),
        &["data", "build", "--bvh", "raw", "--out", "set"],
    );
    assert_cli_error(&out, &["dataset-1_walk_normal_001.bvh"]);
    assert!(!dir.path().join("set").exists());
}

#[test]
fn dataset_with_corrupt_clip_offsets_is_refused() {
    // Finding: clip offsets were not checked against the arrays, so training sliced out
    // of bounds and panicked.
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("raw");
    std::fs::create_dir(&raw).unwrap();
    copy_fixture(&raw, "dataset-1_walk_normal_001.bvh");
    let out = mprog(
        dir.path(),
        &["data", "build", "--bvh", "raw", "--out", "set"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let index = dir.path().join("set/clips.json");
    let text = std::fs::read_to_string(&index).unwrap();
    let mut doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    doc["clips"][0]["offset"] = 1_000_000.into();
    std::fs::write(&index, doc.to_string()).unwrap();
    let set = dir.path().join("set");
    let m = no_panic("offsets", move || {
        mprog::dataset::Dataset::load(&set)
            .map(|_| ())
            .unwrap_err()
            .to_string()
    });
    assert_mentions(&m, &["clips.json", "offset"]);
}

/// `check` warns of every prompt `run` would (issue 53): one the model reads through its
/// nearest captions (best cosine 0.5–0.7), one far from every caption, and none for a
/// paraphrase of a caption it knows. Needs the shipped sentence-encoder model.
#[test]
fn check_warns_of_every_prompt_run_would() {
    let dir = tempfile::tempdir().unwrap();
    let program =
        |prompt: &str| format!("prompt \"{prompt}\"\nlength 4s\nalways {{ r_hand.y > 1 m }}\n");
    for (file, prompt) in [
        ("snapped.mprog", "a person claps above the head"),
        ("far.mprog", "a person plays the violin"),
        ("near.mprog", "someone strolls ahead"),
    ] {
        std::fs::write(dir.path().join(file), program(prompt)).unwrap();
    }
    let json = |file: &str| -> serde_json::Value {
        let out = mprog(dir.path(), &["check", file, "--format", "json"]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let far_prompts = |v: &serde_json::Value| -> Vec<String> {
        let items = v.as_array().map_or_else(|| vec![v.clone()], |a| a.clone());
        items
            .iter()
            .flat_map(|f| f["diagnostics"].as_array().cloned().unwrap_or_default())
            .filter(|d| d["code"] == "mprog::far_prompt")
            .map(|d| d["hint"].as_str().unwrap_or_default().to_string())
            .collect()
    };
    let snapped = far_prompts(&json("snapped.mprog"));
    assert_eq!(snapped.len(), 1, "{snapped:?}");
    assert!(
        snapped[0].contains("conditioned on the mean of its nearest captions"),
        "{snapped:?}"
    );
    let far = far_prompts(&json("far.mprog"));
    assert_eq!(far.len(), 1, "{far:?}");
    assert!(far[0].contains("nearest known:"), "{far:?}");
    assert!(far_prompts(&json("near.mprog")).is_empty());
}
