//! Robot-team simulator: the ground-truth factory of mapmerge.
//!
//! It is for: building seeded worlds (disaster area, indoor floor, or a given map), driving a
//! team of robots along collision-free paths with noisy range sensors, and returning each
//! robot's partial occupancy map in its own randomly rotated and shifted frame, together with
//! the exact pixel transforms between the maps ([`Case::truth`]) and the achieved overlap of
//! their explored areas. The registration crates use [`strategies`] in property tests and the
//! evaluation harness uses [`generate_case`] to build suites. It also cuts one map into two
//! parts with known truth ([`crop_pair`]): crisp-walled pairs without robots.
//!
//! It is not for: SLAM (poses are perfect; only ranges are noisy), registration, or map I/O.
//!
//! Frames: every transform follows the project conventions (pixel `x` column, `y` row from
//! the top, integer coordinates at pixel centres). `RobotMap::map_to_world` maps a pixel of the
//! robot's map to a pixel of the world raster; `Case::truth(i, j)` maps a pixel of map `j` onto
//! map `i`. Maps are rendered by casting each beam in the world and rasterising the same beam,
//! moved rigidly, in the robot's frame, so the truth is exact (no resampling).
//!
//! Determinism: the same [`CaseConfig`] and seed give the same [`Case`], bit for bit, whatever
//! the number of threads.
//!
//! What range noise does to a map: a hit at range `r` reads `r (1 + u)`, `u` uniform in
//! `[-b, b]`, and the inverse sensor model clears every cell before the reading. Readings that
//! overshoot clear the cells just behind an obstacle's face, and nothing clears the far end of
//! the band, so walls settle near `r (1 + b)`: pushed away from the robot by about `b r` cells,
//! differently in each robot's map. At 30-50 % a beam that reads long passes through thin
//! rubble, and with the default [`InverseSensorModel`] most obstacles disappear from the map;
//! a mapper that clears gently ([`InverseSensorModel::hector`]) keeps them as bands of speckle,
//! and the counting mappers of GMapping and slam_toolbox ([`HitRatioModel`]), which keep a
//! cell occupied wherever a quarter (a tenth) of the beams that reached it ended in it, keep
//! the far end of each band (a wide band over the obstacle's face).
//! Real mappers do one or the other; registration has to live with both (see
//! `docs/EVALUATION.md`).
//!
//! Cost (`cargo bench -p mapsim`, 2-core AMD EPYC VM): the paper preset takes 14 ms, a
//! 400 x 400 case with two 360-beam lidars about 0.5 s. A 4000 x 4000 case with range 300
//! takes 30.5 s and 1.27 GB peak, writing its files included (`cargo xtask gen --preset
//! disaster --size 4000 --range 300`). Most of the time is ray casting; the overlap control
//! casts only every `max_range / 10` cells of the tour, and once per distinct sensor.

use std::f64::consts::PI;

use glam::DVec2;
use grid_core::{OccupancyGrid, Rigid2, UNKNOWN};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

mod crops;
mod overlap;
mod planner;
mod raycast;
mod sensor;
#[cfg(feature = "proptest")]
pub mod strategies;
mod world;

pub use crops::{CropConfig, CropPair, crop_pair};
pub use world::{World, WorldConfig, WorldKind};

/// Result alias of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong when generating a case.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A configuration value is out of range; the message names the field.
    #[error("invalid configuration: {0}")]
    Config(String),
    /// World dimensions out of the supported range.
    #[error("world size {width} x {height} is outside the supported range (24..=20000 a side)")]
    WorldSize {
        /// Width in cells.
        width: usize,
        /// Height in cells.
        height: usize,
    },
    /// An obstacle raster of the wrong length.
    #[error("obstacle raster has {got} cells, expected {expected}")]
    RasterLen {
        /// Cells given.
        got: usize,
        /// `width * height`.
        expected: usize,
    },
    /// The world has no free region wide enough for a robot to drive through.
    #[error("the world has no free region wide enough for the robots")]
    NoFreeSpace,
    /// The achieved overlap is further than the tolerance from the requested one.
    #[error(
        "achieved overlap {achieved:.3} is more than {tolerance} from the requested {requested}"
    )]
    OverlapMissed {
        /// Requested overlap fraction.
        requested: f64,
        /// What the generated maps have.
        achieved: f64,
        /// The configured tolerance.
        tolerance: f64,
    },
    /// A grid could not be built.
    #[error(transparent)]
    Grid(#[from] grid_core::Error),
}

/// One robot's sensor.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RobotConfig {
    /// Beams, evenly spread over 360 degrees, beam 0 along the heading. Default 360 (lidar);
    /// 16 for an infrared ring.
    pub beams: usize,
    /// Maximum range in cells; farther obstacles return nothing. Default 80.
    pub max_range: f64,
    /// Multiplicative range noise bound `b`: a hit at true range `r` reads `r (1 + U(-b, b))`.
    /// Default 0.02.
    pub noise_bound: f64,
    /// Probability that a beam returns no reading at all. Default 0.
    pub dropout: f64,
    /// Indices of beams that never return a reading (failed sensors). Default empty.
    pub failed_beams: Vec<usize>,
}

impl Default for RobotConfig {
    fn default() -> Self {
        Self {
            beams: 360,
            max_range: 80.0,
            noise_bound: 0.02,
            dropout: 0.0,
            failed_beams: Vec::new(),
        }
    }
}

impl RobotConfig {
    /// The paper's infrared ring: 16 beams, range 30 cells, the given noise bound.
    pub fn infrared(noise_bound: f64) -> Self {
        Self {
            beams: 16,
            max_range: 30.0,
            noise_bound,
            ..Self::default()
        }
    }
}

/// Everything that defines a case, apart from the seed.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseConfig {
    /// The world. Default: 400 x 400 disaster area.
    pub world: WorldConfig,
    /// One entry per robot, at least 2 and at most 32. Default: two default lidars.
    pub robots: Vec<RobotConfig>,
    /// Requested overlap of consecutive robots' explored areas, as a fraction of the smaller
    /// one, in `[0, 1]`. `0` asks for disjoint explored areas. Default 0.5.
    pub overlap: f64,
    /// Largest accepted `|achieved - requested|` overlap; generation fails with
    /// [`Error::OverlapMissed`] beyond it. Default 0.1 (`f64::INFINITY` never fails).
    pub overlap_tolerance: f64,
    /// Each map's rotation is drawn from `U(-max_rotation, max_rotation)` radians. Default pi.
    pub max_rotation: f64,
    /// Unknown margin around each robot's explored area, in cells. Default 5.
    pub margin: usize,
    /// A random extra margin `U(0, extra_margin)` per side, so the maps' offsets vary. Default 20.
    pub extra_margin: usize,
    /// Distance between consecutive poses along a path, in cells. Default 2.
    pub pose_step: f64,
    /// Minimum distance (cells) from path to obstacles: the planner's robot radius. Default 3.
    pub clearance: f64,
    /// Spacing of the exploration waypoints in cells; `None` = 0.8 x the smallest max range.
    pub waypoint_spacing: Option<f64>,
    /// How every robot's mapper folds beams into its grid: log-odds or hit counts. Default
    /// [`InverseSensorModel::default`], log-odds.
    pub mapper: MapperModel,
}

/// The mapper's inverse sensor model: the log-odds added to a cell a beam passes through
/// (`free`, negative) and to the cell it ends in (`occupied`, positive), both clamped to
/// `[-clamp, clamp]`. A cell's final log-odds becomes its percent; what lies between the free
/// and occupied thresholds reads as unknown (`OccupancyGrid::classify`).
///
/// How strongly `free` clears against `occupied` decides what range noise leaves of the
/// walls. The default (`free` -1.4, `occupied` 2.2: cell probabilities 0.2 and 0.9) clears
/// hard, so under strong noise obstacles that beams read past fade away. Hector mapping's
/// defaults (`update_factor_free` 0.4, `update_factor_occupied` 0.9: log-odds -0.405 and
/// 2.197, [`Self::hector`]) clear gently, so a noisy wall stays as a band of speckle: the same
/// sensor gives another map, and registration should do on both. OctoMap's (0.4 and 0.7,
/// [`Self::octomap`]) lies between in the ratio of a hit to a pass but, its hit being small,
/// keeps about as little of a noisy wall as the default.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct InverseSensorModel {
    /// Log-odds added to each cell a beam passes through. Default -1.4.
    pub free: f32,
    /// Log-odds added to the cell a beam ends in. Default 2.2.
    pub occupied: f32,
    /// Bound of the log-odds magnitude. Default 5.0.
    pub clamp: f32,
}

impl Default for InverseSensorModel {
    fn default() -> Self {
        Self {
            free: -1.4,
            occupied: 2.2,
            clamp: 5.0,
        }
    }
}

impl InverseSensorModel {
    /// Hector mapping's defaults: cell probabilities 0.4 for a pass, 0.9 for a hit.
    pub fn hector() -> Self {
        Self {
            free: (0.4f32 / 0.6).ln(),
            occupied: (0.9f32 / 0.1).ln(),
            clamp: 5.0,
        }
    }

    /// OctoMap's defaults: cell probabilities 0.4 for a pass, 0.7 for a hit, log-odds
    /// clamped at 3.5 (OctoMap's upper clamping threshold, probability 0.97; its lower one,
    /// 0.12, is -2.0, and this model's clamp is symmetric). A hit outweighs two passes, but a
    /// cell hit once and passed once reads unknown (0.85 - 0.41 is below the occupied
    /// threshold), so under strong noise it keeps about as little wall as the default.
    pub fn octomap() -> Self {
        Self {
            free: (0.4f32 / 0.6).ln(),
            occupied: (0.7f32 / 0.3).ln(),
            clamp: 3.5,
        }
    }
}

/// A counting mapper: every cell keeps how many beams reached it (its passes, the beams that
/// ended in it included) and how many ended in it (its hits), and reads occupied when more
/// than `occupied_above` of its passes were hits, free otherwise, and unknown until more than
/// `min_passes` beams reached it. The published map holds no probabilities, only occupied,
/// free and unknown.
///
/// This is how GMapping (`occ_thresh`, [`Self::gmapping`]) and Karto, the mapper of ROS 2's
/// slam_toolbox (`occupancy_threshold` and `min_pass_through`, [`Self::slam_toolbox`]), build
/// the maps they publish. Nothing is clamped. Under range noise a cell of a wall's band is hit
/// by about one beam in `2 b r` and passed by those that read beyond it, so the cells that
/// stay occupied are the band's last few: about 3 under GMapping's quarter, which sit behind
/// the wall's face as [`InverseSensorModel::default`]'s do, and about 9 under Karto's tenth,
/// a band over the face (docs/EVALUATION.md, "The maps of GMapping and slam_toolbox").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HitRatioModel {
    /// Hits per pass above which a cell is occupied, in `(0, 1)`.
    pub occupied_above: f32,
    /// Passes a cell needs beyond this count to be known.
    pub min_passes: u32,
}

impl HitRatioModel {
    /// GMapping's defaults (`slam_gmapping`'s `occ_thresh` 0.25): occupied when more than a
    /// quarter of the beams that reached a cell ended in it, known once one beam reached it.
    pub fn gmapping() -> Self {
        Self {
            occupied_above: 0.25,
            min_passes: 0,
        }
    }

    /// Karto's defaults in slam_toolbox (`occupancy_threshold` 0.1, `min_pass_through` 2):
    /// occupied when more than a tenth of the beams that reached a cell ended in it, known
    /// once three beams reached it.
    pub fn slam_toolbox() -> Self {
        Self {
            occupied_above: 0.1,
            min_passes: 2,
        }
    }
}

/// How a robot folds its beams into its map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MapperModel {
    /// Log-odds per cell, clamped, published as a probability (mapsim's default, hector,
    /// OctoMap).
    LogOdds(InverseSensorModel),
    /// Hit and pass counts per cell, published as occupied, free or unknown (GMapping, Karto).
    HitRatio(HitRatioModel),
}

impl Default for MapperModel {
    fn default() -> Self {
        Self::LogOdds(InverseSensorModel::default())
    }
}

impl From<InverseSensorModel> for MapperModel {
    fn from(m: InverseSensorModel) -> Self {
        Self::LogOdds(m)
    }
}

impl From<HitRatioModel> for MapperModel {
    fn from(m: HitRatioModel) -> Self {
        Self::HitRatio(m)
    }
}

impl Default for CaseConfig {
    fn default() -> Self {
        Self {
            world: WorldConfig::default(),
            robots: vec![RobotConfig::default(), RobotConfig::default()],
            overlap: 0.5,
            overlap_tolerance: 0.1,
            max_rotation: PI,
            margin: 5,
            extra_margin: 20,
            pose_step: 2.0,
            clearance: 3.0,
            waypoint_spacing: None,
            mapper: MapperModel::default(),
        }
    }
}

impl CaseConfig {
    /// The paper's setting: a 150 x 150 disaster area explored by 2 robots with 16-beam
    /// infrared rings (range 30 cells), range noise bounds 10 % and 15 %, overlap 0.5.
    pub fn paper() -> Self {
        Self {
            world: WorldConfig {
                width: 150,
                height: 150,
                ..WorldConfig::default()
            },
            robots: vec![RobotConfig::infrared(0.10), RobotConfig::infrared(0.15)],
            margin: 4,
            extra_margin: 10,
            ..Self::default()
        }
    }

    /// A floor plan (`WorldKind::Grid`: its occupied and unknown cells are obstacles) explored
    /// by one default lidar robot per entry of `noise_bounds`, with that range noise bound.
    pub fn floor(plan: OccupancyGrid, noise_bounds: &[f64]) -> Self {
        Self {
            world: WorldConfig {
                kind: WorldKind::Grid(plan),
                width: 0,
                height: 0,
                ..WorldConfig::default()
            },
            robots: noise_bounds
                .iter()
                .map(|&noise_bound| RobotConfig {
                    noise_bound,
                    ..RobotConfig::default()
                })
                .collect(),
            ..Self::default()
        }
    }

    /// A structured indoor floor of `size x size` cells with two lidar robots.
    pub fn indoor(size: usize) -> Self {
        Self {
            world: WorldConfig {
                kind: WorldKind::Indoor,
                width: size,
                height: size,
                ..WorldConfig::default()
            },
            ..Self::default()
        }
    }

    /// Check every field; generation calls this first.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::Config(m));
        if !(2..=32).contains(&self.robots.len()) {
            return bad(format!("{} robots (need 2..=32)", self.robots.len()));
        }
        for (i, r) in self.robots.iter().enumerate() {
            if !(1..=100_000).contains(&r.beams) {
                return bad(format!("robot {i}: {} beams (need 1..=100000)", r.beams));
            }
            if !(r.max_range.is_finite() && r.max_range >= 2.0) {
                return bad(format!("robot {i}: max_range {} (need >= 2)", r.max_range));
            }
            if !(0.0..0.9).contains(&r.noise_bound) {
                return bad(format!(
                    "robot {i}: noise_bound {} (need 0..0.9)",
                    r.noise_bound
                ));
            }
            if !(0.0..1.0).contains(&r.dropout) {
                return bad(format!("robot {i}: dropout {} (need 0..1)", r.dropout));
            }
            if let Some(j) = r.failed_beams.iter().find(|&&j| j >= r.beams) {
                return bad(format!("robot {i}: failed beam {j} >= {} beams", r.beams));
            }
            if (0..r.beams).all(|j| r.failed_beams.contains(&j)) {
                return bad(format!("robot {i}: every beam failed"));
            }
        }
        if !(0.0..=1.0).contains(&self.overlap) {
            return bad(format!("overlap {} (need 0..=1)", self.overlap));
        }
        if self.overlap_tolerance.is_nan() || self.overlap_tolerance < 0.0 {
            return bad(format!("overlap_tolerance {}", self.overlap_tolerance));
        }
        if !(self.max_rotation.is_finite() && self.max_rotation >= 0.0) {
            return bad(format!("max_rotation {}", self.max_rotation));
        }
        if !(self.pose_step.is_finite() && self.pose_step >= 0.25) {
            return bad(format!("pose_step {} (need >= 0.25)", self.pose_step));
        }
        if !(self.clearance.is_finite() && (0.5..=200.0).contains(&self.clearance)) {
            return bad(format!("clearance {} (need 0.5..=200)", self.clearance));
        }
        if let Some(s) = self.waypoint_spacing
            && !(s.is_finite() && s >= 2.0)
        {
            return bad(format!("waypoint_spacing {s} (need >= 2)"));
        }
        match &self.mapper {
            MapperModel::LogOdds(m) => {
                let valid = m.free.is_finite()
                    && m.free < 0.0
                    && m.occupied.is_finite()
                    && m.occupied > 0.0
                    && m.clamp.is_finite()
                    && m.clamp > 0.0;
                if !valid {
                    return bad(format!(
                        "inverse_model free {} occupied {} clamp {} (need free < 0 < occupied, clamp > 0)",
                        m.free, m.occupied, m.clamp
                    ));
                }
            }
            MapperModel::HitRatio(m) => {
                if !(m.occupied_above > 0.0 && m.occupied_above < 1.0) {
                    return bad(format!(
                        "hit ratio model occupied_above {} (need 0 < occupied_above < 1)",
                        m.occupied_above
                    ));
                }
            }
        }
        Ok(())
    }
}

/// One robot's result.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotMap {
    /// The partial map in the robot's own frame (origin at zero, the world's resolution).
    pub map: OccupancyGrid,
    /// Maps a pixel of [`Self::map`] to a pixel of the world raster.
    pub map_to_world: Rigid2,
    /// The robot's poses in world pixels, in driving order.
    pub path: Vec<DVec2>,
}

impl RobotMap {
    /// The path in the robot's map pixels.
    pub fn path_in_map(&self) -> Vec<DVec2> {
        let inv = self.map_to_world.inverse();
        self.path.iter().map(|&p| inv.apply(p)).collect()
    }
}

/// A generated case: the world, each robot's map with its pose, and the overlaps.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// The seed it was generated from.
    pub seed: u64,
    /// The configuration it was generated from.
    pub config: CaseConfig,
    /// The world (obstacle raster).
    pub world: World,
    /// One map per robot, in the order of `config.robots`.
    pub robots: Vec<RobotMap>,
    /// Achieved overlap: the mean over consecutive robots `(i, i + 1)` of
    /// `|E_i & E_j| / min(|E_i|, |E_j|)`, `E` being the world cells a map knows.
    pub achieved_overlap: f64,
    /// The pairwise overlap matrix (diagonal 1).
    pub overlaps: Vec<Vec<f64>>,
}

impl Case {
    /// The transform mapping a pixel of map `j` onto the same place in map `i`.
    ///
    /// Panics if `i` or `j` is not a robot index, like slice indexing.
    pub fn truth(&self, i: usize, j: usize) -> Rigid2 {
        self.robots[i]
            .map_to_world
            .inverse()
            .compose(&self.robots[j].map_to_world)
    }

    /// Number of world cells known in map `i`.
    pub fn explored_cells(&self, i: usize) -> usize {
        explored_masks(&self.world, &self.robots)
            .iter()
            .filter(|&&m| m & (1 << i) != 0)
            .count()
    }
}

/// Per world cell, a bitmask of the robots whose map knows it.
fn explored_masks(world: &World, robots: &[RobotMap]) -> Vec<u32> {
    let w = world.width();
    let mut masks = vec![0u32; w * world.height()];
    masks.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (i, r) in robots.iter().enumerate() {
            let inv = r.map_to_world.inverse();
            for (x, m) in row.iter_mut().enumerate() {
                let p = inv.apply(DVec2::new(x as f64, y as f64)).round();
                if p.x >= 0.0
                    && p.y >= 0.0
                    && r.map
                        .get(p.x as usize, p.y as usize)
                        .is_some_and(|c| c != UNKNOWN)
                {
                    *m |= 1 << i;
                }
            }
        }
    });
    masks
}

/// RNG streams, so that changing one stage's consumption never shifts another's numbers.
const STREAM_WORLD: u64 = 1;
const STREAM_TOUR: u64 = 2;
const STREAM_ROBOT: u64 = 100;

fn rng(seed: u64, stream: u64) -> ChaCha8Rng {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    r.set_stream(stream);
    r
}

/// Generate a case: world, tour, overlap-controlled robot segments, maps with truth.
pub fn generate_case(config: &CaseConfig, seed: u64) -> Result<Case> {
    config.validate()?;
    let world = World::generate(&config.world, &mut rng(seed, STREAM_WORLD))?;
    let n = config.robots.len();
    let min_range = config
        .robots
        .iter()
        .map(|r| r.max_range)
        .fold(f64::INFINITY, f64::min);
    let spacing = config.waypoint_spacing.unwrap_or(0.8 * min_range);
    let tour = planner::tour(
        &world,
        config.clearance,
        spacing,
        config.pose_step,
        &mut rng(seed, STREAM_TOUR),
    )?;
    let len = tour.len();
    if len < 4 * n {
        return Err(Error::NoFreeSpace);
    }

    // Overlap control on noise-free footprints.
    let seg_len = (len / n) as i64;
    let (lo, hi) = if n == 2 {
        (-(seg_len * 6 / 10), len as i64)
    } else {
        (-(seg_len * 3 / 10), len as i64)
    };
    let raster = overlap::CoarseRaster::new(&world);
    // Robots with the same sensor over the same window share one footprint computation (a
    // reversed robot too when its beams are symmetric under a half turn).
    let mut computed: Vec<(Key, overlap::Footprints)> = Vec::new();
    type Key = (std::ops::Range<usize>, RobotConfig, bool);
    let keys: Vec<Key> = config
        .robots
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let window = overlap::segment(i, n, len, hi);
            let reversed = i % 2 == 1 && !overlap::flip_invariant(r);
            let mut sensor = r.clone();
            // Noise and dropout do not change the noise-free footprint.
            sensor.noise_bound = 0.0;
            sensor.dropout = 0.0;
            (window, sensor, reversed)
        })
        .collect();
    for key in &keys {
        if computed.iter().all(|(k, _)| k != key) {
            let (window, sensor, reversed) = key;
            let stride = overlap::footprint_stride(sensor, config.pose_step);
            let fp = overlap::footprints(
                &world,
                &tour,
                window.clone(),
                sensor,
                *reversed,
                raster,
                stride,
            );
            computed.push((key.clone(), fp));
        }
    }
    let fps: Vec<&overlap::Footprints> = keys
        .iter()
        .map(|key| {
            &computed
                .iter()
                .find(|(k, _)| k == key)
                .expect("computed above")
                .1
        })
        .collect();
    let mut masks = Vec::new();
    let mut eval = |d: i64| overlap::reference_overlap(&fps, len, d, &mut masks, raster);
    let safety = (0.25 * min_range / config.pose_step).ceil() as i64;
    let delta = overlap::choose_delta(&mut eval, config.overlap, lo, hi, safety);

    // Robots are independent (each draws from its own random stream), so they are simulated
    // side by side; mapping one robot's rays is sequential (clamped log-odds depend on order).
    let robots = config
        .robots
        .par_iter()
        .enumerate()
        .map(|(i, rc)| {
            let mut poses: Vec<_> = tour[overlap::segment(i, n, len, delta)].to_vec();
            if i % 2 == 1 {
                // Odd robots drive the tour backwards, so neighbours start far apart.
                poses.reverse();
                for p in &mut poses {
                    p.heading += PI;
                }
            }
            let mut r = rng(seed, STREAM_ROBOT + i as u64);
            let rays = sensor::measure(&world, &poses, rc, &mut r);
            let (map, map_to_world) =
                sensor::build_map(&rays, &poses, config, world.resolution(), &mut r)?;
            Ok(RobotMap {
                map,
                map_to_world,
                path: poses.iter().map(|p| p.pos).collect(),
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let overlaps = overlap::overlap_matrix(&explored_masks(&world, &robots), n);
    let achieved = overlap::mean_consecutive(&overlaps);
    if (achieved - config.overlap).abs() > config.overlap_tolerance {
        return Err(Error::OverlapMissed {
            requested: config.overlap,
            achieved,
            tolerance: config.overlap_tolerance,
        });
    }
    Ok(Case {
        seed,
        config: config.clone(),
        world,
        robots,
        achieved_overlap: achieved,
        overlaps,
    })
}
