//! Text to AST: the pest grammar, the AST types and spans.

pub mod ast;
mod parser;
pub mod span;

pub use parser::{parse, RESERVED};
pub use span::Span;
