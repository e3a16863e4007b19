//! Pairs cut from one map: the crisp-walled pairs someone makes by cutting a real building map
//! in two, turning one part and asking for the transform back.
//!
//! Unlike the robots of [`crate::generate_case`], the two maps hold the same cells where they
//! overlap, so a right answer fits almost every wall and a placement that lays one room on
//! another shows as walls in the other map's free space. With no overlap, a pair cut along a
//! straight line is what a tool must decline although its parts look alike (rooms repeat).

use std::f64::consts::PI;

use glam::DVec2;
use grid_core::{CellState, OccupancyGrid, Rigid2, UNKNOWN};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::{Error, Result};

/// How a map is cut into a pair, with documented defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CropConfig {
    /// Share of the smaller part's extent across the cut that both parts hold, in `[0, 1)`.
    /// Default 0.3.
    pub overlap: f64,
    /// Where the cut lies across the known cells' extent, as a fraction drawn uniformly from
    /// this range. Default `(0.35, 0.65)`.
    pub cut: (f64, f64),
    /// Unknown cells around each part's known cells. Default 10.
    pub margin: usize,
    /// Bend the second part before it is turned, as a map built with a drifting heading is
    /// bent: each of its cells turns about the part's middle by this angle (degrees) times
    /// its signed distance from the middle across the cut over the part's half extent there,
    /// so the part's two ends turn by `-bend_deg` and `+bend_deg`. The truth stays the
    /// unbent one, which the middle of the part keeps. Default 0.
    pub bend_deg: f64,
    /// Share of the second part's wall cells kept, each drawn at random; the others become
    /// unknown, as a sensor that marks walls only in part leaves them (a glancing beam, a
    /// surface that returns little). In `(0, 1]`. Default 1: every wall cell kept.
    pub keep_walls: f64,
}

impl Default for CropConfig {
    fn default() -> Self {
        Self {
            overlap: 0.3,
            cut: (0.35, 0.65),
            margin: 10,
            bend_deg: 0.0,
            keep_walls: 1.0,
        }
    }
}

/// Two parts of one map with the transform between them.
#[derive(Debug, Clone, PartialEq)]
pub struct CropPair {
    /// The first part, unturned: the map's region around its known cells, the other cells
    /// unknown.
    pub a: OccupancyGrid,
    /// The second part, turned by a random angle about its middle (nearest-neighbour
    /// resampling) on a square canvas that holds any turn.
    pub b: OccupancyGrid,
    /// Maps a pixel of `b` onto the same place in `a`.
    pub truth: Rigid2,
    /// Known cells of the map in both parts over those of the smaller part (before `b` is
    /// turned).
    pub overlap: f64,
    /// Whether the cut runs along columns (the parts are west and east) rather than rows.
    pub vertical_cut: bool,
    /// The angle `b` was turned by, radians.
    pub angle: f64,
}

/// Cut `map` across its known cells at a random place, along a random axis, into two parts
/// that share `config.overlap` of the smaller one's extent; turn the second by a random angle.
/// Deterministic for a given seed.
pub fn crop_pair(map: &OccupancyGrid, config: &CropConfig, seed: u64) -> Result<CropPair> {
    let (lo, hi) = config.cut;
    let valid = (0.0..1.0).contains(&config.overlap) && 0.0 < lo && lo <= hi && hi < 1.0;
    let keeps = config.keep_walls > 0.0 && config.keep_walls <= 1.0;
    if !valid || !config.bend_deg.is_finite() || !keeps {
        return Err(Error::Config(format!(
            "crop overlap {} must lie in [0, 1), the cut range {:?} within (0, 1), the bend \
             {} be finite and the share of walls kept {} lie in (0, 1]",
            config.overlap, config.cut, config.bend_deg, config.keep_walls
        )));
    }
    let Some((x0, y0, w, h)) = map.known_bounds(0) else {
        return Err(Error::Config("the map to crop has no known cell".into()));
    };
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let vertical_cut = rng.random::<bool>();
    let cut = rng.random_range(lo..=hi);
    let angle = rng.random_range(-PI..PI);
    // The band both parts hold, as fractions of the extent across the cut: `overlap` of the
    // smaller part's extent, `min(cut, 1 - cut) + band / 2`.
    let smaller = cut.min(1.0 - cut);
    let band = config.overlap * smaller / (1.0 - config.overlap / 2.0);
    let extent = if vertical_cut { w } else { h } as f64;
    let across = |x: usize, y: usize| {
        let (v, start) = if vertical_cut { (x, x0) } else { (y, y0) };
        (v as f64 - start as f64 + 0.5) / extent
    };
    let in_a = |x: usize, y: usize| across(x, y) < cut + band / 2.0;
    let in_b = |x: usize, y: usize| across(x, y) >= cut - band / 2.0;
    let part = |keep: &dyn Fn(usize, usize) -> bool| {
        let mut p = map.clone();
        let width = map.width();
        for (i, cell) in p.cells_mut().iter_mut().enumerate() {
            if !keep(i % width, i / width) {
                *cell = UNKNOWN;
            }
        }
        p
    };
    let (mut known_a, mut known_b, mut shared) = (0usize, 0usize, 0usize);
    for y in y0..y0 + h {
        for x in x0..x0 + w {
            if map.state(x, y) == CellState::Unknown {
                continue;
            }
            let (ka, kb) = (in_a(x, y), in_b(x, y));
            known_a += usize::from(ka);
            known_b += usize::from(kb);
            shared += usize::from(ka && kb);
        }
    }
    if known_a == 0 || known_b == 0 {
        return Err(Error::Config(
            "a part of the cut map has no known cell".into(),
        ));
    }
    let m = config.margin as i64;
    let a = part(&in_a)
        .region(
            x0 as i64 - m,
            y0 as i64 - m,
            w + 2 * config.margin,
            h + 2 * config.margin,
        )
        .map_err(|e| Error::Config(e.to_string()))?;
    let map_to_a = Rigid2::new(0.0, (m - x0 as i64) as f64, (m - y0 as i64) as f64);
    // The second part turned about the middle of the known cells, onto a canvas whose middle
    // that becomes.
    let side = (w as f64).hypot(h as f64).ceil() as usize + 2 * config.margin;
    let middle = DVec2::new(x0 as f64 + w as f64 / 2.0, y0 as f64 + h as f64 / 2.0);
    let half = (side / 2) as f64;
    let map_to_b = Rigid2::new(angle, half, half).compose(&Rigid2::new(0.0, -middle.x, -middle.y));
    let mut b = part(&in_b);
    if config.bend_deg != 0.0 {
        // The part's extent across the cut, in the map's cells.
        let (start, end) = (cut - band / 2.0, 1.0);
        let from = |f: f64| f * extent + if vertical_cut { x0 } else { y0 } as f64;
        let (lo_px, hi_px) = (from(start), from(end));
        let mid_across = (lo_px + hi_px) / 2.0;
        let half_across = ((hi_px - lo_px) / 2.0).max(1.0);
        let pivot = if vertical_cut {
            DVec2::new(mid_across, middle.y)
        } else {
            DVec2::new(middle.x, mid_across)
        };
        b = bent(
            &b,
            pivot,
            vertical_cut,
            half_across,
            config.bend_deg.to_radians(),
        );
    }
    if config.keep_walls < 1.0 {
        // Drawn after the cut and the angle, so that those stay what the seed gave them.
        for cell in b.cells_mut() {
            if OccupancyGrid::classify(*cell) == CellState::Occupied
                && rng.random::<f64>() >= config.keep_walls
            {
                *cell = UNKNOWN;
            }
        }
    }
    let b = b
        .warp(&map_to_b, side, side)
        .map_err(|e| Error::Config(e.to_string()))?;
    Ok(CropPair {
        a,
        b,
        truth: map_to_a.compose(&map_to_b.inverse()),
        overlap: shared as f64 / known_a.min(known_b) as f64,
        vertical_cut,
        angle,
    })
}

/// `map` bent about `pivot`: the cell at signed distance `u` from the pivot across the cut
/// (along x when `vertical_cut`, else along y) turned by `max_angle * u / half`, nearest
/// neighbour, cells from outside the map unknown.
fn bent(
    map: &OccupancyGrid,
    pivot: DVec2,
    vertical_cut: bool,
    half: f64,
    max_angle: f64,
) -> OccupancyGrid {
    let mut out = map.clone();
    let (w, h) = (map.width(), map.height());
    for (i, cell) in out.cells_mut().iter_mut().enumerate() {
        let p = DVec2::new((i % w) as f64, (i / w) as f64);
        let u = if vertical_cut {
            p.x - pivot.x
        } else {
            p.y - pivot.y
        };
        // Where the cell came from: turned back by its angle.
        let q = pivot + DVec2::from_angle(-max_angle * u / half).rotate(p - pivot);
        let (qx, qy) = (q.x.round(), q.y.round());
        *cell = if qx >= 0.0 && qy >= 0.0 && (qx as usize) < w && (qy as usize) < h {
            map.cells()[qy as usize * w + qx as usize]
        } else {
            UNKNOWN
        };
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use grid_core::Pose2;

    /// A 60 x 40 map: free everywhere, a wall along each side and a few posts.
    fn room() -> OccupancyGrid {
        let (w, h) = (60, 40);
        let mut cells = vec![0u8; w * h];
        for y in 0..h {
            for x in 0..w {
                if x == 0 || y == 0 || x == w - 1 || y == h - 1 || (x % 13 == 5 && y % 11 == 4) {
                    cells[y * w + x] = 100;
                }
            }
        }
        OccupancyGrid::from_cells(w, h, 0.05, Pose2::default(), cells).unwrap()
    }

    #[test]
    fn the_truth_takes_every_known_cell_of_b_onto_the_same_cell_of_a_where_both_hold_it() {
        let map = room();
        for seed in 0..20 {
            let pair = crop_pair(&map, &CropConfig::default(), seed).unwrap();
            // The turned part's cells came from the map by nearest neighbour: where the truth
            // lands a known cell of b on a known cell of a, both hold the same map cell.
            let (mut compared, mut same) = (0usize, 0usize);
            for y in 0..pair.b.height() {
                for x in 0..pair.b.width() {
                    let Some(v) = pair.b.get(x, y).filter(|&v| v != UNKNOWN) else {
                        continue;
                    };
                    let q = pair.truth.apply(DVec2::new(x as f64, y as f64)).round();
                    if let Some(u) = pair.a.get(q.x as usize, q.y as usize)
                        && u != UNKNOWN
                        && q.x >= 0.0
                        && q.y >= 0.0
                    {
                        compared += 1;
                        same += usize::from(u == v);
                    }
                }
            }
            assert!(compared > 0, "seed {seed}: nothing shared");
            assert!(
                same as f64 >= 0.97 * compared as f64,
                "seed {seed}: {same} of {compared}"
            );
            assert!(
                (0.2..0.45).contains(&pair.overlap),
                "seed {seed}: {}",
                pair.overlap
            );
        }
    }

    #[test]
    fn with_no_overlap_the_parts_share_no_cell_and_a_seed_gives_the_same_pair() {
        let map = room();
        let config = CropConfig {
            overlap: 0.0,
            ..CropConfig::default()
        };
        for seed in 0..20 {
            let pair = crop_pair(&map, &config, seed).unwrap();
            assert_eq!(pair.overlap, 0.0, "seed {seed}");
            assert_eq!(pair, crop_pair(&map, &config, seed).unwrap());
        }
        assert!(matches!(
            crop_pair(
                &map,
                &CropConfig {
                    overlap: 1.0,
                    ..config
                },
                1
            ),
            Err(Error::Config(_))
        ));
    }

    #[test]
    fn a_bent_part_turns_its_ends_and_keeps_its_middle() {
        let map = room();
        let straight = crop_pair(&map, &CropConfig::default(), 3).unwrap();
        let config = CropConfig {
            bend_deg: 8.0,
            ..CropConfig::default()
        };
        let pair = crop_pair(&map, &config, 3).unwrap();
        // Only the second part changes, not the truth.
        assert_eq!(
            (&pair.a, pair.truth, pair.overlap),
            (&straight.a, straight.truth, straight.overlap)
        );
        assert_ne!(pair.b, straight.b);
        // The room's posts of the second part, unbent and bent: the bend moves them by up to
        // the part's half extent times the angle, and the middle ones little.
        let posts = |b: &OccupancyGrid| -> Vec<DVec2> {
            let w = b.width();
            (0..b.cells().len())
                .filter(|&i| b.state(i % w, i / w) == CellState::Occupied)
                .map(|i| DVec2::new((i % w) as f64, (i / w) as f64))
                .collect()
        };
        let moved = |p: DVec2| {
            posts(&pair.b)
                .iter()
                .map(|q| (*q - p).length())
                .fold(f64::INFINITY, f64::min)
        };
        let straight_posts = posts(&straight.b);
        let far = straight_posts.iter().map(|&p| moved(p)).fold(0.0, f64::max);
        assert!(far > 1.0 && far < 8.0, "{far}");
        let near = straight_posts
            .iter()
            .map(|&p| moved(p))
            .fold(f64::INFINITY, f64::min);
        assert!(near < 0.5, "{near}");
        assert!(matches!(
            crop_pair(
                &map,
                &CropConfig {
                    bend_deg: f64::NAN,
                    ..config
                },
                1
            ),
            Err(Error::Config(_))
        ));
    }

    #[test]
    fn a_part_with_walls_marked_in_part_keeps_that_share_of_them_and_nothing_else_changes() {
        let map = room();
        let whole = crop_pair(&map, &CropConfig::default(), 5).unwrap();
        let config = CropConfig {
            keep_walls: 0.5,
            ..CropConfig::default()
        };
        let pair = crop_pair(&map, &config, 5).unwrap();
        // The same cut and angle: only the second part's walls thin out.
        assert_eq!(
            (&pair.a, pair.truth, pair.overlap),
            (&whole.a, whole.truth, whole.overlap)
        );
        let count = |b: &OccupancyGrid, state| {
            let w = b.width();
            (0..b.cells().len())
                .filter(|&i| b.state(i % w, i / w) == state)
                .count()
        };
        let (all, kept) = (
            count(&whole.b, CellState::Occupied),
            count(&pair.b, CellState::Occupied),
        );
        assert!(
            (0.35..0.65).contains(&(kept as f64 / all as f64)),
            "{kept} of {all}"
        );
        // Free cells stay free; the dropped walls become unknown.
        assert_eq!(
            count(&pair.b, CellState::Free),
            count(&whole.b, CellState::Free)
        );
        assert_eq!(pair, crop_pair(&map, &config, 5).unwrap());
        for keep_walls in [0.0, 1.5, f64::NAN] {
            let config = CropConfig {
                keep_walls,
                ..config
            };
            assert!(matches!(crop_pair(&map, &config, 1), Err(Error::Config(_))));
        }
    }
}
