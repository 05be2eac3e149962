//! Checking: AST → checked IR. Resolves names (joints, aliases, people, parameters,
//! functions, loop variables), checks types and units, inlines functions, unrolls loops
//! into lanes, turns time blocks into frame domains and `if`s into masks, and reports every
//! problem as a diagnostic. The output is the backend-free [`Ir`] plus the header.
//!
//! | file | what it checks |
//! | --- | --- |
//! | `header.rs` | prompt, length, params (+ overrides), people, definitions, recursion |
//! | `stmt.rs` | statements, time blocks, loops, `if`, weights |
//! | `expr.rs` | expressions, names, members, lists, `@` |
//! | `ops.rs` | operators: kinds and units |
//! | `calls.rs` | builtin and user function calls |
//! | `numeric.rs` | numeric builtins: vector maths, `abs`/`sqrt`/`sin`…, `min`/`max`, `clamp`, `vec` |
//! | `time.rs` | time positions (`2s`, `50%`, `end - 1`) |
//! | `timeline.rs` | prompts and timelines (`prompt a 0s..8s "…"`): spans in frames, gaps, blends |
//! | `builder.rs` | IR nodes: shapes, sharing, constant folding |
//! | `advice.rs` | warnings on the IR: impossible, out-of-reach and jumping constraints |
//! | `bounds.rs`, `feasibility.rs`, `reach.rs` | the interval analysis behind them |

mod advice;
mod bounds;
mod builder;
pub mod builtins;
mod calls;
mod expr;
pub mod feasibility;
mod geometry;
mod header;
mod numeric;
mod ops;
pub mod reach;
mod start;
mod stmt;
mod time;
mod timeline;
pub mod units;
pub mod values;

use crate::lang::diag::{Diagnostic, Severity};
use crate::lang::ir::{CostEstimate, Ir, NodeId, Op};
use crate::lang::syntax::ast::{Expr, FnDef, Module, Span};
use builder::Builder;
use std::collections::HashMap;
use units::Unit;
use values::Cx;

pub use timeline::TimedPrompt;

/// Most tensor ops a program may need per evaluation.
pub const MAX_OPS: usize = 20_000;
/// Most tensor elements a program may produce per sample and evaluation.
pub const MAX_ELEMENTS_PER_SAMPLE: usize = 20_000_000;
/// Most expression elaborations one check may take.
pub const MAX_WORK: usize = 1_000_000;
/// Longest motion accepted, in frames.
pub const MAX_LENGTH: usize = 4000;
/// Frames the motion model generates at most.
pub const MODEL_MAX_FRAMES: usize = 196;

/// A person of the program.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct PersonInfo {
    /// Name (`me` in single-person programs).
    pub name: String,
    /// Their own prompt (`people a "…"`), or the first of their own timeline; `None` when
    /// they take the program's (`me` copies the program's).
    pub prompt: Option<String>,
    /// Their timeline at the declared length, in time order: one entry `0..length` for a
    /// prompt without a span (their own or the program's), empty without any prompt.
    pub timeline: Vec<TimedPrompt>,
}

/// A parameter after overrides.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ParamInfo {
    /// Name.
    pub name: String,
    /// Value in SI units (1 or 3 numbers).
    pub value: Vec<f64>,
    /// Unit, as text.
    pub unit: String,
    /// Factor from the unit the default was written in to SI (`--set` values use it).
    #[serde(skip)]
    pub scale: f64,
    #[serde(skip)]
    pub(crate) node: NodeId,
    #[serde(skip)]
    pub(crate) unit_value: Unit,
    #[serde(skip)]
    pub(crate) span: Span,
}

/// The header of a checked program.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Header {
    /// The program's prompt: its `prompt "…"` line, or the first prompt of its timeline
    /// (`prompt 0s..8s "…"` lines naming no person).
    pub prompt: Option<String>,
    /// Length in frames.
    pub length: usize,
    /// People in tensor order.
    pub people: Vec<PersonInfo>,
    /// `spacing`: metres between neighbouring people at the start (`None`: the default).
    pub spacing: Option<f64>,
    /// Declared starts (`at`/`facing`), one per person, or empty when none is declared.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub starts: Vec<crate::lang::ir::StartOverride>,
    /// Parameters.
    pub params: Vec<ParamInfo>,
}

/// A checked program.
#[derive(Clone, Debug)]
pub struct Checked {
    /// Prompt, length, people, params.
    pub header: Header,
    /// The op list.
    pub ir: Ir,
    /// Its estimated cost.
    pub cost: CostEstimate,
    /// Constant geometry it names (walls, targets, regions), for pictures and the viewer.
    pub overlays: Vec<crate::scene::Overlay>,
    /// Joint-pair contacts it asks for (`contact(a.r_hand, b.r_hand, d)`), with their frames.
    pub contacts: Vec<crate::scene::Contact>,
}

/// The checker's state while walking one program.
pub(crate) struct Checker<'a> {
    pub b: Builder,
    pub diags: Vec<Diagnostic>,
    pub source: &'a str,
    pub header: Header,
    pub multi: bool,
    pub user_fns: HashMap<&'a str, &'a FnDef>,
    pub lib_fns: HashMap<&'a str, &'a FnDef>,
    pub lib_lets: HashMap<&'a str, &'a Expr>,
    /// What each user function's body sees besides its arguments: the top-level `let`s
    /// declared above it.
    pub fn_envs: HashMap<&'a str, values::Env<'a>>,
    /// The top-level `let`s, in source order (for "declared after" diagnostics).
    pub top_lets: Vec<(&'a str, Span)>,
    /// Recursive functions (reported once; calls to them elaborate to errors).
    pub poisoned: std::collections::HashSet<&'a str>,
    /// Expressions elaborated so far (see [`MAX_WORK`]).
    pub work: usize,
    pub statements: Vec<crate::lang::ir::Statement>,
    /// See [`Checked::overlays`].
    pub overlays: Vec<crate::scene::Overlay>,
    /// Contacts as (end, end, frame domain), resolved into [`Checked::contacts`].
    pub contacts: Vec<(crate::scene::JointOf, crate::scene::JointOf, usize)>,
}

impl<'a> Checker<'a> {
    /// Records a diagnostic; inside a library function it moves to the user's call site.
    pub fn report(&mut self, cx: &Cx, mut d: Diagnostic) {
        if let Some(site) = cx.site {
            d.span = site;
            d.message = format!("{} (inside this library call)", d.message);
        }
        self.diags.push(d);
    }

    /// Shorthand for an error.
    pub fn error(
        &mut self,
        cx: &Cx,
        code: &'static str,
        span: Span,
        msg: impl Into<String>,
    ) -> ErrorBuilder<'_, 'a> {
        ErrorBuilder {
            checker: self,
            cx: cx.clone(),
            d: Some(Diagnostic::error(code, span, msg)),
        }
    }

    /// The 1-based line of a byte offset in the user's source.
    pub fn line_of(&self, offset: usize) -> usize {
        crate::lang::diag::line_col(self.source, offset).0
    }
}

/// A diagnostic being built; it is recorded when dropped.
pub(crate) struct ErrorBuilder<'c, 'a> {
    checker: &'c mut Checker<'a>,
    cx: Cx,
    d: Option<Diagnostic>,
}

impl ErrorBuilder<'_, '_> {
    /// Label under the span.
    pub fn label(mut self, l: impl Into<String>) -> Self {
        self.d = self.d.take().map(|d| d.label(l));
        self
    }

    /// Fix-it hint.
    pub fn help(mut self, h: impl Into<String>) -> Self {
        self.d = self.d.take().map(|d| d.help(h));
        self
    }

    /// Turns it into a warning.
    pub fn warning(mut self) -> Self {
        self.d = self.d.take().map(|mut d| {
            d.severity = Severity::Warning;
            d
        });
        self
    }
}

impl Drop for ErrorBuilder<'_, '_> {
    fn drop(&mut self) {
        if let Some(d) = self.d.take() {
            let cx = self.cx.clone();
            self.checker.report(&cx, d);
        }
    }
}

/// Checks a parsed program against the library and lowers it to IR.
/// `overrides` replace parameter defaults (values in the unit the default was written in).
pub fn module_to_ir<'a>(
    module: &'a Module,
    source: &'a str,
    library: &'a [Module],
    overrides: &[(String, f64)],
) -> (Option<Checked>, Vec<Diagnostic>) {
    let mut c = Checker {
        b: Builder::new(),
        diags: Vec::new(),
        source,
        header: Header::default(),
        multi: false,
        user_fns: HashMap::new(),
        lib_fns: HashMap::new(),
        lib_lets: HashMap::new(),
        fn_envs: HashMap::new(),
        top_lets: Vec::new(),
        poisoned: Default::default(),
        work: 0,
        statements: Vec::new(),
        overlays: Vec::new(),
        contacts: Vec::new(),
    };
    c.load_library(library);
    c.scope_of_functions(module);
    c.header_items(module, overrides);
    let header_ok = !c.diags.iter().any(|d| d.severity == Severity::Error);
    c.body(module);
    if c.b.overflow {
        c.diags.push(
            Diagnostic::error(
                crate::lang::codes::TOO_COSTLY,
                Span::default(),
                format!(
                    "the program expands to more than {} tensor ops",
                    builder::MAX_NODES
                ),
            )
            .help("loops and functions are unrolled when checking; use fewer or smaller loops"),
        );
    }
    let has_errors = c.diags.iter().any(|d| d.severity == Severity::Error);
    // A timeline alone is a program: prompts in a row, with nothing else to satisfy.
    let has_timeline = c.header.people.iter().any(|p| p.timeline.len() > 1);
    if c.statements.is_empty() && !has_errors && !has_timeline {
        c.diags.push(
            Diagnostic::error(
                crate::lang::codes::EMPTY_PROGRAM,
                Span::new(0, 0),
                "the program has no constraints",
            )
            .label("nothing to satisfy here")
            .help(
                "add a constraint, e.g. `always { head.y > 1.5 m }` or `at end { pelvis.z > 2 m }`",
            ),
        );
    }
    if c.diags.iter().any(|d| d.severity == Severity::Error) {
        // The statements that checked cleanly still get the IR warnings (`body` keeps
        // only those), so one repair round sees every problem.
        if header_ok && !c.b.overflow && !c.statements.is_empty() {
            let ir = c.finish();
            if within_limits(&ir) {
                c.diags.extend(advice::warnings(&ir));
            }
        }
        return (None, c.diags);
    }
    let ir = c.finish();
    // Constants are folded in f64 and stored as f32: a literal like `1e39` or a product
    // like `1e30 * 1e30` would evaluate to ∞ or NaN.
    for node in &ir.nodes {
        if let Op::Const(v) = &node.op
            && let Some(x) = v.iter().find(|x| !x.is_finite())
        {
            c.diags.push(
                Diagnostic::error(
                    crate::lang::codes::NUMBER_OUT_OF_RANGE,
                    node.span,
                    format!("this value is {x} in 32-bit floats (|x| ≤ 3.4e38)"),
                )
                .label("not a finite number")
                .help("use a smaller number; lengths are in metres, times in seconds"),
            );
        }
    }
    if c.diags.iter().any(|d| d.severity == Severity::Error) {
        return (None, c.diags);
    }
    let cost = ir.cost_estimate();
    if cost.ops > MAX_OPS || cost.elements_per_sample > MAX_ELEMENTS_PER_SAMPLE {
        c.diags.push(
            Diagnostic::error(
                crate::lang::codes::TOO_COSTLY,
                Span::new(0, 0),
                format!(
                    "evaluating this program is estimated at {} tensor ops and {} elements per \
                     sample; the limits are {MAX_OPS} ops and {MAX_ELEMENTS_PER_SAMPLE} elements",
                    cost.ops, cost.elements_per_sample
                ),
            )
            .help("use fewer nested loops over `joints`, shorter `during` ranges, or a shorter length"),
        );
        return (None, c.diags);
    }
    c.diags.extend(advice::warnings(&ir));
    let header = c.header.clone();
    let overlays = std::mem::take(&mut c.overlays);
    let contacts = c
        .contacts
        .iter()
        .filter_map(|&(a, b, domain)| {
            let frames = ir.resolve_domain(domain, ir.length);
            Some(crate::scene::Contact {
                label: None,
                a,
                b,
                frames: (*frames.iter().min()?, *frames.iter().max()?),
            })
        })
        .collect();
    (
        Some(Checked {
            header,
            ir,
            cost,
            overlays,
            contacts,
        }),
        c.diags,
    )
}

/// Whether an IR from a program with errors is safe to analyse: finite constants and a
/// cost under the limits.
fn within_limits(ir: &Ir) -> bool {
    let finite = ir.nodes.iter().all(|n| match &n.op {
        Op::Const(v) => v.iter().all(|x| x.is_finite()),
        _ => true,
    });
    let cost = ir.cost_estimate();
    finite && cost.ops <= MAX_OPS && cost.elements_per_sample <= MAX_ELEMENTS_PER_SAMPLE
}

impl Checker<'_> {
    /// Drops nodes no statement reads and packs the rest into an [`Ir`].
    fn finish(&mut self) -> Ir {
        let nodes = std::mem::take(&mut self.b.nodes);
        let mut live = vec![false; nodes.len()];
        for s in &self.statements {
            live[s.error] = true;
            if let Some(m) = s.mask {
                live[m] = true;
            }
        }
        for i in (0..nodes.len()).rev() {
            if live[i] {
                for a in nodes[i].op.args() {
                    live[a] = true;
                }
            }
        }
        let mut remap = vec![usize::MAX; nodes.len()];
        let mut kept = Vec::new();
        for (i, mut n) in nodes.into_iter().enumerate() {
            if live[i] {
                n.op.map_args(|a| remap[a]);
                remap[i] = kept.len();
                kept.push(n);
            }
        }
        let mut statements = std::mem::take(&mut self.statements);
        for s in &mut statements {
            s.error = remap[s.error];
            s.mask = s.mask.map(|m| remap[m]);
        }
        Ir {
            nodes: kept,
            domains: std::mem::take(&mut self.b.domains),
            statements,
            people: self.header.people.len(),
            length: self.header.length,
            spacing: self.header.spacing,
            starts: self.header.starts.clone(),
        }
    }
}
