//! Fuzzing findings as regression tests: every file under `tests/fixtures/fuzz/<target>/`
//! goes through the code path of the fuzz target of that name (`fuzz/fuzz_targets/`) and
//! must be answered without a panic, a hang or an absurd allocation; the ignored test
//! replays a whole local corpus (`fuzz/corpus/`, after `fuzz/run.sh`) the same way.

use burn::tensor::{Device, Tensor, TensorData};
use mprog::formats::BvhImportOptions;
use mprog::formats::bvh::{ParseLimits, import_bvh_bytes};
use mprog::formats::json::read_json_str;
use mprog::formats::npy::{MotionFile, classify, read_npy_bytes};
use mprog::lang::{check_source, compile};
use mprog::skeleton::{FPS, NUM_JOINTS, rest_pose};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// `fuzz_targets/mprog_check.rs`: check, compile, evaluate on a tiny motion.
fn mprog_check(data: &[u8]) {
    let Ok(source) = std::str::from_utf8(data) else {
        return;
    };
    let _ = check_source(source, "fuzz.mprog", &[("x".into(), 2.0)]).render_plain();
    let Ok(program) = compile(source, "fuzz.mprog", &[]) else {
        return;
    };
    let people = program.people().len();
    let frames = program.length().clamp(1, 6);
    if program.ir().cost_estimate_at(frames).elements_per_sample > 200_000 {
        return;
    }
    let rest = rest_pose();
    let data: Vec<f32> = (0..people * frames)
        .flat_map(|_| rest.iter().flat_map(|v| [v.x, v.y, v.z]))
        .collect();
    let x = Tensor::<5>::from_data(
        TensorData::new(data, [1, people, frames, NUM_JOINTS, 3]),
        &Device::flex(),
    );
    let e = program
        .try_evaluate(x)
        .expect("a compiled program evaluates");
    assert_eq!(e.total.dims(), [1]);
}

/// `fuzz_targets/bvh.rs`.
fn bvh(data: &[u8]) {
    let opts = BvhImportOptions {
        limits: ParseLimits {
            max_values: 200_000,
        },
        ..BvhImportOptions::default()
    };
    if let Ok(out) = import_bvh_bytes("fuzz.bvh", data, &opts) {
        assert!(out.motion.is_finite() && !out.motion.is_empty());
    }
}

/// `fuzz_targets/npy.rs`.
fn npy(data: &[u8]) {
    let Ok(array) = read_npy_bytes("fuzz.npy", data) else {
        return;
    };
    assert_eq!(array.shape.iter().product::<usize>(), array.data.len());
    if let Ok(MotionFile::Joints(people)) = classify("fuzz.npy", array) {
        assert!(people.iter().all(|m| m.is_finite() && !m.is_empty()));
    }
}

/// `fuzz_targets/json.rs`.
fn json(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok((people, _)) = read_json_str("fuzz.json", text) {
        for p in people {
            let m = p.motion.resample(FPS);
            assert!(m.is_finite() && !m.is_empty());
        }
    }
}

/// `fuzz_targets/mcp.rs`: JSON-RPC lines to the MCP server after its handshake.
fn mcp(data: &[u8]) {
    if let Err(e) = mprog::mcp::fuzz_one(data) {
        panic!("{e}");
    }
}

/// A fuzz target's body.
type Target = fn(&[u8]);

const TARGETS: [(&str, Target); 5] = [
    ("mprog_check", mprog_check),
    ("bvh", bvh),
    ("npy", npy),
    ("json", json),
    ("mcp", mcp),
];

fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| {
            d.flatten()
                .map(|e| e.path())
                .filter(|p| p.is_file())
                .collect()
        })
        .unwrap_or_default();
    out.sort();
    out
}

/// Runs every file of `root/<target>/` through its target on a 2 MiB-stack thread;
/// returns how many ran.
fn replay(root: &Path, per_input: Duration) -> usize {
    let mut count = 0;
    for (target, f) in TARGETS {
        for path in files(&root.join(target)) {
            // A running fuzzer may delete corpus files it has reduced.
            let Ok(data) = std::fs::read(&path) else {
                continue;
            };
            let started = Instant::now();
            let result = std::thread::Builder::new()
                .stack_size(2 << 20)
                .spawn(move || f(&data))
                .unwrap()
                .join();
            assert!(result.is_ok(), "{target}: {} panicked", path.display());
            assert!(
                started.elapsed() < per_input,
                "{target}: {} took {:?}",
                path.display(),
                started.elapsed()
            );
            count += 1;
        }
    }
    count
}

#[test]
fn fuzzing_findings_stay_fixed() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/fuzz");
    let n = replay(&root, Duration::from_secs(5));
    assert!(n >= 1, "no findings under {}", root.display());
}

#[test]
#[ignore = "replays the local fuzz corpus (fuzz/corpus/, made by fuzz/run.sh)"]
fn fuzz_corpus_replays_cleanly() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus");
    let n = replay(&root, Duration::from_secs(20));
    eprintln!("replayed {n} corpus inputs");
}
