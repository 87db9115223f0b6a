//! Cube renderer benchmarks (placeholder).
fn main() {}
