//! Laying placed maps onto one canvas and combining their cells.

use grid_core::metrics::Agreement;
use grid_core::{CellState, DVec2, OccupancyGrid, Rigid2, UNKNOWN};
use rayon::prelude::*;

use crate::{FusionError, Result};

/// How the cells of maps known at the same place are combined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FusionRule {
    /// The paper's rule: the mean of the occupancy probabilities of the maps known at the cell,
    /// weighted by their reliabilities normalised over those maps (for two maps
    /// `alpha * M1 + beta * M2` with `alpha + beta = 1`); a map known alone keeps its cell. A
    /// cell that one map sees free and an equally reliable one occupied gets 0.5, which a
    /// trinary file writes as unknown.
    #[default]
    WeightedMean,
    /// Occupied (the highest probability among them) where any map known at the cell sees it
    /// occupied, the weighted mean elsewhere. It keeps every wall any robot saw, which a
    /// planner needs to stay clear of them, at the price of a wider wall where two maps place
    /// it a cell apart.
    OccupiedWins,
}

impl std::str::FromStr for FusionRule {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "mean" | "weighted-mean" => Ok(Self::WeightedMean),
            "occupied-wins" => Ok(Self::OccupiedWins),
            _ => Err(format!(
                "unknown fusion rule `{s}`: expected `mean` or `occupied-wins`"
            )),
        }
    }
}

/// Settings of [`fuse`].
#[derive(Debug, Clone, PartialEq)]
pub struct FusionConfig {
    /// How overlapping cells are combined; default [`FusionRule::WeightedMean`].
    pub rule: FusionRule,
    /// Unknown cells kept around the known cells of the fused map; default 2.
    pub margin: usize,
    /// Refuse a fused canvas with more cells than this; default 100 million (as
    /// `grid_core::io::DEFAULT_MAX_CELLS` for inputs).
    pub max_cells: usize,
}

impl Default for FusionConfig {
    fn default() -> Self {
        Self {
            rule: FusionRule::WeightedMean,
            margin: 2,
            max_cells: grid_core::io::DEFAULT_MAX_CELLS,
        }
    }
}

/// One input of [`fuse`]: a map, where it goes, and how much it is trusted.
#[derive(Debug, Clone, Copy)]
pub struct MapPlacement<'a> {
    /// The map.
    pub grid: &'a OccupancyGrid,
    /// Maps a pixel of `grid` onto a pixel of the reference map.
    pub pose: Rigid2,
    /// Reliability of the map (finite, greater than 0); only ratios matter.
    pub weight: f64,
}

/// The result of [`fuse`].
#[derive(Debug, Clone)]
pub struct FusedMap {
    /// The fused map: the reference's resolution, and an origin that gives every cell the
    /// world coordinates it has in the reference map.
    pub grid: OccupancyGrid,
    /// The reference pixel that is the fused map's cell `(0, 0)`.
    pub offset: (i64, i64),
    /// Per input, the transform from its pixels to the fused map's pixels.
    pub poses: Vec<Rigid2>,
    /// Per input, the map resampled onto the fused canvas (nearest neighbour, unknown outside
    /// it): what the fusion combined, for pictures and per-map statistics.
    pub layers: Vec<OccupancyGrid>,
    /// Agreement over every pair of inputs known (free or occupied) at the same cell; its
    /// [`Agreement::acceptance_index`] is Birk and Carpin's acceptance index of the merge, and
    /// for two inputs it equals `grid_core::metrics::agreement` of the second placed on the
    /// first.
    pub agreement: Agreement,
    /// Cells where at least two inputs hold a probability.
    pub overlap_cells: usize,
}

/// Fuse `maps` into one map in the frame of the reference map whose geometry is `reference`
/// (usually the first map's).
///
/// The canvas covers the known cells of every input, placed by its pose, plus
/// [`FusionConfig::margin`]. Each input is resampled onto it by nearest neighbour; a cell takes
/// the combination ([`FusionConfig::rule`]) of the inputs that hold a probability there and is
/// unknown where none does. The same inputs give the same cells, whatever the thread count.
pub fn fuse(
    reference: &grid_core::GridGeometry,
    maps: &[MapPlacement<'_>],
    config: &FusionConfig,
) -> Result<FusedMap> {
    if maps.is_empty() {
        return Err(FusionError::NoMaps);
    }
    for (index, m) in maps.iter().enumerate() {
        let resolution = m.grid.resolution();
        if ((resolution - reference.resolution) / reference.resolution).abs() > 1e-6 {
            return Err(FusionError::Resolution {
                index,
                resolution,
                reference: reference.resolution,
            });
        }
        if !(m.weight.is_finite() && m.weight > 0.0) {
            return Err(FusionError::Weight {
                index,
                weight: m.weight,
            });
        }
        if ![m.pose.theta, m.pose.tx, m.pose.ty]
            .iter()
            .all(|v| v.is_finite())
        {
            return Err(FusionError::NotFinite {
                what: format!("map {index}'s pose"),
            });
        }
    }
    let (x0, y0, width, height) = canvas(maps, config)?;
    let shift = Rigid2::new(0.0, -(x0 as f64), -(y0 as f64));
    let poses: Vec<Rigid2> = maps.iter().map(|m| shift.compose(&m.pose)).collect();
    let layers = maps
        .par_iter()
        .zip(&poses)
        .map(|(m, pose)| m.grid.warp(pose, width, height))
        .collect::<std::result::Result<Vec<_>, _>>()?;
    let weights: Vec<f64> = maps.iter().map(|m| m.weight).collect();
    let mut cells = vec![UNKNOWN; width * height];
    let (agreement, overlap_cells) = cells
        .par_chunks_mut(width)
        .enumerate()
        .map(|(y, row)| {
            let mut tally = Tally::default();
            for (x, cell) in row.iter_mut().enumerate() {
                let i = y * width + x;
                *cell = combine(
                    layers.iter().map(|l| l.cells()[i]),
                    &weights,
                    config.rule,
                    &mut tally,
                );
            }
            (tally.agreement, tally.overlap)
        })
        .reduce(
            || (Agreement::default(), 0),
            |(a, n), (b, m)| {
                (
                    Agreement {
                        agree: a.agree + b.agree,
                        disagree: a.disagree + b.disagree,
                    },
                    n + m,
                )
            },
        );
    let geometry = reference.region(x0, y0, width, height);
    let grid =
        OccupancyGrid::from_cells(width, height, geometry.resolution, geometry.origin, cells)?;
    Ok(FusedMap {
        grid,
        offset: (x0, y0),
        poses,
        layers,
        agreement,
        overlap_cells,
    })
}

/// The fused canvas `(x0, y0, width, height)` in reference pixels: the bounding box of every
/// input's known cells placed by its pose, grown by the margin.
fn canvas(maps: &[MapPlacement<'_>], config: &FusionConfig) -> Result<(i64, i64, usize, usize)> {
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for m in maps {
        let Some((x, y, w, h)) = m.grid.known_bounds(0) else {
            continue;
        };
        let (x0, y0) = (x as f64, y as f64);
        let (x1, y1) = ((x + w - 1) as f64, (y + h - 1) as f64);
        for corner in [(x0, y0), (x1, y0), (x0, y1), (x1, y1)] {
            let p = m.pose.apply(DVec2::new(corner.0, corner.1));
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    if !lo.is_finite() {
        return Err(FusionError::NothingKnown);
    }
    let margin = config.margin as f64;
    // A cell placed at a half-integer rounds either way: one cell more on each side keeps it.
    let lo = (lo - margin - 1.0).floor();
    let hi = (hi + margin + 1.0).ceil();
    let (width, height) = ((hi.x - lo.x) as u64 + 1, (hi.y - lo.y) as u64 + 1);
    if width.saturating_mul(height) > config.max_cells as u64 {
        return Err(FusionError::TooLarge {
            width,
            height,
            max: config.max_cells,
        });
    }
    Ok((lo.x as i64, lo.y as i64, width as usize, height as usize))
}

/// Counts gathered while combining cells.
#[derive(Debug, Default)]
struct Tally {
    agreement: Agreement,
    overlap: usize,
}

/// The fused value of one cell from the inputs' values there (`UNKNOWN` or percent).
fn combine(
    values: impl Iterator<Item = u8>,
    weights: &[f64],
    rule: FusionRule,
    tally: &mut Tally,
) -> u8 {
    let (mut sum_w, mut sum_wp) = (0.0f64, 0.0f64);
    let (mut known, mut free, mut occupied, mut highest) = (0usize, 0usize, 0usize, 0u8);
    for (v, w) in values.zip(weights) {
        if v > 100 {
            continue;
        }
        known += 1;
        sum_w += w;
        sum_wp += w * v as f64;
        highest = highest.max(v);
        match OccupancyGrid::classify(v) {
            CellState::Free => free += 1,
            CellState::Occupied => occupied += 1,
            CellState::Unknown => {}
        }
    }
    if known == 0 {
        return UNKNOWN;
    }
    if known > 1 {
        tally.overlap += 1;
    }
    tally.agreement.agree += free * free.saturating_sub(1) / 2;
    tally.agreement.agree += occupied * occupied.saturating_sub(1) / 2;
    tally.agreement.disagree += free * occupied;
    match rule {
        FusionRule::OccupiedWins if occupied > 0 => highest,
        _ => (sum_wp / sum_w).round().clamp(0.0, 100.0) as u8,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use grid_core::Pose2;

    const F: u8 = 0;
    const O: u8 = 100;
    const U: u8 = UNKNOWN;

    fn grid(w: usize, h: usize, cells: Vec<u8>) -> OccupancyGrid {
        OccupancyGrid::from_cells(w, h, 0.05, Pose2::new(1.0, -2.0, 0.3), cells).unwrap()
    }

    fn tight() -> FusionConfig {
        FusionConfig {
            margin: 0,
            ..FusionConfig::default()
        }
    }

    fn place(grid: &OccupancyGrid, pose: Rigid2, weight: f64) -> MapPlacement<'_> {
        MapPlacement { grid, pose, weight }
    }

    /// The fused map's cell that holds reference pixel `(x, y)`.
    fn at(f: &FusedMap, x: i64, y: i64) -> u8 {
        let (u, v) = (x - f.offset.0, y - f.offset.1);
        f.grid.get(u as usize, v as usize).unwrap()
    }

    #[test]
    fn a_map_alone_is_copied_cell_for_cell_where_it_is_known() {
        // Known cells in columns 1-3, rows 1-2 of a 5 x 4 map.
        #[rustfmt::skip]
        let cells = vec![
            U, U, U, U, U,
            U, F, O, 40, U,
            U, O, F, F, U,
            U, U, U, U, U,
        ];
        let a = grid(5, 4, cells.clone());
        let f = fuse(&a.geometry(), &[place(&a, Rigid2::IDENTITY, 1.0)], &tight()).unwrap();
        // The canvas is the known box plus the one cell kept for rounding.
        assert_eq!(f.offset, (0, 0));
        assert_eq!((f.grid.width(), f.grid.height()), (5, 4));
        assert_eq!(f.grid.cells(), &cells[..]);
        // The same world coordinates for the same cell.
        let p = DVec2::new(2.0, 1.0);
        let w = a.pixel_to_world(p);
        let q = f.grid.world_to_pixel(w);
        assert!((q - p).length() < 1e-9, "{q}");
    }

    #[test]
    fn the_canvas_follows_the_known_cells_and_keeps_world_coordinates() {
        let mut cells = vec![U; 20 * 10];
        cells[3 * 20 + 12] = O;
        cells[6 * 20 + 15] = F;
        let a = grid(20, 10, cells);
        let config = FusionConfig {
            margin: 2,
            ..FusionConfig::default()
        };
        let f = fuse(&a.geometry(), &[place(&a, Rigid2::IDENTITY, 1.0)], &config).unwrap();
        // Known box x 12..=15, y 3..=6, grown by 2 + 1 on each side.
        assert_eq!(f.offset, (9, 0));
        assert_eq!((f.grid.width(), f.grid.height()), (10, 10));
        assert_eq!(at(&f, 12, 3), O);
        assert_eq!(at(&f, 15, 6), F);
        for p in [DVec2::new(12.0, 3.0), DVec2::new(15.0, 6.0)] {
            let q = f.grid.world_to_pixel(a.pixel_to_world(p));
            assert!((q - (p - DVec2::new(9.0, 0.0))).length() < 1e-9, "{q}");
        }
    }

    #[test]
    fn overlapping_cells_take_the_reliability_weighted_mean() {
        let a = grid(3, 1, vec![O, F, O]);
        let b = grid(3, 1, vec![F, F, U]);
        // B's pixel x lands on A's pixel x + 1: B covers A's columns 1-2 and column 3.
        let t = Rigid2::new(0.0, 1.0, 0.0);
        let f = fuse(
            &a.geometry(),
            &[place(&a, Rigid2::IDENTITY, 0.8), place(&b, t, 0.2)],
            &tight(),
        )
        .unwrap();
        assert_eq!(at(&f, 0, 0), O, "A alone keeps its cell");
        assert_eq!(at(&f, 1, 0), F, "free and free");
        assert_eq!(at(&f, 2, 0), 80, "0.8 * occupied + 0.2 * free");
        assert_eq!(at(&f, 3, 0), U, "B's unknown cell past A");
        assert_eq!(f.overlap_cells, 2);
        assert_eq!(
            f.agreement,
            Agreement {
                agree: 1,
                disagree: 1
            }
        );
        // Equal reliabilities make a disagreement an even split.
        let even = fuse(
            &a.geometry(),
            &[place(&a, Rigid2::IDENTITY, 1.0), place(&b, t, 1.0)],
            &tight(),
        )
        .unwrap();
        assert_eq!(at(&even, 2, 0), 50);
        let wins = fuse(
            &a.geometry(),
            &[place(&a, Rigid2::IDENTITY, 0.2), place(&b, t, 0.8)],
            &FusionConfig {
                rule: FusionRule::OccupiedWins,
                ..tight()
            },
        )
        .unwrap();
        assert_eq!(
            at(&wins, 2, 0),
            O,
            "occupied wins over a more reliable free"
        );
        assert_eq!(at(&wins, 1, 0), F);
    }

    #[test]
    fn a_quarter_turned_piece_lands_back_in_place() {
        // A 6 x 4 map cut in two overlapping pieces; the second turned by a quarter turn and
        // shifted, then placed back by the inverse: the fusion gives the map back.
        let w = 6;
        let whole: Vec<u8> = (0..24)
            .map(|i| if (i * 7) % 5 < 2 { O } else { F })
            .collect();
        let truth = grid(w, 4, whole.clone());
        let left = truth.region(0, 0, 4, 4).unwrap();
        let right = truth.region(2, 0, 4, 4).unwrap();
        // Turn `right` by +90 degrees onto a 4 x 4 canvas: (x, y) -> (3 - y, x).
        let turn = Rigid2::new(std::f64::consts::FRAC_PI_2, 3.0, 0.0);
        let turned = right.warp(&turn, 4, 4).unwrap();
        let pose = Rigid2::new(0.0, 2.0, 0.0).compose(&turn.inverse());
        let f = fuse(
            &left.geometry(),
            &[
                place(&left, Rigid2::IDENTITY, 1.0),
                place(&turned, pose, 1.0),
            ],
            &tight(),
        )
        .unwrap();
        for y in 0..4 {
            for x in 0..w {
                assert_eq!(at(&f, x as i64, y as i64), whole[y * w + x], "({x}, {y})");
            }
        }
        assert_eq!(f.agreement.disagree, 0);
        assert_eq!(f.agreement.agree, 8);
        // World coordinates are the reference's (and hence the whole map's).
        let q = f
            .grid
            .world_to_pixel(truth.pixel_to_world(DVec2::new(5.0, 3.0)));
        assert!((q - DVec2::new(5.0 - f.offset.0 as f64, 3.0 - f.offset.1 as f64)).length() < 1e-9);
    }

    #[test]
    fn the_acceptance_index_of_two_maps_is_the_metric_of_the_pair() {
        let a = grid(
            8,
            6,
            (0..48u32)
                .map(|i| [F, O, U][(i * i % 7 % 3) as usize])
                .collect(),
        );
        let b = grid(
            7,
            5,
            (0..35u32)
                .map(|i| [O, F, F, U][(i * 3 % 11 % 4) as usize])
                .collect(),
        );
        let t = Rigid2::new(0.4, 1.3, -0.6);
        let f = fuse(
            &a.geometry(),
            &[place(&a, Rigid2::IDENTITY, 1.0), place(&b, t, 1.0)],
            &tight(),
        )
        .unwrap();
        assert_eq!(f.agreement, grid_core::metrics::agreement(&a, &b, &t));
    }

    #[test]
    fn bad_inputs_are_refused() {
        let a = grid(2, 1, vec![F, O]);
        let g = a.geometry();
        assert!(matches!(fuse(&g, &[], &tight()), Err(FusionError::NoMaps)));
        assert!(matches!(
            fuse(&g, &[place(&a, Rigid2::IDENTITY, f64::NAN)], &tight()),
            Err(FusionError::Weight { index: 0, .. })
        ));
        assert!(matches!(
            fuse(
                &g,
                &[
                    place(&a, Rigid2::IDENTITY, 1.0),
                    place(&a, Rigid2::new(0.0, f64::INFINITY, 0.0), 1.0)
                ],
                &tight()
            ),
            Err(FusionError::NotFinite { .. })
        ));
        let coarse = OccupancyGrid::from_cells(2, 1, 0.1, Pose2::default(), vec![F, O]).unwrap();
        assert!(matches!(
            fuse(
                &g,
                &[
                    place(&a, Rigid2::IDENTITY, 1.0),
                    place(&coarse, Rigid2::IDENTITY, 1.0)
                ],
                &tight()
            ),
            Err(FusionError::Resolution { index: 1, .. })
        ));
        let unknown = grid(2, 1, vec![U, U]);
        assert!(matches!(
            fuse(&g, &[place(&unknown, Rigid2::IDENTITY, 1.0)], &tight()),
            Err(FusionError::NothingKnown)
        ));
        let far = Rigid2::new(0.0, 1e6, 1e6);
        let err = fuse(
            &g,
            &[place(&a, Rigid2::IDENTITY, 1.0), place(&a, far, 1.0)],
            &tight(),
        )
        .unwrap_err();
        assert!(matches!(err, FusionError::TooLarge { .. }), "{err}");
    }
}
