//! `mprog mcp`'s request handling over an in-memory stream, with raw JSON-RPC: the
//! handshake and tool list, malformed requests (each answered with a protocol error, or
//! ignored when not JSON at all, and the server keeps serving), and the path checks.

use mprog::mcp::{Config, HANDSHAKE, exchange, server};
use serde_json::{Value, json};
use std::time::Duration;

fn config(out: &std::path::Path) -> Config {
    Config {
        out_dir: out.to_path_buf(),
        // Runs are not made here: a run that gets past its checks fails to start.
        exe: "/nonexistent/mprog".into(),
        model: None,
        time_limit: Duration::from_secs(5),
        card: None,
        far_prompts: None,
        coverage: None,
    }
}

/// Sends the handshake and `requests` (one per line), then a `tools/list` with id "last";
/// returns the server's messages once the answers to "last" and to `ids` have come.
fn session(out: &std::path::Path, requests: &[String], ids: &[u64]) -> Vec<Value> {
    let mut input = HANDSHAKE.to_string();
    for r in requests {
        input.push_str(r);
        input.push('\n');
    }
    input.push_str(r#"{"jsonrpc":"2.0","id":"last","method":"tools/list"}"#);
    input.push('\n');
    let responses = exchange(
        server(&config(out)).unwrap(),
        input.into_bytes(),
        |got| {
            got.iter().any(|m| m["id"] == "last")
                && ids.iter().all(|id| got.iter().any(|m| m["id"] == *id))
        },
        Duration::from_secs(60),
    )
    .unwrap();
    assert!(
        responses
            .iter()
            .any(|m| m["id"] == "last" && m["result"]["tools"].is_array()),
        "the server stopped answering: {responses:#?}"
    );
    responses
}

fn call(id: u64, name: &str, arguments: Value) -> String {
    json!({"jsonrpc": "2.0", "id": id, "method": "tools/call",
           "params": {"name": name, "arguments": arguments}})
    .to_string()
}

fn by_id(responses: &[Value], id: u64) -> &Value {
    responses
        .iter()
        .find(|m| m["id"] == id)
        .unwrap_or_else(|| panic!("no response {id}: {responses:#?}"))
}

#[test]
fn tools_are_listed_and_check_answers() {
    let dir = tempfile::tempdir().unwrap();
    let r = session(
        dir.path(),
        &[call(
            1,
            "check",
            json!({"source": "length 4s\nalways { r_hnad.y > 1 m }\n"}),
        )],
        &[1],
    );
    let init = by_id(&r, 0);
    assert_eq!(init["result"]["serverInfo"]["name"], "mprog", "{init}");
    let last = r.iter().find(|m| m["id"] == "last").unwrap();
    let names: Vec<&str> = last["result"]["tools"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["check", "score", "run", "joints", "library"]);
    let check = &by_id(&r, 1)["result"];
    assert_eq!(check["isError"], false);
    assert_eq!(check["structuredContent"]["diagnostics"][0]["line"], 2);
}

#[test]
fn malformed_requests_get_protocol_errors_and_the_server_lives_on() {
    let dir = tempfile::tempdir().unwrap();
    let r = session(
        dir.path(),
        &[
            "this is not JSON".into(),
            "{\"unclosed\": ".into(),
            call(1, "nope", json!({})),
            call(2, "check", json!({"source": 3})),
            call(3, "check", json!({})),
            call(4, "run", json!({"source": "x", "seed": -1})),
            json!({"jsonrpc": "2.0", "id": 5, "method": "tools/call", "params": "x"}).to_string(),
            json!({"jsonrpc": "2.0", "id": 6, "method": "no/such/method"}).to_string(),
            call(7, "score", json!({"source": "x", "motion": ["a"]})),
        ],
        &[1, 2, 3, 4, 6, 7],
    );
    for id in (1..=7).filter(|&id| id != 5) {
        let m = by_id(&r, id);
        let code = m["error"]["code"].as_i64();
        assert!(code.is_some_and(|c| c < 0), "request {id}: {m}");
    }
    // JSON of the wrong shape cannot be matched to its id: an Invalid Request error
    // without one (the SDK's rule), and no answer at all to a line that is not JSON.
    let unmatched: Vec<&Value> = r.iter().filter(|m| m.get("id").is_none()).collect();
    assert_eq!(unmatched.len(), 1, "{unmatched:#?}");
    assert_eq!(unmatched[0]["error"]["code"], -32600);
    assert!(
        by_id(&r, 2)["error"]["message"]
            .as_str()
            .unwrap()
            .contains("`source` must be a string")
    );
}

#[test]
fn paths_out_of_the_output_folder_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(dir.path().join("secret.json"), "{}").unwrap();
    std::os::unix::fs::symlink(dir.path(), out.join("up")).unwrap();
    let src = "prompt \"a person waves\"\nlength 1s\nat end { r_hand.y > head.y }\n";
    let r = session(
        &out,
        &[
            call(1, "run", json!({"source": src, "output": "../x.json"})),
            call(
                2,
                "run",
                json!({"source": src, "output": ["ok.json", "/tmp/x.json"]}),
            ),
            call(3, "run", json!({"source": src, "output": "up/x.json"})),
            call(
                4,
                "score",
                json!({"source": src, "motion": "../secret.json"}),
            ),
            call(
                5,
                "score",
                json!({"source": src, "motion": "up/secret.json"}),
            ),
            call(6, "run", json!({"source": src, "output": "x.txt"})),
            call(
                7,
                "run",
                json!({"source": "length 1s\nalways { hed.y > 1 m }", "output": "x.json"}),
            ),
        ],
        &[1, 2, 3, 4, 5, 6, 7],
    );
    for id in 1..=5 {
        let res = &by_id(&r, id)["result"];
        assert_eq!(res["isError"], true, "{id}: {res}");
        let msg = res["structuredContent"]["error"].as_str().unwrap();
        assert!(msg.starts_with("refused path"), "{id}: {msg}");
    }
    let bad_kind = &by_id(&r, 6)["result"];
    assert_eq!(bad_kind["isError"], true);
    let diags = &by_id(&r, 7)["result"]["structuredContent"]["diagnostics"];
    assert_eq!(diags[0]["code"], "mprog::unknown_joint");
    assert!(!dir.path().join("x.json").exists() && !out.join("x.json").exists());
}

/// A stand-in for `mprog run`: logs `start`, sleeps 30 s when asked for seed 1 (at once
/// otherwise), logs `end` and writes an empty report.
fn fake_runner(dir: &std::path::Path) -> std::path::PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let exe = dir.join("fake-mprog");
    let log = dir.join("log");
    let script = format!(
        "#!/bin/sh\necho start >> {log}\nreport=\nslow=\n\
         while [ $# -gt 0 ]; do\n  [ \"$1\" = --report ] && report=\"$2\"\n  \
         [ \"$1\" = --seed ] && [ \"$2\" = 1 ] && slow=1\n  shift\ndone\n\
         [ -n \"$slow\" ] && sleep 30\necho end >> {log}\necho '{{\"outputs\": []}}' > \"$report\"\n",
        log = log.display()
    );
    std::fs::write(&exe, script).unwrap();
    std::fs::set_permissions(&exe, std::fs::Permissions::from_mode(0o755)).unwrap();
    exe
}

#[test]
fn a_cancelled_request_stops_its_run() {
    let dir = tempfile::tempdir().unwrap();
    let config = Config {
        exe: fake_runner(dir.path()),
        time_limit: Duration::from_secs(60),
        ..config(&dir.path().join("out"))
    };
    let src = "prompt \"a person waves\"\nlength 1s\nat end { r_hand.y > head.y }\n";
    let mut input = HANDSHAKE.to_string();
    for line in [
        call(
            1,
            "run",
            json!({"source": src, "seed": 1, "output": "slow.json"}),
        ),
        json!({"jsonrpc": "2.0", "method": "notifications/cancelled",
               "params": {"requestId": 1, "reason": "the user changed their mind"}})
        .to_string(),
        // Runs take turns: this one can only finish soon if the first one was stopped.
        call(
            2,
            "run",
            json!({"source": src, "seed": 2, "output": "fast.json"}),
        ),
    ] {
        input.push_str(&line);
        input.push('\n');
    }
    let started = std::time::Instant::now();
    let r = exchange(
        server(&config).unwrap(),
        input.into_bytes(),
        |got| got.iter().any(|m| m["id"] == 2),
        Duration::from_secs(60),
    )
    .unwrap();
    let second = &by_id(&r, 2)["result"];
    assert_eq!(second["isError"], false, "{second}");
    assert!(
        started.elapsed() < Duration::from_secs(20),
        "{:?}",
        started.elapsed()
    );
    // The first run started and never ended; the second ran to its end.
    let log = std::fs::read_to_string(dir.path().join("log")).unwrap_or_default();
    assert!(
        log == "start\nstart\nend\n" || log == "start\nend\n",
        "{log:?}"
    );
}
