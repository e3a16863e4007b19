//! Score ascent: a compass search on the verification score around the answer.
//!
//! ICP ([`crate::refine`]) stops where its wall pairs balance, which with a narrow robust
//! kernel need not be where the maps agree best: on maps whose walls stay in place but
//! broken into speckle about two cells thick (a scan-matching mapper's, such as Hector's), the
//! pairs that carry weight are the few cells that happen to coincide, and the fit can settle
//! a few pixels off while the verification score ([`Verification::score`]) still rises all
//! the way to the truth. The ascent climbs that score directly, less a penalty for the walls
//! each map puts in the other's free space ([`AscentConfig::contradiction_weight`]): from the
//! pose, it tries a step along each axis and a turn each way about B's walls' centre, moves
//! to the best that scores higher, and halves the step when none does.
//!
//! It is not for every map: where walls are thin and a noisy range sensor pushed them behind
//! the obstacle faces, differently in each map, the score peaks where the pushed walls
//! coincide, a few pixels from the truth, and ICP's range-bias offsets
//! ([`crate::refine::RefineConfig::range_bias`]) do better. [`wall_thickness`] tells the two
//! apart ([`AscentConfig::min_wall_thickness`]). Thin walls are climbed too where the maps'
//! frontiers ([`frontier_ratio`]) show a short-range sensor, which pushes its walls little
//! ([`ShortRange`]).

use grid_core::{CellState, OccupancyGrid, Rigid2};
use rayon::prelude::*;

use crate::verify::{PreparedMap, Verification, VerifyConfig, verify};

/// The steps of the ascent, with documented defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AscentConfig {
    /// First translation step, in pixels. Default 2.
    pub initial_step_px: f64,
    /// The ascent stops once no step of this size or larger improves the score. Default 0.25.
    pub final_step_px: f64,
    /// Turn tried with each translation step, in degrees per pixel of step (the turn is
    /// about the centre of B's walls). Default 0.25: 0.5 degrees with the first step.
    pub turn_deg_per_px: f64,
    /// Moves at most (each tries six poses). Default 40.
    pub max_moves: usize,
    /// The ascent runs when both maps' walls are at least this thick ([`wall_thickness`]),
    /// or on a short-range sensor's maps (`short_range`). Default 1.1. The default mapper of
    /// `mapsim` marks walls one cell thick, often with unknown cells behind (0.66-0.85 on the
    /// 80 maps of the 30 % rows of seed 7, `mapmerge info` on the maps `cargo xtask eval
    /// --export` writes), and a noisy range sensor pushes them behind the obstacle faces by
    /// amounts that differ from map to map: the score there peaks 3-5 px from the truth, and
    /// climbing it registered 3 more and 18 fewer of the 120 pairs at 30 % overlap (seeds
    /// 7-9). Hector's model marks walls about two cells thick and in place (1.25-1.76); the
    /// floors of `fixtures/maps` measure 0.65-2.34 as drawn (docs/EVALUATION.md, "The score
    /// ascent"). A short-range sensor with few beams also leaves one-cell walls, but little
    /// pushed: on mapsim's paper preset (16-beam infrared rings, range 30 cells) at 30 %
    /// overlap the ascent without this gate registered 50 instead of 45 of 63 pairs (seeds 7,
    /// 8, 9, 23), where the default mapper's lidar rows at 30 % overlap lost 17 of 40 (seed
    /// 7; docs/EVALUATION.md, "A second held-out seed, and the score ascent on the paper's
    /// sensor"). The walls do not tell the two sensors apart; the free space's frontiers do
    /// (`short_range`). `mapmerge estimate|merge --climb` sets 0, for a user who knows the
    /// sensor.
    pub min_wall_thickness: f64,
    /// When the ascent also runs on walls thinner than `min_wall_thickness`: on the maps of a
    /// short-range sensor ([`ShortRange`]). `None`: never. Default: on, [`ShortRange::default`].
    pub short_range: Option<ShortRange>,
    /// What the climb maximises: [`Verification::score`] less this many times the wall
    /// cells that land in the other map's free space (`wall_contradiction * wall_support`).
    /// Default 3. The score grows with the walls compared, so a pose that brings more of
    /// them into the overlap can outscore the truth even while it puts some of them where the
    /// other robot saw through: in five of the nine answers 3-12 px off in hector's 30 % rows
    /// (seeds 7-12) 3.4-10.4 % of the compared walls lay in free space, at the truth refined
    /// 0.5-1.3 %.
    /// Over the 240 pairs of hector's 30 % rows at seeds 7-12 weights 0, 1, 2, 3, 4 and 5
    /// registered 222, 222, 225, 228, 228 and 227, over its 160 pairs on real floors 129, 129,
    /// 130, 131, 129 and 128 (docs/EVALUATION.md, "Walls in free space weigh against the
    /// ascent").
    pub contradiction_weight: f64,
}

impl Default for AscentConfig {
    fn default() -> Self {
        Self {
            initial_step_px: 2.0,
            final_step_px: 0.25,
            turn_deg_per_px: 0.25,
            max_moves: 40,
            min_wall_thickness: 1.1,
            short_range: Some(ShortRange::default()),
            contradiction_weight: 3.0,
        }
    }
}

/// The ascent on thin walls, for a short-range sensor's maps: a sensor whose beams end in open
/// space more often than on a wall has a short range, or few beams, and saw its walls from
/// near, where range noise pushes them little, so the score peaks near the truth. The paper's
/// 16-beam infrared ring (range 30 cells) draws such maps, with walls one cell thick and
/// dotted, where ICP can stop a few pixels or degrees off (docs/EVALUATION.md, "Frontiers
/// tell a short-range sensor").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShortRange {
    /// Frontier cells per free cell beside a wall ([`frontier_ratio`]) that both maps need.
    /// Default 1.2. On the maps `cargo xtask eval --export` writes (the smaller of each
    /// pair's two), the default mapper's lidar maps at 10 % noise measure 0.76-1.04 in the
    /// simulated 30 % rows (seeds 7-9) and 0.65-1.19 on the real floors taken as worlds (10 %
    /// and 20 % noise, seed 7), and the paper preset's 1.05-2.90 at 30 % overlap (60 of the
    /// 63 pairs of seeds 7, 8, 9 and 23 at 1.2 or more) and 0.94-3.58 at half overlap.
    pub min_frontier_ratio: f64,
    /// The answer's wall lift ([`Verification::wall_lift`]) must be below this. Default 0.85.
    /// Walls that agree almost everywhere leave the score nothing to add but whole-cell
    /// steps: on real robots' maps cut in two (`cargo xtask eval --suites sensor`, seeds 7-9),
    /// whose cut leaves long frontiers, the rule without this bar moved 18 answers at lift
    /// 0.91-0.97, 13 of them further from the truth (from 0.02-0.19 px off to 0.17-1.11 px).
    /// The paper preset's answers that the climb brought within 3 px had lifts of 0.37-0.71,
    /// and none of its answers reached 0.9.
    pub max_wall_lift: f64,
}

impl Default for ShortRange {
    fn default() -> Self {
        Self {
            min_frontier_ratio: 1.2,
            max_wall_lift: 0.85,
        }
    }
}

/// How thick a map's walls are: its occupied cells per side shared by an occupied and a free
/// cell (4-neighbours). A wall one cell thick seen from one side scores 1, a band two cells
/// thick 2; walls that end in unknown cells score less. 0 for a map without such sides.
pub fn wall_thickness(grid: &OccupancyGrid) -> f64 {
    let (w, h) = (grid.width(), grid.height());
    let free = |x: usize, y: usize| grid.state(x, y) == CellState::Free;
    let (mut occupied, mut sides) = (0usize, 0usize);
    for y in 0..h {
        for x in 0..w {
            if grid.state(x, y) != CellState::Occupied {
                continue;
            }
            occupied += 1;
            sides += usize::from(x > 0 && free(x - 1, y))
                + usize::from(x + 1 < w && free(x + 1, y))
                + usize::from(y > 0 && free(x, y - 1))
                + usize::from(y + 1 < h && free(x, y + 1));
        }
    }
    if sides == 0 {
        0.0
    } else {
        occupied as f64 / sides as f64
    }
}

/// A map's frontier cells (free cells beside an unknown cell or the map's edge, as in
/// frontier-based exploration) per free cell beside an occupied one (4-neighbours; a cell
/// beside both counts in both). It is high where the sensor's beams ended in open space, at
/// the end of their range, more often than on walls. 0 for a map without a free cell beside a
/// wall.
pub fn frontier_ratio(grid: &OccupancyGrid) -> f64 {
    let (mut frontier, mut beside_walls) = (0usize, 0usize);
    // A cell that is not free costs one test; a free cell's neighbours are read from its row
    // and the rows above and below.
    for (here, up, down) in rows_with_neighbours(grid) {
        for x in 0..here.len() {
            if OccupancyGrid::classify(here[x]) != CellState::Free {
                continue;
            }
            let neighbours = [
                x.checked_sub(1).map(|x| here[x]),
                here.get(x + 1).copied(),
                up.map(|r| r[x]),
                down.map(|r| r[x]),
            ];
            let (mut open, mut wall) = (false, false);
            for n in neighbours {
                match n.map(OccupancyGrid::classify) {
                    None | Some(CellState::Unknown) => open = true,
                    Some(CellState::Occupied) => wall = true,
                    Some(CellState::Free) => {}
                }
            }
            frontier += usize::from(open);
            beside_walls += usize::from(wall);
        }
    }
    if beside_walls == 0 {
        0.0
    } else {
        frontier as f64 / beside_walls as f64
    }
}

/// The share of a map's occupied cells with no occupied cell among their eight neighbours: how
/// much of its walls a noisy range sensor broke into speckle. It grows with the sensor's noise
/// bound (`mapsim`'s default mapper, each map of `cargo xtask eval --out`: 0.03-0.08 at 10 %,
/// 0.09-0.21 at 20 %, 0.16-0.30 at 30 %, 0.28-0.46 at 50 %; docs/EVALUATION.md, "Equal noise
/// of 20 %"), so two maps of alike sensors score alike. 0 for a map without occupied cells.
pub fn lone_wall_share(grid: &OccupancyGrid) -> f64 {
    let w = grid.width();
    let occupied = |c: &u8| OccupancyGrid::classify(*c) == CellState::Occupied;
    let (mut walls, mut lone) = (0usize, 0usize);
    // The scan of the (mostly not occupied) cells is one test a cell, and an occupied cell's
    // neighbours are three short slices.
    for (here, up, down) in rows_with_neighbours(grid) {
        for (x, c) in here.iter().enumerate() {
            if !occupied(c) {
                continue;
            }
            walls += 1;
            let around = x.saturating_sub(1)..=(x + 1).min(w - 1);
            let neighbour = (x > 0 && occupied(&here[x - 1]))
                || (x + 1 < w && occupied(&here[x + 1]))
                || [up, down]
                    .into_iter()
                    .flatten()
                    .any(|r| r[around.clone()].iter().any(occupied));
            lone += usize::from(!neighbour);
        }
    }
    if walls == 0 {
        0.0
    } else {
        lone as f64 / walls as f64
    }
}

/// Each row of `grid`'s cells, with the rows above and below it (`None` at the edges).
fn rows_with_neighbours(
    grid: &OccupancyGrid,
) -> impl Iterator<Item = (&[u8], Option<&[u8]>, Option<&[u8]>)> {
    let (w, h) = (grid.width(), grid.height());
    let cells = grid.cells();
    let row = move |y: usize| &cells[y * w..][..w];
    (0..h).map(move |y| {
        (
            row(y),
            y.checked_sub(1).map(row),
            (y + 1 < h).then(|| row(y + 1)),
        )
    })
}

/// Climb the verification score, less the contradiction penalty
/// ([`AscentConfig::contradiction_weight`]), from `start` (B onto A). Returns the pose reached
/// and its verification (that of `start` when no step improved it).
pub fn ascend(
    a: &PreparedMap,
    b: &PreparedMap,
    start: &Rigid2,
    config: &AscentConfig,
    verify_config: &VerifyConfig,
) -> (Rigid2, Verification) {
    let objective = |v: &Verification| {
        v.score() - config.contradiction_weight * v.wall_contradiction * v.wall_support as f64
    };
    let centre = b.wall_centre();
    let mut pose = *start;
    let mut best = verify(a, b, &pose, verify_config);
    let mut step = config.initial_step_px;
    let mut moves = 0;
    while step >= config.final_step_px && moves < config.max_moves {
        let turn = (step * config.turn_deg_per_px).to_radians();
        let c = pose.apply(centre);
        let tries = [
            Rigid2::new(pose.theta, pose.tx + step, pose.ty),
            Rigid2::new(pose.theta, pose.tx - step, pose.ty),
            Rigid2::new(pose.theta, pose.tx, pose.ty + step),
            Rigid2::new(pose.theta, pose.tx, pose.ty - step),
            Rigid2::rotation_about(turn, c).compose(&pose).normalized(),
            Rigid2::rotation_about(-turn, c).compose(&pose).normalized(),
        ];
        let scored: Vec<Verification> = tries
            .par_iter()
            .map(|t| verify(a, b, t, verify_config))
            .collect();
        // The first of equals, so the result does not depend on the threads.
        let winner = (0..tries.len())
            .filter(|&i| objective(&scored[i]) > objective(&best))
            .max_by(|&i, &j| {
                objective(&scored[i])
                    .total_cmp(&objective(&scored[j]))
                    .then(j.cmp(&i))
            });
        match winner {
            Some(i) => {
                (pose, best) = (tries[i], scored[i]);
                moves += 1;
            }
            None => step /= 2.0,
        }
    }
    (pose, best)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testmaps::room;
    use grid_core::{Pose2, UNKNOWN};

    #[test]
    fn a_pose_a_few_pixels_and_a_degree_off_climbs_to_the_truth() {
        let a = room();
        let truth = Rigid2::default();
        let vc = VerifyConfig::default();
        let (pa, pb) = (PreparedMap::new(&a, &vc), PreparedMap::new(&a, &vc));
        let at_truth = verify(&pa, &pb, &truth, &vc).score();
        for start in [
            Rigid2::new(0.0, 3.0, -2.0),
            Rigid2::new(1.0f64.to_radians(), -2.5, 1.5),
            Rigid2::new(-0.8f64.to_radians(), 1.0, 3.0),
        ] {
            let before = verify(&pa, &pb, &start, &vc).score();
            let (found, v) = ascend(&pa, &pb, &start, &AscentConfig::default(), &vc);
            let err = grid_core::metrics::displacement_error(&a, &found, &truth).unwrap();
            // The score counts walls within a tolerance at whole cells: poses within about
            // half a cell of the truth tie with it.
            assert!(err < 1.0, "from {start:?}: {found:?} is {err} px off");
            assert!(
                v.score() > before,
                "from {start:?}: {} <= {before}",
                v.score()
            );
            assert_eq!(v, verify(&pa, &pb, &found, &vc));
            assert!(
                v.score() >= 0.99 * at_truth,
                "{} against {at_truth}",
                v.score()
            );
        }
    }

    #[test]
    fn walls_one_and_two_cells_thick_measure_one_and_two() {
        // Rows of free cells, then `thick` rows of wall, then unknown, 10 cells wide.
        let band = |thick: usize| {
            let mut cells = vec![UNKNOWN; 10 * 6];
            cells[..20].fill(0);
            cells[20..20 + 10 * thick].fill(100);
            OccupancyGrid::from_cells(10, 6, 0.05, Pose2::default(), cells).unwrap()
        };
        assert_eq!(wall_thickness(&band(1)), 1.0);
        assert_eq!(wall_thickness(&band(2)), 2.0);
        assert_eq!(wall_thickness(&band(0)), 0.0);
        // The same wall with free space on both sides: two sides a cell.
        let mut cells = vec![0; 10 * 5];
        cells[20..30].fill(100);
        let both = OccupancyGrid::from_cells(10, 5, 0.05, Pose2::default(), cells).unwrap();
        assert_eq!(wall_thickness(&both), 0.5);
    }

    #[test]
    fn frontier_cells_are_counted_per_free_cell_beside_a_wall() {
        // 10 x 6: row 0 wall, rows 1-3 free, rows 4-5 unknown. The free rows' end cells touch
        // the map's edge. Beside the wall: row 1 (10). Frontier: row 3 (10, beside unknown)
        // and the end cells of rows 1-2 (4, at the edge).
        let mut cells = vec![UNKNOWN; 10 * 6];
        cells[..10].fill(100);
        cells[10..40].fill(0);
        let map = |cells: Vec<u8>| {
            OccupancyGrid::from_cells(10, 6, 0.05, Pose2::default(), cells).unwrap()
        };
        assert_eq!(frontier_ratio(&map(cells.clone())), 14.0 / 10.0);
        // A wall across row 4 too: row 3 is then beside a wall, and only the free rows' end
        // cells are frontier.
        let mut walled = cells.clone();
        walled[40..50].fill(100);
        assert_eq!(frontier_ratio(&map(walled)), 6.0 / 20.0);
        // No free cell beside a wall.
        cells[..10].fill(0);
        assert_eq!(frontier_ratio(&map(cells)), 0.0);
    }

    #[test]
    fn lone_wall_cells_are_those_without_an_occupied_neighbour() {
        // A 10 x 6 map: a wall of 10 cells along row 1, a pair of diagonal neighbours and two
        // lone cells (one beside an unknown cell), the rest free or unknown.
        let mut cells = vec![0; 10 * 6];
        cells[10..20].fill(100);
        cells[4 * 10 + 2] = 100;
        cells[5 * 10 + 3] = 100;
        cells[3 * 10 + 6] = 100;
        cells[4 * 10 + 8] = 100;
        cells[5 * 10 + 9] = UNKNOWN;
        cells[0] = UNKNOWN;
        let mut grid = OccupancyGrid::from_cells(10, 6, 0.05, Pose2::default(), cells).unwrap();
        // Of 14 occupied cells, the one at (6, 3) and the one at (8, 4) are lone.
        assert_eq!(lone_wall_share(&grid), 2.0 / 14.0);
        // A corner cell's missing neighbours do not count as occupied.
        grid.cells_mut()[5 * 10] = 100;
        assert_eq!(lone_wall_share(&grid), 3.0 / 15.0);
        // No occupied cell: 0.
        let free = OccupancyGrid::from_cells(4, 4, 0.05, Pose2::default(), vec![0; 16]).unwrap();
        assert_eq!(lone_wall_share(&free), 0.0);
    }

    /// The row-slice scan counts as the plain definition does, at every border and size.
    #[test]
    fn lone_wall_share_is_its_definition_on_random_grids() {
        let definition = |g: &OccupancyGrid| {
            let (w, h) = (g.width() as i64, g.height() as i64);
            let occ = |x: i64, y: i64| {
                x >= 0
                    && y >= 0
                    && x < w
                    && y < h
                    && g.state(x as usize, y as usize) == CellState::Occupied
            };
            let (mut walls, mut lone) = (0, 0);
            for y in 0..h {
                for x in 0..w {
                    if occ(x, y) {
                        walls += 1;
                        let n = (-1..=1)
                            .flat_map(|dy| (-1..=1).map(move |dx| (dx, dy)))
                            .filter(|&d| d != (0, 0))
                            .any(|(dx, dy)| occ(x + dx, y + dy));
                        lone += usize::from(!n);
                    }
                }
            }
            if walls == 0 {
                0.0
            } else {
                lone as f64 / walls as f64
            }
        };
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        for (w, h) in [(1, 1), (1, 7), (7, 1), (2, 2), (13, 9), (40, 31)] {
            for _ in 0..20 {
                let cells: Vec<u8> = (0..w * h)
                    .map(|_| {
                        seed ^= seed << 13;
                        seed ^= seed >> 7;
                        seed ^= seed << 17;
                        [0, 100, 100, UNKNOWN, 0, 70][(seed % 6) as usize]
                    })
                    .collect();
                let g = OccupancyGrid::from_cells(w, h, 0.05, Pose2::default(), cells).unwrap();
                assert_eq!(lone_wall_share(&g), definition(&g), "{w} x {h}");
            }
        }
    }

    #[test]
    fn the_truth_stays_put() {
        let a = room();
        let vc = VerifyConfig::default();
        let (pa, pb) = (PreparedMap::new(&a, &vc), PreparedMap::new(&a, &vc));
        let (found, v) = ascend(&pa, &pb, &Rigid2::default(), &AscentConfig::default(), &vc);
        assert_eq!(found, Rigid2::default());
        assert_eq!(v, verify(&pa, &pb, &Rigid2::default(), &vc));
    }
}
