//! `mprog mcp`: a Model Context Protocol server over stdio, so an agent can write, check,
//! run, look at the result and repair with no glue code. Built on `rmcp`, the official
//! Rust SDK.
//!
//! | file | what |
//! | --- | --- |
//! | `server.rs` | the request handler: tools, the prompt card as prompt and resource |
//! | `tools.rs` | the tools' names, descriptions and input schemas |
//! | `args.rs` | tool arguments from JSON, with limits |
//! | `calls.rs` | `check`, `score`, `joints`, `library` |
//! | `run.rs` | `run`: a child `mprog run`, one at a time, time limit, cancellation |
//! | `paths.rs` | the output folder: relative paths only, no `..`, no links |
//!
//! Requests are untrusted like programs are: programs keep the language's limits, files
//! are read and written only under the output folder, and a malformed request gets a
//! protocol error, never a crash.

pub mod args;
pub mod calls;
pub mod paths;
pub mod run;
pub mod server;
pub mod tools;

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

/// How the server is set up.
#[derive(Clone)]
pub struct Config {
    /// Where runs write and `score` reads.
    pub out_dir: PathBuf,
    /// The `mprog` binary that makes runs (normally this one).
    pub exe: PathBuf,
    /// Model bundle folder for runs (None: the binary's default).
    pub model: Option<PathBuf>,
    /// Longest a run may take.
    pub time_limit: Duration,
    /// The prompt card served as the MCP prompt and resource (None: the card without the
    /// model's action list); the CLI passes the one for the model runs use.
    pub card: Option<String>,
    /// What the model says of a prompt, for `check`'s `mprog::far_prompt` warnings (a
    /// sentence-encoder model's; the CLI passes it).
    pub far_prompts: Option<Arc<crate::lang::PromptReport>>,
    /// The poses the model was trained on, for `check`'s `mprog::unseen_pose` warnings
    /// (the CLI passes the bundle's; `run` results carry the run's own).
    pub coverage: Option<Arc<crate::coverage::Coverage>>,
}

impl std::fmt::Debug for Config {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Config")
            .field("out_dir", &self.out_dir)
            .field("exe", &self.exe)
            .field("model", &self.model)
            .field("time_limit", &self.time_limit)
            .field("card", &self.card.as_ref().map(String::len))
            .field("far_prompts", &self.far_prompts.is_some())
            .field("coverage", &self.coverage.is_some())
            .finish()
    }
}

/// The handler for `config`.
pub fn server(config: &Config) -> std::io::Result<server::Server> {
    Ok(server::Server {
        out: paths::OutDir::new(&config.out_dir)?,
        runner: std::sync::Arc::new(run::Runner::new(
            config.exe.clone(),
            config.model.clone(),
            config.time_limit,
        )),
        card: std::sync::Arc::new(
            config
                .card
                .clone()
                .unwrap_or_else(crate::docgen::prompt::system_prompt),
        ),
        far_prompts: config.far_prompts.clone(),
        coverage: config.coverage.clone(),
    })
}

/// Serves requests on `reader`/`writer` until the client closes the stream.
pub async fn serve<R, W>(server: server::Server, reader: R, writer: W) -> Result<(), String>
where
    R: tokio::io::AsyncRead + Send + Unpin + 'static,
    W: tokio::io::AsyncWrite + Send + Unpin + 'static,
{
    use rmcp::ServiceExt;
    let running = server
        .serve((reader, writer))
        .await
        .map_err(|e| format!("MCP handshake failed: {e}"))?;
    running
        .waiting()
        .await
        .map_err(|e| format!("MCP server stopped: {e}"))?;
    Ok(())
}

/// Serves on standard input and output (a single-threaded runtime; runs are child
/// processes, `score` runs on a blocking thread).
pub fn serve_stdio(config: &Config) -> Result<(), String> {
    let server = server(config).map_err(|e| format!("{}: {e}", config.out_dir.display()))?;
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| e.to_string())?;
    rt.block_on(serve(server, tokio::io::stdin(), tokio::io::stdout()))
}

/// The first two messages of a session: `initialize` and `notifications/initialized`.
pub const HANDSHAKE: &str = concat!(
    r#"{"jsonrpc":"2.0","id":0,"method":"initialize","params":{"protocolVersion":"2025-06-18","capabilities":{},"clientInfo":{"name":"mprog-test","version":"0"}}}"#,
    "\n",
    r#"{"jsonrpc":"2.0","method":"notifications/initialized"}"#,
    "\n"
);

/// One session in memory, for tests and fuzzing: `input` is everything the client sends
/// (JSON-RPC messages, one per line); the server's messages are collected until `done`
/// says enough have come, the server closes, or `timeout` passes. Then the client hangs up.
pub fn exchange(
    server: server::Server,
    input: Vec<u8>,
    done: impl Fn(&[serde_json::Value]) -> bool,
    timeout: Duration,
) -> Result<Vec<serde_json::Value>, String> {
    use tokio::io::{AsyncBufReadExt, AsyncWriteExt};
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| e.to_string())?;
    rt.block_on(async move {
        let (client, end) = tokio::io::duplex(1 << 16);
        let (server_read, server_write) = tokio::io::split(end);
        let serving = tokio::spawn(serve(server, server_read, server_write));
        let (client_read, mut client_write) = tokio::io::split(client);
        let writer = tokio::spawn(async move {
            let _ = client_write.write_all(&input).await;
            client_write
        });
        let mut lines = tokio::io::BufReader::new(client_read).lines();
        let mut got = Vec::new();
        let deadline = tokio::time::Instant::now() + timeout;
        while !done(&got) {
            match tokio::time::timeout_at(deadline, lines.next_line()).await {
                Ok(Ok(Some(line))) => got.push(
                    serde_json::from_str(&line)
                        .map_err(|e| format!("the server sent a line that is not JSON: {e}"))?,
                ),
                Ok(Ok(None)) | Ok(Err(_)) | Err(_) => break,
            }
        }
        // Hanging up ends the session; the server must then stop by itself.
        if let Ok(mut w) = writer.await {
            let _ = w.shutdown().await;
            drop(w);
        }
        drop(lines);
        match tokio::time::timeout(Duration::from_secs(10), serving).await {
            Ok(Ok(_)) => Ok(got),
            Ok(Err(e)) => Err(format!("the server task failed: {e}")),
            Err(_) => Err("the server did not stop after the client hung up".into()),
        }
    })
}

/// What the `mcp` fuzz target and its regression test do with one input: a session with
/// the handshake, `data` as the client's further lines, then a `ping`. The server must
/// answer the ping (it survived everything before it) and stop when the client hangs up.
/// Runs are never started (the runner does not exist); files go to a temporary folder.
pub fn fuzz_one(data: &[u8]) -> Result<(), String> {
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    let server = server(&Config {
        out_dir: dir.path().join("out"),
        exe: dir.path().join("no-runner"),
        model: None,
        time_limit: Duration::from_secs(2),
        card: None,
        far_prompts: None,
        coverage: None,
    })
    .map_err(|e| e.to_string())?;
    let mut input = HANDSHAKE.as_bytes().to_vec();
    input.extend_from_slice(data);
    input.extend_from_slice(b"\n{\"jsonrpc\":\"2.0\",\"id\":\"fuzz-end\",\"method\":\"ping\"}\n");
    let is_end = |m: &serde_json::Value| m["id"] == "fuzz-end";
    let got = exchange(
        server,
        input,
        |got| got.iter().any(is_end),
        Duration::from_secs(20),
    )?;
    if got.iter().any(is_end) {
        Ok(())
    } else {
        Err(format!("no answer to the final ping: {got:?}"))
    }
}
