//! Tab completion candidates, without terminal code: `:commands` at the start of a line,
//! and elsewhere joint names, aliases, built-ins, library functions, keywords, units and
//! the names the session's program defines (`let`, `def`, `param`, people).

use super::command::COMMANDS;
use crate::lang::check::builtins::BUILTINS;
use crate::lang::stdlib;
use crate::lang::syntax::ast::{Item, Stmt};
use crate::lang::syntax::source_to_ast;
use crate::skeleton::all_joint_names;

/// Language keywords and the time words.
pub const KEYWORDS: &[&str] = &[
    "prompt", "length", "spacing", "param", "people", "def", "let", "always", "at", "during",
    "for", "in", "if", "else", "weight", "minimize", "maximize", "and", "or", "not", "start",
    "mid", "end", "time", "joints", "me",
];

/// Commands whose argument is a file name.
pub const FILE_COMMANDS: &[&str] = &["load", "l", "motion", "m", "render", "r", "view", "v"];

/// What the word before the cursor is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Context {
    /// The first word, starting with `:`.
    Command,
    /// The argument of a file-taking command.
    File,
    /// mprog code.
    Code,
}

/// Where the word under the cursor starts, and what kind of word it is.
pub fn word_at(line: &str, pos: usize) -> (usize, Context) {
    let before = &line[..pos.min(line.len())];
    let start = before
        .char_indices()
        .rev()
        .take_while(|(_, c)| c.is_ascii_alphanumeric() || *c == '_')
        .last()
        .map_or(before.len(), |(i, _)| i);
    let trimmed = before.trim_start();
    if trimmed.starts_with(':') && !trimmed.contains(char::is_whitespace) {
        return (line.len() - line.trim_start().len(), Context::Command);
    }
    if let Some(rest) = trimmed.strip_prefix(':') {
        let cmd = rest.split_whitespace().next().unwrap_or("");
        if FILE_COMMANDS.contains(&cmd) {
            return (start, Context::File);
        }
    }
    (start, Context::Code)
}

/// Completions of `prefix` in code, given the session's program source (sorted, unique).
pub fn code_candidates(prefix: &str, program: &str) -> Vec<String> {
    let mut names: Vec<String> = all_joint_names().map(str::to_string).collect();
    names.extend(BUILTINS.iter().map(|b| b.name.to_string()));
    names.extend(stdlib::docs().into_iter().map(|d| d.name));
    names.extend(KEYWORDS.iter().map(|k| k.to_string()));
    names.extend(defined_names(program));
    let mut out: Vec<String> = names
        .into_iter()
        .filter(|n| n.starts_with(prefix) && n != prefix)
        .collect();
    out.sort();
    out.dedup();
    out
}

/// Completions of a `:command` prefix (with the colon).
pub fn command_candidates(prefix: &str) -> Vec<String> {
    let p = prefix.trim_start_matches(':');
    let mut out: Vec<String> = COMMANDS
        .iter()
        .filter(|c| c.name.starts_with(p))
        .map(|c| format!(":{}", c.name))
        .collect();
    out.sort();
    out
}

/// Names the program defines.
fn defined_names(program: &str) -> Vec<String> {
    let (module, _) = source_to_ast(program);
    let mut out = Vec::new();
    for item in &module.items {
        match item {
            Item::Param { name, .. } => out.push(name.name.clone()),
            Item::Def(f) => out.push(f.name.name.clone()),
            Item::People { people, .. } => out.extend(people.iter().map(|p| p.name.name.clone())),
            Item::Stmt(Stmt::Let { name, .. }) => out.push(name.name.clone()),
            _ => {}
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn commands_complete_at_line_start() {
        assert_eq!(word_at(":lo", 3), (0, Context::Command));
        assert_eq!(command_candidates(":lo"), vec![":load"]);
        assert_eq!(command_candidates(":s"), vec![":save", ":score", ":show"]);
    }

    #[test]
    fn file_arguments_are_files() {
        assert_eq!(word_at(":load prog", 10).1, Context::File);
        assert_eq!(word_at(":motion ", 8).1, Context::File);
    }

    #[test]
    fn code_words_complete_from_every_source() {
        let (start, ctx) = word_at(":eval dist(l_ha", 15);
        assert_eq!((start, ctx), (11, Context::Code));
        assert_eq!(code_candidates("l_ha", ""), vec!["l_hand"]);
        assert!(code_candidates("right_", "").contains(&"right_wrist".to_string()));
        assert!(code_candidates("massC", "").contains(&"massCtrNoHead".to_string()));
        assert!(code_candidates("groundD", "").contains(&"groundDist".to_string()));
        assert!(code_candidates("minim", "").contains(&"minimize".to_string()));
        let prog = "param reach = 10 cm\ndef holds(d) = dist(l_hand, r_hand) == d\nlet hands = midPoint(l_hand, r_hand)\n";
        assert_eq!(code_candidates("rea", prog), vec!["reach"]);
        assert_eq!(code_candidates("hol", prog), vec!["holds"]);
        assert!(code_candidates("hand", prog).contains(&"hands".to_string()));
    }

    #[test]
    fn word_after_a_dot_is_its_own_word() {
        assert_eq!(word_at("a.r_ha", 6), (2, Context::Code));
    }
}
