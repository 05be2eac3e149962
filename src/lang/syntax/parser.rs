//! pest parse tree → AST. The only module that touches pest: it runs the grammar, applies
//! operator precedence with a Pratt parser, and turns pest errors into diagnostics.
//! Input limits (size, bracket depth, expression depth) are enforced here so that no
//! input can exhaust the stack later.

use super::ast::*;
use crate::lang::diag::Diagnostic;
use pest::Parser;
use pest::iterators::Pair;
use pest::pratt_parser::{Assoc, Op, PrattParser};
use std::cell::RefCell;
use std::sync::LazyLock;

#[derive(pest_derive::Parser)]
#[grammar = "../grammar/mprog.pest"]
struct MprogParser;

/// Largest accepted source, in bytes.
pub const MAX_SOURCE_BYTES: usize = 256 * 1024;
/// Deepest accepted nesting of `( [ {`.
pub const MAX_BRACKET_DEPTH: usize = 48;
/// Deepest accepted expression tree (operators included).
pub const MAX_EXPR_DEPTH: usize = 96;

static PRATT: LazyLock<PrattParser<Rule>> = LazyLock::new(|| {
    PrattParser::new()
        .op(Op::infix(Rule::or_op, Assoc::Left))
        .op(Op::infix(Rule::and_op, Assoc::Left))
        .op(Op::prefix(Rule::not_op))
        .op(Op::infix(Rule::eq, Assoc::Left)
            | Op::infix(Rule::lt, Assoc::Left)
            | Op::infix(Rule::le, Assoc::Left)
            | Op::infix(Rule::gt, Assoc::Left)
            | Op::infix(Rule::ge, Assoc::Left))
        .op(Op::infix(Rule::add, Assoc::Left) | Op::infix(Rule::sub, Assoc::Left))
        .op(Op::infix(Rule::mul, Assoc::Left) | Op::infix(Rule::div, Assoc::Left))
        .op(Op::prefix(Rule::neg))
        .op(Op::postfix(Rule::member) | Op::postfix(Rule::at_time))
});

/// Parses a whole file. On a syntax error the module is empty and the error is returned.
pub fn source_to_ast(source: &str) -> (Module, Vec<Diagnostic>) {
    if let Some(d) = check_limits(source) {
        return (Module::default(), vec![d]);
    }
    let pairs = match MprogParser::parse(Rule::program, source) {
        Ok(mut p) => p.next().map(|p| p.into_inner()),
        Err(e) => return (Module::default(), vec![syntax_error(e, source)]),
    };
    let builder = Builder {
        source,
        diags: RefCell::new(Vec::new()),
    };
    let mut module = Module::default();
    for pair in pairs.into_iter().flatten() {
        if let Some(item) = builder.item(pair) {
            module.items.push(item);
        }
    }
    (module, builder.diags.into_inner())
}

/// Refuses inputs too large or too deeply bracketed to parse safely.
fn check_limits(source: &str) -> Option<Diagnostic> {
    if source.len() > MAX_SOURCE_BYTES {
        return Some(
            Diagnostic::error(
                crate::lang::codes::TOO_LARGE,
                Span::new(0, 0),
                format!(
                    "the program is {} bytes; the limit is {MAX_SOURCE_BYTES}",
                    source.len()
                ),
            )
            .help("split the task into smaller programs or use functions and loops"),
        );
    }
    let mut depth = 0usize;
    let mut in_string = false;
    let mut in_comment = false;
    for (i, c) in source.char_indices() {
        match c {
            '\n' => {
                in_comment = false;
                in_string = false;
            }
            _ if in_comment => {}
            '"' => in_string = !in_string,
            _ if in_string => {}
            '#' => in_comment = true,
            '(' | '[' | '{' => {
                depth += 1;
                if depth > MAX_BRACKET_DEPTH {
                    return Some(
                        Diagnostic::error(
                            crate::lang::codes::TOO_DEEP,
                            Span::new(i, i + 1),
                            format!(
                                "brackets are nested more than {MAX_BRACKET_DEPTH} levels deep"
                            ),
                        )
                        .label("too deep")
                        .help("flatten the expression with `let` bindings or functions"),
                    );
                }
            }
            ')' | ']' | '}' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    None
}

/// Human names for grammar rules in "expected …" messages.
fn rule_name(rule: &Rule) -> String {
    match rule {
        Rule::EOI => "end of file",
        Rule::expr | Rule::time_list => "an expression",
        Rule::ident => "a name",
        Rule::number | Rule::num_lit => "a number",
        Rule::unit => "a unit (m, cm, s, frames, deg, %)",
        Rule::per_s => "`/s`",
        Rule::string => "a quoted string",
        Rule::block => "`{`",
        Rule::weight_suffix => "`weight`",
        Rule::or_op | Rule::and_op => "`and`/`or`",
        Rule::eq | Rule::lt | Rule::le | Rule::gt | Rule::ge => "a comparison",
        Rule::add | Rule::sub | Rule::mul | Rule::div => "an operator",
        Rule::member => "`.`",
        Rule::at_time => "`@`",
        Rule::param_list => "parameter names",
        Rule::person | Rule::prompt_who => "a person name",
        Rule::prompt_span => "a time span (`0s..8s`)",
        Rule::start_place | Rule::start_at | Rule::start_facing | Rule::kw_facing => {
            "`at [x, 0, z]` or `facing [dx, 0, dz]`"
        }
        Rule::kw_start => "`start`",
        Rule::fn_block => "`{`",
        Rule::prompt_decl
        | Rule::length_decl
        | Rule::spacing_decl
        | Rule::start_decl
        | Rule::param_decl
        | Rule::people_decl
        | Rule::def_decl
        | Rule::let_stmt
        | Rule::always_block
        | Rule::at_block
        | Rule::during_block
        | Rule::for_stmt
        | Rule::if_stmt
        | Rule::weight_block
        | Rule::minimize_stmt
        | Rule::maximize_stmt
        | Rule::expr_stmt => "a statement",
        other => return format!("{other:?}"),
    }
    .to_string()
}

fn syntax_error(e: pest::error::Error<Rule>, source: &str) -> Diagnostic {
    use pest::error::{ErrorVariant, InputLocation};
    let (start, end) = match e.location {
        InputLocation::Pos(p) => (p, p),
        InputLocation::Span((a, b)) => (a, b),
    };
    let found =
        source[start.min(source.len())..]
            .chars()
            .next()
            .map_or("end of file".to_string(), |c| match c {
                '\n' => "end of line".to_string(),
                c => format!("`{c}`"),
            });
    let (message, expected) = match &e.variant {
        ErrorVariant::ParsingError { positives, .. } => {
            let mut names: Vec<String> = positives.iter().map(rule_name).collect();
            names.sort();
            names.dedup();
            let expected = match names.len() {
                0 => String::new(),
                1 => names[0].clone(),
                _ => {
                    let last = names.pop().unwrap_or_default();
                    format!("{} or {last}", names.join(", "))
                }
            };
            (format!("unexpected {found}"), expected)
        }
        ErrorVariant::CustomError { message } => (message.clone(), String::new()),
    };
    let end = if end == start {
        (start + found_len(source, start)).min(source.len())
    } else {
        end
    };
    let mut d = Diagnostic::error(crate::lang::codes::SYNTAX, Span::new(start, end), message);
    if !expected.is_empty() {
        d = d.label(format!("expected {expected}"));
    }
    d.help(syntax_hint(source, start))
}

fn found_len(source: &str, at: usize) -> usize {
    source
        .get(at..)
        .and_then(|s| s.chars().next())
        .map_or(0, char::len_utf8)
}

/// A hint for the most common slips, judged from the text around the error.
fn syntax_hint(source: &str, at: usize) -> String {
    let rest = source.get(at..).unwrap_or("");
    let line_start = source[..at.min(source.len())]
        .rfind('\n')
        .map_or(0, |i| i + 1);
    let line = source[line_start..].lines().next().unwrap_or("");
    let opened = source.matches('{').count();
    if rest.is_empty() && opened > source.matches('}').count() {
        "a `{` is never closed; add the matching `}`".into()
    } else if rest.starts_with('=') && !rest.starts_with("==") {
        "compare with `==`; bind names with `let name = value`".into()
    } else if rest.starts_with("&&") || rest.starts_with("||") || rest.starts_with('!') {
        "logical operators are the words `and`, `or`, `not`".into()
    } else if rest.starts_with('{') && line.trim_start().starts_with("def") {
        "a function is `def name(a, b) = expr` or `def name(a, b) { … }`".into()
    } else if line.trim_start().starts_with("prompt") {
        "a prompt is `prompt \"text\"`, or one span of a timeline: `prompt 0s..8s \"text\"` \
         (`prompt a 0s..8s \"text\"` for person `a`)"
            .into()
    } else if line.trim_start().starts_with("at") || line.trim_start().starts_with("during") {
        "time blocks are `at 0, 50%, end { … }`, `at 2s { … }` or `during 1s..2s { … }`".into()
    } else {
        "one statement per line; blocks are `always { … }`, `at t { … }`, `during a..b { … }`, \
         `for j in [..] { … }`, `if cond { … }`"
            .into()
    }
}

/// Turns pest pairs into AST nodes; collects depth diagnostics.
struct Builder<'s> {
    source: &'s str,
    diags: RefCell<Vec<Diagnostic>>,
}

fn span_of(pair: &Pair<Rule>) -> Span {
    let s = pair.as_span();
    Span::new(s.start(), s.end())
}

impl Builder<'_> {
    fn item(&self, pair: Pair<Rule>) -> Option<Item> {
        let span = span_of(&pair);
        Some(match pair.as_rule() {
            Rule::prompt_decl => {
                let (mut person, mut range, mut text) = (None, None, String::new());
                for part in pair.into_inner() {
                    match part.as_rule() {
                        Rule::prompt_who => person = part.into_inner().next().map(ident),
                        Rule::prompt_span => {
                            let mut ends = part.into_inner();
                            let from = self.expr(ends.next()?);
                            range = Some((from, self.expr(ends.next()?)));
                        }
                        Rule::string => text = unescape(part.into_inner().next()?.as_str()),
                        _ => {}
                    }
                }
                Item::Prompt {
                    person,
                    range,
                    text,
                    span,
                }
            }
            Rule::length_decl => Item::Length {
                value: self.expr(pair.into_inner().next()?),
                span,
            },
            Rule::spacing_decl => Item::Spacing {
                value: self.expr(pair.into_inner().next()?),
                span,
            },
            Rule::param_decl => {
                let mut inner = pair.into_inner();
                let name = ident(inner.next()?);
                Item::Param {
                    name,
                    value: self.expr(inner.next()?),
                    span,
                }
            }
            Rule::people_decl => {
                let people = pair
                    .into_inner()
                    .filter_map(|p| {
                        let mut inner = p.into_inner();
                        let name = ident(inner.next()?);
                        let mut prompt = None;
                        let mut start = None;
                        for part in inner {
                            match part.as_rule() {
                                Rule::string => {
                                    prompt = part.into_inner().next().map(|s| unescape(s.as_str()))
                                }
                                Rule::start_place => start = Some(self.start_place(part)),
                                _ => {}
                            }
                        }
                        Some(PersonDecl {
                            name,
                            prompt,
                            start,
                        })
                    })
                    .collect();
                Item::People { people, span }
            }
            Rule::start_decl => Item::Start {
                place: self.start_place(
                    pair.into_inner()
                        .find(|p| p.as_rule() == Rule::start_place)?,
                ),
                span,
            },
            Rule::def_decl => Item::Def(self.def(pair)?),
            Rule::EOI => return None,
            _ => Item::Stmt(self.stmt(pair)?),
        })
    }

    /// `at [x, 0, z] facing [dx, 0, dz]` (either part may be missing).
    fn start_place(&self, pair: Pair<Rule>) -> StartPlace {
        let span = span_of(&pair);
        let mut place = StartPlace {
            at: None,
            facing: None,
            span,
        };
        for part in pair.into_inner() {
            let rule = part.as_rule();
            let Some(e) = part.into_inner().find(|p| p.as_rule() == Rule::expr) else {
                continue;
            };
            match rule {
                Rule::start_at => place.at = Some(self.expr(e)),
                Rule::start_facing => place.facing = Some(self.expr(e)),
                _ => {}
            }
        }
        place
    }

    fn def(&self, pair: Pair<Rule>) -> Option<FnDef> {
        let span = span_of(&pair);
        let mut inner = pair.into_inner();
        let name = ident(inner.next()?);
        let mut params = Vec::new();
        let mut body = None;
        for p in inner {
            match p.as_rule() {
                Rule::param_list => params = p.into_inner().map(ident).collect(),
                Rule::fn_block => {
                    let items = p
                        .into_inner()
                        .filter_map(|i| match i.as_rule() {
                            Rule::let_stmt => {
                                let mut li = i.into_inner();
                                let name = ident(li.next()?);
                                Some(FnItem::Let {
                                    name,
                                    value: self.expr(li.next()?),
                                })
                            }
                            Rule::expr => Some(FnItem::Expr(self.expr(i))),
                            _ => None,
                        })
                        .collect();
                    body = Some(FnBody::Block(items));
                }
                Rule::expr => body = Some(FnBody::Expr(self.expr(p))),
                _ => {}
            }
        }
        Some(FnDef {
            name,
            params,
            body: body?,
            doc: doc_above(self.source, span.start),
            span,
        })
    }

    fn block(&self, pair: Pair<Rule>) -> Vec<Stmt> {
        pair.into_inner().filter_map(|p| self.stmt(p)).collect()
    }

    fn weight(&self, pair: Option<Pair<Rule>>) -> Option<Expr> {
        pair.and_then(|p| p.into_inner().next())
            .map(|e| self.expr(e))
    }

    fn stmt(&self, pair: Pair<Rule>) -> Option<Stmt> {
        let span = span_of(&pair);
        let rule = pair.as_rule();
        let mut inner = pair.into_inner();
        Some(match rule {
            Rule::let_stmt => {
                let name = ident(inner.next()?);
                Stmt::Let {
                    name,
                    value: self.expr(inner.next()?),
                    span,
                }
            }
            Rule::always_block | Rule::at_block | Rule::during_block => {
                let kind = match rule {
                    Rule::always_block => TimeKind::Always,
                    Rule::at_block => {
                        TimeKind::At(inner.next()?.into_inner().map(|e| self.expr(e)).collect())
                    }
                    _ => {
                        let a = self.expr(inner.next()?);
                        TimeKind::During(a, self.expr(inner.next()?))
                    }
                };
                let mut weight = None;
                let mut body = Vec::new();
                for p in inner {
                    match p.as_rule() {
                        Rule::weight_suffix => weight = self.weight(Some(p)),
                        Rule::block => body = self.block(p),
                        _ => {}
                    }
                }
                Stmt::Time {
                    kind,
                    weight,
                    body,
                    span,
                }
            }
            Rule::for_stmt => {
                let var = ident(inner.next()?);
                let set = self.expr(inner.next()?);
                Stmt::For {
                    var,
                    set,
                    body: self.block(inner.next()?),
                    span,
                }
            }
            Rule::if_stmt => {
                let cond = self.expr(inner.next()?);
                let then = self.block(inner.next()?);
                let otherwise = inner.next().map(|p| match p.as_rule() {
                    Rule::if_stmt => self.stmt(p).into_iter().collect(),
                    _ => self.block(p),
                });
                Stmt::If {
                    cond,
                    then,
                    otherwise,
                    span,
                }
            }
            Rule::weight_block => {
                let weight = self.expr(inner.next()?);
                Stmt::Weight {
                    weight,
                    body: self.block(inner.next()?),
                    span,
                }
            }
            Rule::minimize_stmt | Rule::maximize_stmt => {
                let value = self.expr(inner.next()?);
                let sign = if rule == Rule::minimize_stmt {
                    1.0
                } else {
                    -1.0
                };
                Stmt::Minimize {
                    value,
                    sign,
                    weight: self.weight(inner.next()),
                    span,
                }
            }
            Rule::expr_stmt => {
                let value = self.expr(inner.next()?);
                Stmt::Constraint {
                    value,
                    weight: self.weight(inner.next()),
                    span,
                }
            }
            _ => return None,
        })
    }

    fn expr(&self, pair: Pair<Rule>) -> Expr {
        self.expr_depth(pair).0
    }

    /// Builds an expression and its depth bottom-up (no recursion along operator chains).
    fn expr_depth(&self, pair: Pair<Rule>) -> (Expr, usize) {
        let guard = |e: Expr, depth: usize| -> (Expr, usize) {
            if depth == MAX_EXPR_DEPTH + 1 {
                self.diags.borrow_mut().push(
                    Diagnostic::error(
                        crate::lang::codes::TOO_DEEP,
                        e.span,
                        format!("expression nested more than {MAX_EXPR_DEPTH} levels deep"),
                    )
                    .label("too deep")
                    .help("split it with `let` bindings"),
                );
            }
            if depth > MAX_EXPR_DEPTH {
                (
                    Expr {
                        kind: ExprKind::Error,
                        span: e.span,
                    },
                    depth,
                )
            } else {
                (e, depth)
            }
        };
        PRATT
            .map_primary(|p| self.primary(p))
            .map_prefix(|op, (rhs, d)| {
                let span = span_of(&op).to(rhs.span);
                let op = if op.as_rule() == Rule::neg {
                    UnOp::Neg
                } else {
                    UnOp::Not
                };
                guard(
                    Expr {
                        kind: ExprKind::Unary(op, Box::new(rhs)),
                        span,
                    },
                    d + 1,
                )
            })
            .map_postfix(|(lhs, d), op| {
                let span = lhs.span.to(span_of(&op));
                let rule = op.as_rule();
                let Some(arg) = op.into_inner().next() else {
                    return (
                        Expr {
                            kind: ExprKind::Error,
                            span,
                        },
                        d,
                    );
                };
                let kind = if rule == Rule::member {
                    ExprKind::Member(Box::new(lhs), ident(arg))
                } else {
                    let (t, td) = self.primary(arg);
                    return guard(
                        Expr {
                            kind: ExprKind::At(Box::new(lhs), Box::new(t)),
                            span,
                        },
                        d.max(td) + 1,
                    );
                };
                guard(Expr { kind, span }, d + 1)
            })
            .map_infix(|(lhs, ld), op, (rhs, rd)| {
                let span = lhs.span.to(rhs.span);
                let op = match op.as_rule() {
                    Rule::or_op => BinOp::Or,
                    Rule::and_op => BinOp::And,
                    Rule::eq => BinOp::Eq,
                    Rule::lt => BinOp::Lt,
                    Rule::le => BinOp::Le,
                    Rule::gt => BinOp::Gt,
                    Rule::ge => BinOp::Ge,
                    Rule::add => BinOp::Add,
                    Rule::sub => BinOp::Sub,
                    Rule::mul => BinOp::Mul,
                    _ => BinOp::Div,
                };
                let kind = ExprKind::Binary(op, Box::new(lhs), Box::new(rhs));
                guard(Expr { kind, span }, ld.max(rd) + 1)
            })
            .parse(pair.into_inner())
    }

    fn primary(&self, pair: Pair<Rule>) -> (Expr, usize) {
        let span = span_of(&pair);
        let leaf = |kind| (Expr { kind, span }, 1);
        match pair.as_rule() {
            Rule::number => {
                let mut inner = pair.into_inner();
                let value = inner.next().and_then(|n| n.as_str().parse::<f64>().ok());
                let unit_pair = inner.next();
                let unit_end = unit_pair.as_ref().map_or(span.end, |u| u.as_span().end());
                // `180 deg/s` is `180 deg / 1 s`: a rate, in the units' own arithmetic.
                let per_s = inner.next().map(|p| span_of(&p));
                let unit = unit_pair.map(|u| match u.as_str() {
                    "m" => UnitLit::M,
                    "cm" => UnitLit::Cm,
                    "mm" => UnitLit::Mm,
                    "s" => UnitLit::S,
                    "ms" => UnitLit::Ms,
                    "frame" | "frames" => UnitLit::Frames,
                    "deg" => UnitLit::Deg,
                    "rad" => UnitLit::Rad,
                    _ => UnitLit::Percent,
                });
                match value {
                    Some(v) if v.is_finite() => match per_s {
                        None => leaf(ExprKind::Number(v, unit)),
                        Some(per) => {
                            let num = Expr {
                                kind: ExprKind::Number(v, unit),
                                span: Span::new(span.start, unit_end),
                            };
                            let one_s = Expr {
                                kind: ExprKind::Number(1.0, Some(UnitLit::S)),
                                span: per,
                            };
                            let kind = ExprKind::Binary(BinOp::Div, Box::new(num), Box::new(one_s));
                            (Expr { kind, span }, 2)
                        }
                    },
                    _ => {
                        self.diags.borrow_mut().push(
                            Diagnostic::error(
                                crate::lang::codes::BAD_NUMBER,
                                span,
                                "number out of range",
                            )
                            .help("write a finite number such as `1.5` or `2e3`"),
                        );
                        leaf(ExprKind::Error)
                    }
                }
            }
            Rule::ident => leaf(ExprKind::Name(pair.as_str().to_string())),
            Rule::paren => match pair.into_inner().next() {
                Some(e) => self.expr_depth(e),
                None => leaf(ExprKind::Error),
            },
            Rule::expr => self.expr_depth(pair),
            Rule::list => {
                let (items, depth) = self.exprs(pair.into_inner());
                (
                    Expr {
                        kind: ExprKind::List(items),
                        span,
                    },
                    depth + 1,
                )
            }
            Rule::call => {
                let mut inner = pair.into_inner();
                let Some(name) = inner.next().map(ident) else {
                    return leaf(ExprKind::Error);
                };
                let (args, depth) = self.exprs(inner);
                (
                    Expr {
                        kind: ExprKind::Call(name, args),
                        span,
                    },
                    depth + 1,
                )
            }
            _ => leaf(ExprKind::Error),
        }
    }

    fn exprs(&self, pairs: pest::iterators::Pairs<Rule>) -> (Vec<Expr>, usize) {
        let mut depth = 0;
        let items = pairs
            .map(|p| {
                let (e, d) = self.expr_depth(p);
                depth = depth.max(d);
                e
            })
            .collect();
        (items, depth)
    }
}

fn ident(pair: Pair<Rule>) -> Ident {
    Ident {
        name: pair.as_str().to_string(),
        span: span_of(&pair),
    }
}

fn unescape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut chars = s.chars();
    while let Some(c) = chars.next() {
        if c == '\\' {
            match chars.next() {
                Some('n') => out.push('\n'),
                Some('t') => out.push('\t'),
                Some(other) => out.push(other),
                None => {}
            }
        } else {
            out.push(c);
        }
    }
    out
}

/// The `##` comment lines directly above byte offset `at`, without the markers.
fn doc_above(source: &str, at: usize) -> String {
    let before = &source[..at.min(source.len())];
    // The first reversed line is the text before `def` on its own line (usually empty).
    let mut lines: Vec<&str> = Vec::new();
    for line in before
        .lines()
        .rev()
        .skip(usize::from(!before.ends_with('\n')))
    {
        match line.trim_start().strip_prefix("##") {
            Some(doc) => lines.push(doc.strip_prefix(' ').unwrap_or(doc)),
            None => break,
        }
    }
    lines.reverse();
    lines.join("\n")
}
