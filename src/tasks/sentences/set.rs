//! The task file (`bench/sentences/tasks.toml`): one entry per sentence, its program beside it.

use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The shipped sentence set.
pub const DEFAULT_SET: &str = "bench/sentences/tasks.toml";

/// One sentence-level task.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SentenceTask {
    /// Short id; the judge's key (`s01`).
    pub id: String,
    /// The sentence, as a user would write it.
    pub sentence: String,
    /// How many people the sentence names.
    pub people: usize,
    /// Seconds the sentence asks for.
    pub seconds: f32,
    /// The program written from the sentence, relative to the task file.
    pub program: PathBuf,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SetFile {
    task: Vec<SentenceTask>,
}

/// Reads a task file; programs come back as paths beside it. Errors name the file and
/// what is wrong with it.
pub fn read_set(path: &Path) -> Result<Vec<SentenceTask>, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let file: SetFile =
        toml::from_str(&text).map_err(|e| format!("{} is not a task file: {e}", path.display()))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut seen = std::collections::HashSet::new();
    let mut tasks = Vec::with_capacity(file.task.len());
    for mut t in file.task {
        if !seen.insert(t.id.clone()) {
            return Err(format!(
                "{}: task id {} appears twice",
                path.display(),
                t.id
            ));
        }
        if t.people == 0 {
            return Err(format!("{}: task {} has no people", path.display(), t.id));
        }
        t.program = dir.join(&t.program);
        tasks.push(t);
    }
    Ok(tasks)
}
