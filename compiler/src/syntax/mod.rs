//! Text to AST: the pest grammar, the AST types and spans.

pub mod ast;
mod brackets;
pub mod lex;
mod parser;
mod recover;

pub use crate::span::{self, Span};
pub use parser::{parse, parse_expr, parse_for_check, parse_recovering, RESERVED};
