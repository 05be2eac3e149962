//! `mprog repl` driven as a person would, through a pseudo-terminal: tmux runs the binary,
//! `send-keys` types, `capture-pane` reads the screen. Skips (with a message) when tmux is
//! not installed (`apt-get install -y tmux`).

use glam::Vec3;
use mprog::motion::Motion;
use mprog::skeleton::rest_pose;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

struct Tmux {
    socket: String,
}

impl Tmux {
    fn run(&self, args: &[&str]) -> String {
        let out = Command::new("tmux")
            .arg("-L")
            .arg(&self.socket)
            .args(args)
            .output()
            .expect("tmux runs");
        String::from_utf8_lossy(&out.stdout).to_string()
    }

    fn keys(&self, keys: &[&str]) {
        let mut args = vec!["send-keys", "-t", "repl"];
        args.extend_from_slice(keys);
        self.run(&args);
    }

    /// Types a line literally and presses Enter.
    fn line(&self, text: &str) {
        self.run(&["send-keys", "-t", "repl", "-l", text]);
        self.keys(&["Enter"]);
    }

    fn screen(&self) -> String {
        self.run(&["capture-pane", "-p", "-t", "repl", "-S", "-200"])
    }

    /// Waits until the screen contains `what` (panics with the screen after 60 s).
    fn wait_for(&self, what: &str) -> String {
        let start = Instant::now();
        loop {
            let s = self.screen();
            if s.contains(what) {
                return s;
            }
            if start.elapsed() > Duration::from_secs(60) {
                panic!("waited 60 s for {what:?}; screen:\n{s}");
            }
            std::thread::sleep(Duration::from_millis(100));
        }
    }
}

impl Drop for Tmux {
    fn drop(&mut self) {
        let _ = Command::new("tmux")
            .args(["-L", &self.socket, "kill-server"])
            .output();
    }
}

fn write_walk(path: &Path) {
    let rest = rest_pose();
    let m = Motion::new(
        (0..40)
            .map(|t| std::array::from_fn(|j| rest[j] + Vec3::new(0.0, 0.0, 0.05 * t as f32)))
            .collect(),
    );
    mprog::formats::write_motion(path, &[m], &mprog::formats::Meta::new()).unwrap();
}

#[test]
fn a_person_uses_the_repl_in_a_terminal() {
    if Command::new("tmux").arg("-V").output().is_err() {
        eprintln!("skipping: tmux is not installed (apt-get install -y tmux)");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    write_walk(&dir.path().join("walk.npy"));
    let state = dir.path().join("state");
    let tmux = Tmux {
        socket: format!("mprog-repl-test-{}", std::process::id()),
    };
    let cmd = format!(
        "cd {} && XDG_STATE_HOME={} {} repl --motion walk.npy",
        dir.path().display(),
        state.display(),
        env!("CARGO_BIN_EXE_mprog")
    );
    tmux.run(&[
        "new-session",
        "-d",
        "-s",
        "repl",
        "-x",
        "160",
        "-y",
        "60",
        &cmd,
    ]);
    tmux.wait_for("mprog>");
    tmux.wait_for("40 frames");

    // A statement over several lines: Enter inside an open brace continues the input.
    tmux.line("length 2s");
    tmux.line("always {");
    tmux.line("head.y > 1.8 m");
    tmux.line("}");
    tmux.wait_for("line 3: head.y > 1.8 m");
    tmux.line(":show");
    tmux.wait_for("  4 │ }");

    // A trailing operator continues the line too.
    tmux.line(":eval pelvis.z >");
    tmux.line("1 m");
    tmux.wait_for("zero at 20");

    // Tab completes joint names.
    tmux.run(&["send-keys", "-t", "repl", "-l", ":eval dist(l_ha"]);
    tmux.keys(&["Tab"]);
    tmux.wait_for(":eval dist(l_hand");
    tmux.line(", r_hand)");
    tmux.wait_for("min ");

    // Mistakes come back as miette diagnostics with a hint.
    tmux.line("r_hnad.y > 1");
    tmux.wait_for("did you mean `r_hand`?");

    tmux.line(":grad l_hand.y > 3 m");
    tmux.wait_for("left_wrist");
    tmux.line(":score");
    tmux.wait_for("total ");
    tmux.line(":render walk.png");
    tmux.wait_for("wrote walk.png");
    tmux.line(":quit");
    let start = Instant::now();
    while !state.join("mprog/history").exists() || tmux.run(&["list-sessions"]).contains("repl") {
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "the REPL did not quit:\n{}",
            tmux.screen()
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    let history = std::fs::read_to_string(state.join("mprog/history")).unwrap();
    assert!(
        history.contains(":grad l_hand.y > 3 m") && history.contains("always {"),
        "{history}"
    );
    assert!(dir.path().join("walk.png").exists());
}
