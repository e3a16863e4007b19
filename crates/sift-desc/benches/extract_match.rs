//! Criterion bench: extraction and matching (filled in below).
fn main() {}
