//! What expressions elaborate to while checking: typed values that point at IR nodes,
//! joints and people (possibly different per loop lane), finite sets for loops, and
//! formulas (comparisons combined with and/or/not) that become an error or a mask
//! depending on where they are used.

use super::units::Unit;
use crate::lang::ir::NodeId;
use crate::lang::syntax::ast::{BinOp, Expr, Span};
use std::rc::Rc;

/// A per-lane index (person or joint): the same for every lane, or one per lane.
#[derive(Clone, Debug, PartialEq)]
pub enum LaneVec {
    /// Same in every lane.
    One(usize),
    /// One entry per lane.
    Lanes(Rc<Vec<usize>>),
}

impl LaneVec {
    /// The entry of lane `l`.
    pub fn get(&self, l: usize) -> usize {
        match self {
            LaneVec::One(x) => *x,
            LaneVec::Lanes(v) => v[l],
        }
    }

    /// True when every lane has the same entry.
    pub fn is_one(&self) -> bool {
        matches!(self, LaneVec::One(_))
    }
}

/// A numeric value: a scalar or 3-vector node with a unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Num {
    /// The node holding it.
    pub node: NodeId,
    /// Its unit.
    pub unit: Unit,
    /// Vector (3 channels) or scalar.
    pub vector: bool,
}

/// A formula: comparisons combined with `and`, `or`, `not`, or a plain error term.
#[derive(Clone, Debug, PartialEq)]
pub enum Formula {
    /// `a op b` with both sides already elaborated.
    Cmp {
        op: BinOp,
        a: NodeId,
        b: NodeId,
        unit: Unit,
        span: Span,
    },
    /// Sum of errors / both conditions.
    And(Rc<Formula>, Rc<Formula>),
    /// Minimum of errors / either condition.
    Or(Rc<Formula>, Rc<Formula>),
    /// Negated error / negated condition.
    Not(Rc<Formula>),
}

impl Formula {
    /// Unit of the error this formula yields.
    pub fn unit(&self) -> Unit {
        match self {
            Formula::Cmp { unit, .. } => *unit,
            Formula::And(a, _) | Formula::Or(a, _) | Formula::Not(a) => a.unit(),
        }
    }
}

/// A checked value.
#[derive(Clone, Debug, PartialEq)]
pub enum Val {
    /// Scalar or vector.
    Num(Num),
    /// A joint of a person (`person` is `None` for a bare joint in a multi-person program).
    Joint {
        person: Option<LaneVec>,
        joint: LaneVec,
    },
    /// A person.
    Person(LaneVec),
    /// A finite list of joints, for loops.
    JointSet(Vec<(Option<usize>, usize)>),
    /// A finite list of people, for loops.
    PersonSet(Vec<usize>),
    /// A constraint / condition.
    Formula(Rc<Formula>),
    /// Something already reported as wrong.
    Error,
}

impl Val {
    /// What kind of value this is, for messages.
    pub fn describe(&self) -> &'static str {
        match self {
            Val::Num(n) if n.vector => "a vector",
            Val::Num(_) => "a scalar",
            Val::Joint { .. } => "a joint",
            Val::Person(_) => "a person",
            Val::JointSet(_) => "a list of joints",
            Val::PersonSet(_) => "a list of people",
            Val::Formula(_) => "a constraint",
            Val::Error => "an invalid value",
        }
    }
}

/// One loop level's items.
#[derive(Clone, Debug, PartialEq)]
pub enum LoopItem {
    /// A joint (with its person, if given).
    Joint(Option<usize>, usize),
    /// A person.
    Person(usize),
}

/// What a name in scope stands for.
#[derive(Clone, Debug)]
pub enum Binding<'a> {
    /// A `let` or a function argument: re-elaborated where used (call by name), with the
    /// scope and library call site it was written in.
    Thunk {
        expr: &'a Expr,
        env: Env<'a>,
        site: Option<Span>,
    },
    /// The variable of loop level `n`.
    Loop(usize),
}

/// One entry of a scope chain.
#[derive(Debug)]
pub struct Scope<'a> {
    pub name: &'a str,
    pub binding: Binding<'a>,
    pub next: Env<'a>,
}

/// A persistent scope chain (innermost first).
pub type Env<'a> = Option<Rc<Scope<'a>>>;

/// Adds a binding in front of `env`.
pub fn bind<'a>(env: &Env<'a>, name: &'a str, binding: Binding<'a>) -> Env<'a> {
    Some(Rc::new(Scope {
        name,
        binding,
        next: env.clone(),
    }))
}

/// Finds the innermost binding of `name`.
pub fn lookup<'a>(env: &Env<'a>, name: &str) -> Option<Binding<'a>> {
    let mut cur = env.as_ref();
    while let Some(s) = cur {
        if s.name == name {
            return Some(s.binding.clone());
        }
        cur = s.next.as_ref();
    }
    None
}

/// All names bound in `env`.
pub fn names<'a>(env: &Env<'a>) -> Vec<&'a str> {
    let mut out = Vec::new();
    let mut cur = env.as_ref();
    while let Some(s) = cur {
        out.push(s.name);
        cur = s.next.as_ref();
    }
    out
}

/// Where an expression is being elaborated.
#[derive(Clone, Debug)]
pub struct Cx {
    /// Frames the value is computed over.
    pub domain: usize,
    /// The user-code call site while inside a library function (diagnostics go there).
    pub site: Option<Span>,
    /// Function-call nesting.
    pub depth: usize,
    /// Enclosing loops, outermost first.
    pub loops: Rc<Vec<Rc<Vec<LoopItem>>>>,
    /// Product of the loop sizes.
    pub lanes: usize,
}

impl Cx {
    /// The top-level context: every frame, no loops.
    pub fn top() -> Self {
        Cx {
            domain: 0,
            site: None,
            depth: 0,
            loops: Rc::new(Vec::new()),
            lanes: 1,
        }
    }

    /// Item index of loop `level` for each lane.
    pub fn loop_indices(&self, level: usize) -> LaneVec {
        let stride: usize = self.loops[level + 1..].iter().map(|l| l.len()).product();
        let len = self.loops[level].len();
        if self.lanes == 1 {
            return LaneVec::One(0);
        }
        LaneVec::Lanes(Rc::new(
            (0..self.lanes).map(|l| (l / stride) % len).collect(),
        ))
    }
}
