//! The `shaping` command line: the only place that touches files and terminals.

fn main() {
    println!("shaping {}", env!("CARGO_PKG_VERSION"));
}
