//! Diagnostics: every problem found in a program, with a stable code, a span, a label and
//! a hint on how to fix it. Stages collect them instead of stopping at the first; this
//! module renders them as a miette report (fancy or plain) or as JSON for repair loops.

use super::syntax::ast::Span;
use miette::{GraphicalReportHandler, GraphicalTheme, LabeledSpan, NamedSource, SourceCode};
use serde::Serialize;
use std::fmt;
use std::sync::Arc;

/// How bad a diagnostic is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    /// The program is rejected.
    Error,
    /// The program runs, but probably not as intended.
    Warning,
}

/// One problem in a program.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    /// Stable code, e.g. `mprog::unknown_joint`.
    pub code: &'static str,
    /// Error or warning.
    pub severity: Severity,
    /// One-line description.
    pub message: String,
    /// Where.
    pub span: Span,
    /// Text under the caret.
    pub label: String,
    /// How to fix it.
    pub help: Option<String>,
}

impl Diagnostic {
    /// An error at `span`.
    pub fn error(code: &'static str, span: Span, message: impl Into<String>) -> Self {
        Diagnostic {
            code,
            severity: Severity::Error,
            message: message.into(),
            span,
            label: String::new(),
            help: None,
        }
    }

    /// A warning at `span`.
    pub fn warning(code: &'static str, span: Span, message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Warning,
            ..Diagnostic::error(code, span, message)
        }
    }

    /// Sets the label shown under the span.
    pub fn label(mut self, label: impl Into<String>) -> Self {
        self.label = label.into();
        self
    }

    /// Sets the fix-it hint.
    pub fn help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }
}

/// All diagnostics of one program, with the source they point into.
#[derive(Clone)]
pub struct Diagnostics {
    /// File name shown in reports.
    pub name: String,
    /// The program text.
    pub source: Arc<String>,
    /// In source order.
    pub items: Vec<Diagnostic>,
}

impl fmt::Debug for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Diagnostics")
            .field("name", &self.name)
            .field("items", &self.items)
            .finish()
    }
}

/// A diagnostic as JSON: positions are 1-based lines and columns (columns in characters).
#[derive(Clone, Debug, Serialize)]
pub struct JsonDiagnostic {
    /// Stable code.
    pub code: &'static str,
    /// `error` or `warning`.
    pub severity: Severity,
    /// One-line description.
    pub message: String,
    /// Text under the caret.
    pub label: String,
    /// How to fix it.
    pub hint: Option<String>,
    /// Start line.
    pub line: usize,
    /// Start column.
    pub column: usize,
    /// End line.
    pub end_line: usize,
    /// End column (exclusive).
    pub end_column: usize,
    /// The source text of the span.
    pub snippet: String,
}

impl Diagnostics {
    /// Wraps diagnostics for `source`, sorted by position (errors first on ties).
    pub fn new(name: &str, source: Arc<String>, mut items: Vec<Diagnostic>) -> Self {
        items.sort_by_key(|d| (d.span.start, d.severity != Severity::Error, d.span.end));
        items.dedup_by(|a, b| a.code == b.code && a.span == b.span && a.message == b.message);
        Diagnostics {
            name: name.to_string(),
            source,
            items,
        }
    }

    /// True when at least one item is an error.
    pub fn has_errors(&self) -> bool {
        self.items.iter().any(|d| d.severity == Severity::Error)
    }

    /// Number of errors.
    pub fn error_count(&self) -> usize {
        self.items
            .iter()
            .filter(|d| d.severity == Severity::Error)
            .count()
    }

    /// Only the warnings.
    pub fn warnings(&self) -> impl Iterator<Item = &Diagnostic> {
        self.items
            .iter()
            .filter(|d| d.severity == Severity::Warning)
    }

    /// 1-based (line, column) of a byte offset.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        line_col(&self.source, offset)
    }

    /// The diagnostics as JSON values.
    pub fn to_json(&self) -> Vec<JsonDiagnostic> {
        self.items
            .iter()
            .map(|d| {
                let (line, column) = self.line_col(d.span.start);
                let (end_line, end_column) = self.line_col(d.span.end);
                let snippet = self
                    .source
                    .get(d.span.start..d.span.end)
                    .unwrap_or("")
                    .to_string();
                JsonDiagnostic {
                    code: d.code,
                    severity: d.severity,
                    message: d.message.clone(),
                    label: d.label.clone(),
                    hint: d.help.clone(),
                    line,
                    column,
                    end_line,
                    end_column,
                    snippet,
                }
            })
            .collect()
    }

    /// Renders every item with the given miette theme, one report after another.
    pub fn render(&self, theme: GraphicalTheme) -> String {
        let handler = GraphicalReportHandler::new_themed(theme)
            .with_width(100)
            .with_links(false);
        let source = Arc::new(NamedSource::new(self.name.clone(), self.source.to_string()));
        let mut out = String::new();
        for item in &self.items {
            let report = Report {
                item,
                source: source.clone(),
                len: self.source.len(),
            };
            // Writing into a String cannot fail.
            let _ = handler.render_report(&mut out, &report);
        }
        out
    }

    /// Colour-free ASCII rendering, stable for snapshots.
    pub fn render_plain(&self) -> String {
        self.render(GraphicalTheme::none())
    }

    /// Fancy rendering for terminals.
    pub fn render_fancy(&self) -> String {
        self.render(GraphicalTheme::unicode())
    }

    /// The fancy layout without colour codes (for pipes and files).
    pub fn render_uncoloured(&self) -> String {
        self.render(GraphicalTheme::unicode_nocolor())
    }

    /// Fancy with colour for a terminal (unless `NO_COLOR` is set), uncoloured otherwise.
    pub fn render_for(&self, to_terminal: bool) -> String {
        if to_terminal && std::env::var_os("NO_COLOR").is_none() {
            self.render_fancy()
        } else {
            self.render_uncoloured()
        }
    }
}

impl fmt::Display for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.render_plain())
    }
}

impl std::error::Error for Diagnostics {}

/// 1-based (line, column) of a byte offset in `text`; columns count characters.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = text.get(..offset).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = before[line_start..].chars().count() + 1;
    (line, column)
}

/// One diagnostic viewed as a miette diagnostic.
struct Report<'a> {
    item: &'a Diagnostic,
    source: Arc<NamedSource<String>>,
    len: usize,
}

impl fmt::Debug for Report<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.item.fmt(f)
    }
}

impl fmt::Display for Report<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.item.message)
    }
}

impl std::error::Error for Report<'_> {}

impl miette::Diagnostic for Report<'_> {
    fn code<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        Some(Box::new(self.item.code))
    }

    fn severity(&self) -> Option<miette::Severity> {
        Some(match self.item.severity {
            Severity::Error => miette::Severity::Error,
            Severity::Warning => miette::Severity::Warning,
        })
    }

    fn help<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        self.item
            .help
            .as_ref()
            .map(|h| Box::new(h) as Box<dyn fmt::Display>)
    }

    fn source_code(&self) -> Option<&dyn SourceCode> {
        Some(&*self.source)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        let start = self.item.span.start.min(self.len);
        let end = self.item.span.end.clamp(start, self.len);
        let label = (!self.item.label.is_empty()).then(|| self.item.label.clone());
        Some(Box::new(std::iter::once(LabeledSpan::new(
            label,
            start,
            end - start,
        ))))
    }
}

/// Levenshtein distance, for "did you mean" hints.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.iter().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

/// The closest candidate to `name`, if it is close enough to be a likely typo.
pub fn did_you_mean<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
    let lower = name.to_ascii_lowercase();
    let limit = (name.chars().count() / 3).max(1) + 1;
    candidates
        .into_iter()
        .map(|c| (edit_distance(&lower, &c.to_ascii_lowercase()), c))
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, c)| (*d, c.len()))
        .map(|(_, c)| c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distance_counts_edits() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "ab"), 2);
        assert_eq!(edit_distance("r_hnad", "r_hand"), 2);
    }

    #[test]
    fn did_you_mean_picks_close_names() {
        assert_eq!(
            did_you_mean("r_hnad", ["r_hand", "l_hand", "head"]),
            Some("r_hand")
        );
        assert_eq!(did_you_mean("zzzzzz", ["r_hand", "head"]), None);
    }

    #[test]
    fn line_col_counts_characters() {
        assert_eq!(line_col("ab\ncé d", 7), (2, 4));
        assert_eq!(line_col("", 5), (1, 1));
    }
}
