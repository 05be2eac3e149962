//! The `run` tool: generation steered by a program, in a child `mprog run` process. A
//! child can be stopped at any point (a cancelled request or the time limit kill it; its
//! outputs are written atomically, so no half-written file is left under an output's
//! name, at most a `.mprog-*.tmp` beside it), and the server stays small and responsive
//! while it works. Runs take the one lock: others queue.

use super::args::RunArgs;
use super::calls::SOURCE_NAME;
use super::paths::OutDir;
use base64::Engine;
use serde_json::{Value, json};
use std::future::Future;
use std::path::PathBuf;
use std::process::Stdio;
use std::time::{Duration, Instant};
use tokio::io::AsyncReadExt;

/// Most bytes of the child's output kept (its error messages are at the end).
const MAX_LOG: u64 = 1 << 20;

/// How runs are made.
#[derive(Debug)]
pub struct Runner {
    /// The `mprog` binary that does the work.
    pub exe: PathBuf,
    /// Model bundle folder (None: the binary's default).
    pub model: Option<PathBuf>,
    /// Longest a run may take, waiting in the queue excluded.
    pub time_limit: Duration,
    /// One run at a time.
    lock: tokio::sync::Mutex<()>,
}

/// A finished run: the report (JSON) and the PNG strip.
pub struct Done {
    pub report: Value,
    pub png: Option<String>,
}

impl Runner {
    /// A runner of `exe`.
    pub fn new(exe: PathBuf, model: Option<PathBuf>, time_limit: Duration) -> Runner {
        Runner {
            exe,
            model,
            time_limit,
            lock: tokio::sync::Mutex::new(()),
        }
    }

    /// Runs `args`, writing its outputs under `out`; stops when `cancelled` completes.
    /// Err is a message for the caller: a refused path, a program with errors (as the
    /// diagnostics' JSON), a failed, timed-out or cancelled run.
    pub async fn run(
        &self,
        out: &OutDir,
        args: RunArgs,
        cancelled: impl Future<Output = ()>,
    ) -> Result<Done, Value> {
        let fail = |m: String| json!({ "error": m });
        let outputs: Vec<PathBuf> = args
            .outputs
            .iter()
            .map(|o| out.for_writing(o))
            .collect::<Result<_, _>>()
            .map_err(fail)?;
        crate::formats::check_outputs(&outputs).map_err(|e| fail(e.to_string()))?;
        // The rig and its map are files the caller put in the output folder; read there only.
        let rig = args
            .rig
            .as_deref()
            .map(|r| out.for_reading(r))
            .transpose()
            .map_err(fail)?;
        let rig_map = args
            .rig_map
            .as_deref()
            .map(|r| out.for_reading(r))
            .transpose()
            .map_err(fail)?;
        if let Some(r) = &rig {
            crate::formats::Character::load(r, rig_map.as_deref())
                .map_err(|e| fail(e.to_string()))?;
        }
        if let Err(d) = crate::lang::compile(&args.source, SOURCE_NAME, &args.set) {
            return Err(
                json!({"error": "the program has errors", "file": SOURCE_NAME,
                              "ok": false, "diagnostics": d.to_json()}),
            );
        }
        tokio::pin!(cancelled);
        let _turn = tokio::select! {
            g = self.lock.lock() => g,
            () = &mut cancelled => return Err(fail("cancelled while waiting for another run".into())),
        };
        let tmp = tempfile::tempdir().map_err(|e| fail(format!("temporary folder: {e}")))?;
        let program = tmp.path().join(SOURCE_NAME);
        let report = tmp.path().join("report.json");
        std::fs::write(&program, &args.source).map_err(|e| fail(e.to_string()))?;
        let png = outputs
            .iter()
            .find(|p| p.extension().is_some_and(|e| e == "png"))
            .cloned()
            .unwrap_or_else(|| tmp.path().join("strip.png"));
        let mut cmd = tokio::process::Command::new(&self.exe);
        cmd.arg("run")
            .arg(&program)
            .args(["--solver", &args.solver, "--seed", &args.seed.to_string()])
            .arg("--report")
            .arg(&report);
        for (k, v) in &args.knobs {
            cmd.arg("--knob").arg(format!("{k}={v}"));
        }
        for (k, v) in &args.set {
            cmd.arg("--set").arg(format!("{k}={v}"));
        }
        if !args.baseline {
            cmd.arg("--no-baseline");
        }
        if let Some(m) = &self.model {
            cmd.arg("--model").arg(m);
        }
        if let Some(r) = &rig {
            cmd.arg("--rig").arg(r);
        }
        if let Some(m) = &rig_map {
            cmd.arg("--rig-map").arg(m);
        }
        cmd.arg("-o").args(&outputs);
        if !outputs.contains(&png) {
            cmd.arg(&png);
        }
        let start = Instant::now();
        let mut child = cmd
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .kill_on_drop(true)
            .spawn()
            .map_err(|e| fail(format!("cannot start {}: {e}", self.exe.display())))?;
        let mut stderr = child.stderr.take().expect("piped").take(MAX_LOG);
        let log = tokio::spawn(async move {
            let mut buf = Vec::new();
            let _ = stderr.read_to_end(&mut buf).await;
            String::from_utf8_lossy(&buf).into_owned()
        });
        let status = tokio::select! {
            s = child.wait() => s.map_err(|e| fail(e.to_string()))?,
            () = tokio::time::sleep(self.time_limit) => {
                let _ = child.kill().await;
                return Err(fail(format!(
                    "the run took longer than the server's limit of {} s and was stopped; \
                     use faster settings (e.g. knobs {{\"steps\": 10}}) or a shorter length",
                    self.time_limit.as_secs()
                )));
            }
            () = &mut cancelled => {
                let _ = child.kill().await;
                return Err(fail("cancelled: the run was stopped".into()));
            }
        };
        let log = log.await.unwrap_or_default();
        if !status.success() {
            let tail: String = log
                .chars()
                .rev()
                .take(4000)
                .collect::<Vec<_>>()
                .into_iter()
                .rev()
                .collect();
            return Err(fail(format!("the run failed ({status}):\n{tail}")));
        }
        let mut report: Value = std::fs::read(&report)
            .ok()
            .and_then(|b| serde_json::from_slice(&b).ok())
            .ok_or_else(|| fail("the run wrote no report".into()))?;
        report["files"] = json!(relative_files(out, &report));
        if let Some(o) = report.as_object_mut() {
            o.remove("outputs");
        }
        report["wall_seconds"] = json!(start.elapsed().as_secs_f64());
        let png = std::fs::read(&png)
            .ok()
            .map(|b| base64::engine::general_purpose::STANDARD.encode(b));
        Ok(Done { report, png })
    }
}

/// The report's files (absolute paths) relative to the output folder; the PNG strip of
/// a temporary folder is left out.
fn relative_files(out: &OutDir, report: &Value) -> Vec<String> {
    report["outputs"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|p| p.as_str())
        .filter_map(|p| std::path::Path::new(p).strip_prefix(out.root()).ok())
        .map(|p| p.display().to_string())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::PermissionsExt;

    /// A stand-in for `mprog run`: logs its start and end to `log`, sleeps `seconds`, and
    /// writes an empty report.
    fn fake_runner(dir: &std::path::Path, seconds: f64) -> PathBuf {
        let exe = dir.join("fake-mprog");
        let log = dir.join("log");
        std::fs::write(
            &exe,
            format!(
                "#!/bin/sh\necho start >> {log}\nsleep {seconds}\necho end >> {log}\n\
                 while [ $# -gt 0 ]; do if [ \"$1\" = --report ]; then echo '{{\"outputs\": [], \"plausibility\": {{\"ok\": false, \"problems\": []}}}}' > \"$2\"; fi; shift; done\n",
                log = log.display()
            ),
        )
        .unwrap();
        std::fs::set_permissions(&exe, std::fs::Permissions::from_mode(0o755)).unwrap();
        exe
    }

    fn args() -> RunArgs {
        RunArgs {
            source: "prompt \"x\"\nlength 1s\nat end { head.y > 1 m }\n".into(),
            solver: "guide".into(),
            seed: 1,
            knobs: vec![],
            set: vec![],
            outputs: vec!["a.json".into()],
            baseline: false,
            rig: None,
            rig_map: None,
        }
    }

    /// The fake runner with its arguments logged one per line.
    fn echoing_runner(dir: &std::path::Path) -> PathBuf {
        let exe = dir.join("echo-mprog");
        let log = dir.join("args");
        std::fs::write(
            &exe,
            format!(
                "#!/bin/sh
for a in \"$@\"; do echo \"$a\" >> {log}; done
                 while [ $# -gt 0 ]; do if [ \"$1\" = --report ]; then echo '{{\"outputs\": []}}' > \"$2\"; fi; shift; done
",
                log = log.display()
            ),
        )
        .unwrap();
        std::fs::set_permissions(&exe, std::fs::Permissions::from_mode(0o755)).unwrap();
        exe
    }

    #[test]
    fn a_rig_is_read_inside_the_output_folder_and_checked_before_the_run() {
        let dir = tempfile::tempdir().unwrap();
        let out = OutDir::new(&dir.path().join("out")).unwrap();
        let runner = Runner::new(echoing_runner(dir.path()), None, Duration::from_secs(30));
        let never = std::future::pending::<()>;
        let with = |rig: &str| RunArgs {
            rig: Some(rig.into()),
            ..args()
        };
        let e = block_on(runner.run(&out, with("../hero.bvh"), never()))
            .err()
            .unwrap();
        assert!(
            e["error"].as_str().unwrap().starts_with("refused path"),
            "{e}"
        );
        let rig = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/fixtures/rigs/mixamo_tall.bvh"
        );
        std::fs::copy(rig, out.root().join("hero.bvh")).unwrap();
        std::fs::write(out.root().join("bad.bvh"), "HIERARCHY\nROOT Hips\n{\n").unwrap();
        let e = block_on(runner.run(&out, with("bad.bvh"), never()))
            .err()
            .unwrap();
        assert!(e["error"].as_str().unwrap().contains("bad.bvh"), "{e}");
        assert!(!dir.path().join("args").exists(), "a bad rig was run");
        block_on(runner.run(&out, with("hero.bvh"), never())).unwrap();
        let logged = std::fs::read_to_string(dir.path().join("args")).unwrap();
        let logged: Vec<&str> = logged.lines().collect();
        let at = logged.iter().position(|a| *a == "--rig").unwrap();
        assert_eq!(
            std::path::Path::new(logged[at + 1]),
            out.root().join("hero.bvh")
        );
    }

    fn block_on<F: Future>(f: F) -> F::Output {
        tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .unwrap()
            .block_on(f)
    }

    #[test]
    fn runs_take_turns() {
        let dir = tempfile::tempdir().unwrap();
        let out = OutDir::new(&dir.path().join("out")).unwrap();
        let runner = Runner::new(fake_runner(dir.path(), 0.3), None, Duration::from_secs(30));
        let never = std::future::pending::<()>;
        let (a, b) = block_on(async {
            tokio::join!(
                runner.run(&out, args(), never()),
                runner.run(&out, args(), never())
            )
        });
        assert!(a.is_ok() && b.is_ok());
        // The run's plausibility report reaches the tool's result as it is.
        assert_eq!(a.ok().unwrap().report["plausibility"]["ok"], false);
        let log = std::fs::read_to_string(dir.path().join("log")).unwrap();
        assert_eq!(log, "start\nend\nstart\nend\n", "runs overlapped");
    }

    #[test]
    fn the_time_limit_and_cancellation_stop_a_run() {
        let dir = tempfile::tempdir().unwrap();
        let out = OutDir::new(&dir.path().join("out")).unwrap();
        let runner = Runner::new(
            fake_runner(dir.path(), 30.0),
            None,
            Duration::from_millis(300),
        );
        let started = Instant::now();
        let e = block_on(runner.run(&out, args(), std::future::pending()))
            .err()
            .unwrap();
        assert!(
            e["error"]
                .as_str()
                .unwrap()
                .contains("longer than the server's limit"),
            "{e}"
        );
        assert!(started.elapsed() < Duration::from_secs(10));
        let runner = Runner::new(runner.exe.clone(), None, Duration::from_secs(60));
        let started = Instant::now();
        let e = block_on(async {
            let cancel = tokio::time::sleep(Duration::from_millis(300));
            runner.run(&out, args(), cancel).await
        })
        .err()
        .unwrap();
        assert!(e["error"].as_str().unwrap().starts_with("cancelled"), "{e}");
        assert!(started.elapsed() < Duration::from_secs(10));
        // Both children were killed before they logged their end.
        let log = std::fs::read_to_string(dir.path().join("log")).unwrap();
        assert_eq!(log, "start\nstart\n");
    }
}
