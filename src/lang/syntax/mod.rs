//! Syntax: source text → [`ast::Module`]. See `grammar/mprog.pest` for the grammar.

pub mod ast;
mod parser;

pub use parser::{MAX_BRACKET_DEPTH, MAX_EXPR_DEPTH, MAX_SOURCE_BYTES, source_to_ast};
