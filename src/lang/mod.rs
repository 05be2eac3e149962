//! The `.mprog` language: source → AST → checked IR → burn error graph.
//!
//! | stage | module | function | output |
//! | --- | --- | --- | --- |
//! | parse | [`syntax`] | [`syntax::source_to_ast`] | [`syntax::ast::Module`] |
//! | check + lower | [`check`] | [`check::module_to_ir`] | [`ir::Ir`] + [`check::Header`] |
//! | evaluate | [`eval`] | [`eval::evaluate`] | [`Evaluation`] (burn tensors) |
//!
//! [`compile`] runs the first two stages and returns a [`Program`]; [`check_source`]
//! returns every diagnostic (errors and warnings) for `mprog check`; [`with_unseen_poses`]
//! adds the warnings that need the model's training data ([`unseen`]). The language itself
//! is described in `book/src/reference/language.md` (the book) (syntax, semantics, the scale of the total error).

pub mod check;
pub mod codes;
pub mod diag;
pub mod eval;
pub mod ir;
pub mod stdlib;
pub mod syntax;
pub mod unseen;

pub use check::{Header, ParamInfo, PersonInfo, TimedPrompt};
pub use diag::{Diagnostic, Diagnostics, Severity};
pub use eval::{EvalError, Evaluation, FrameErrors, MAX_EVAL_ELEMENTS};
pub use ir::CostEstimate;
pub use unseen::{unseen_poses, with_unseen_poses};

use burn::tensor::Tensor;
use std::sync::Arc;
use syntax::ast::Span;

/// A checked program, ready to evaluate.
#[derive(Debug, Clone)]
pub struct Program {
    name: String,
    checked: check::Checked,
    warnings: Diagnostics,
    cache: eval::IndexCache,
}

/// What one statement of a program is, for breakdowns.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct StatementInfo {
    /// `line N: <source>`.
    pub label: String,
    /// 1-based source line.
    pub line: usize,
    /// Unit of its error.
    pub unit: String,
    /// Its weight.
    pub weight: f64,
    /// Loop iterations it stands for.
    pub lanes: usize,
    /// Its source span.
    pub span: Span,
}

/// Parses and checks `source`; returns every diagnostic, warnings included.
pub fn check_source(source: &str, name: &str, overrides: &[(String, f64)]) -> Diagnostics {
    match compile_inner(source, name, overrides) {
        Ok(p) => p.warnings,
        Err(d) => d,
    }
}

/// The prompts a program gives (its `prompt` lines, timeline spans included, and each
/// person's on a `people` line) with where they are written; empty when the program does
/// not parse.
pub fn prompts_of(source: &str) -> Vec<(String, syntax::ast::Span)> {
    let (module, _) = syntax::source_to_ast(source);
    let mut out = Vec::new();
    for item in &module.items {
        match item {
            syntax::ast::Item::Prompt { text, span, .. } => out.push((text.clone(), *span)),
            syntax::ast::Item::People { people, span } => out.extend(
                people
                    .iter()
                    .filter_map(|p| p.prompt.clone().map(|t| (t, *span))),
            ),
            _ => {}
        }
    }
    out
}

/// What the motion model says of a prompt before generating from it: the lines `mprog run`
/// and `mprog gen` print (far from every training caption, read through its nearest
/// captions, …); empty when it reads the prompt as written. The language itself knows no
/// model: the CLI and the MCP server pass the model's.
pub type PromptReport = dyn Fn(&str) -> Vec<String> + Send + Sync;

/// `diags` with an `mprog::far_prompt` warning on every prompt of `source` the model has
/// something to say about (`report`), so `check` warns of every prompt `run` would.
pub fn with_far_prompts(diags: Diagnostics, source: &str, report: &PromptReport) -> Diagnostics {
    let mut items = diags.items;
    for (prompt, span) in prompts_of(source) {
        let lines = report(&prompt);
        if lines.is_empty() {
            continue;
        }
        items.push(
            Diagnostic::warning(
                codes::FAR_PROMPT,
                span,
                format!("the motion model has no training caption like \"{prompt}\""),
            )
            .label("not a caption the model knows")
            .help(format!(
                "{}; the motion will follow the constraints more than the words. `mprog prompt` lists the actions the model knows",
                lines.join("; ")
            )),
        );
    }
    Diagnostics::new(&diags.name, diags.source, items)
}

/// Parses, checks and lowers a program. `overrides` replace `param` defaults (values in the
/// unit the default was written in). Errors come back as [`Diagnostics`].
pub fn compile(
    source: &str,
    name: &str,
    overrides: &[(String, f64)],
) -> Result<Program, Diagnostics> {
    compile_inner(source, name, overrides)
}

fn compile_inner(
    source: &str,
    name: &str,
    overrides: &[(String, f64)],
) -> Result<Program, Diagnostics> {
    let text = Arc::new(source.to_string());
    let (module, mut diags) = syntax::source_to_ast(source);
    if diags.iter().any(|d| d.severity == Severity::Error) {
        return Err(Diagnostics::new(name, text, diags));
    }
    let (checked, more) = check::module_to_ir(&module, source, stdlib::library(), overrides);
    diags.extend(more);
    let diagnostics = Diagnostics::new(name, text, diags);
    match checked {
        Some(checked) if !diagnostics.has_errors() => Ok(Program {
            name: name.to_string(),
            checked,
            warnings: diagnostics,
            cache: eval::IndexCache::default(),
        }),
        _ => Err(diagnostics),
    }
}

/// A program's error is the sum of its statements' errors; its terms are the statements.
impl crate::objective::MotionError for Program {
    fn error(&self, joints: Tensor<5>) -> Tensor<1> {
        self.evaluate(joints).total
    }

    fn terms(&self, joints: Tensor<5>) -> Tensor<2> {
        self.evaluate(joints).per_statement
    }

    fn error_until(&self, joints: Tensor<5>, until: usize) -> Tensor<1> {
        self.evaluate_until(joints, until).total
    }

    fn terms_until(&self, joints: Tensor<5>, until: usize) -> Tensor<2> {
        self.evaluate_until(joints, until).per_statement
    }

    fn active_frames(&self, frames: usize) -> Option<Vec<bool>> {
        Some(self.checked.ir.active_frames(frames))
    }
}

impl Program {
    /// Constant geometry the program names (walls, targets, regions), in world
    /// coordinates, for pictures and the viewer.
    pub fn overlays(&self) -> &[crate::scene::Overlay] {
        &self.checked.overlays
    }

    /// Joint-pair contacts the program asks for, with their frames, for the viewer.
    pub fn contacts(&self) -> &[crate::scene::Contact] {
        &self.checked.contacts
    }

    /// Errors of a batch of motions `[batch, people, frames, 22, 3]` (metres, Y up).
    ///
    /// # Panics
    /// If the tensor's shape does not fit the program or the evaluation is estimated above
    /// [`MAX_EVAL_ELEMENTS`]; [`Program::try_evaluate`] reports both.
    pub fn evaluate(&self, joints: Tensor<5>) -> Evaluation {
        match self.try_evaluate(joints) {
            Ok(e) => e,
            Err(e) => panic!("{}: {e}", self.name),
        }
    }

    /// Errors of a batch of motions, or why the tensor does not fit, or a refusal when the
    /// evaluation is estimated above [`MAX_EVAL_ELEMENTS`] tensor elements.
    pub fn try_evaluate(&self, joints: Tensor<5>) -> Result<Evaluation, EvalError> {
        self.try_evaluate_with_limit(joints, MAX_EVAL_ELEMENTS)
    }

    /// [`Program::try_evaluate`] with another element limit. The cost is estimated for the
    /// tensor's batch and frame count (not the declared length) before any tensor work.
    pub fn try_evaluate_with_limit(
        &self,
        joints: Tensor<5>,
        max_elements: usize,
    ) -> Result<Evaluation, EvalError> {
        let [batch, _, frames, _, _] = joints.dims();
        let cost = self.checked.ir.cost_estimate_at(frames);
        let elements = cost.elements(batch);
        if elements > max_elements {
            return Err(EvalError::TooCostly {
                program: self.name.clone(),
                batch,
                frames,
                ops: cost.ops,
                elements,
                limit: max_elements,
            });
        }
        eval::evaluate(&self.checked.ir, joints, &self.cache)
    }

    /// [`Program::evaluate`] counting only the frames before `until` (each statement's
    /// mean over its frames before it; 0 for a statement with none): a window of a long
    /// motion.
    ///
    /// # Panics
    /// As [`Program::evaluate`].
    pub fn evaluate_until(&self, joints: Tensor<5>, until: usize) -> Evaluation {
        let [batch, _, frames, _, _] = joints.dims();
        let cost = self.checked.ir.cost_estimate_at(frames);
        if cost.elements(batch) > MAX_EVAL_ELEMENTS {
            panic!(
                "{}: evaluating {batch} motion(s) of {frames} frames exceeds the element limit",
                self.name
            );
        }
        match eval::evaluate_until(&self.checked.ir, joints, &self.cache, until) {
            Ok(e) => e,
            Err(e) => panic!("{}: {e}", self.name),
        }
    }

    /// Each statement's error per frame (host values, no gradient), in statement order:
    /// what [`Program::evaluate`] averages.
    pub fn evaluate_frames(&self, joints: Tensor<5>) -> Result<Vec<FrameErrors>, EvalError> {
        eval::evaluate_frames(&self.checked.ir, joints, &self.cache)
    }

    /// The statements, in the column order of [`Evaluation::per_statement`].
    pub fn statements(&self) -> Vec<StatementInfo> {
        self.checked
            .ir
            .statements
            .iter()
            .map(|s| StatementInfo {
                label: s.label.clone(),
                line: s.line,
                unit: s.unit.clone(),
                weight: s.weight,
                lanes: s.lanes,
                span: s.span,
            })
            .collect()
    }

    /// The program's name (file name).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The `prompt` line.
    pub fn prompt(&self) -> Option<&str> {
        self.checked.header.prompt.as_deref()
    }

    /// One prompt per person (the person's own, else the program's); for a timeline, the
    /// prompt of its first span ([`Program::timelines`] has them all).
    pub fn prompts(&self) -> Vec<Option<String>> {
        let h = &self.checked.header;
        h.people
            .iter()
            .map(|p| p.prompt.clone().or_else(|| h.prompt.clone()))
            .collect()
    }

    /// Each person's timeline (tensor order): their prompts in time order with the frames
    /// each covers at [`Program::length`], together covering `0..length` (consecutive ones
    /// may overlap, a blend). A prompt without a span is one entry `0..length`; a person
    /// without any prompt (their own or the program's) has none.
    pub fn timelines(&self) -> Vec<Vec<TimedPrompt>> {
        self.checked
            .header
            .people
            .iter()
            .map(|p| p.timeline.clone())
            .collect()
    }

    /// Length in frames (20 fps).
    pub fn length(&self) -> usize {
        self.checked.header.length
    }

    /// The people, in tensor order (`me` for single-person programs).
    pub fn people(&self) -> &[PersonInfo] {
        &self.checked.header.people
    }

    /// Where each person starts (the `spacing` line, else the default placements).
    pub fn placements(&self) -> Vec<crate::scene::Placement> {
        self.checked.ir.start_placements()
    }

    /// Parameters after overrides.
    pub fn params(&self) -> &[ParamInfo] {
        &self.checked.header.params
    }

    /// Prompt, length, people and params.
    pub fn header(&self) -> &Header {
        &self.checked.header
    }

    /// Estimated evaluation cost at the declared length.
    pub fn cost_estimate(&self) -> CostEstimate {
        self.checked.cost
    }

    /// The lowered op list.
    pub fn ir(&self) -> &ir::Ir {
        &self.checked.ir
    }

    /// Warnings found while checking.
    pub fn warnings(&self) -> &Diagnostics {
        &self.warnings
    }
}
