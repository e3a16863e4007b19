//! Criterion bench: pyramid and detection.
fn main() {}
