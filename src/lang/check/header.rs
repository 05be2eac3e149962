//! Header items and definitions: people, prompt (timelines are `timeline.rs`'s),
//! parameters (with `--set` overrides), length, user functions (duplicates, reserved
//! names, recursion), and the library's functions and constants.

use super::units::Unit;
use super::values::{Cx, Val};
use super::{Checker, MAX_LENGTH, MODEL_MAX_FRAMES, ParamInfo, PersonInfo};
use crate::lang::diag::{Diagnostic, did_you_mean};
use crate::lang::syntax::ast::*;
use crate::skeleton::joint_index;
use std::collections::{HashMap, HashSet};

/// Closest start spacing (m): two torsos side by side.
const MIN_SPACING: f64 = 0.4;
/// Farthest start spacing (m).
const MAX_SPACING: f64 = 20.0;

/// Names a person, parameter or function may not take.
pub const RESERVED: &[&str] = &[
    "x", "y", "z", "xz", "me", "joints", "people", "start", "mid", "end", "time", "true", "false",
];

impl<'a> Checker<'a> {
    /// Registers the library's functions and constants.
    pub fn load_library(&mut self, library: &'a [Module]) {
        for module in library {
            for item in &module.items {
                match item {
                    Item::Def(f) => {
                        self.lib_fns.insert(f.name.name.as_str(), f);
                    }
                    Item::Stmt(Stmt::Let { name, value, .. }) => {
                        self.lib_lets.insert(name.name.as_str(), value);
                    }
                    _ => {}
                }
            }
        }
    }

    /// Processes people, prompt, definitions, parameters and length.
    pub fn header_items(&mut self, module: &'a Module, overrides: &[(String, f64)]) {
        let cx = Cx::top();
        let mut seen_people: Option<Span> = None;
        let mut seen_prompt: Option<Span> = None;
        for item in &module.items {
            match item {
                Item::People { people, span } => {
                    if let Some(first) = seen_people {
                        self.duplicate_header(&cx, "people", *span, first);
                        continue;
                    }
                    seen_people = Some(*span);
                    self.declare_people(people, &cx);
                }
                // The program's prompt for the whole motion; timeline prompts (with a
                // span or a person) are read by `declare_timelines`.
                Item::Prompt {
                    person: None,
                    range: None,
                    text,
                    span,
                } => {
                    if let Some(first) = seen_prompt {
                        self.duplicate_header(&cx, "prompt", *span, first);
                    }
                    seen_prompt = Some(*span);
                    self.header.prompt = Some(text.clone());
                }
                _ => {}
            }
        }
        if self.header.people.is_empty() {
            self.header.people.push(PersonInfo {
                name: "me".into(),
                prompt: self.header.prompt.clone(),
                timeline: Vec::new(),
            });
        }
        self.multi = self.header.people.len() > 1;
        self.declare_functions(module, &cx);
        for item in &module.items {
            if let Item::Param { name, value, span } = item {
                self.declare_param(name, value, *span, overrides, &cx);
            }
        }
        for (name, _) in overrides {
            if !self.header.params.iter().any(|p| &p.name == name) {
                let mut d = Diagnostic::error(
                    crate::lang::codes::UNKNOWN_PARAM,
                    Span::new(0, 0),
                    format!("`--set {name}=…` names no parameter of this program"),
                );
                let names: Vec<&str> = self.header.params.iter().map(|p| p.name.as_str()).collect();
                d = match did_you_mean(name, names.iter().copied()) {
                    Some(s) => d.help(format!("did you mean `{s}`?")),
                    None if names.is_empty() => d.help("this program declares no `param`s"),
                    None => d.help(format!("its parameters are: {}", names.join(", "))),
                };
                self.diags.push(d);
            }
        }
        let length_ok = self.declare_length(module, &cx);
        self.declare_spacing(module, &cx);
        self.declare_starts(module, &cx);
        self.declare_timelines(module, length_ok, &cx);
    }

    pub(super) fn duplicate_header(&mut self, cx: &Cx, what: &str, span: Span, first: Span) {
        let line = self.line_of(first.start);
        self.error(
            cx,
            crate::lang::codes::DUPLICATE,
            span,
            format!("a second `{what}` line"),
        )
        .label("duplicate")
        .help(format!(
            "`{what}` is already given on line {line}; keep one"
        ));
    }

    fn declare_people(&mut self, people: &[PersonDecl], cx: &Cx) {
        for p in people {
            let n = p.name.name.as_str();
            if joint_index(n).is_some() || RESERVED.contains(&n) {
                self.error(
                    cx,
                    crate::lang::codes::RESERVED_NAME,
                    p.name.span,
                    format!("`{n}` cannot name a person"),
                )
                .label("reserved")
                .help(
                    "it is a joint name or a keyword; use a short name such as `a`, `b`, `alice`",
                );
                continue;
            }
            if self.header.people.iter().any(|q| q.name == n) {
                self.error(
                    cx,
                    crate::lang::codes::DUPLICATE,
                    p.name.span,
                    format!("person `{n}` is declared twice"),
                )
                .label("duplicate")
                .help("give each person a different name");
                continue;
            }
            self.header.people.push(PersonInfo {
                name: n.to_string(),
                prompt: p.prompt.clone(),
                timeline: Vec::new(),
            });
        }
    }

    fn declare_functions(&mut self, module: &'a Module, cx: &Cx) {
        for item in &module.items {
            let Item::Def(f) = item else { continue };
            let n = f.name.name.as_str();
            if super::builtins::find(n).is_some()
                || RESERVED.contains(&n)
                || joint_index(n).is_some()
            {
                self.error(
                    cx,
                    crate::lang::codes::RESERVED_NAME,
                    f.name.span,
                    format!("`{n}` is a built-in name"),
                )
                .label("cannot be redefined")
                .help("choose another function name");
                continue;
            }
            if let Some(prev) = self.user_fns.get(n) {
                let line = self.line_of(prev.span.start);
                self.error(
                    cx,
                    crate::lang::codes::DUPLICATE,
                    f.name.span,
                    format!("function `{n}` is defined twice"),
                )
                .label("second definition")
                .help(format!(
                    "the first definition is on line {line}; rename or remove one"
                ));
                continue;
            }
            let mut seen = HashSet::new();
            for p in &f.params {
                if !seen.insert(p.name.as_str()) {
                    self.error(
                        cx,
                        crate::lang::codes::DUPLICATE,
                        p.span,
                        format!("parameter `{}` appears twice", p.name),
                    )
                    .label("duplicate")
                    .help("give each parameter a different name");
                }
            }
            self.user_fns.insert(n, f);
        }
        self.check_recursion(cx);
    }

    /// Rejects user functions that call themselves, directly or through others.
    fn check_recursion(&mut self, cx: &Cx) {
        let mut graph: HashMap<&'a str, Vec<&'a str>> = HashMap::new();
        for (&name, f) in &self.user_fns {
            let mut calls = Vec::new();
            match &f.body {
                FnBody::Expr(e) => calls_in(e, &mut calls),
                FnBody::Block(items) => {
                    for i in items {
                        match i {
                            FnItem::Let { value, .. } | FnItem::Expr(value) => {
                                calls_in(value, &mut calls)
                            }
                        }
                    }
                }
            }
            calls.extend(self.calls_through_lets(f));
            calls.retain(|c| self.user_fns.contains_key(c));
            graph.insert(name, calls);
        }
        let mut names: Vec<&'a str> = graph.keys().copied().collect();
        names.sort();
        let mut reported: HashSet<&'a str> = HashSet::new();
        for &start in &names {
            if let Some(cycle) = find_cycle(&graph, start) {
                if cycle.iter().any(|n| reported.contains(n)) {
                    continue;
                }
                reported.extend(cycle.iter().copied());
                let span = self.user_fns[start].name.span;
                let path = cycle.join(" → ");
                self.error(cx, crate::lang::codes::RECURSION, span, format!("function `{start}` calls itself: {path}"))
                    .label("recursive")
                    .help("mprog has no recursion; repeat work with `for` over a list, or write the steps out");
            }
        }
        for n in reported {
            self.user_fns.remove(n);
            self.poisoned.insert(n);
        }
    }

    fn declare_param(
        &mut self,
        name: &Ident,
        value: &'a Expr,
        span: Span,
        overrides: &[(String, f64)],
        cx: &Cx,
    ) {
        let n = name.name.as_str();
        if joint_index(n).is_some()
            || RESERVED.contains(&n)
            || self.header.people.iter().any(|p| p.name == n)
            || super::builtins::find(n).is_some()
        {
            self.error(
                cx,
                crate::lang::codes::RESERVED_NAME,
                name.span,
                format!("`{n}` cannot name a parameter"),
            )
            .label("already means something")
            .help("it is a joint, person, keyword or built-in; choose another name");
            return;
        }
        if self.header.params.iter().any(|p| p.name == n) {
            self.error(
                cx,
                crate::lang::codes::DUPLICATE,
                name.span,
                format!("parameter `{n}` is declared twice"),
            )
            .label("duplicate")
            .help("keep one `param` line per name");
            return;
        }
        let val = self.expr(value, &None, cx);
        let Val::Num(num) = val else {
            if val != Val::Error {
                self.error(
                    cx,
                    crate::lang::codes::TYPE_MISMATCH,
                    value.span,
                    format!(
                        "a parameter must be a number or vector, not {}",
                        val.describe()
                    ),
                )
                .help("write e.g. `param diameter = 0.4 m` or `param target = [1, 0, 2]`");
            }
            return;
        };
        let Some(values) = self
            .b
            .const_of(num.node)
            .map(|v| v.iter().map(|&x| f64::from(x)).collect::<Vec<f64>>())
        else {
            self.error(
                cx,
                crate::lang::codes::NOT_CONSTANT,
                value.span,
                "a parameter's value must be constant",
            )
            .label("depends on the motion")
            .help("parameters are fixed numbers; use `let` for values computed from joints");
            return;
        };
        let scale = match &value.kind {
            ExprKind::Number(_, Some(u)) => super::expr::unit_scale(*u),
            _ => 1.0,
        };
        let mut values = values;
        if let Some((_, v)) = overrides.iter().rev().find(|(k, _)| k == n) {
            if num.vector {
                self.error(
                    cx,
                    crate::lang::codes::BAD_OVERRIDE,
                    name.span,
                    format!("`--set {n}=…` cannot replace a vector"),
                )
                .help("only scalar parameters can be set from the command line");
            } else if !v.is_finite() || !((v * scale) as f32).is_finite() {
                self.error(
                    cx,
                    crate::lang::codes::BAD_OVERRIDE,
                    name.span,
                    format!("`--set {n}` needs a finite number (|x| ≤ 3.4e38), got {v}"),
                )
                .help("e.g. `--set diameter=0.5`");
            } else {
                values = vec![v * scale];
            }
        }
        let node = self.b.konst(&values, value.span);
        self.header.params.push(ParamInfo {
            name: n.to_string(),
            value: values,
            unit: num.unit.to_string(),
            scale,
            node,
            unit_value: num.unit,
            span,
        });
    }

    /// `spacing 1 m`: a constant distance, for two or more people.
    fn declare_spacing(&mut self, module: &'a Module, cx: &Cx) {
        let mut first: Option<Span> = None;
        for item in &module.items {
            let Item::Spacing { value, span } = item else {
                continue;
            };
            if let Some(f) = first {
                self.duplicate_header(cx, "spacing", *span, f);
                continue;
            }
            first = Some(*span);
            if !self.multi {
                self.error(
                    cx,
                    crate::lang::codes::SPACING_NEEDS_PEOPLE,
                    *span,
                    "`spacing` places several people, and this program has one",
                )
                .label("one person")
                .help("declare the people first: `people a \"…\", b \"…\"`, or remove this line");
                continue;
            }
            let val = self.expr(value, &None, cx);
            let metres = match val {
                Val::Num(n) if !n.vector && (n.unit == Unit::M || n.unit.free) => {
                    // Rounded to the millimetre: the constant is stored in f32.
                    self.b
                        .const_of(n.node)
                        .map(|v| (f64::from(v[0]) * 1e3).round() / 1e3)
                }
                Val::Error => continue,
                _ => {
                    let what = match val {
                        Val::Num(n) if !n.vector => format!("a quantity in {}", n.unit),
                        _ => val.describe().to_string(),
                    };
                    self.error(
                        cx,
                        crate::lang::codes::TYPE_MISMATCH,
                        value.span,
                        format!("`spacing` needs a distance in metres, not {what}"),
                    )
                    .help("write e.g. `spacing 1 m` or `spacing 80 cm`");
                    continue;
                }
            };
            let Some(metres) = metres else {
                self.error(
                    cx,
                    crate::lang::codes::NOT_CONSTANT,
                    value.span,
                    "the spacing must be constant",
                )
                .label("depends on the motion")
                .help("write a fixed distance such as `spacing 1 m`");
                continue;
            };
            if !(MIN_SPACING..=MAX_SPACING).contains(&metres) {
                self.error(
                    cx,
                    crate::lang::codes::BAD_SPACING,
                    value.span,
                    format!("a spacing of {metres} m is out of range"),
                )
                .label("here")
                .help(format!(
                    "people start {MIN_SPACING} m to {MAX_SPACING} m apart; closer than that their bodies overlap"
                ));
                continue;
            }
            self.header.spacing = Some(metres);
        }
    }

    /// Reads `length` into `header.length`; false when the line is wrong (the default
    /// length stands in).
    fn declare_length(&mut self, module: &'a Module, cx: &Cx) -> bool {
        let mut length = None;
        for item in &module.items {
            let Item::Length { value, span } = item else {
                continue;
            };
            if let Some((_, first)) = length {
                self.duplicate_header(cx, "length", *span, first);
                continue;
            }
            let Some(t) = self.time_point(value, &None, cx) else {
                length = Some((None, *span));
                continue;
            };
            if t.fraction != 0.0 {
                self.error(
                    cx,
                    crate::lang::codes::BAD_LENGTH,
                    value.span,
                    "the length cannot be relative to itself",
                )
                .help("write `length 6s` or `length 120 frames`");
                length = Some((None, *span));
                continue;
            }
            let frames = t.frames.round();
            if !(2.0..=MAX_LENGTH as f64).contains(&frames) {
                self.error(
                    cx,
                    crate::lang::codes::BAD_LENGTH,
                    value.span,
                    format!("a length of {frames} frames is out of range"),
                )
                .label("here")
                .help(format!(
                    "lengths go from 2 frames to {MAX_LENGTH} frames ({} s)",
                    MAX_LENGTH / 20
                ));
                length = Some((None, *span));
                continue;
            }
            length = Some((Some(frames as usize), *span));
        }
        let ok = !matches!(length, Some((None, _)));
        self.header.length = match length {
            Some((Some(f), _)) => f,
            Some((None, _)) => MODEL_MAX_FRAMES,
            None => {
                self.diags.push(
                    Diagnostic::warning(
                        crate::lang::codes::MISSING_LENGTH,
                        Span::new(0, 0),
                        "no `length` line; using 196 frames (9.8 s)",
                    )
                    .help("add e.g. `length 6s` or `length 120 frames`"),
                );
                MODEL_MAX_FRAMES
            }
        };
        ok
    }
}

/// Names of all functions called in `e`.
fn calls_in<'a>(e: &'a Expr, out: &mut Vec<&'a str>) {
    match &e.kind {
        ExprKind::Call(name, args) => {
            out.push(name.name.as_str());
            args.iter().for_each(|a| calls_in(a, out));
        }
        ExprKind::List(items) => items.iter().for_each(|a| calls_in(a, out)),
        ExprKind::Member(a, _) | ExprKind::Unary(_, a) => calls_in(a, out),
        ExprKind::At(a, b) | ExprKind::Binary(_, a, b) => {
            calls_in(a, out);
            calls_in(b, out);
        }
        ExprKind::Number(..) | ExprKind::Name(_) | ExprKind::Error => {}
    }
}

/// A call path from `start` back to itself, if there is one.
fn find_cycle<'a>(graph: &HashMap<&'a str, Vec<&'a str>>, start: &'a str) -> Option<Vec<&'a str>> {
    // Iterative DFS keeping the current path.
    let mut stack: Vec<(&'a str, usize)> = vec![(start, 0)];
    let mut on_path: Vec<&'a str> = vec![start];
    let mut visited: HashSet<&'a str> = HashSet::new();
    while let Some((node, i)) = stack.pop() {
        let next = graph.get(node).and_then(|v| v.get(i)).copied();
        match next {
            None => {
                on_path.pop();
            }
            Some(n) => {
                stack.push((node, i + 1));
                if n == start {
                    let mut cycle = on_path.clone();
                    cycle.push(start);
                    return Some(cycle);
                }
                if visited.insert(n) {
                    stack.push((n, 0));
                    on_path.push(n);
                }
            }
        }
    }
    None
}
