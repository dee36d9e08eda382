//! Text to AST: the pest grammar, the AST types and spans.

pub mod ast;
mod brackets;
pub mod lex;
mod parser;
mod recover;
pub mod span;

pub use parser::{parse, parse_for_check, parse_recovering, RESERVED};
pub use span::Span;
