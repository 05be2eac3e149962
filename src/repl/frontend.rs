//! The terminal frontend: rustyline line editing, multi-line input, tab completion and
//! persistent history around a [`Session`]. Everything it shows comes from the backend's
//! [`super::Reply`]; on a pipe (no terminal) it reads lines the same way, so scripts work.

use super::complete::{self, Context as WordContext};
use super::input::needs_more;
use super::session::Session;
use rustyline::completion::{Completer, FilenameCompleter, Pair};
use rustyline::error::ReadlineError;
use rustyline::highlight::Highlighter;
use rustyline::hint::Hinter;
use rustyline::history::DefaultHistory;
use rustyline::validate::{ValidationContext, ValidationResult, Validator};
use rustyline::{Config, Editor, Helper};
use std::io::{IsTerminal, Write};
use std::path::PathBuf;

/// Options of the terminal frontend.
#[derive(Clone, Debug, Default)]
pub struct FrontendOptions {
    /// Plain ASCII diagnostics without colours.
    pub plain: bool,
    /// Do not read or write the history file.
    pub no_history: bool,
}

/// rustyline helper: completion and the multi-line rule.
pub struct ReplHelper {
    files: FilenameCompleter,
    /// The session's program, for the names it defines.
    pub program: String,
}

impl Completer for ReplHelper {
    type Candidate = Pair;

    fn complete(
        &self,
        line: &str,
        pos: usize,
        ctx: &rustyline::Context<'_>,
    ) -> rustyline::Result<(usize, Vec<Pair>)> {
        let (start, kind) = complete::word_at(line, pos);
        let words = match kind {
            WordContext::File => return self.files.complete(line, pos, ctx),
            WordContext::Command => complete::command_candidates(&line[start..pos]),
            WordContext::Code => complete::code_candidates(&line[start..pos], &self.program),
        };
        let pairs = words
            .into_iter()
            .map(|w| Pair {
                display: w.clone(),
                replacement: w,
            })
            .collect();
        Ok((start, pairs))
    }
}

impl Hinter for ReplHelper {
    type Hint = String;
}

impl Highlighter for ReplHelper {}

impl Validator for ReplHelper {
    fn validate(&self, ctx: &mut ValidationContext) -> rustyline::Result<ValidationResult> {
        Ok(if needs_more(ctx.input()) {
            ValidationResult::Incomplete
        } else {
            ValidationResult::Valid(None)
        })
    }
}

impl Helper for ReplHelper {}

/// `$XDG_STATE_HOME/mprog/history`, else `~/.local/state/mprog/history`.
pub fn history_path() -> Option<PathBuf> {
    let state = std::env::var_os("XDG_STATE_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| {
            std::env::var_os("HOME")
                .filter(|v| !v.is_empty())
                .map(|h| PathBuf::from(h).join(".local/state"))
        })?;
    Some(state.join("mprog").join("history"))
}

/// Runs the REPL until `:quit` or end of input.
pub fn run(mut session: Session, opts: &FrontendOptions) -> rustyline::Result<()> {
    let terminal = std::io::stdin().is_terminal() && std::io::stdout().is_terminal();
    let fancy = terminal && !opts.plain;
    let config = Config::builder().auto_add_history(false).build();
    let mut editor: Editor<ReplHelper, DefaultHistory> = Editor::with_config(config)?;
    editor.set_helper(Some(ReplHelper {
        files: FilenameCompleter::new(),
        program: String::new(),
    }));
    let history = if opts.no_history {
        None
    } else {
        history_path()
    };
    if let Some(path) = &history
        && let Err(e) = editor.load_history(path)
        && path.exists()
    {
        warn(&format!("cannot read history {}: {e}", path.display()));
    }
    if terminal {
        println!("mprog repl — `:help` lists commands, Tab completes, Ctrl-D leaves.");
    }
    let mut history_warned = false;
    let mut buffer = String::new();
    loop {
        let prompt = if buffer.is_empty() {
            "mprog> "
        } else {
            "  ...> "
        };
        match editor.readline(prompt) {
            Ok(line) => {
                if !buffer.is_empty() {
                    buffer.push('\n');
                }
                buffer.push_str(&line);
                if needs_more(&buffer) {
                    continue;
                }
            }
            Err(ReadlineError::Interrupted) => {
                buffer.clear();
                continue;
            }
            Err(ReadlineError::Eof) => break,
            Err(e) => return Err(e),
        }
        let input = std::mem::take(&mut buffer);
        if !input.trim().is_empty() {
            let _ = editor.add_history_entry(input.trim_end());
            if let Some(path) = &history
                && let Err(e) = save_history(&mut editor, path)
                && !history_warned
            {
                warn(&format!("cannot write history {}: {e}", path.display()));
                history_warned = true;
            }
        }
        if input.trim_start().starts_with(":gen") {
            println!("generating (this takes a while on the CPU)…");
        } else if input.trim_start().starts_with(":run") {
            println!("solving (a minute or more on the CPU at the solver's defaults)…");
        }
        let reply = session.handle(&input);
        print!("{}", reply.render(fancy));
        let _ = std::io::stdout().flush();
        if let Some(h) = editor.helper_mut() {
            h.program = session.source().to_string();
        }
        if reply.quit {
            break;
        }
    }
    Ok(())
}

fn save_history(
    editor: &mut Editor<ReplHelper, DefaultHistory>,
    path: &std::path::Path,
) -> Result<(), String> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    }
    editor.save_history(path).map_err(|e| e.to_string())
}

fn warn(msg: &str) {
    eprintln!("warning: {msg}");
}
