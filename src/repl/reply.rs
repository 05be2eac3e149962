//! What the backend answers: text, diagnostics (rendered by the frontend like `mprog
//! check`), or an error line. No terminal code: a frontend picks fancy or plain rendering.

use crate::lang::Diagnostics;

/// One piece of an answer.
#[derive(Clone, Debug)]
pub enum Item {
    /// Plain text (may span lines).
    Text(String),
    /// Checker diagnostics, rendered like `mprog check`.
    Diagnostics(Diagnostics),
    /// Something went wrong (bad file, no motion, …).
    Error(String),
    /// Worth knowing, not an error (e.g. history could not be written).
    Warning(String),
}

/// The backend's answer to one input.
#[derive(Clone, Debug, Default)]
pub struct Reply {
    /// What to show, in order.
    pub items: Vec<Item>,
    /// True when the session should end.
    pub quit: bool,
}

impl Reply {
    /// A reply of one text.
    pub fn text(s: impl Into<String>) -> Self {
        Reply {
            items: vec![Item::Text(s.into())],
            quit: false,
        }
    }

    /// A reply of one error.
    pub fn error(s: impl Into<String>) -> Self {
        Reply {
            items: vec![Item::Error(s.into())],
            quit: false,
        }
    }

    /// A reply showing diagnostics.
    pub fn diagnostics(d: Diagnostics) -> Self {
        Reply {
            items: vec![Item::Diagnostics(d)],
            quit: false,
        }
    }

    /// Adds an item.
    pub fn push(&mut self, item: Item) {
        self.items.push(item);
    }

    /// True when any item is an error or has error diagnostics.
    pub fn is_error(&self) -> bool {
        self.items.iter().any(|i| match i {
            Item::Error(_) => true,
            Item::Diagnostics(d) => d.has_errors(),
            _ => false,
        })
    }

    /// The whole answer as text; `fancy` picks miette's unicode theme for diagnostics
    /// (colours included), else the plain ASCII one that tests snapshot.
    pub fn render(&self, fancy: bool) -> String {
        let mut out = String::new();
        for item in &self.items {
            let piece = match item {
                Item::Text(t) => t.clone(),
                Item::Diagnostics(d) if fancy => d.render_fancy(),
                Item::Diagnostics(d) => d.render_plain(),
                Item::Error(e) => format!("error: {e}"),
                Item::Warning(w) => format!("warning: {w}"),
            };
            out.push_str(piece.trim_end_matches('\n'));
            out.push('\n');
        }
        out
    }
}
