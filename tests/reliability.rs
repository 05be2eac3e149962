//! Long commands under stress, through the built binary in temporary folders:
//! * `mprog gen` is bit-for-bit reproducible from seed, settings and weights;
//! * `mprog train` killed with SIGKILL at any moment leaves a checkpoint it resumes from;
//! * Ctrl-C (SIGINT) stops training with a checkpoint and generation with no output.

use burn::tensor::Device;
use mprog::model::prompt::PromptEncoder;
use mprog::model::text::Vocabulary;
use mprog::model::weights::{BUNDLE_VERSION, Manifest};
use mprog::model::{Mdm, ModelBundle, ModelConfig, TrainConfig};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// The binary under test: cargo's, or `$MPROG_TEST_BIN` (see `tests/adversarial.rs`).
fn bin() -> Command {
    let bin = std::env::var_os("MPROG_TEST_BIN")
        .map_or_else(|| env!("CARGO_BIN_EXE_mprog").into(), PathBuf::from);
    let mut c = Command::new(bin);
    c.env("NO_COLOR", "1").env_remove("MPROG_MODEL");
    c
}

fn run(dir: &Path, args: &[&str]) -> Output {
    bin().args(args).current_dir(dir).output().unwrap()
}

#[track_caller]
fn ok(out: &Output) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "command failed:\n{stderr}");
    stderr
}

fn model_config(d_model: usize, layers: usize) -> ModelConfig {
    ModelConfig {
        features: 263,
        d_model,
        layers,
        heads: 2,
        d_ff: 2 * d_model,
        dropout: 0.1,
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

/// Saves a random bundle (f16 weights, like shipped bundles) in `dir`.
fn bundle(dir: &Path, config: ModelConfig) {
    let vocab = Vocabulary::from_captions(["a person walks forward", "a person waves"], 8);
    let model = Mdm::new(&config, vocab.len(), &Device::flex());
    ModelBundle {
        config,
        text: PromptEncoder::Words(vocab),
        mean: (0..263).map(|i| 0.01 * i as f32).collect(),
        std: vec![0.5; 263],
        model,
        manifest: Manifest {
            version: BUNDLE_VERSION,
            weights_id: "tiny-test".into(),
            steps: 0,
            train_seconds: 0.0,
            half_precision: true,
            text_encoder_id: None,
            control_id: None,
            consistency: None,
        },
    }
    .save(dir)
    .unwrap();
}

fn gen_args<'a>(seed: &'a str, out: &'a str) -> Vec<&'a str> {
    let text = "a person walks forward";
    let a = [
        "gen", "--model", "model", "--text", text, "--frames", "24", "--seed", seed,
    ];
    let mut v = a.to_vec();
    v.extend(["--steps", "8", "--count", "2", "-o", out]);
    v
}

#[test]
fn gen_is_bit_identical_for_the_same_seed_and_differs_for_another() {
    let dir = tempfile::tempdir().unwrap();
    bundle(&dir.path().join("model"), model_config(16, 1));
    let d = dir.path();
    ok(&run(d, &gen_args("7", "a.npy")));
    ok(&run(d, &gen_args("7", "b.npy")));
    ok(&run(d, &gen_args("8", "c.npy")));
    for i in 0..2 {
        let read = |stem: &str| std::fs::read(d.join(format!("{stem}_{i}.npy"))).unwrap();
        let (a, b, c) = (read("a"), read("b"), read("c"));
        assert!(a.len() > 24 * 66 * 4, "sample {i}: {} bytes", a.len());
        assert_eq!(a, b, "sample {i}: same seed, different bytes");
        assert_ne!(a, c, "sample {i}: another seed gave the same motion");
    }
    // Different samples of one batch differ too.
    assert_ne!(
        std::fs::read(d.join("a_0.npy")).unwrap(),
        std::fs::read(d.join("a_1.npy")).unwrap()
    );
}

/// A training set built by `mprog data build` from copies of one small walking BVH.
fn dataset(dir: &Path) -> PathBuf {
    let raw = dir.join("raw");
    std::fs::create_dir_all(&raw).unwrap();
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/adversarial/dataset-1_walk_normal_001.bvh");
    for name in [
        "dataset-1_walk_normal_001",
        "dataset-1_walk_normal_002",
        "dataset-1_run_normal_003",
    ] {
        std::fs::copy(&src, raw.join(format!("{name}.bvh"))).unwrap();
    }
    ok(&run(
        dir,
        &["data", "build", "--bvh", "raw", "--out", "set"],
    ));
    dir.join("set")
}

/// A tiny training config that checkpoints after every step.
fn train_config(dir: &Path) -> PathBuf {
    let config = TrainConfig {
        model: model_config(16, 1),
        batch_size: 2,
        crop_frames: 16,
        warmup_steps: 1,
        checkpoint_every: 1,
        steps: 100_000,
        ..TrainConfig::default()
    };
    let p = dir.join("tiny.toml");
    std::fs::write(&p, toml::to_string(&config).unwrap()).unwrap();
    p
}

fn spawn(dir: &Path, args: &[&str]) -> Child {
    bin()
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// The step of the newest complete checkpoint (`ckpt/`, else `ckpt.old/`).
fn checkpoint_step(run: &Path) -> Option<usize> {
    ["ckpt", "ckpt.old"].iter().find_map(|d| {
        let text = std::fs::read_to_string(run.join(d).join("state.json")).ok()?;
        let v: serde_json::Value = serde_json::from_str(&text).ok()?;
        v["step"].as_u64().map(|s| s as usize)
    })
}

/// Waits until the run has a checkpoint of at least `step`.
fn wait_for_step(child: &mut Child, run: &Path, step: usize) -> usize {
    let start = Instant::now();
    loop {
        if let Some(s) = checkpoint_step(run).filter(|&s| s >= step) {
            return s;
        }
        if let Some(status) = child.try_wait().unwrap() {
            let mut err = String::new();
            std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut err).unwrap();
            panic!("training exited early ({status}):\n{err}");
        }
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no checkpoint {step}"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[test]
fn training_killed_with_sigkill_resumes_from_an_intact_checkpoint() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    dataset(d);
    let config = train_config(d);
    let config = config.to_str().unwrap();
    let start = ["train", "--data", "set", "--config", config, "--out", "run"];
    let resume = ["train", "--data", "set", "--out", "run", "--resume"];
    let run_dir = d.join("run");
    let mut last = 0;
    // Kill at several delays after a checkpoint appears: some kills land mid-step, some
    // mid-save (a checkpoint is written every step).
    for (round, delay_ms) in [0u64, 7, 23, 61].into_iter().enumerate() {
        let args: &[&str] = if round == 0 { &start } else { &resume };
        let mut child = spawn(d, args);
        let seen = wait_for_step(&mut child, &run_dir, last + 2);
        std::thread::sleep(Duration::from_millis(delay_ms));
        child.kill().unwrap(); // SIGKILL
        child.wait().unwrap();
        let step = checkpoint_step(&run_dir).expect("a complete checkpoint survives the kill");
        assert!(
            step >= seen,
            "round {round}: checkpoint went back from {seen} to {step}"
        );
        last = step;
    }
    let out = run(d, &[&resume[..], &["--steps", "2"]].concat());
    let stderr = ok(&out);
    assert_eq!(checkpoint_step(&run_dir), Some(last + 2), "{stderr}");
    assert!(
        stderr.contains(&format!("stopped at step {}", last + 2)),
        "{stderr}"
    );
    // The exported bundle of the resumed run loads.
    ModelBundle::load(&run_dir.join("bundle"), &Device::flex()).unwrap();
}

fn sigint(child: &Child) {
    let pid = libc::pid_t::try_from(child.id()).unwrap();
    // SAFETY: kill(2) on the pid of a child we spawned and have not reaped yet.
    let rc = unsafe { libc::kill(pid, libc::SIGINT) };
    assert_eq!(rc, 0, "kill -INT {pid} failed");
}

#[test]
fn training_stops_cleanly_on_ctrl_c_with_a_checkpoint() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    dataset(d);
    // Checkpoints only every 1000 steps: the one after Ctrl-C is the interrupt's own.
    let text = std::fs::read_to_string(train_config(d))
        .unwrap()
        .replace("checkpoint_every = 1\n", "checkpoint_every = 1000\n");
    std::fs::write(d.join("rare.toml"), text).unwrap();
    let mut child = spawn(
        d,
        &[
            "train",
            "--data",
            "set",
            "--config",
            "rare.toml",
            "--out",
            "run",
        ],
    );
    // Without a terminal, training logs `step N …` every 25 steps: Ctrl-C after the first.
    let mut lines = std::io::BufRead::lines(std::io::BufReader::new(child.stderr.take().unwrap()));
    let mut stderr = String::new();
    for line in lines.by_ref() {
        let line = line.unwrap();
        stderr += &line;
        stderr += "\n";
        if line.starts_with("step ") {
            break;
        }
    }
    sigint(&child);
    for line in lines {
        stderr += &line.unwrap();
        stderr += "\n";
    }
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "{stderr}");
    let step = checkpoint_step(&d.join("run")).expect("checkpoint saved on Ctrl-C");
    assert!(step >= 25, "{stderr}");
    assert!(
        stderr.contains(&format!("interrupted at step {step}")),
        "{stderr}"
    );
    let leftovers: Vec<_> = std::fs::read_dir(d.join("run"))
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| n.ends_with(".tmp") || n == "ckpt.new")
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    let out = run(
        d,
        &[
            "train", "--data", "set", "--out", "run", "--resume", "--steps", "1",
        ],
    );
    ok(&out);
    assert_eq!(checkpoint_step(&d.join("run")), Some(step + 1));
}

#[test]
fn generation_stops_on_ctrl_c_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    bundle(
        &d.join("model"),
        ModelConfig {
            max_frames: 196,
            input_skip: false,
            ..model_config(64, 2)
        },
    );
    // DDPM's 1000 steps on 8 motions of 196 frames take many seconds with this model.
    let args = [
        "gen",
        "--model",
        "model",
        "--text",
        "a person waves",
        "--frames",
        "196",
        "--count",
        "8",
        "--sampler",
        "ddpm",
        "-o",
        "out.npy",
        "out.json",
    ];
    let started = Instant::now();
    let child = spawn(d, &args);
    std::thread::sleep(Duration::from_millis(1500));
    sigint(&child);
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        out.status.code(),
        Some(130),
        "after {:?}:\n{stderr}",
        started.elapsed()
    );
    assert!(stderr.contains("interrupted after"), "{stderr}");
    let files: Vec<_> = std::fs::read_dir(d)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| n != "model")
        .collect();
    assert!(files.is_empty(), "outputs after Ctrl-C: {files:?}");
}
