//! The MCP client test: the official Python MCP SDK drives `mprog mcp` over stdio
//! (`tests/mcp/client.py`): it lists the tools, gets a located diagnostic for a broken
//! program, runs a small program to files and a PNG with fast settings (the shipped
//! model), and is refused a path escape. `.ci/run` installs the SDK into a virtual
//! environment and points `MPROG_MCP_PYTHON` at it; without it the test skips with a
//! message.

use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

#[test]
fn python_sdk_lists_checks_runs_and_is_refused_an_escape() {
    let python = std::env::var("MPROG_MCP_PYTHON").unwrap_or_else(|_| "python3".into());
    let has_sdk = Command::new(&python)
        .args(["-c", "import mcp"])
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !has_sdk {
        eprintln!(
            "skipped: `{python}` has no `mcp` package (the official Python MCP SDK); .ci/run \
             installs it, or point MPROG_MCP_PYTHON at a Python that has it"
        );
        return;
    }
    let bin = std::env::var_os("MPROG_TEST_BIN")
        .map_or_else(|| env!("CARGO_BIN_EXE_mprog").into(), PathBuf::from);
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let log = dir.path().join("client.log");
    let mut child = Command::new(&python)
        .arg(root.join("tests/mcp/client.py"))
        .arg(&bin)
        .arg(&out)
        .current_dir(&root)
        .env("NO_COLOR", "1")
        .env_remove("MPROG_DEVICE")
        .stdout(std::fs::File::create(&log).unwrap())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if started.elapsed() > Duration::from_secs(900) {
            let _ = child.kill();
            panic!("the MCP client did not finish in 15 minutes");
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    let mut stderr = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut stderr).unwrap();
    let stdout = std::fs::read_to_string(&log).unwrap_or_default();
    println!("{stdout}");
    assert!(
        status.success(),
        "client failed ({status}):\n{stdout}\n{stderr}"
    );
    assert!(
        stdout.contains("mcp client: 6 passed, 0 failed"),
        "{stdout}"
    );
    println!(
        "the client session took {:.1} s",
        started.elapsed().as_secs_f64()
    );
}
