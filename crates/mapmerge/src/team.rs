//! A robot team's maps merged into one: every pair registered ([`crate::register`]), one pose
//! per map from the accepted pairs ([`fusion::solve_poses`]), then the placed maps fused
//! ([`fusion::fuse`]).

use fusion::{FusedMap, FusionConfig, MapPlacement, PairEdge, PoseGraphConfig, PoseGraphSolution};
use grid_core::{DVec2, OccupancyGrid};
use rayon::prelude::*;

use crate::{Error, RegisterConfig, Registration, register};

/// Settings of [`merge_team`].
#[derive(Debug, Clone)]
pub struct TeamConfig {
    /// How each pair is registered; default [`RegisterConfig::default`].
    pub register: RegisterConfig,
    /// How the poses are solved from the accepted pairs; default
    /// [`PoseGraphConfig::default`] (a tree of the most confident answers, loop answers within
    /// 3 degrees and 8 px of it refine the poses by least squares).
    pub poses: PoseGraphConfig,
    /// How the placed maps are fused; default [`FusionConfig::default`] (the paper's weighted
    /// mean).
    pub fusion: FusionConfig,
    /// The map whose frame the result is in; default 0, the first.
    pub reference: usize,
    /// An accepted pair becomes an edge of the pose graph only with a wall lift of at least
    /// this; default 0.75 (a pair is accepted from 0.65, or lower when it stands out). A map placed wrong spoils
    /// the merged map, while one left out is only missing (and reported), and in a team a map
    /// often has another way in: of the 400 maps of `cargo xtask team --seed 7` at 50 and 30 %
    /// overlap the bar cut those placed more than 3 px off from 48 to 18, and those placed
    /// within 3 px from 304 to 298 (docs/EVALUATION.md, "Merging a team").
    pub min_edge_lift: f64,
}

impl Default for TeamConfig {
    fn default() -> Self {
        Self {
            register: RegisterConfig::default(),
            poses: PoseGraphConfig::default(),
            fusion: FusionConfig::default(),
            reference: 0,
            min_edge_lift: 0.75,
        }
    }
}

/// One registered pair: map `b` onto map `a`, `a < b`.
#[derive(Debug, Clone)]
pub struct TeamPair {
    /// The map the answer is in.
    pub a: usize,
    /// The map placed into `a`.
    pub b: usize,
    /// The registration.
    pub registration: Registration,
    /// For an accepted pair at [`TeamConfig::min_edge_lift`] or more, its index among the
    /// pose graph's edges (in [`PoseGraphSolution::status`] and
    /// [`PoseGraphSolution::residuals`]); `None` for a declined pair and for one accepted
    /// below that bar.
    pub edge: Option<usize>,
}

/// The result of [`merge_team`].
#[derive(Debug, Clone)]
pub struct TeamMerge {
    /// Every pair `a < b`, in order (`(0, 1), (0, 2), ..., (1, 2), ...`).
    pub pairs: Vec<TeamPair>,
    /// One pose per map, each map's pixels onto the reference's; `None` for a map that no
    /// accepted pair links to the reference.
    pub poses: PoseGraphSolution,
    /// The maps with a pose, in index order: the inputs of the fusion, whose
    /// [`FusedMap::poses`] and [`FusedMap::layers`] follow this order.
    pub placed: Vec<usize>,
    /// The placed maps fused in the reference's frame (shifted by whole cells); `None` when no
    /// map but the reference could be placed.
    pub fused: Option<FusedMap>,
}

/// Where the pose graph measures how far apart two answers put a map: the mean pixel of its
/// known cells ([`OccupancyGrid::known_centroid`]), the middle of the grid when none is known.
pub fn known_centre(g: &OccupancyGrid) -> DVec2 {
    g.known_centroid()
        .unwrap_or_else(|| DVec2::new(g.width() as f64, g.height() as f64) * 0.5)
}

/// How much the pose graph trusts an accepted answer: the wall cells that agree (compared
/// both ways), discounted by the wall lift. An answer's precision grows with the walls it
/// rests on, so a small overlap's answer, even one that fits well, counts for less than a
/// large overlap's: the spanning tree prefers the large overlaps, and a small overlap's loop
/// answer pulls the refined poses little.
fn edge_weight(v: &crate::verify::Verification) -> f64 {
    let agreeing = v.wall_support as f64 * v.wall_agreement.clamp(0.0, 1.0);
    (agreeing * v.wall_lift.clamp(0.0, 1.0)).max(1e-3)
}

/// Merge a team's `maps`, weighted by `weights` (each map's reliability, one per map): register
/// every pair `a < b` in parallel (`on_pair` is called after each, for a progress bar), solve
/// one pose per map in the frame of map [`TeamConfig::reference`] from the accepted pairs
/// (weighted by the walls they agree on, discounted by the wall lift), and fuse the maps that
/// got a pose.
///
/// The same maps and settings give the same result, whatever the thread count.
pub fn merge_team(
    maps: &[&OccupancyGrid],
    weights: &[f64],
    config: &TeamConfig,
    on_pair: &(dyn Fn() + Sync),
) -> Result<TeamMerge, Error> {
    config.validate()?;
    if weights.len() != maps.len() {
        return Err(Error::Input(format!(
            "{} weights for {} maps: give one per map",
            weights.len(),
            maps.len()
        )));
    }
    if config.reference >= maps.len() {
        return Err(Error::Input(format!(
            "the reference map {} is not one of the {} maps",
            config.reference,
            maps.len()
        )));
    }
    let n = maps.len();
    let indices: Vec<(usize, usize)> = (0..n)
        .flat_map(|a| (a + 1..n).map(move |b| (a, b)))
        .collect();
    let registrations = indices
        .par_iter()
        .map(|&(a, b)| {
            let r = register(maps[a], maps[b], &config.register);
            on_pair();
            r
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut edges = Vec::new();
    let mut pairs = Vec::with_capacity(indices.len());
    for (&(a, b), registration) in indices.iter().zip(registrations) {
        let edge = registration
            .accepted
            .as_ref()
            .filter(|c| c.verification.wall_lift >= config.min_edge_lift)
            .map(|c| {
                edges.push(PairEdge {
                    a,
                    b,
                    b_to_a: c.transform,
                    weight: edge_weight(&c.verification),
                });
                edges.len() - 1
            });
        pairs.push(TeamPair {
            a,
            b,
            registration,
            edge,
        });
    }
    let centres: Vec<DVec2> = maps.iter().map(|m| known_centre(m)).collect();
    let poses = fusion::solve_poses(&centres, config.reference, &edges, &config.poses)?;
    let placed: Vec<usize> = (0..n).filter(|&k| poses.poses[k].is_some()).collect();
    let fused = if placed.len() < 2 {
        None
    } else {
        let placements: Vec<MapPlacement<'_>> = placed
            .iter()
            .map(|&k| MapPlacement {
                grid: maps[k],
                pose: poses.poses[k].expect("placed"),
                weight: weights[k],
            })
            .collect();
        Some(fusion::fuse(
            &maps[config.reference].geometry(),
            &placements,
            &config.fusion,
        )?)
    };
    Ok(TeamMerge {
        pairs,
        poses,
        placed,
        fused,
    })
}
