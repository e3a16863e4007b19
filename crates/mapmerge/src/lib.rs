//! The mapmerge pipeline: register occupancy grid maps of a robot team without initial guesses.
//!
//! It is for: composing the feature crates (`sift-desc`, `blob-features`), the hypothesis
//! generator (`ransac-rigid`) and the checks on the maps themselves (refinement, verification)
//! into one call per pair, [`register_with`]. It is not for: file formats (see
//! `grid_core::io`) or the command line (the `mapmerge` binary in this package).
//!
//! ```
//! use grid_core::io::{LoadOptions, load_map};
//! use mapmerge::{RegisterConfig, register};
//!
//! let maps = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/maps");
//! let a = load_map(format!("{maps}/sunil_pair_a/sunil_pair_a.yaml"), &LoadOptions::default())?;
//! let b = load_map(format!("{maps}/sunil_pair_b/sunil_pair_b.yaml"), &LoadOptions::default())?;
//! // Settings out of range are an error (`mapmerge::Error`); a pair without a trustworthy
//! // answer is not: it comes back with `accepted: None` and the reason.
//! let registration = register(&a, &b, &RegisterConfig::default())?;
//! match &registration.accepted {
//!     // B's pixel p lies at `t.apply(p)` in A (README, "Conventions").
//!     Some(answer) => {
//!         let t = answer.transform;
//!         println!("theta {:.2} deg, tx {:.1}, ty {:.1}", t.theta.to_degrees(), t.tx, t.ty);
//!         assert!(answer.verification.wall_lift >= 0.65);
//!     }
//!     None => println!("declined: {}", registration.reason.as_deref().unwrap_or("")),
//! }
//! assert!(registration.accepted.is_some(), "the fixture pair overlaps");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod ascent;
pub mod distance;
mod error;
pub mod global;
pub mod refine;
mod register;
pub mod search;
pub mod settings;
pub mod team;
pub mod verify;

#[cfg(test)]
mod testmaps;

pub use error::Error;
pub use register::{
    APART_POINTS, Candidate, KindTotals, ManhattanRotation, Method, Origin, PairConfig,
    PolishConfig, RegisterConfig, Registration, RunnerUp, SpectrumRotation, Timings, TurnScan,
    framed, mean_apart, refine_and_score, register, register_with, unframed,
};
