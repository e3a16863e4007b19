//! proptest strategies yielding partial maps with known truth.
//!
//! `map_pair(PairParams::default())` yields `(map_a, map_b, b_to_a)`: two robots' maps and the
//! transform mapping a pixel of B onto A. Cases whose overlap cannot be met within the
//! tolerance are filtered out (proptest regenerates them), so keep ranges reasonable.

use std::ops::RangeInclusive;

use grid_core::{OccupancyGrid, Rigid2};
use proptest::prelude::*;

use crate::{Case, CaseConfig, RobotConfig, WorldConfig, WorldKind, generate_case};

/// Which worlds a strategy may draw.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Worlds {
    /// Disaster areas only.
    Disaster,
    /// Indoor floors only.
    Indoor,
    /// Either, half and half.
    Both,
}

/// Ranges a strategy draws from.
#[derive(Debug, Clone)]
pub struct PairParams {
    /// World side in cells (square worlds). Default `150..=300`.
    pub size: RangeInclusive<usize>,
    /// Requested overlap. Default `0.3..=0.8`.
    pub overlap: RangeInclusive<f64>,
    /// Range noise bound of each robot. Default `0.0..=0.15`.
    pub noise: RangeInclusive<f64>,
    /// Beams per robot (lidar 360 or a 16-beam ring, say). Default `[16, 360]`.
    pub beams: Vec<usize>,
    /// Maximum range as a fraction of the world side. Default `0.2..=0.3`.
    pub range_fraction: RangeInclusive<f64>,
    /// World kinds. Default [`Worlds::Both`].
    pub worlds: Worlds,
    /// Overlap tolerance passed to the generator. Default 0.15.
    pub overlap_tolerance: f64,
}

impl Default for PairParams {
    fn default() -> Self {
        Self {
            size: 150..=300,
            overlap: 0.3..=0.8,
            noise: 0.0..=0.15,
            beams: vec![16, 360],
            range_fraction: 0.2..=0.3,
            worlds: Worlds::Both,
            overlap_tolerance: 0.15,
        }
    }
}

/// Configs drawn from `params`, with a seed.
pub fn case_config(params: PairParams) -> impl Strategy<Value = (CaseConfig, u64)> {
    let beams = params.beams.clone();
    (
        params.size.clone(),
        params.overlap.clone(),
        params.noise.clone(),
        params.noise.clone(),
        0..beams.len().max(1),
        params.range_fraction.clone(),
        any::<bool>(),
        any::<u64>(),
    )
        .prop_map(move |(size, overlap, na, nb, bi, rf, coin, seed)| {
            let kind = match params.worlds {
                Worlds::Disaster => WorldKind::Disaster,
                Worlds::Indoor => WorldKind::Indoor,
                Worlds::Both if coin => WorldKind::Indoor,
                Worlds::Both => WorldKind::Disaster,
            };
            let beams = beams.get(bi).copied().unwrap_or(360);
            let robot = |noise| RobotConfig {
                beams,
                max_range: (size as f64 * rf).max(10.0),
                noise_bound: noise,
                ..RobotConfig::default()
            };
            let config = CaseConfig {
                world: WorldConfig {
                    kind,
                    width: size,
                    height: size,
                    ..WorldConfig::default()
                },
                robots: vec![robot(na), robot(nb)],
                overlap,
                overlap_tolerance: params.overlap_tolerance,
                ..CaseConfig::default()
            };
            (config, seed)
        })
}

/// Whole cases drawn from `params` (failed generations are filtered out).
pub fn case(params: PairParams) -> impl Strategy<Value = Case> {
    case_config(params).prop_filter_map("overlap not reachable", |(config, seed)| {
        generate_case(&config, seed).ok()
    })
}

/// `(map_a, map_b, b_to_a)` drawn from `params`.
pub fn map_pair(
    params: PairParams,
) -> impl Strategy<Value = (OccupancyGrid, OccupancyGrid, Rigid2)> {
    case(params).prop_map(|c| {
        let truth = c.truth(0, 1);
        let mut robots = c.robots.into_iter();
        let a = robots.next().map(|r| r.map);
        let b = robots.next().map(|r| r.map);
        // Two robots are always configured, so both maps exist.
        (a.expect("robot 0"), b.expect("robot 1"), truth)
    })
}
