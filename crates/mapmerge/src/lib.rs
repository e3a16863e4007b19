//! The mapmerge pipeline: register occupancy grid maps of a robot team without initial guesses.
//!
//! It is for: composing the feature crates (`sift-desc`, `blob-features`), the hypothesis
//! generator (`ransac-rigid`) and the checks on the maps themselves (refinement, verification)
//! into one call per pair, [`register_with`]. It is not for: file formats (see
//! `grid_core::io`) or the command line (the `mapmerge` binary in this package).

pub mod ascent;
pub mod distance;
pub mod global;
pub mod refine;
mod register;
pub mod search;
pub mod team;
pub mod verify;

#[cfg(test)]
mod testmaps;

pub use register::{
    Candidate, KindTotals, ManhattanRotation, Method, Origin, PairConfig, PolishConfig,
    RegisterConfig, Registration, SpectrumRotation, Timings, TurnScan, framed, refine_and_score,
    register, register_with,
};
