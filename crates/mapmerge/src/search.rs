//! Correlative local search: move a hypothesis to the best-scoring translation within a few
//! pixels before ICP polishes it.
//!
//! A hypothesis is fixed by a handful of keypoints located to a few pixels on a noisy map (or,
//! from a whole-map search, by a coarse grid); ICP with a small robust scale (see
//! [`crate::refine`]) keeps a good pose exactly but cannot pull a pose that starts 4-6 px off,
//! because near such a pose no wall pairs agree well enough to carry weight. The search scores
//! every pose of a coarse-to-fine grid around the hypothesis on both maps' walls, as
//! correlative scan matching does (Olson 2009): each wall cell of one map adds
//! `exp(-d^2 / 2 sigma^2)` for the distance `d` to the nearest wall of the other map (nothing
//! where that map is unknown), in both directions, less [`SearchConfig::free_penalty`] where
//! `d` exceeds two kernel widths on known cells (a wall where the other robot saw free
//! space), so that a placement does not gain by sliding towards more overlap whatever its
//! walls land on. The pose with the highest score wins; ties
//! keep the hypothesis. The window is small, so the search improves a hypothesis; it cannot
//! make a wrong one right.
//!
//! By default only the translation is searched. Measured with `cargo xtask eval --suites
//! overlap,mismatch --cases 20` (hybrid): without the search 78 % of the disaster pairs at 50 %
//! overlap and 35 % of the 10 %/15 % noise pairs succeeded; with the translation search 90 %
//! and 65 %. Searching +-2 degrees as well did worse at 30 % overlap (15 % instead of 30 %, the
//! median rotation error doubled to 0.77 degrees) and cost 5 times as much: the walls of a
//! noisy range sensor are pushed away from the robot by about the noise bound times the range,
//! differently in each map, and a slightly rotated pose can fit those biased walls better than
//! the true one. Rotation is left to ICP for feature-based hypotheses.
//!
//! The placements of the whole-map searches (the rotation sweep's 2-degree grid of angles, the
//! Hough search, the symmetry probes) are searched over +-2 degrees as well, besides the
//! translation-only search, and the better-scoring of the refined poses is kept
//! (`PairConfig::turn_search`): on `cargo xtask eval --suites overlap,zero,paper,real,noise
//! --cases 20 --seed 7` disaster 0.3 rose from 40 to 55 % (see `docs/EVALUATION.md`).

use grid_core::{DVec2, Rigid2};

use crate::verify::{PreparedMap, UNKNOWN_QUARTERS, strided};

/// The search window and grid, with documented defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SearchConfig {
    /// Largest translation tried, in pixels, along each axis. Default 8.
    pub radius_px: f64,
    /// Translation step of the coarse grid, in pixels; each finer level halves it. Default 2.
    pub step_px: f64,
    /// Largest rotation tried, in degrees. Default 0: translation only (see the module docs).
    pub max_angle_deg: f64,
    /// Rotation step of the coarse grid, in degrees; each finer level halves it. Default 1.
    pub angle_step_deg: f64,
    /// Finer levels after the coarse grid, each a 3 x 3 x 3 grid at half the previous steps
    /// around the best pose so far. Default 3 (final steps 0.25 px and 0.125 degrees).
    pub levels: usize,
    /// Width of the score kernel, in pixels. Default 3.5: wider than a wall's spread under
    /// 10 % range noise (about 1.5 px at the simulator's ranges), so that walls each map pushed
    /// its own way by range bias still draw the pose towards the truth. Over seeds 7-9 it
    /// registered 185 of the 360 pairs of the 30 % and real rows where 1.5 px registered 169,
    /// with fewer false accepts (`cargo xtask eval --search-sigma PX`). Maps whose walls stay
    /// in place as speckle (`--mapper hector`) lose by it: 98 instead of 105 of their 120 pairs
    /// at 30 % overlap; 2.5 px costs neither kind of map anything (docs/EVALUATION.md, "The
    /// local search's kernel width").
    pub sigma_px: f64,
    /// Wall cells used per map on the finer levels (strided sample). Default 2000.
    pub max_points: usize,
    /// Wall cells used per map on the coarse grid, the bulk of the poses. Default 500.
    pub coarse_points: usize,
    /// Subtracted from the score for each wall cell that lands on a known cell more than two
    /// kernel widths (`2 sigma_px`) from the other map's walls: a wall where the other robot
    /// saw free space. Default 1. Without it the score only grows with the walls compared,
    /// and on a small overlap the search slides a placement towards more overlap: the rotation
    /// sweep placed hector's 30 % pairs 12000002 and 11000013 4.0-4.6 px from the truth, and
    /// the search moved them 8.8 and 17.8 px away, where they failed verification (with the
    /// penalty 4.7 and 2.6 px, and they pass). Over the 30 % rows at seeds 7-12 (240 pairs per
    /// mapper) and the real floors (240 and 160) penalties 0, 0.5, 1 and 2 registered 181,
    /// 183, 184, 184 (default mapper, 30 %), 228, 228, 230, 230 (hector, 30 %), 109, -, 119,
    /// 111 (default, real floors) and 131, -, 132, 132 (hector, real floors); the zero-overlap
    /// pairs declined stayed the same (docs/EVALUATION.md, "Walls in free space weigh against
    /// the local search").
    pub free_penalty: f64,
    /// The search turns B about the centroid of its walls as placed (translation steps then do
    /// not have to make up for the swing of a turn), or about the centroid of only those that
    /// land on A's known cells, the overlap, when that lies at least this far (pixels) from
    /// the former. Default `f64::INFINITY`: always about all walls. On a small overlap of
    /// large maps B's walls as a whole lie hundreds of pixels from the shared ones, and a turn
    /// of a degree about their centroid moves the shared walls by more than the search's
    /// translations take back: with 150, `cargo xtask eval --suites large --seed S` (maps about
    /// 1800 x 900 cells) registered 9 and 13 of 20 pairs at S = 7 and 8 instead of 5 and 12
    /// (hector's mapper at 8: 16 instead of 14), and the 30 % rows (seeds 7-9), hector's real
    /// floors and the zero-overlap rows changed no outcome; but the default
    /// mapper's real floors (seeds 7-9) registered 146 instead of 149 of 300 pairs, 9 of them
    /// moving across the 3 px line either way on uos_cic (980 x 1477 cells), and 300 px did no
    /// better there (docs/EVALUATION.md, "A large floor"). Not the default until a form
    /// helps both floors; `--search-overlap-pivot 150` measures it.
    pub overlap_pivot_px: f64,
}

impl Default for SearchConfig {
    fn default() -> Self {
        Self {
            radius_px: 8.0,
            step_px: 2.0,
            max_angle_deg: 0.0,
            angle_step_deg: 1.0,
            levels: 3,
            sigma_px: 3.5,
            max_points: 2000,
            coarse_points: 500,
            free_penalty: 1.0,
            overlap_pivot_px: f64::INFINITY,
        }
    }
}

/// Kernel values by distance in quarter pixels, zero beyond 4 sigma. Distances are read as
/// bytes ([`PreparedMap::known_wall_quarters`], at most 254 quarters): a sigma above 15.8 px
/// sees every wall farther than 63.5 px at 63.5 px.
struct Kernel {
    /// One value per byte, so that a lookup needs no bounds check: 0 beyond 4 sigma and at
    /// [`UNKNOWN_QUARTERS`].
    table: [f32; 256],
}

impl Kernel {
    fn new(sigma: f64, free_penalty: f64) -> Self {
        let n = (16.0 * sigma).ceil() as usize + 1;
        let mut table = [0.0; 256];
        for (i, v) in table.iter_mut().enumerate() {
            let d = i as f64 / 4.0;
            let kernel = if i < n {
                (-d * d / (2.0 * sigma * sigma)).exp()
            } else {
                0.0
            };
            let penalty = if d > 2.0 * sigma { free_penalty } else { 0.0 };
            *v = (kernel - penalty) as f32;
        }
        table[UNKNOWN_QUARTERS as usize] = 0.0;
        Self { table }
    }

    /// The kernel at a distance in quarter pixels ([`PreparedMap::known_wall_quarters`]);
    /// zero for an unknown cell.
    #[inline]
    fn at(&self, quarters: u8) -> f32 {
        self.table[quarters as usize]
    }
}

/// Sum of kernel values of `points` mapped by `t` onto `onto`'s walls (nothing where `onto`
/// is unknown: the kernel of an infinite distance is 0).
fn half_score(points: &[DVec2], onto: &PreparedMap, t: &Rigid2, k: &Kernel) -> f32 {
    shifted_score(&turned(points, t.theta), onto, t.translation(), k)
}

/// [`half_score`] of points already turned by the pose's rotation ([`turned`]), for the
/// pose's translation `shift`.
fn shifted_score(turned: &[DVec2], onto: &PreparedMap, shift: DVec2, k: &Kernel) -> f32 {
    let mut s = 0.0;
    for &r in turned {
        s += k.at(onto.known_wall_quarters(r + shift));
    }
    s
}

/// Fractional bits of the fixed-point coordinates of [`shifted_scores`].
const FRACTION_BITS: u32 = 20;

/// `v` in fixed point with [`FRACTION_BITS`] fractional bits (truncated), clamped to a billion
/// pixels either way so that a point plus a shift cannot overflow.
#[inline]
fn fixed(v: f64) -> i64 {
    (v.clamp(-1e9, 1e9) * (1u64 << FRACTION_BITS) as f64) as i64
}

/// [`shifted_score`] for each of `shifts`, in order, with the same sums (each adds the points
/// in order). Point by point rather than shift by shift: the cells one point visits over the
/// shifts lie close together, so they stay in the nearest cache.
///
/// Points and shifts are added in fixed point ([`FRACTION_BITS`]): an integer sum, a shift
/// and one unsigned test per axis instead of a floating-point sum, two conversions and four
/// tests. The cell differs from that of the floating-point sum only where the sum lies within
/// about a millionth of a pixel of a cell's edge. The turn search took 1.0 instead of 1.5 ms
/// (`cargo bench -p mapmerge --bench register -- turn_search`).
fn shifted_scores(turned: &[DVec2], onto: &PreparedMap, shifts: &[DVec2], k: &Kernel) -> Vec<f32> {
    let mut sums = vec![0.0f32; shifts.len()];
    // Each point moved once by the half cell of rounding and the window's origin, so that a
    // shifted point's window cell is its coordinates truncated, where they lie in the window:
    // the same cells as `known_wall_quarters` but where a point lies within rounding of a
    // cell's edge. A negative sum wraps to beyond the window's sides.
    let (x0, y0, w, h) = onto.walls.window();
    let corner = DVec2::new(0.5 - x0 as f64, 0.5 - y0 as f64);
    let (w_fixed, h_fixed) = ((w as u64) << FRACTION_BITS, (h as u64) << FRACTION_BITS);
    let shifts: Vec<(i64, i64)> = shifts.iter().map(|s| (fixed(s.x), fixed(s.y))).collect();
    for &r in turned {
        let r = r + corner;
        if !r.is_finite() {
            continue;
        }
        let (rx, ry) = (fixed(r.x), fixed(r.y));
        for (s, &(sx, sy)) in sums.iter_mut().zip(&shifts) {
            let (qx, qy) = ((rx + sx) as u64, (ry + sy) as u64);
            if qx < w_fixed && qy < h_fixed {
                let (x, y) = (
                    (qx >> FRACTION_BITS) as usize,
                    (qy >> FRACTION_BITS) as usize,
                );
                *s += k.at(onto.known_quarters_at(y * w + x));
            }
        }
    }
    sums
}

/// [`shifted_score`] for each shift `base + step` of `steps` (whole cells), in order: a point
/// lands on the cell of `r + base` moved by the step, so it is rounded once and then stepped
/// through the cells. The same sums as [`shifted_scores`] over those shifts but where a point
/// lies within rounding of a cell's edge.
fn lattice_scores(
    turned: &[DVec2],
    onto: &PreparedMap,
    base: DVec2,
    steps: &[(i64, i64)],
    k: &Kernel,
) -> Vec<f32> {
    let mut sums = vec![0.0f32; steps.len()];
    let (x0, y0, w, h) = onto.walls.window();
    for &r in turned {
        let q = r + base;
        let Some((cx, cy)) = crate::verify::nearest_cell(q) else {
            // Off the map's low side at the base: look each shift up.
            for (s, &(dx, dy)) in sums.iter_mut().zip(steps) {
                let shift = DVec2::new(dx as f64, dy as f64);
                *s += k.at(onto.known_wall_quarters(q + shift));
            }
            continue;
        };
        let (cx, cy) = (cx as i64 - x0 as i64, cy as i64 - y0 as i64);
        for (s, &(dx, dy)) in sums.iter_mut().zip(steps) {
            // A negative coordinate wraps to beyond any side: one test per axis.
            let (x, y) = ((cx + dx) as u64 as usize, (cy + dy) as u64 as usize);
            if x < w && y < h {
                *s += k.at(onto.known_quarters_at(y * w + x));
            }
        }
    }
    sums
}

/// Fewest of B's walls on A's known cells whose centroid [`overlap_centre`] takes.
const MIN_OVERLAP_WALLS: usize = 20;

/// Where the search turns the placement `b_to_a`: the centroid (in A's frame) of `pb` (B's
/// walls) that land on A's known cells, when at least [`MIN_OVERLAP_WALLS`] do and it lies at
/// least `min_lever_px` from the centroid of all of `pb`; else the latter (see
/// [`SearchConfig::overlap_pivot_px`]).
fn overlap_centre(a: &PreparedMap, pb: &[DVec2], b_to_a: &Rigid2, min_lever_px: f64) -> DVec2 {
    let all = b_to_a.apply(pb.iter().copied().sum::<DVec2>() / pb.len() as f64);
    if min_lever_px == f64::INFINITY {
        return all;
    }
    let (sum, n) = pb
        .iter()
        .map(|&p| b_to_a.apply(p))
        .filter(|&q| a.known_wall_quarters(q) != UNKNOWN_QUARTERS)
        .fold((DVec2::ZERO, 0usize), |(s, n), q| (s + q, n + 1));
    if n >= MIN_OVERLAP_WALLS && (sum / n as f64 - all).length() >= min_lever_px {
        sum / n as f64
    } else {
        all
    }
}

/// `points` turned by `theta`.
fn turned(points: &[DVec2], theta: f64) -> Vec<DVec2> {
    let rot = DVec2::from_angle(theta);
    points.iter().map(|p| rot.rotate(*p)).collect()
}

/// The best pose near `b_to_a` (maps pixels of `b` onto `a`) by the correlative score.
pub fn local_search(
    a: &PreparedMap,
    b: &PreparedMap,
    b_to_a: &Rigid2,
    config: &SearchConfig,
) -> Rigid2 {
    let pa = strided(&a.wall_samples, config.max_points);
    let pb = strided(&b.wall_samples, config.max_points);
    if pa.is_empty() || pb.is_empty() {
        return *b_to_a;
    }
    let (ca, cb) = (
        strided(&pa, config.coarse_points),
        strided(&pb, config.coarse_points),
    );
    let kernel = Kernel::new(config.sigma_px, config.free_penalty);
    // Rotate about the centre of the walls compared (see `SearchConfig::overlap_pivot_px`), so
    // a rotation step does not also swing them.
    let centre = overlap_centre(a, &pb, b_to_a, config.overlap_pivot_px);
    let pose = |dtheta: f64, d: DVec2| {
        let about = Rigid2::new(0.0, centre.x, centre.y)
            .compose(&Rigid2::new(dtheta, 0.0, 0.0))
            .compose(&Rigid2::new(0.0, -centre.x, -centre.y));
        Rigid2::new(0.0, d.x, d.y).compose(&about).compose(b_to_a)
    };
    let score = |t: &Rigid2, coarse: bool| {
        let (pa, pb) = if coarse { (&ca, &cb) } else { (&pa, &pb) };
        half_score(pb, a, t, &kernel) + half_score(pa, b, &t.inverse(), &kernel)
    };
    let mut best = (0.0, DVec2::ZERO);
    let mut best_score = score(b_to_a, true);
    let mut step = config.step_px;
    let mut astep = config.angle_step_deg.to_radians();
    let (mut n_t, mut n_a) = (
        (config.radius_px / config.step_px).round() as i64,
        if config.max_angle_deg > 0.0 {
            (config.max_angle_deg / config.angle_step_deg).round() as i64
        } else {
            0
        },
    );
    for level in 0..=config.levels {
        if level == 1 {
            // The finer levels compare on more points: rescore the winner on them.
            best_score = score(&pose(best.0, best.1), false);
        }
        let coarse = level == 0;
        let (sa, sb) = if coarse { (&ca, &cb) } else { (&pa, &pb) };
        let (theta0, d0) = best;
        let offsets: Vec<DVec2> = (-n_t..=n_t)
            .flat_map(|iy| (-n_t..=n_t).map(move |ix| DVec2::new(ix as f64, iy as f64)))
            .map(|o| d0 + o * step)
            .collect();
        for ia in -n_a..=n_a {
            let dtheta = theta0 + ia as f64 * astep;
            // Every pose at this angle turns the points alike (a pose's angle does not depend
            // on its translation): turn them once, then only shift them per pose.
            let at_angle = pose(dtheta, d0);
            let (tb, ta) = (
                turned(sb, at_angle.theta),
                turned(sa, at_angle.inverse().theta),
            );
            let poses: Vec<Rigid2> = offsets.iter().map(|&d| pose(dtheta, d)).collect();
            let shifts_a: Vec<DVec2> = poses.iter().map(|t| t.inverse().translation()).collect();
            // B's points move with the offset itself: on the levels of whole-pixel steps they
            // step through whole cells.
            let sums_b = if step.fract() == 0.0 && step.abs() < 1e6 {
                let steps: Vec<(i64, i64)> = offsets
                    .iter()
                    .map(|&d| {
                        let o = d - d0;
                        (o.x.round() as i64, o.y.round() as i64)
                    })
                    .collect();
                lattice_scores(&tb, a, at_angle.translation(), &steps, &kernel)
            } else {
                let shifts_b: Vec<DVec2> = poses.iter().map(|t| t.translation()).collect();
                shifted_scores(&tb, a, &shifts_b, &kernel)
            };
            let sums_a = shifted_scores(&ta, b, &shifts_a, &kernel);
            for (k, &d) in offsets.iter().enumerate() {
                let s = sums_b[k] + sums_a[k];
                // Strictly better only: on a plateau the hypothesis (or the earlier pose)
                // stays, which keeps the result independent of the grid's visiting order.
                if s > best_score {
                    best_score = s;
                    best = (dtheta, d);
                }
            }
        }
        if level < config.levels {
            step /= 2.0;
            astep /= 2.0;
            // Half steps, one each way: covers the half-cell the coarser level could not split.
            n_t = 1;
            n_a = n_a.min(1);
        }
    }
    if best == (0.0, DVec2::ZERO) {
        *b_to_a
    } else {
        pose(best.0, best.1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testmaps::room;
    use crate::verify::VerifyConfig;

    #[test]
    fn walls_on_known_cells_far_from_the_other_maps_walls_cost_the_free_penalty() {
        let (sigma, penalty) = (3.5f64, 0.75);
        let k = Kernel::new(sigma, penalty);
        let kernel = |d: f64| (-d * d / (2.0 * sigma * sigma)).exp();
        assert_eq!(k.at(0), 1.0);
        // Up to two kernel widths (7 px, 28 quarters) the kernel alone; beyond, less the
        // penalty; beyond four widths the penalty alone.
        assert_eq!(k.at(28), kernel(7.0) as f32);
        assert_eq!(k.at(29), (kernel(7.25) - penalty) as f32);
        assert_eq!(k.at(254), -0.75);
        // Unknown cells cost nothing.
        assert_eq!(k.at(UNKNOWN_QUARTERS), 0.0);
        assert_eq!(Kernel::new(sigma, 0.0).at(254), 0.0);
    }

    #[test]
    fn the_search_turns_about_the_overlap_when_it_lies_far_from_all_walls() {
        // A's known cells span (10..=109, 10..=89). Thirty of B's walls land inside, about
        // (40, 50); thirty far outside, about (1000, 50): the overlap's centroid lies 480 px
        // from all walls' centroid.
        let a = room();
        let pa = PreparedMap::new(&a, &VerifyConfig::default());
        let inside: Vec<DVec2> = (0..30).map(|k| DVec2::new(25.0 + k as f64, 50.0)).collect();
        let outside: Vec<DVec2> = (0..30)
            .map(|k| DVec2::new(985.0 + k as f64, 50.0))
            .collect();
        let pb: Vec<DVec2> = inside.iter().chain(&outside).copied().collect();
        let id = Rigid2::IDENTITY;
        assert_eq!(overlap_centre(&pa, &pb, &id, 150.0), DVec2::new(39.5, 50.0));
        assert_eq!(overlap_centre(&pa, &pb, &id, 480.0), DVec2::new(39.5, 50.0));
        // Closer than the lever, or turned off: all walls' centroid.
        assert_eq!(
            overlap_centre(&pa, &pb, &id, 481.0),
            DVec2::new(519.5, 50.0)
        );
        assert_eq!(
            overlap_centre(&pa, &pb, &id, f64::INFINITY),
            DVec2::new(519.5, 50.0)
        );
        // Too few walls in the overlap to say where it is.
        let few: Vec<DVec2> = inside[..19].iter().chain(&outside).copied().collect();
        let all = few.iter().copied().sum::<DVec2>() / few.len() as f64;
        assert_eq!(overlap_centre(&pa, &few, &id, 0.0), all);
        // The placement moves the walls first: shifted 2000 px, none lands on A.
        let away = Rigid2::new(0.0, 2000.0, 0.0);
        assert_eq!(
            overlap_centre(&pa, &pb, &away, 0.0),
            DVec2::new(2519.5, 50.0)
        );
    }

    #[test]
    fn a_hypothesis_a_few_pixels_off_moves_to_the_truth() {
        let a = room();
        let truth = Rigid2::new(0.0, 0.0, 0.0);
        let vc = VerifyConfig::default();
        let (pa, pb) = (PreparedMap::new(&a, &vc), PreparedMap::new(&a, &vc));
        let with_rotation = SearchConfig {
            max_angle_deg: 2.0,
            ..SearchConfig::default()
        };
        for (start, config) in [
            (Rigid2::new(0.0, 5.0, -4.0), SearchConfig::default()),
            (Rigid2::new(0.0, -6.0, 3.0), SearchConfig::default()),
            (Rigid2::new(0.0, 7.0, 7.0), SearchConfig::default()),
            (Rigid2::new(1.5f64.to_radians(), 5.0, -4.0), with_rotation),
            (Rigid2::new(-1.0f64.to_radians(), -6.0, 3.0), with_rotation),
        ] {
            let found = local_search(&pa, &pb, &start, &config);
            let err = grid_core::metrics::displacement_error(&a, &found, &truth).unwrap();
            // Scores are read at the nearest cell, so poses within half a cell tie: the
            // search lands within a pixel and ICP does the sub-pixel part.
            assert!(err < 1.0, "from {start:?}: {found:?} is {err} px off");
            if config.max_angle_deg > 0.0 {
                // Nearest-cell scores make plateaus in angle too: within half a coarse step.
                let rot = grid_core::metrics::rotation_error_deg(&found, &truth);
                assert!(
                    rot <= 0.5 * config.angle_step_deg + 1e-9,
                    "from {start:?}: rotation {rot} degrees off"
                );
            } else {
                assert_eq!(found.theta, start.theta, "translation-only search turned");
            }
        }
    }

    #[test]
    fn shifts_scored_together_score_as_each_alone() {
        let a = room();
        let pa = PreparedMap::new(&a, &VerifyConfig::default());
        let k = Kernel::new(3.5, 0.0);
        let points = turned(&strided(&pa.wall_samples, 300), 0.3);
        // A lattice of whole cells around a fractional base, some of it off the map.
        for (base, step) in [
            (DVec2::new(17.3, -8.6), 2),
            (DVec2::new(-60.25, 4.7), 1),
            (DVec2::new(95.1, 40.2), 8),
            (DVec2::new(-150.4, -20.2), 4),
        ] {
            let steps: Vec<(i64, i64)> = (-4..=4)
                .flat_map(|j| (-4..=4).map(move |i| (i * step, j * step)))
                .collect();
            let each: Vec<f32> = steps
                .iter()
                .map(|&(dx, dy)| {
                    let shift = base + DVec2::new(dx as f64, dy as f64);
                    shifted_score(&points, &pa, shift, &k)
                })
                .collect();
            assert_eq!(
                lattice_scores(&points, &pa, base, &steps, &k),
                each,
                "{base}"
            );
            // Shifts of any fraction, read from the window directly, give the same sums.
            let shifts: Vec<DVec2> = steps
                .iter()
                .map(|&(dx, dy)| base + DVec2::new(dx as f64, dy as f64) * 0.37)
                .collect();
            let each: Vec<f32> = shifts
                .iter()
                .map(|&s| shifted_score(&points, &pa, s, &k))
                .collect();
            assert_eq!(shifted_scores(&points, &pa, &shifts, &k), each, "{base}");
            // Walls are hit, but for the lattice far off the map.
            assert_eq!(each.iter().any(|&v| v > 10.0), base.x > -100.0, "{each:?}");
        }
    }

    #[test]
    fn the_truth_stays_put() {
        let a = room();
        let vc = VerifyConfig::default();
        let (pa, pb) = (PreparedMap::new(&a, &vc), PreparedMap::new(&a, &vc));
        let found = local_search(&pa, &pb, &Rigid2::default(), &SearchConfig::default());
        assert_eq!(found, Rigid2::default());
    }
}
