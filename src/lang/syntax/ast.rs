//! The abstract syntax tree of a `.mprog` file: what the parser produces and the checker
//! consumes. Nodes carry byte spans into their source and no types; names are unresolved.

use serde::Serialize;

/// A byte range `[start, end)` in one source text.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, serde::Deserialize)]
pub struct Span {
    /// First byte.
    pub start: usize,
    /// One past the last byte.
    pub end: usize,
}

impl Span {
    /// A span from two byte offsets.
    pub fn new(start: usize, end: usize) -> Self {
        Span { start, end }
    }

    /// The smallest span covering both.
    pub fn to(self, other: Span) -> Span {
        Span::new(self.start.min(other.start), self.end.max(other.end))
    }
}

/// A name with its position.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Ident {
    /// The name as written.
    pub name: String,
    /// Where it was written.
    pub span: Span,
}

/// A parsed file: header lines, definitions and statements in source order.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Module {
    /// Top-level items.
    pub items: Vec<Item>,
}

/// One top-level item.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum Item {
    /// `prompt "…"`, `prompt 0s..8s "…"` (a span of the timeline) or
    /// `prompt a 0s..8s "…"` (a span of person `a`'s timeline).
    Prompt {
        /// The person it is for (`a`), if named.
        person: Option<Ident>,
        /// The time span `from..to`, if given.
        range: Option<(Expr, Expr)>,
        /// The prompt.
        text: String,
        /// The whole line.
        span: Span,
    },
    /// `length 6s`.
    Length { value: Expr, span: Span },
    /// `spacing 1 m`: metres between neighbouring people at the start.
    Spacing { value: Expr, span: Span },
    /// `param name = value`.
    Param {
        name: Ident,
        value: Expr,
        span: Span,
    },
    /// `people a "…", b "…"`.
    People { people: Vec<PersonDecl>, span: Span },
    /// `start at [x, 0, z] facing [dx, 0, dz]`: where the one person stands on frame 0.
    Start { place: StartPlace, span: Span },
    /// `def f(a, b) = …` or `def f(a) { … }`.
    Def(FnDef),
    /// A statement (constraints, blocks, `let`).
    Stmt(Stmt),
}

/// One person of a `people` line.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PersonDecl {
    /// The person's name (`a`).
    pub name: Ident,
    /// Their text prompt, if given.
    pub prompt: Option<String>,
    /// `at [x, 0, z] facing [dx, 0, dz]` after the prompt, if given.
    pub start: Option<StartPlace>,
}

/// Where a person stands on frame 0: a position on the floor, a facing direction, or both.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StartPlace {
    /// `at [x, 0, z]`.
    pub at: Option<Expr>,
    /// `facing [dx, 0, dz]`.
    pub facing: Option<Expr>,
    /// The whole `at … facing …` text.
    pub span: Span,
}

/// A user function.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FnDef {
    /// Function name.
    pub name: Ident,
    /// Parameter names.
    pub params: Vec<Ident>,
    /// Body.
    pub body: FnBody,
    /// `##` lines right above the definition, joined.
    pub doc: String,
    /// The whole definition.
    pub span: Span,
}

/// A function body: one expression, or a block of `let`s and expressions.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum FnBody {
    /// `= expr`.
    Expr(Expr),
    /// `{ let …; expr; … }`: the value is the last expression, or the AND of all
    /// expressions when they are constraints.
    Block(Vec<FnItem>),
}

/// An item inside a block body.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum FnItem {
    /// `let name = value`.
    Let { name: Ident, value: Expr },
    /// An expression.
    Expr(Expr),
}

/// Which frames a time block covers.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum TimeKind {
    /// `always`: every frame.
    Always,
    /// `at t1, t2, …`: keyframes.
    At(Vec<Expr>),
    /// `during a..b`: frames in `[a, b)`.
    During(Expr, Expr),
}

/// A statement.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum Stmt {
    /// `let name = value` (lazy: the value is re-evaluated where it is used).
    Let {
        name: Ident,
        value: Expr,
        span: Span,
    },
    /// `always/at/during … { … }`.
    Time {
        kind: TimeKind,
        weight: Option<Expr>,
        body: Vec<Stmt>,
        span: Span,
    },
    /// `for var in set { … }`.
    For {
        var: Ident,
        set: Expr,
        body: Vec<Stmt>,
        span: Span,
    },
    /// `if cond { … } else { … }`.
    If {
        cond: Expr,
        then: Vec<Stmt>,
        otherwise: Option<Vec<Stmt>>,
        span: Span,
    },
    /// `weight w { … }`.
    Weight {
        weight: Expr,
        body: Vec<Stmt>,
        span: Span,
    },
    /// `minimize e` (`sign` 1) or `maximize e` (`sign` -1).
    Minimize {
        value: Expr,
        sign: f64,
        weight: Option<Expr>,
        span: Span,
    },
    /// A constraint expression, optionally `weight w`.
    Constraint {
        value: Expr,
        weight: Option<Expr>,
        span: Span,
    },
}

impl Stmt {
    /// The statement's span.
    pub fn span(&self) -> Span {
        match self {
            Stmt::Let { span, .. }
            | Stmt::Time { span, .. }
            | Stmt::For { span, .. }
            | Stmt::If { span, .. }
            | Stmt::Weight { span, .. }
            | Stmt::Minimize { span, .. }
            | Stmt::Constraint { span, .. } => *span,
        }
    }
}

/// An expression with its span.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Expr {
    /// What it is.
    pub kind: ExprKind,
    /// Where it is.
    pub span: Span,
}

/// Units that may follow a number literal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum UnitLit {
    /// Metres.
    M,
    /// Centimetres.
    Cm,
    /// Millimetres.
    Mm,
    /// Seconds.
    S,
    /// Milliseconds.
    Ms,
    /// Frames (1/20 s).
    Frames,
    /// Degrees.
    Deg,
    /// Radians.
    Rad,
    /// Percent of the motion's length (time positions only).
    Percent,
}

/// Binary operators.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum BinOp {
    Or,
    And,
    Eq,
    Lt,
    Le,
    Gt,
    Ge,
    Add,
    Sub,
    Mul,
    Div,
}

impl BinOp {
    /// The operator as written.
    pub fn symbol(self) -> &'static str {
        match self {
            BinOp::Or => "or",
            BinOp::And => "and",
            BinOp::Eq => "==",
            BinOp::Lt => "<",
            BinOp::Le => "<=",
            BinOp::Gt => ">",
            BinOp::Ge => ">=",
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
        }
    }

    /// True for `== < <= > >=`.
    pub fn is_comparison(self) -> bool {
        matches!(
            self,
            BinOp::Eq | BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge
        )
    }
}

/// Prefix operators.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum UnOp {
    /// `-x`.
    Neg,
    /// `not c`.
    Not,
}

/// Expression forms.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum ExprKind {
    /// A number with an optional unit.
    Number(f64, Option<UnitLit>),
    /// A name: joint, alias, variable, parameter, person, set or time keyword.
    Name(String),
    /// `[a, b, c]`: a vector, or a list of joints or people.
    List(Vec<Expr>),
    /// `f(args)`.
    Call(Ident, Vec<Expr>),
    /// `e.name`: a component (`.x .y .z .xz`) or a person's joint (`a.r_hand`).
    Member(Box<Expr>, Ident),
    /// `e@time`.
    At(Box<Expr>, Box<Expr>),
    /// Prefix operator.
    Unary(UnOp, Box<Expr>),
    /// Infix operator.
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// Placeholder after a reported syntax problem.
    Error,
}
