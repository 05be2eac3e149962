//! The standard library: `stdlib/*.mprog`, compiled into the binary, parsed once, and
//! visible to every program. Its `##` comments are the reference documentation.

use super::syntax::ast::{Item, Module, Stmt};
use super::syntax::source_to_ast;
use std::sync::LazyLock;

/// The library files: (path, text).
pub const FILES: &[(&str, &str)] = &[
    (
        "stdlib/geometry.mprog",
        include_str!("../../stdlib/geometry.mprog"),
    ),
    ("stdlib/body.mprog", include_str!("../../stdlib/body.mprog")),
    (
        "stdlib/people.mprog",
        include_str!("../../stdlib/people.mprog"),
    ),
];

static LIBRARY: LazyLock<Vec<Module>> = LazyLock::new(|| {
    // A file that does not parse contributes nothing; `tests` in this crate check them all.
    FILES
        .iter()
        .map(|(_, text)| source_to_ast(text).0)
        .collect()
});

/// The parsed library modules.
pub fn library() -> &'static [Module] {
    &LIBRARY
}

/// Documentation of one library item.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct LibDoc {
    /// Name.
    pub name: String,
    /// `name(a, b)` for functions, `name` for constants.
    pub signature: String,
    /// Its `##` comment.
    pub doc: String,
    /// File it lives in.
    pub file: &'static str,
}

/// Documentation of every library function and constant, in file order.
pub fn docs() -> Vec<LibDoc> {
    let mut out = Vec::new();
    for ((file, text), module) in FILES.iter().zip(library()) {
        for item in &module.items {
            match item {
                Item::Def(f) => {
                    let params: Vec<&str> = f.params.iter().map(|p| p.name.as_str()).collect();
                    out.push(LibDoc {
                        name: f.name.name.clone(),
                        signature: format!("{}({})", f.name.name, params.join(", ")),
                        doc: f.doc.clone(),
                        file,
                    });
                }
                Item::Stmt(Stmt::Let { name, span, .. }) => {
                    let doc = doc_lines_above(text, span.start);
                    out.push(LibDoc {
                        name: name.name.clone(),
                        signature: name.name.clone(),
                        doc,
                        file,
                    });
                }
                _ => {}
            }
        }
    }
    out
}

fn doc_lines_above(text: &str, at: usize) -> String {
    let mut lines: Vec<&str> = text[..at]
        .lines()
        .rev()
        .skip(usize::from(!text[..at].ends_with('\n')))
        .map_while(|l| {
            l.trim_start()
                .strip_prefix("##")
                .map(|d| d.strip_prefix(' ').unwrap_or(d))
        })
        .collect();
    lines.reverse();
    lines.join("\n")
}
