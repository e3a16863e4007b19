//! Registration of one pair: correspondences → RANSAC hypotheses → refinement → verification.

use std::time::Instant;

use rayon::prelude::*;

use blob_features::{BlobConfig, BlobCorrespondences, Blobs};
use grid_core::{
    CellState, Correspondence, CorrespondenceSource, DVec2, EvidenceKind, OccupancyGrid, Rigid2,
};
use ransac_rigid::{RansacConfig, estimate_rigid};
use sift_desc::{SiftConfig, SiftCorrespondences};

use crate::Error;
use crate::ascent::{AscentConfig, ascend, frontier_ratio, lone_wall_share, wall_thickness};
use crate::global::{
    GlobalConfig, SweepConfig, global_hypotheses, manhattan_direction, spectrum_rotation_near,
    sweep_placements, twins,
};
use crate::refine::{RefineConfig, refine_with_bias};
use crate::search::{SearchConfig, local_search};
use crate::verify::{
    PreparedMap, StandOut, Verification, VerifyConfig, agreeing_lever, agreeing_wall_spread_px,
    strided, verify, verify_with_offsets, wall_residual_px,
};

/// Everything that tunes [`register_with`], with documented defaults.
#[derive(Debug, Clone)]
pub struct PairConfig {
    /// RANSAC settings (seed included: the result is deterministic for a seed).
    pub ransac: RansacConfig,
    /// Correlative local search around each hypothesis before ICP; `None` disables it.
    /// Default: on, [`SearchConfig::default`] (+-8 px, translation only).
    pub search: Option<SearchConfig>,
    /// A second correlative search, over rotation as well, for the placements of the
    /// whole-map searches (global search, sweep, symmetry probes): they come from a coarse
    /// grid of angles, and ICP alone does not turn a placement a degree or two off back onto
    /// the maps' walls. The pose it leads to is refined and kept when it scores better than
    /// the other two. `None` disables it. Default: +-2 degrees, otherwise
    /// [`SearchConfig::default`]. On `cargo xtask eval --suites overlap,zero,paper,real,noise
    /// --cases 20 --seed 7` disaster 0.3 rose from 40 to 55 % and intel_lab from 65 to 70 %,
    /// wpi_ilab fell from 15 to 10 %, no other row's success changed and every zero-overlap
    /// pair was declined; +-1 degree gave 50 % at disaster 0.3 and lost a paper pair, +-3
    /// degrees 55 % with aws_small_house 5 -> 0 %. Its cost: that eval's mean time per case
    /// rose from 1346 to 1893 ms (the sweep stage 903 -> 1226 ms); feature-based hypotheses
    /// (those of the 2048 x 2048 bench pair) do not take it.
    pub turn_search: Option<SearchConfig>,
    /// ICP refinement of each feature-based candidate.
    pub refine: RefineConfig,
    /// Verification thresholds that decide acceptance.
    pub verify: VerifyConfig,
    /// Global search (Hough-spectrum angles, FFT-correlation translations) tried when no
    /// feature-based candidate passes verification; `None` disables it. Default: off. The
    /// rotation sweep, which runs whenever the global search would, proposes what it does at
    /// every angle; over the eval sets of `docs/EVALUATION.md` ("The global search dropped",
    /// 2026-12-04: 640 overlapping pairs, 281 zero-overlap pairs) the pipeline without it
    /// registered 1 pair fewer (417 against 418, answers moving across the 3 px line both
    /// ways), accepted 3 fewer wrong answers (2 overlapping pairs 3-10 px off, 1 zero-overlap
    /// pair), and took 17-32 % less time per case. `Some(GlobalConfig::default())` turns it
    /// on.
    pub global: Option<GlobalConfig>,
    /// Rotation sweep, tried unless a feature-based candidate passed verification with a good
    /// fit (see [`SweepConfig::confident_wall_lift`]); `None` disables it. Default: on,
    /// [`SweepConfig::default`].
    pub sweep: Option<SweepConfig>,
    /// Refinement of the whole-map searches' placements (the sweep, the symmetry probes, and
    /// the global search when it is on): a wider first gate, since they come from a coarse
    /// grid. Default: gate 12 px shrinking to 2 px, at most 24 px of movement.
    pub global_refine: RefineConfig,
    /// Symmetry probes of the best accepted candidate: at its angle, and its angle turned by a
    /// quarter, a half and three quarters of a turn, the best translations are found by
    /// correlation ([`crate::global::twins`], with the `global` settings or their
    /// defaults), and each twin is refined and verified like a sweep placement. A
    /// row of alike rooms, or a room or rubble field that looks the same turned, fits a twin
    /// about as well, and a twin that fits about as well as the best makes the pair ambiguous
    /// (the rule of [`VerifyConfig::max_ambiguity`], including its contradiction gate): it is
    /// declined instead of answered by a coin toss. The probes are skipped when the best is
    /// a feature-based candidate with a very good fit (`symmetry_confident_wall_lift`):
    /// keypoints that agree do not repeat with the walls. Default on.
    pub symmetry_probes: bool,
    /// The symmetry probes are skipped when the best candidate is a RANSAC answer with at
    /// least this wall lift. Default 0.9, above the sweep's bar
    /// ([`SweepConfig::confident_wall_lift`], 0.8): a rotated copy of a small map, whose
    /// RANSAC answer refined to 3.5 degrees off at wall lift 0.85, was found by the probe at
    /// its angle (lift 1.0). On `cargo xtask eval --suites overlap,zero,paper,real,noise
    /// --seed 7` the probes then run on more pairs, and no row's success changed (0.7
    /// overlap and paper medians moved by 0.02 and 0.06 px) at up to 0.2 s more per pair;
    /// the sweep at 0.9 instead cost 0.35-0.65 s more.
    pub symmetry_confident_wall_lift: f64,
    /// Score each candidate with the range-bias offsets its refinement fitted applied to the
    /// walls (see [`crate::verify::verify_with_offsets`]).
    pub offsets_in_verification: bool,
    /// A last refinement of the best candidate when its walls agree almost everywhere;
    /// `None` disables it. Default: on, [`PolishConfig::default`].
    pub polish: Option<PolishConfig>,
    /// The best candidate's angle taken from the Hough spectra of both maps' walls, then its
    /// translation refined at that angle, unless the polish applies; `None` disables it.
    /// Default: on, [`SpectrumRotation::default`].
    pub spectrum_rotation: Option<SpectrumRotation>,
    /// The best candidate's angle taken from both maps' dominant wall directions when its
    /// agreeing walls spread far, then its translation refined at that angle, unless the
    /// polish applies; `None` disables it. Default: on, [`ManhattanRotation::default`].
    pub manhattan_rotation: Option<ManhattanRotation>,
    /// Each map is registered on its own frame: the bounding box of its known cells grown by
    /// this many cells of unknown on every side, cut out of the map or padded with unknown
    /// where the map is smaller ([`framed`]). The answer is then the same whatever unknown
    /// border the maps came with (a map_server map padded to 4000 x 4000, the same map
    /// cropped tight), and the transform, candidates and matches are given in the maps' own
    /// pixels. `None` registers the maps as given. Default `Some(64)`: the scale space's crop
    /// margin (`scale_space::ScaleSpaceConfig::crop_margin`), so the intensity image is the
    /// same as for a map with that much unknown border or more.
    pub frame_margin: Option<usize>,
    /// Refine a whole-map placement (global search, sweep, symmetry probes) from where it was
    /// proposed as well, not only from where its local search and its turn search moved it.
    /// Default false: on `cargo xtask eval --suites overlap,zero,paper,real,noise --cases 20
    /// --seed 7` (at 9c1cf25, before the frames) every row registered the same pairs without
    /// it (three answers moved by 0.3-0.5 px, each nearer the truth), and it is a third of
    /// those placements' refinements: the bench's partial pair took 1.5-1.7 s instead of
    /// 1.9-2.3 s on one thread (scratch timing, three runs each).
    pub refine_placements_as_proposed: bool,
    /// Of the placements one whole-map search proposes (global search, sweep, symmetry
    /// probes), at most this many are refined by ICP: those whose best start (the poses the
    /// local and turn searches lead to) the maps agree with most, by the verification's
    /// score. The others are kept as candidates at that start, scored there
    /// ([`Candidate::refined`] false), and one is refined only if it comes to rank first or
    /// to stand out, so the answer is always refined. `None` refines every placement.
    /// Default `Some(8)`: the 2048 x 2048 bench's hard pair, whose searches propose about
    /// 50 placements, registers in 0.50-0.51 s instead of 0.63 s with every placement
    /// refined (`cargo bench -p mapmerge --bench register`, ICP's stopping rule in both),
    /// and on the 30 % overlap rows and real floors of `cargo xtask eval` (seeds 7-9, both
    /// mappers; 640 pairs) two pairs changed, both for the better (docs/EVALUATION.md, "ICP
    /// that stops once converged").
    pub refined_placements: Option<usize>,
    /// A last climb of the accepted answer's verification score ([`crate::ascent`]) when both
    /// maps' walls are thick enough ([`AscentConfig::min_wall_thickness`]) or both maps come
    /// from a short-range sensor ([`AscentConfig::short_range`]), kept when it
    /// scores higher and still passes; not for an answer polished
    /// ([`PolishConfig::min_wall_lift`]) or one that stood out. `None` disables it. Default:
    /// on, [`AscentConfig::default`]. On the 30 % overlap rows of `cargo xtask eval` mapped
    /// with hector's model (`--mapper hector`) it registered 110 of the 120 pairs of seeds
    /// 7-9 (105 without it, `--no-ascent`; 3 instead of 8 answers accepted off the truth) and
    /// 110 of seeds 10-12 (99; 5 instead of 16), and on the real floors (hector, seeds 8-9) 129
    /// of 160 (127); the default mapper's maps are not climbed (docs/EVALUATION.md, "The score
    /// ascent").
    pub ascent: Option<AscentConfig>,
    /// The accepted answer turned about its overlap by small angles each way, each turn's
    /// translation refined at that angle ([`TurnScan`]), the best-scoring turn kept when it
    /// scores higher and still passes; not for an answer polished, one that stood out or one
    /// that took the Manhattan angle. `None` disables it. Default: on,
    /// [`TurnScan::default`]. On the real floors at 30 % overlap (`cargo xtask eval --suites
    /// floors`, seeds 7-9) it registered 199 instead of 182 of 300 pairs (intel_lab 56
    /// instead of 48 of 60, uos_avz 58 instead of 52); the regression batch (`cargo xtask
    /// regress`) kept every other outcome (docs/EVALUATION.md, "Real floors at 30 % overlap").
    pub turn_scan: Option<TurnScan>,
}

/// The angle of an accepted answer from the Hough spectra of all the walls of both maps
/// ([`crate::global::spectrum_rotation_near`]), its translation then refined by ICP at that
/// angle (with the range-bias offsets), kept if it still passes verification. It runs only on
/// answers whose walls agree no better than noisy walls do
/// ([`SpectrumRotation::min_wall_residual_px`]) and whose agreeing walls span a short lever
/// ([`SpectrumRotation::max_lever_px`]).
///
/// On a small overlap the walls ICP pairs span a short lever, and a noisy range sensor's
/// walls are pushed by amounts that differ from wall to wall: the fitted angle is then off by
/// up to 2 degrees, which on B's far cells is several pixels. The spectrum uses every wall of
/// both maps, shared or not, so on maps whose walls run in a few common directions (buildings,
/// a walled arena) its angle does not depend on the overlap. On `cargo xtask eval --suites
/// overlap,zero,paper,real,noise --cases 20 --seed 7` disaster 0.3 rose from 25 to 35 %
/// (median rotation error 0.43 -> 0.27 degrees) and indoor 0.3's median displacement fell from
/// 2.21 to 1.51 px at the same 90 %; no other row's success changed, and every zero-overlap
/// pair was still declined. At 70 % overlap, where ICP's angle is already good, medians grew
/// by a few tenths of a pixel (indoor 0.41 -> 0.58 px).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpectrumRotation {
    /// Bins of the spectra over `[0, pi)`. Default 720 (a quarter degree; the peak is
    /// interpolated within a bin).
    pub bins: usize,
    /// Wall cells per map (evenly strided). Default 6000.
    pub max_points: usize,
    /// Only a spectrum peak this close to the answer's angle (degrees, modulo a half turn) is
    /// taken. Default 2.
    pub max_delta_deg: f64,
    /// The spectrum angle is taken only when the answer's walls lie on average at least this
    /// far (pixels) from the other map's, over those within 3 px of one
    /// ([`crate::verify::wall_residual_px`]). Walls that agree more closely pin the angle
    /// better than the spectra do: the spectra take every wall of both maps, and two maps that
    /// hold different parts of a building have different spectra, whose correlation peak can
    /// lie a few tenths of a degree off. Default 0.3: the answers of 94 simulated pairs
    /// exported by `cargo xtask eval` (noisy walls) lie at 0.33-1.4 px, and two crops of a
    /// fixture floor (walls marked in full or in part) at 0.005-0.24 px, where the spectrum
    /// angle moved answers within 0.3 px of the truth up to 5.7 px off (docs/EVALUATION.md,
    /// "Crisp walls and the spectrum angle").
    pub min_wall_residual_px: f64,
    /// The spectrum angle is taken only when the walls that agree under the answer (B's wall
    /// cells within 3 px of A's) spread less than this far about their centre (radius of
    /// gyration, pixels; [`crate::verify::agreeing_wall_spread_px`]). ICP's angle rests on
    /// that lever and grows more precise with it, while the spectra's does not: two partial
    /// maps of a building hold different parts of it, whose walls tilt the spectra's
    /// correlation peak. Default 140: at the answers of the simulated 30 % overlap pairs
    /// (400 x 400 worlds) the agreeing walls spread 55-126 px, at the intel_lab pairs, where
    /// the spectrum angle moved answers 0.4-3.4 px off to 1.8-5.1 px, 141-169 px (scratch
    /// traces). On `cargo xtask eval --suites real --cases 20 --seed 7` (either mapper) it
    /// registered 4 and 7 more of the 80 pairs, and the 30 % rows of seeds 7-9 kept their
    /// successes within one (docs/EVALUATION.md, "Crisp walls and the spectrum angle").
    pub max_lever_px: f64,
}

impl Default for SpectrumRotation {
    fn default() -> Self {
        Self {
            bins: 720,
            max_points: 6000,
            max_delta_deg: 2.0,
            min_wall_residual_px: 0.3,
            max_lever_px: 140.0,
        }
    }
}

/// The best candidate's angle taken from both maps' dominant wall directions, modulo a quarter
/// turn ([`crate::global::manhattan_direction`]), then its translation refined at that angle:
/// for answers whose agreeing walls spread far (where [`SpectrumRotation`] leaves ICP's angle
/// alone) on floors built at right angles.
///
/// On a large map a small overlap pins the angle poorly even with a long lever: the walls of
/// simulated lidar maps with range noise come out tilted as a whole, each map its own way
/// (each map's dominant direction lies up to half a degree off the floor's), and the pose ICP
/// and the verification score prefer lies a few tenths of a degree off; on B's far cells that
/// is several pixels. Every straight wall of a map, in the overlap or not, tells its dominant
/// direction, and the difference of the two maps' directions is the rotation modulo a quarter
/// turn; it is taken only near the answer's own angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ManhattanRotation {
    /// Wall cells per map (evenly strided). Default 20000: with 6000 the `large` suite's
    /// seeds 7 and 8 registered 13 and 15 of 20 pairs instead of 15 and 16.
    pub max_points: usize,
    /// Only a direction difference this close to the answer's angle (degrees, modulo a
    /// quarter turn) is taken. Default 2: on `cargo xtask eval --suites large` (seeds 7 and
    /// 8, hector's mapper at 8) 49 of 60 pairs registered instead of 47 with 1, and the
    /// default mapper's 30 % rows and real floors (seeds 7-9), zero-overlap rows (1, 2, 3, 7)
    /// and overlap rows (7) changed no outcome.
    pub max_delta_deg: f64,
    /// Each map's [`crate::global::ManhattanDirection::contrast`] must reach this. Default 1.5.
    pub min_contrast: f64,
    /// Taken only when the walls that agree under the answer spread at least this far
    /// ([`crate::verify::agreeing_wall_spread_px`]); below it [`SpectrumRotation`] applies.
    /// Default 140.
    pub min_lever_px: f64,
    /// Taken only when B's known cells reach at least this many times that spread from the
    /// agreeing walls' centre ([`crate::verify::agreeing_lever`]): where the overlap takes
    /// up most of B, ICP's angle on the shared walls is as good as B's far cells need.
    /// Default 1.2: the answers the angle moved in the 50 % and 70 % rows of `cargo xtask eval
    /// --suites overlap --seed 7` lie at 0.93-1.10 (on the disaster world, whose walls have
    /// no dominant direction beyond the arena's border, it turned four of them 0.34-0.70
    /// degrees off, though none past 3 px), the intel_lab pairs of `--suites real --seed 7` at
    /// 1.18-1.96 and the warehouse pairs at 1.3-2.8.
    pub min_reach_ratio: f64,
    /// Taken only when the answer's walls lie on average at least this far from the other
    /// map's ([`crate::verify::wall_residual_px`]): crisp walls pin the angle better.
    /// Default 0.3, as [`SpectrumRotation::min_wall_residual_px`].
    pub min_wall_residual_px: f64,
    /// Taken only when it lowers the answer's wall lift by at most this. Default 0.1. The
    /// angle is taken though the score prefers the answer's (a tilt of a few tenths of a
    /// degree, above), and on the nav2 warehouse (`cargo xtask eval --suites large`, seeds 7
    /// and 8) the answers it brought within 3 px lost up to 0.077 of lift by it. Where it
    /// cost 0.13-0.17, the maps' dominant directions missed the overlap's by more than a
    /// tilt: on the uos_avz floor at 30 % overlap (`--suites floors`) it turned two answers
    /// within 0.7 px to 0.8 degrees and 3.3-3.4 px off (held-out seed 23), and elsewhere
    /// (large 8000015, floors 8004001) it brought no answer within 3 px. Over `cargo xtask
    /// regress` no outcome changed (those two answers moved 0.1 and 0.4 px nearer the truth);
    /// uos_avz at seed 23 registered 19 instead of 17 of 20 (docs/EVALUATION.md, "A held-out
    /// seed, clean maps' misfits turned, and the Manhattan angle that costs the fit").
    pub max_lift_drop: f64,
}

impl Default for ManhattanRotation {
    fn default() -> Self {
        Self {
            max_points: 20000,
            max_delta_deg: 2.0,
            min_contrast: 1.5,
            min_lever_px: 140.0,
            min_reach_ratio: 1.2,
            min_wall_residual_px: 0.3,
            max_lift_drop: 0.1,
        }
    }
}

/// A scan of the answer's angle: B turned about the centre of its walls on A's known cells
/// (so the shared walls stay in place) by every multiple of `step_deg` up to `max_deg` each
/// way, each turn's translation and range-bias offsets refined by ICP with the angle held,
/// and verified (`at_angle`); the best-scoring turn that passes replaces the answer if it
/// scores higher.
///
/// The local and turn searches turn B about the centre of all its walls, which on a small
/// overlap of a large map lies far from the shared walls: their finer levels try turns of
/// 0.5-0.125 degrees with translations of 1-0.25 px, and about a pivot 200 px away a turn of
/// a quarter degree moves the shared walls by 0.9 px, more than those steps take back. On the
/// real floors at 30 % overlap (`cargo xtask eval --suites floors`, seeds 7 and 8, before
/// the scan) the 18 answers of intel_lab and uos_avz 3-8 px off were turned 0.5-1.7 degrees
/// from the truth, and in 14 of them the truth, refined, had the higher wall lift: the search
/// missed it, the objective did not.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TurnScan {
    /// Largest turn tried each way, in degrees. Default 1.
    pub max_deg: f64,
    /// Step between the turns tried, in degrees. Default 0.25.
    pub step_deg: f64,
    /// Scanned only when the centre of B's walls on A's known cells lies at least this far
    /// (pixels) from the centre of all B's walls, the searches' pivot. Default 170. Scanned
    /// on every answer, the default mapper's 30 % rows at seed 7 registered 28 instead of 36
    /// of 40 pairs: on thin walls pushed by range noise the score prefers a pose a fraction
    /// of a degree off (docs/EVALUATION.md, "Answers that push the maps apart"), and where the
    /// searches turn B about a near pivot they already reach the truth's basin. Every pair
    /// that went from more than 3 px to within 3 px there and on the floors had its shared
    /// walls 185-667 px from that pivot at the truth, every one that went the other way
    /// 119-156 px (scratch measurement at the truth, seed 7).
    pub min_lever_px: f64,
    /// Scanned only when neither map's share of lone wall cells
    /// ([`crate::ascent::lone_wall_share`]) exceeds the other's by more than this factor (a
    /// map without lone wall cells is alike only to another without). Default 2.2. Walls of
    /// sensors with different noise are pushed by different amounts, and on curved walls
    /// that bends the best-scoring angle: on the real suite's uos_cic
    /// row (10 % and 20 % noise, a curved hall) the scan without this gate registered 18
    /// instead of 25 of the 40 pairs of seeds 8 and 9. The ratio is 2.31-5.21 on those
    /// robots' maps (intel_lab and uos_cic, seed 8) and 1.01-2.00 on the floors' robots with
    /// equal noise (scratch measurement).
    pub max_speckle_ratio: f64,
    /// Scanned whatever the lever and the speckle ratio when the answer would be declined by
    /// the bars for maps whose walls are clean ([`crate::verify::CleanWalls`],
    /// [`crate::verify::CleanFit`]): such maps fit cleanly at the right pose, so an answer
    /// that misfits them may be the right placement turned a little. The best turn is then
    /// polished by ICP ([`PolishConfig`]; the score counts whole cells, and turns a quarter
    /// degree apart can trade places by a cell's worth) and replaces the answer only if it
    /// clears those bars and scores higher. Default true. Found on a held-out seed: case
    /// 23031017 of `cargo xtask eval --suites overlap,zero,paper,real,noise,floors,floorzero,
    /// crops --seed 23`, the aws_small_house floor cut in two, answered 1.1 degrees and 3.6 px
    /// off at wall lift 0.84 (the truth fits at 0.95), and declined for walls in free space;
    /// rescued, 0.21 px off. Over `cargo xtask regress` (every set) one case changed, crops
    /// 7001004, declined -> 0.08 px; `--suites crops` at seeds 8-12 (1,000 pairs) no case
    /// changed, and no pair that shares nothing was accepted (docs/EVALUATION.md, "A held-out
    /// seed, clean maps' misfits turned, and the Manhattan angle that costs the fit").
    pub rescue_misfits: bool,
    /// Not scanned when the answer took its angle from the maps' dominant wall directions
    /// ([`ManhattanRotation`]): that angle comes from every straight wall of both maps, the
    /// scan's from the score of the shared ones. Default true. Scanned after it too
    /// (`cargo xtask eval --turn-scan-after-manhattan`), the nav2 warehouse at 30 % overlap
    /// (`--suites large`) registered 13 instead of 16 of 20 pairs at seeds 7 and 8 and 14
    /// instead of 17 with hector's mapper at 8; keeping it, 16, 16 and 17.
    pub keep_manhattan_angle: bool,
}

impl Default for TurnScan {
    fn default() -> Self {
        Self {
            max_deg: 1.0,
            step_deg: 0.25,
            min_lever_px: 170.0,
            max_speckle_ratio: 2.2,
            rescue_misfits: true,
            keep_manhattan_angle: true,
        }
    }
}

impl TurnScan {
    /// The turns tried, in radians, nearest first, each way in turn (never 0).
    pub fn turns(&self) -> Vec<f64> {
        if !(self.step_deg > 0.0 && self.max_deg >= self.step_deg) {
            return Vec::new();
        }
        let n = (self.max_deg / self.step_deg + 1e-9).floor() as usize;
        (1..=n)
            .flat_map(|k| {
                let d = (k as f64 * self.step_deg).to_radians();
                [d, -d]
            })
            .collect()
    }
}

/// The rotation of B onto A nearest to `theta` that the maps' dominant wall directions give
/// (see [`ManhattanRotation`]), if it lies within `config.max_delta_deg` of it and both maps
/// have a clear dominant direction.
fn manhattan_rotation_near(
    a: &PreparedMap,
    b: &PreparedMap,
    theta: f64,
    config: &ManhattanRotation,
) -> Option<f64> {
    let (da, db) = rayon::join(
        || manhattan_direction(&strided(&a.wall_samples, config.max_points)),
        || manhattan_direction(&strided(&b.wall_samples, config.max_points)),
    );
    let (da, db) = (da?, db?);
    if da.contrast.min(db.contrast) < config.min_contrast {
        return None;
    }
    let quarter = std::f64::consts::FRAC_PI_2;
    let d = (da.angle - db.angle - theta).rem_euclid(quarter);
    let d = if d > quarter / 2.0 { d - quarter } else { d };
    (d.abs() <= config.max_delta_deg.to_radians()).then_some(theta + d)
}

/// The centroid (in A's frame) of B's walls that `b_to_a` puts on known cells of A, and that
/// of all B's walls; `None` if none lands on A's known cells.
fn wall_centres(
    a: &PreparedMap,
    b: &PreparedMap,
    b_to_a: &Rigid2,
) -> Option<(grid_core::DVec2, grid_core::DVec2)> {
    let zero = grid_core::DVec2::ZERO;
    let (mut shared, mut n, mut all) = (zero, 0usize, zero);
    for q in b.wall_samples.iter().map(|p| b_to_a.apply(*p)) {
        all += q;
        if crate::verify::cell_of(a.grid, q)
            .is_some_and(|(x, y)| a.grid.state(x, y) != grid_core::CellState::Unknown)
        {
            shared += q;
            n += 1;
        }
    }
    (n > 0).then(|| (shared / n as f64, all / b.wall_samples.len() as f64))
}

/// `b_to_a` turned to angle `theta` about the centre of B's walls that it puts on known cells
/// of A (so that the shared part stays in place); `None` if none lands there.
fn turned_about_overlap(
    a: &PreparedMap,
    b: &PreparedMap,
    b_to_a: &Rigid2,
    theta: f64,
) -> Option<Rigid2> {
    let (shared, _) = wall_centres(a, b, b_to_a)?;
    Some(Rigid2::rotation_about(theta - b_to_a.theta, shared).compose(b_to_a))
}

/// `b_to_a` turned to angle `theta` about its walls on A's known cells
/// ([`turned_about_overlap`]), its translation and range-bias offsets then refined by ICP with
/// the angle held (`config.refine`), and verified with those offsets: the answer at an angle
/// taken from elsewhere (the spectra, the dominant wall directions). `None` if none of B's
/// walls lands on A's known cells.
fn at_angle(
    a: &PreparedMap,
    b: &PreparedMap,
    b_to_a: &Rigid2,
    theta: f64,
    config: &PairConfig,
) -> Option<(Rigid2, Verification)> {
    let start = turned_about_overlap(a, b, b_to_a, theta)?;
    let locked = RefineConfig {
        lock_rotation: true,
        ..config.refine
    };
    let (t, offsets) = refine_with_bias(a, b, &start, &locked);
    let v = verify_with_offsets(a, b, &t, offsets, &config.verify);
    Some((t, v))
}

/// The polish of a clean answer: when the best candidate's walls agree almost everywhere,
/// there is no smeared wall band for the refinement's narrow robust kernel to guard against,
/// and the kernel then only locks onto the cells that happen to coincide. On a rotated copy of a
/// small map, resampled cell by cell, the pixel-exact quarter turn is such a lock: copies
/// turned by 90.8 and 95.2 degrees came out 0.7-0.8 degrees off. A few more iterations with
/// a wider kernel and without range-bias offsets (walls that agree have none) average over
/// the resampling steps instead.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolishConfig {
    /// The best candidate is polished at or above this wall lift, and the polish is kept
    /// only if it stays there (and passes). Default 0.97: above every answer on the noisy
    /// suites of `cargo xtask eval --suites overlap,zero,paper,real,noise --seed 7` (at most
    /// 0.94, in the paper preset's row), where the narrow kernel is what keeps smeared walls
    /// from biasing the pose; the rotated copies of the property tests score 1.
    pub min_wall_lift: f64,
    /// The refinement. Default: gate 3 px shrinking to 2 px, Cauchy scale 2 px, no range
    /// bias, at most 10 iterations (the same outcome as 30 on the property seeds). With the
    /// scale at 2 px the property `random_rigid_copies_are_recovered` holds on seeds 1-20 at
    /// 100 cases each (`MAPMERGE_PROPTEST_SEED=S PROPTEST_CASES=100`); at 0.5 px seed 14
    /// failed (a copy turned 0.55 degrees from a quarter turn came out 0.52 degrees off), at
    /// 1 px too (0.53 degrees): the cells a step of the resampling moved by one pixel count
    /// for a fifth of the others at 0.5 px, for nearly as much at 2 px.
    pub refine: RefineConfig,
}

impl Default for PolishConfig {
    fn default() -> Self {
        Self {
            min_wall_lift: 0.97,
            refine: RefineConfig {
                initial_gate_px: 3.0,
                final_gate_px: 2.0,
                robust_scale_px: 2.0,
                range_bias: None,
                max_iterations: 10,
                ..RefineConfig::default()
            },
        }
    }
}

impl PairConfig {
    /// The frame `grid` is registered on under this configuration ([`framed`] with
    /// [`Self::frame_margin`]) and the position in `grid` of the frame's cell `(0, 0)`; `None`
    /// when frames are off and the maps are registered as given.
    pub fn frame(&self, grid: &OccupancyGrid) -> Option<(OccupancyGrid, DVec2)> {
        self.frame_margin.map(|margin| framed(grid, margin))
    }

    /// The correlative local searches that are on: [`Self::search`] and [`Self::turn_search`].
    pub fn searches_mut(&mut self) -> impl Iterator<Item = &mut SearchConfig> {
        [&mut self.search, &mut self.turn_search]
            .into_iter()
            .flatten()
    }
}

impl Default for PairConfig {
    fn default() -> Self {
        Self {
            ransac: RansacConfig::default(),
            search: Some(SearchConfig::default()),
            turn_search: Some(SearchConfig {
                max_angle_deg: 2.0,
                ..SearchConfig::default()
            }),
            refine: RefineConfig::default(),
            verify: VerifyConfig::default(),
            global: None,
            sweep: Some(SweepConfig::default()),
            global_refine: RefineConfig {
                initial_gate_px: 12.0,
                max_iterations: 25,
                max_shift_px: 24.0,
                ..RefineConfig::default()
            },
            symmetry_probes: true,
            symmetry_confident_wall_lift: 0.9,
            offsets_in_verification: true,
            polish: Some(PolishConfig::default()),
            spectrum_rotation: Some(SpectrumRotation::default()),
            manhattan_rotation: Some(ManhattanRotation::default()),
            frame_margin: Some(64),
            refine_placements_as_proposed: false,
            refined_placements: Some(8),
            ascent: Some(AscentConfig::default()),
            turn_scan: Some(TurnScan::default()),
        }
    }
}

/// One candidate transform after refinement and verification.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Candidate {
    /// B→A transform, pixel convention.
    pub transform: Rigid2,
    /// RANSAC inliers of the hypothesis this candidate came from.
    pub ransac_inliers: usize,
    /// RANSAC's a-contrario confidence of that hypothesis.
    pub ransac_confidence: f64,
    /// The scores on the maps.
    pub verification: Verification,
    /// Whether it passes the verification thresholds.
    pub accepted: bool,
    /// Whether it was accepted because it stands out from every other placement
    /// ([`crate::verify::StandOut`]) rather than by the wall lift bars.
    pub stands_out: bool,
    /// Where the hypothesis came from.
    pub origin: Origin,
    /// Whether ICP refined it. A whole-map placement beyond
    /// [`PairConfig::refined_placements`] is kept where its local search led and scored there;
    /// it is refined only if it comes to be the best candidate, or the one that stands out.
    pub refined: bool,
}

/// Which stage proposed a candidate; serialised in lower case (`"ransac"`, ...), as the
/// `hypothesis` field of `mapmerge estimate --json`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Origin {
    /// A RANSAC hypothesis from keypoint and component correspondences.
    Ransac,
    /// The global search (Hough spectrum and correlation), run when no RANSAC candidate passed
    /// and [`PairConfig::global`] is on (off by default).
    Global,
    /// The rotation sweep of coarse correlation images.
    Sweep,
    /// A symmetry probe: the best candidate's angle, or that angle turned by a quarter, half or
    /// three quarters of a turn, with the best correlation translations.
    Symmetry,
}

impl Origin {
    /// The lower-case name, as serialised.
    pub fn as_str(self) -> &'static str {
        match self {
            Origin::Ransac => "ransac",
            Origin::Global => "global",
            Origin::Sweep => "sweep",
            Origin::Symmetry => "symmetry",
        }
    }
}

impl std::fmt::Display for Origin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.as_str())
    }
}

/// Wall-clock time of each stage, in milliseconds.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct Timings {
    /// Feature extraction and matching (runs beside `prepare_ms`: the two overlap).
    pub correspondences_ms: f64,
    /// RANSAC.
    pub ransac_ms: f64,
    /// Precomputation of both maps for verification (runs beside `correspondences_ms`).
    pub prepare_ms: f64,
    /// Refinement and verification of all candidates.
    pub verify_ms: f64,
    /// Global search, when it ran.
    pub global_ms: f64,
    /// Rotation sweep, when it ran (both ways round when the first found nothing that passes,
    /// see `SweepConfig::reverse`).
    pub sweep_ms: f64,
    /// Symmetry probes of the best accepted candidate, when they ran.
    pub symmetry_ms: f64,
    /// The score ascent of the answer ([`PairConfig::ascent`]) with its gate (both maps'
    /// wall thickness), when they ran.
    pub ascent_ms: f64,
}

/// The answer for one pair.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Registration {
    /// The best verified candidate, if any passed verification.
    pub accepted: Option<Candidate>,
    /// Why the pair was declined, when it was.
    pub reason: Option<String>,
    /// Every candidate, best score first.
    pub candidates: Vec<Candidate>,
    /// Correspondences found, by kind.
    pub correspondences: KindTotals,
    /// RANSAC inliers of the accepted candidate's hypothesis, by kind.
    pub inliers: KindTotals,
    /// Stage timings.
    pub timings: Timings,
    /// The putative correspondences themselves (for drawing), not serialised.
    #[serde(skip)]
    pub matches: Vec<Correspondence>,
}

/// The runner-up of a registration ([`Registration::runner_up`]): the best-ranked candidate
/// placed clearly apart from the answer.
#[derive(Debug, Clone, PartialEq)]
pub struct RunnerUp {
    /// The candidate, as [`Registration::candidates`] holds it.
    pub candidate: Candidate,
    /// How far apart it and the answer put B's walls: the mean distance, in pixels, over up
    /// to [`APART_POINTS`] of B's wall cells ([`mean_apart`]).
    pub apart_px: f64,
    /// Its [`Verification::score`] over the answer's (0 when the answer scores 0). It can
    /// exceed 1: the ranking puts the placements that pass the bars first, and the answer's
    /// pose is refined after the ranking.
    pub score_ratio: f64,
}

/// Wall cells of B over which [`mean_apart`] measures two placements, at most.
pub const APART_POINTS: usize = 500;

/// How far apart placements `x` and `y` put `points` (B's wall cells): the mean distance, in
/// pixels, between each point's two images; 0 for no point. The ambiguity test's and the
/// runner-up's measure of "different" ([`VerifyConfig::distinct_px`]).
pub fn mean_apart(points: &[DVec2], x: &Rigid2, y: &Rigid2) -> f64 {
    points
        .iter()
        .map(|p| (x.apply(*p) - y.apply(*p)).length())
        .sum::<f64>()
        / points.len().max(1) as f64
}

/// The pixels of `grid`'s occupied cells, row by row.
fn wall_cells(grid: &OccupancyGrid) -> Vec<DVec2> {
    (0..grid.height())
        .flat_map(|y| (0..grid.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| grid.state(x, y) == CellState::Occupied)
        .map(|(x, y)| DVec2::new(x as f64, y as f64))
        .collect()
}

impl Registration {
    /// The best-ranked candidate after the first that places `b` (the map registered onto A,
    /// in its own pixels, as the candidates' transforms are) more than `distinct_px` apart from
    /// it ([`mean_apart`] over up to [`APART_POINTS`] of `b`'s wall cells, evenly strided, as
    /// the ambiguity test measures two placements):
    /// the placement a user would weigh the answer against. The first candidate is the answer
    /// when the pair was accepted and the best rejected one when it was declined. `None` when
    /// no candidate is that far from the first, or `b` has no wall cell.
    ///
    /// A runner-up that passes the bars and fits about as well as the answer is what mostly
    /// makes a pair ambiguous, and declined (the ambiguity test also weighs the walls each puts
    /// in free space and whether the two are one broad optimum).
    pub fn runner_up(&self, b: &OccupancyGrid, distinct_px: f64) -> Option<RunnerUp> {
        let first = self.candidates.first()?;
        let walls = wall_cells(b);
        if walls.is_empty() {
            return None;
        }
        let probe = crate::verify::strided(&walls, APART_POINTS);
        self.candidates.iter().skip(1).find_map(|c| {
            let apart_px = mean_apart(&probe, &first.transform, &c.transform);
            (apart_px > distinct_px).then(|| {
                let best = first.verification.score();
                RunnerUp {
                    candidate: c.clone(),
                    apart_px,
                    score_ratio: if best > 0.0 {
                        c.verification.score() / best
                    } else {
                        0.0
                    },
                }
            })
        })
    }
}

/// A count per evidence kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct KindTotals {
    /// From intensity keypoints (SIFT).
    pub intensity: usize,
    /// From area keypoints (components).
    pub area: usize,
}

impl KindTotals {
    /// Count the correspondences `indices` of `corrs` by kind.
    pub fn of(corrs: &[Correspondence], indices: impl Iterator<Item = usize>) -> Self {
        let mut t = Self::default();
        for i in indices {
            match corrs[i].kind {
                EvidenceKind::Intensity => t.intensity += 1,
                EvidenceKind::Area => t.area += 1,
            }
        }
        t
    }
}

/// Whether candidate `c`, placed clearly apart from the best (`best` its scores), is a rival
/// that makes the pair ambiguous ([`VerifyConfig::max_ambiguity`]): it passes, scores almost
/// as well or fits its (smaller) overlap at least as well, or the best itself fits below
/// [`VerifyConfig::trusted_wide_wall_lift`], and it does not put clearly more walls into the
/// other map's free space ([`VerifyConfig::max_contradiction_excess`]; less is clearly more
/// when the best puts few there, [`VerifyConfig::clean_contradiction_excess`]).
///
/// A twin from the symmetry probes is judged by the same rule. At 9c48d15 every twin that
/// passed was a rival, which declined exact copies of small rooms whose quarter-turned twin
/// fits worse (wall lift 0.90 against 1.00, score 257 against 621).
fn rivals(best: &Verification, c: &Candidate, config: &VerifyConfig) -> bool {
    let v = &c.verification;
    c.accepted
        && (fits_about_as_well(best, v, config)
            || best.wide_wall_lift < config.trusted_wide_wall_lift)
        && v.wall_contradiction <= best.wall_contradiction + contradiction_excess(best, config)
}

/// How much more of its walls than `best` a placement may put into the other map's free space
/// and still rival it: [`VerifyConfig::clean_contradiction_excess`] plus the best's own
/// share, at most [`VerifyConfig::max_contradiction_excess`].
fn contradiction_excess(best: &Verification, config: &VerifyConfig) -> f64 {
    (config.clean_contradiction_excess + best.wall_contradiction)
        .min(config.max_contradiction_excess)
}

/// Whether `v` scores almost as well as `best` ([`VerifyConfig::max_ambiguity`]) or fits its
/// walls at least as well (wall lift as high).
fn fits_about_as_well(best: &Verification, v: &Verification, config: &VerifyConfig) -> bool {
    v.score() >= config.max_ambiguity * best.score() || v.wall_lift >= best.wall_lift
}

/// Whether placements `x` and `y` are one broad optimum rather than two answers: the placement
/// halfway between them fits at least [`VerifyConfig::basin_ratio`] as well as the poorer of
/// the two (all three scored by [`verify`], without range-bias offsets). Between two genuine
/// answers (a quarter turn, the next bay of a repetitive floor) the walls pass through free
/// space and the score falls; across a wall band that a noisy sensor smeared over 10-20 px,
/// it does not.
fn one_basin(
    a: &PreparedMap,
    b: &PreparedMap,
    x: &Rigid2,
    y: &Rigid2,
    config: &VerifyConfig,
) -> bool {
    if config.basin_ratio <= 0.0 {
        return false;
    }
    let half = grid_core::wrap_angle(y.theta - x.theta) / 2.0;
    let mid = Rigid2::new(x.theta + half, (x.tx + y.tx) / 2.0, (x.ty + y.ty) / 2.0);
    let score = |t: &Rigid2| verify(a, b, t, config).score();
    score(&mid) >= config.basin_ratio * score(x).min(score(y))
}

/// The candidate [`StandOut`] accepts when none passed the wall lift bars: of those the rule
/// admits ([`StandOut::admits`]), the best scoring, if it [`stands_out`].
/// `apart` measures how far apart two placements put B's walls.
fn standing_out(
    candidates: &[Candidate],
    rule: &StandOut,
    config: &VerifyConfig,
    apart: &dyn Fn(&Rigid2, &Rigid2) -> f64,
) -> Option<usize> {
    let (i, c) = candidates
        .iter()
        .enumerate()
        .filter(|(_, c)| rule.admits(&c.verification, config))
        .max_by(|(_, x), (_, y)| x.verification.score().total_cmp(&y.verification.score()))?;
    stands_out(candidates, c, rule, config, apart).then_some(i)
}

/// Whether every candidate that passes all but the wall tests and lies more than
/// `rule.distance_px` from `c` has a wide lift at least `rule.margin` below `c`'s.
fn stands_out(
    candidates: &[Candidate],
    c: &Candidate,
    rule: &StandOut,
    config: &VerifyConfig,
    apart: &dyn Fn(&Rigid2, &Rigid2) -> f64,
) -> bool {
    let bar = c.verification.wide_wall_lift - rule.margin;
    candidates
        .iter()
        .filter(|o| {
            rule.passes_all_but_walls(&o.verification, config)
                && apart(&o.transform, &c.transform) > rule.distance_px
        })
        .all(|o| o.verification.wide_wall_lift <= bar)
}

/// The share of lone wall cells ([`lone_wall_share`]) from which a map's walls count as
/// speckle in a decline's reason. With `mapsim`'s default mapper each map of `cargo xtask eval
/// --out` holds 0.03-0.08 at 10 % range noise, 0.09-0.21 at 20 %, 0.16-0.30 at 30 % and
/// 0.28-0.46 at 50 % (docs/EVALUATION.md, "Equal noise of 20 %"): from 20 % on, right
/// placements fit about as poorly as wrong ones, and pairs are declined that do overlap.
pub const SPECKLED_LONE_SHARE: f64 = 0.1;

/// Why no placement passed: the best one's fit against the bars it missed and, where both
/// maps' walls are speckle (lone wall cell shares `lone`), that this is what a range sensor
/// with strong noise leaves.
fn unverified_reason(v: &Verification, config: &VerifyConfig, lone: (f64, f64)) -> String {
    let mut reason = format!(
        "no hypothesis passed verification (best: wall lift {:.2} where {:.2} passes, or {:.2} at {} px where {:.2} passes; acceptance index {:.2}; overlap {:.1}% of the smaller map)",
        v.wall_lift,
        config.min_wall_lift,
        v.wide_wall_lift,
        config.wide_tolerance_px,
        config.min_wide_wall_lift,
        v.acceptance_index,
        100.0 * v.overlap_fraction
    );
    if lone.0.min(lone.1) >= SPECKLED_LONE_SHARE {
        reason += &format!(
            "; both maps' walls are speckle (lone wall cells {:.1} % and {:.1} %), as a range sensor with strong noise leaves them: there a right placement fits about as poorly as a wrong one",
            100.0 * lone.0,
            100.0 * lone.1
        );
    }
    reason
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// A pose as every hypothesis is polished and scored: refined from `start` by ICP with
/// `refine` (range-bias offsets included), then verified with `config.verify`, with those
/// offsets applied when `config.offsets_in_verification`. Public so that evaluations score
/// other poses (the truth, say) exactly as the pipeline scores its candidates.
pub fn refine_and_score(
    a: &PreparedMap,
    b: &PreparedMap,
    start: &Rigid2,
    refine: &RefineConfig,
    config: &PairConfig,
) -> (Rigid2, Verification) {
    let (transform, offsets) = refine_with_bias(a, b, start, refine);
    let transform = transform.normalized();
    let v = if config.offsets_in_verification {
        verify_with_offsets(a, b, &transform, offsets, &config.verify)
    } else {
        verify(a, b, &transform, &config.verify)
    };
    (transform, v)
}

/// A whole-map placement, and where the translation-only local search (`PairConfig::search`)
/// moved it and how that pose verified, when that is already known (the screen searched and
/// verified it), so that it is not searched and verified twice.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Placement {
    pose: Rigid2,
    searched: Option<(Rigid2, Verification)>,
}

impl Placement {
    /// A placement not searched yet.
    fn unsearched(pose: Rigid2) -> Self {
        Self {
            pose,
            searched: None,
        }
    }
}

/// The `keep` of `placements` that pass verification, or else that the maps agree with most,
/// once the correlative local search (`config.search`, if any) has moved them
/// ([`screen_order`]): a cheap screen before the full refinement, for a coarse ranking that
/// puts the truth too far down (see [`SweepConfig::screened`]). Returns
/// the placements themselves with where the search moved them, best screened first; all of
/// them, in order and unsearched, when there are no more than `keep`. Deterministic: ties
/// keep the given order.
fn screen(
    a: &PreparedMap,
    b: &PreparedMap,
    placements: Vec<Rigid2>,
    keep: usize,
    config: &PairConfig,
) -> Vec<Placement> {
    if placements.len() <= keep {
        return placements.into_iter().map(Placement::unsearched).collect();
    }
    let scored: Vec<(Rigid2, Verification)> = placements
        .par_iter()
        .map(|p| {
            let moved = config
                .search
                .as_ref()
                .map_or(*p, |sc| local_search(a, b, p, sc));
            (moved, verify(a, b, &moved, &config.verify))
        })
        .collect();
    let verifications: Vec<Verification> = scored.iter().map(|s| s.1).collect();
    screen_order(&verifications, &config.verify)
        .into_iter()
        .take(keep)
        .map(|i| Placement {
            pose: placements[i],
            searched: Some(scored[i]),
        })
        .collect()
}

/// The order in which the screen keeps placements verified as `verifications`: those that pass
/// `config` first, then by [`Verification::score`], best first; ties keep the given order.
///
/// Passing comes first because the score grows with the compared walls: at 30 % overlap a
/// wrong placement laying most of B over A (wall lift 0.2-0.5, far from passing) outscores
/// the truth's small overlap (lift 0.6-0.85, passing) several times over, and the screen
/// dropped the truth for it (docs/EVALUATION.md, "The screen keeps passing placements").
fn screen_order(verifications: &[Verification], config: &VerifyConfig) -> Vec<usize> {
    let mut order: Vec<usize> = (0..verifications.len()).collect();
    order.sort_by(|&i, &j| {
        let (vi, vj) = (&verifications[i], &verifications[j]);
        vj.accepted(config)
            .cmp(&vi.accepted(config))
            .then(vj.score().total_cmp(&vi.score()))
    });
    order
}

/// `grid` on the bounding box of its known cells grown by `margin` cells on every side (see
/// [`PairConfig::frame_margin`]), and the position in `grid` of the frame's cell `(0, 0)`;
/// `grid` itself, at offset zero, when it has no known cell.
pub fn framed(grid: &OccupancyGrid, margin: usize) -> (OccupancyGrid, DVec2) {
    let Some((x0, y0, w, h)) = grid.known_bounds(0) else {
        return (grid.clone(), DVec2::ZERO);
    };
    let (fx, fy) = (x0 as i64 - margin as i64, y0 as i64 - margin as i64);
    let frame = grid
        .region(fx, fy, w + 2 * margin, h + 2 * margin)
        .expect("a known cell gives a non-empty frame");
    (frame, DVec2::new(fx as f64, fy as f64))
}

/// `t`, which maps pixels of B's frame onto A's frame, as a map of B's pixels onto A's, the
/// frames' cells `(0, 0)` lying at `oa` in A and `ob` in B: `p -> t(p - ob) + oa`.
fn unframed(t: &Rigid2, oa: DVec2, ob: DVec2) -> Rigid2 {
    let moved = t.apply(-ob) + oa;
    Rigid2::new(t.theta, moved.x, moved.y)
}

/// Register `b` onto `a` using the correspondences of `sources`.
///
/// Fails only for invalid settings ([`PairConfig::validate`]), before any work: a pair
/// without a trustworthy answer comes back with `accepted: None` and a reason, which the
/// binary turns into exit code 3.
pub fn register_with(
    a: &OccupancyGrid,
    b: &OccupancyGrid,
    sources: &[&(dyn CorrespondenceSource + Sync)],
    config: &PairConfig,
) -> Result<Registration, Error> {
    config.validate()?;
    Ok(register_framed(a, b, sources, config))
}

/// [`register_with`] for settings already checked: each map cut to its frame
/// ([`PairConfig::frame`]), registered, and the answer given in the maps' own pixels.
fn register_framed(
    a: &OccupancyGrid,
    b: &OccupancyGrid,
    sources: &[&(dyn CorrespondenceSource + Sync)],
    config: &PairConfig,
) -> Registration {
    let (Some((fa, oa)), Some((fb, ob))) = rayon::join(|| config.frame(a), || config.frame(b))
    else {
        return register_as_given(a, b, sources, config);
    };
    let mut r = register_as_given(&fa, &fb, sources, config);
    for c in r.accepted.iter_mut().chain(r.candidates.iter_mut()) {
        c.transform = unframed(&c.transform, oa, ob);
    }
    for m in &mut r.matches {
        (m.a, m.b) = (m.a + oa, m.b + ob);
    }
    r
}

/// [`register_with`] on the maps as given (no frames).
fn register_as_given(
    a: &OccupancyGrid,
    b: &OccupancyGrid,
    sources: &[&(dyn CorrespondenceSource + Sync)],
    config: &PairConfig,
) -> Registration {
    let mut timings = Timings::default();
    // The sources, and the maps' preparation for verification, are independent: run them
    // side by side (their times overlap). Sources are concatenated in the given order.
    let ((corrs, correspondences_ms), ((pa, pb), prepare_ms)) = rayon::join(
        || {
            let t0 = Instant::now();
            let parts: Vec<Vec<Correspondence>> = sources
                .par_iter()
                .map(|s| {
                    let mut out = Vec::new();
                    s.correspondences(a, b, &mut out);
                    out
                })
                .collect();
            (parts.concat(), ms(t0))
        },
        || {
            let t0 = Instant::now();
            let maps = rayon::join(
                || PreparedMap::new(a, &config.verify),
                || PreparedMap::new(b, &config.verify),
            );
            (maps, ms(t0))
        },
    );
    timings.correspondences_ms = correspondences_ms;
    timings.prepare_ms = prepare_ms;
    let correspondences = KindTotals::of(&corrs, 0..corrs.len());
    let declined = |reason: String, timings, candidates| Registration {
        accepted: None,
        reason: Some(reason),
        candidates,
        correspondences,
        inliers: KindTotals::default(),
        timings,
        matches: corrs.clone(),
    };
    // A map with fewer known cells than an answer must share cannot be placed: said at once,
    // rather than through whichever rule declines its placements.
    let (which, smaller) = if pa.known_cells <= pb.known_cells {
        ("A", pa.known_cells)
    } else {
        ("B", pb.known_cells)
    };
    if smaller < config.verify.min_overlap_cells {
        let reason = format!(
            "too small: map {which} has {smaller} known cells, fewer than the {} an answer must share with the other map",
            config.verify.min_overlap_cells
        );
        return declined(reason, timings, Vec::new());
    }
    // Walls are what a placement is judged by: a map without one, or two maps with fewer wall
    // cells together than an answer must compare, cannot be placed. Said at once, rather than
    // as "no transform hypothesis" after the samplers have drawn in vain.
    let (walls_a, walls_b) = (pa.occupied_cells, pb.occupied_cells);
    if walls_a == 0 || walls_b == 0 {
        let which = if walls_a == 0 { "A" } else { "B" };
        let reason = format!(
            "no walls: map {which} has no occupied cell, and walls are what a placement is judged by"
        );
        return declined(reason, timings, Vec::new());
    }
    if walls_a + walls_b < config.verify.min_wall_support {
        let reason = format!(
            "too few walls: the maps have {} occupied cells together, fewer than the {} an answer must compare",
            walls_a + walls_b,
            config.verify.min_wall_support
        );
        return declined(reason, timings, Vec::new());
    }

    let t0 = Instant::now();
    let ransac = estimate_rigid(&corrs, &config.ransac);
    timings.ransac_ms = ms(t0);
    let hypotheses = ransac
        .as_ref()
        .map(|r| r.hypotheses.as_slice())
        .unwrap_or_default();

    let t0 = Instant::now();
    // Each hypothesis is polished by ICP, once from itself and once from the best pose of the
    // correlative local search around it (keypoints, or a whole-map search's coarse grid, can
    // put it a few pixels off, outside ICP's narrow basin), and for whole-map placements once
    // more from the best pose of the turn search; the polished pose the maps agree with most
    // wins (the first of equals). A whole-map placement is refined from itself only when
    // neither search moved it, unless `refine_placements_as_proposed`. Global hypotheses
    // refine with their own, wider-gated configuration.
    //
    // `starts` gives the poses a hypothesis is refined from, `polished` refines them and
    // keeps the best.
    let starts = |placement: &Placement, origin: Origin| -> Vec<Rigid2> {
        let model = &placement.pose;
        // Whole-map placements are also searched over rotation.
        let turn_search = if origin == Origin::Ransac {
            None
        } else {
            config.turn_search.as_ref()
        };
        let searched = |sc: Option<&SearchConfig>| {
            let moved = local_search(&pa, &pb, model, sc?);
            (moved != *model).then_some(moved)
        };
        // The searches are independent: run them side by side.
        let (searched, turned) = rayon::join(
            || match placement.searched {
                Some((moved, _)) => (moved != *model).then_some(moved),
                None => searched(config.search.as_ref()),
            },
            || searched(turn_search),
        );
        let from_itself = turn_search.is_none()
            || config.refine_placements_as_proposed
            || (searched.is_none() && turned.is_none());
        [from_itself.then_some(*model), searched, turned]
            .into_iter()
            .flatten()
            .collect()
    };
    let candidate = |(transform, verification): (Rigid2, Verification), origin: Origin| Candidate {
        transform,
        ransac_inliers: 0,
        ransac_confidence: 0.0,
        accepted: verification.accepted(&config.verify),
        stands_out: false,
        verification,
        origin,
        refined: true,
    };
    // The highest-scoring of `scored` (the first of equals), if any.
    let highest = |scored: Vec<(Rigid2, Verification)>| {
        scored.into_iter().reduce(|best, p| {
            if p.1.score() > best.1.score() {
                p
            } else {
                best
            }
        })
    };
    let best_of =
        |scored: Vec<(Rigid2, Verification)>| highest(scored).expect("at least one start");
    let polished = |starts: &[Rigid2], refine_config: &RefineConfig, origin: Origin| {
        // Side by side: the refinements are independent.
        let scored: Vec<(Rigid2, Verification)> = starts
            .par_iter()
            .map(|s| refine_and_score(&pa, &pb, s, refine_config, config))
            .collect();
        candidate(best_of(scored), origin)
    };
    let check = |model: &Rigid2, refine_config: &RefineConfig, origin: Origin| {
        polished(
            &starts(&Placement::unsearched(*model), origin),
            refine_config,
            origin,
        )
    };
    // The placements of one whole-map search: every placement is searched, and when there are
    // more than `refined_placements`, only those whose best start the maps agree with most
    // are refined; the others are kept at that start, as verified there.
    let check_placements = |models: &[Placement], origin: Origin| -> Vec<Candidate> {
        let starts: Vec<Vec<Rigid2>> = models.par_iter().map(|m| starts(m, origin)).collect();
        let refined_all = config.refined_placements.is_none_or(|k| models.len() <= k);
        if refined_all {
            return starts
                .par_iter()
                .map(|s| polished(s, &config.global_refine, origin))
                .collect();
        }
        // A start the screen verified is not verified again.
        let at_start: Vec<(Rigid2, Verification)> = starts
            .par_iter()
            .zip(models)
            .map(|(s, m)| {
                best_of(
                    s.iter()
                        .map(|p| match m.searched {
                            Some((q, v)) if q == *p => (*p, v),
                            _ => (*p, verify(&pa, &pb, p, &config.verify)),
                        })
                        .collect(),
                )
            })
            .collect();
        let mut order: Vec<usize> = (0..models.len()).collect();
        order.sort_by(|&i, &j| at_start[j].1.score().total_cmp(&at_start[i].1.score()));
        let mut refine = vec![false; models.len()];
        for &i in order
            .iter()
            .take(config.refined_placements.unwrap_or(usize::MAX))
        {
            refine[i] = true;
        }
        (0..models.len())
            .into_par_iter()
            .map(|i| {
                if refine[i] {
                    polished(&starts[i], &config.global_refine, origin)
                } else {
                    Candidate {
                        refined: false,
                        ..candidate(at_start[i], origin)
                    }
                }
            })
            .collect()
    };
    let mut candidates: Vec<Candidate> = hypotheses
        .par_iter()
        .map(|h| Candidate {
            ransac_inliers: h.inliers_count,
            ransac_confidence: h.confidence,
            ..check(&h.model, &config.refine, Origin::Ransac)
        })
        .collect();
    timings.verify_ms = ms(t0);
    // The whole-map searches: their placements are checked like the feature-based ones, with
    // the global refinement (they come from a coarse grid).
    let search = |generate: &dyn Fn(&mut Vec<Placement>), origin: Origin| {
        let t0 = Instant::now();
        let mut models = Vec::new();
        generate(&mut models);
        (check_placements(&models, origin), ms(t0))
    };
    if let Some(global) = &config.global
        && !candidates.iter().any(|c| c.accepted)
    {
        let (found, t) = search(
            &|out| {
                let mut found = Vec::new();
                global_hypotheses(&pa, &pb, global, &mut found);
                out.extend(found.into_iter().map(Placement::unsearched));
            },
            Origin::Global,
        );
        candidates.extend(found);
        timings.global_ms = t;
    }
    // A feature-based candidate that passed with at least `bar` of wall lift.
    let confident = |c: &Candidate, bar: f64| {
        c.accepted && c.origin == Origin::Ransac && c.verification.wall_lift >= bar
    };
    // The sweep runs unless a feature-based candidate passed with a good fit. Keypoint matches
    // that agree and walls that agree are two kinds of evidence; one kind alone (a
    // Hough-spectrum placement, or a weak fit) can be a wrong placement on repetitive walls, or
    // a poorer local optimum near the right one. The sweep then proposes the better fit (which
    // wins) or a rival (and the pair is declined as ambiguous).
    if let Some(sweep) = &config.sweep
        && !candidates
            .iter()
            .any(|c| confident(c, sweep.confident_wall_lift))
    {
        // The sweep's placements with `moving`'s walls turned over `field`'s, as maps of B
        // onto A (`back` turns them round when B is the field).
        let swept = |field: &PreparedMap, moving: &PreparedMap, back: bool| {
            let found = sweep_placements(
                field,
                moving,
                sweep,
                sweep.screened.max(sweep.keep_normalized),
            );
            let onto_a = |placements: Vec<Rigid2>| -> Vec<Rigid2> {
                if back {
                    placements
                        .into_iter()
                        .map(|t| t.inverse().normalized())
                        .collect()
                } else {
                    placements
                }
            };
            let mut out: Vec<Placement> = onto_a(found.plain)
                .into_iter()
                .map(Placement::unsearched)
                .collect();
            out.extend(screen(
                &pa,
                &pb,
                onto_a(found.normalized),
                sweep.keep_normalized,
                config,
            ));
            out
        };
        let (found, t) = search(&|out| out.extend(swept(&pa, &pb, false)), Origin::Sweep);
        candidates.extend(found);
        timings.sweep_ms = t;
        // Nothing passed: the other way round (see `SweepConfig::reverse`).
        if sweep.reverse && !candidates.iter().any(|c| c.accepted) {
            let (found, t) = search(&|out| out.extend(swept(&pb, &pa, true)), Origin::Sweep);
            candidates.extend(found);
            timings.sweep_ms += t;
        }
    }
    // A whole-map placement kept where its search led, refined now that it matters.
    let settle = |c: &mut Candidate| {
        if !c.refined {
            let scored = refine_and_score(&pa, &pb, &c.transform, &config.global_refine, config);
            *c = candidate(scored, c.origin);
        }
    };
    // Best first; the best is always a refined candidate.
    let rank = |candidates: &mut Vec<Candidate>| loop {
        candidates.sort_by(|x, y| {
            y.accepted
                .cmp(&x.accepted)
                .then(y.verification.score().total_cmp(&x.verification.score()))
        });
        match candidates.first_mut() {
            Some(best) if !best.refined => settle(best),
            _ => break,
        }
    };
    rank(&mut candidates);
    // How far apart two placements put B's walls, on average (the ambiguity test's and the
    // stand-out rule's measure of "different").
    let probe = crate::verify::strided(&pb.wall_samples, APART_POINTS);
    let apart = |x: &Rigid2, y: &Rigid2| mean_apart(&probe, x, y);
    // Nothing passed the bars: a placement may still stand out from every other (speckled
    // walls of a very noisy sensor). It is then probed for twins like any accepted answer.
    let refined_standing_out = |candidates: &mut Vec<Candidate>, rule: &StandOut| loop {
        let i = standing_out(candidates, rule, &config.verify, &apart)?;
        if candidates[i].refined {
            return Some(i);
        }
        settle(&mut candidates[i]);
    };
    if let Some(rule) = &config.verify.stand_out
        && candidates.first().is_some_and(|c| !c.accepted)
        && let Some(i) = refined_standing_out(&mut candidates, rule)
    {
        candidates[i].accepted = true;
        candidates[i].stands_out = true;
        rank(&mut candidates);
    }
    if config.symmetry_probes
        && let Some(best) = candidates
            .first()
            .filter(|c| c.accepted && !confident(c, config.symmetry_confident_wall_lift))
    {
        let t0 = Instant::now();
        let mut probes = Vec::new();
        twins(
            &pa,
            &pb,
            &best.transform,
            &config.global.unwrap_or_default(),
            &mut probes,
        );
        let probes: Vec<Placement> = probes.into_iter().map(Placement::unsearched).collect();
        candidates.extend(check_placements(&probes, Origin::Symmetry));
        rank(&mut candidates);
        timings.symmetry_ms = ms(t0);
    }
    // A placement that stood out must still stand out from the twins the probes found.
    if let Some(rule) = &config.verify.stand_out
        && let Some(best) = candidates.first()
        && best.stands_out
        && !stands_out(&candidates, best, rule, &config.verify, &apart)
    {
        candidates[0].accepted = false;
        candidates[0].stands_out = false;
        rank(&mut candidates);
    }
    // Whether a candidate's walls agree almost everywhere: the polish's case, which the
    // spectrum angle and the ascent (made for noisy walls) leave alone.
    let clean = |c: &Candidate| {
        config
            .polish
            .is_some_and(|p| c.verification.wall_lift >= p.min_wall_lift)
    };
    // The best candidate, when clean, is polished (only the best: on the 2048 bench pair
    // polishing every RANSAC candidate cost about 35 ms).
    if let Some(polish) = &config.polish
        && let Some(best) = candidates.first_mut().filter(|c| c.accepted && clean(c))
    {
        let t = refine_with_bias(&pa, &pb, &best.transform, &polish.refine)
            .0
            .normalized();
        let v = verify(&pa, &pb, &t, &config.verify);
        if v.wall_lift >= polish.min_wall_lift && v.accepted(&config.verify) {
            (best.transform, best.verification) = (t, v);
        }
    }
    // The best candidate's angle from the walls' Hough spectra (see `SpectrumRotation`).
    if let Some(sr) = &config.spectrum_rotation
        && let Some(best) = candidates.first_mut().filter(|c| c.accepted && !clean(c))
        && wall_residual_px(&pa, &pb, &best.transform, 3.0, sr.max_points)
            .is_some_and(|r| r >= sr.min_wall_residual_px)
        && agreeing_wall_spread_px(&pa, &pb, &best.transform, 3.0)
            .is_some_and(|spread| spread < sr.max_lever_px)
        && let Some(theta) = spectrum_rotation_near(
            &pa,
            &pb,
            best.transform.theta,
            sr.bins,
            sr.max_points,
            sr.max_delta_deg.to_radians(),
        )
        && let Some((t, v)) = at_angle(&pa, &pb, &best.transform, theta, config)
    {
        // A placement that stood out keeps the angle if it stays above the rule's bars.
        let still_out = best.stands_out
            && config
                .verify
                .stand_out
                .is_some_and(|r| r.admits(&v, &config.verify));
        if v.accepted(&config.verify) || still_out {
            (best.transform, best.verification) = (t.normalized(), v);
        }
    }
    // The best candidate's angle from the maps' dominant wall directions (see
    // `ManhattanRotation`).
    let mut angle_from_walls = false;
    if let Some(mr) = &config.manhattan_rotation
        && let Some(best) = candidates.first_mut().filter(|c| c.accepted && !clean(c))
        && wall_residual_px(&pa, &pb, &best.transform, 3.0, mr.max_points)
            .is_some_and(|r| r >= mr.min_wall_residual_px)
        && agreeing_lever(&pa, &pb, &best.transform, 3.0)
            .is_some_and(|(spread, ratio)| spread >= mr.min_lever_px && ratio >= mr.min_reach_ratio)
        && let Some(theta) = manhattan_rotation_near(&pa, &pb, best.transform.theta, mr)
        && let Some((t, v)) = at_angle(&pa, &pb, &best.transform, theta, config)
        && v.accepted(&config.verify)
        && v.wall_lift >= best.verification.wall_lift - mr.max_lift_drop
    {
        (best.transform, best.verification) = (t.normalized(), v);
        angle_from_walls = true;
    }
    // Both maps' shares of lone wall cells (the turn scan's gate and the clean-walls bar),
    // scanned once, when first needed.
    let lone = std::cell::OnceCell::new();
    let lone_shares = || {
        *lone.get_or_init(|| rayon::join(|| lone_wall_share(pa.grid), || lone_wall_share(pb.grid)))
    };
    // Why the bars for maps with clean walls decline a placement verified as `v`, if they do
    // (`VerifyConfig::clean_walls`, then `clean_fit`): the rescue of the turn scan asks it,
    // and the answer is declined for it below.
    let clean_walls_misfit = |v: &Verification| -> Option<String> {
        if let Some(clean) = &config.verify.clean_walls {
            let (sa, sb) = lone_shares();
            let bar = clean.bar(sa, sb);
            if v.mutual_contradiction > bar {
                return Some(format!(
                    "contradicted: each map puts {:.1} % or more of its compared walls in the other's free space, where maps with walls this clean (lone wall cells {:.1} % and {:.1} %) allow {:.1} %",
                    100.0 * v.mutual_contradiction,
                    100.0 * sa,
                    100.0 * sb,
                    100.0 * bar
                ));
            }
        }
        if let Some(fit) = &config.verify.clean_fit {
            let (sa, sb) = lone_shares();
            if fit.falls_short(v.wide_wall_lift, sa, sb) {
                return Some(format!(
                    "misfit: both maps draw their walls cleanly (lone wall cells {:.1} % and {:.1} %), where a right placement fits its walls at wide lift {:.2} or more; the best fits at {:.2}",
                    100.0 * sa,
                    100.0 * sb,
                    fit.min_wide_wall_lift,
                    v.wide_wall_lift
                ));
            }
        }
        None
    };
    // The answer's angle scanned about its overlap (see `TurnScan`), unless it was polished or
    // stood out, as the ascent below, or took the Manhattan angle.
    if let Some(scan) = &config.turn_scan
        && !(angle_from_walls && scan.keep_manhattan_angle)
        && let Some(best) = candidates
            .first_mut()
            .filter(|c| c.accepted && !c.stands_out && !clean(c))
    {
        let from = best.transform;
        let lever =
            wall_centres(&pa, &pb, &from).map_or(0.0, |(shared, all)| (shared - all).length());
        let alike = || {
            let (sa, sb) = lone_shares();
            sa.max(sb) <= scan.max_speckle_ratio * sa.min(sb)
        };
        let rescue = scan.rescue_misfits && clean_walls_misfit(&best.verification).is_some();
        let turns = if rescue || (lever >= scan.min_lever_px && alike()) {
            scan.turns()
        } else {
            Vec::new()
        };
        let passing: Vec<(Rigid2, Verification)> = turns
            .par_iter()
            .filter_map(|d| {
                at_angle(&pa, &pb, &from, from.theta + d, config)
                    .filter(|(_, v)| v.accepted(&config.verify))
            })
            .collect();
        if let Some((t, v)) = highest(passing)
            && v.score() > best.verification.score()
        {
            if rescue {
                // The turn found the basin; ICP finds the pose in it (see
                // `TurnScan::rescue_misfits`).
                let polished = config.polish.map(|polish| {
                    let p = refine_with_bias(&pa, &pb, &t, &polish.refine)
                        .0
                        .normalized();
                    (p, verify(&pa, &pb, &p, &config.verify))
                });
                let clears = |v: &Verification| {
                    v.accepted(&config.verify)
                        && v.score() > best.verification.score()
                        && clean_walls_misfit(v).is_none()
                };
                if let Some((p, pv)) = polished.filter(|(_, pv)| clears(pv)) {
                    (best.transform, best.verification) = (p, pv);
                } else if clears(&v) {
                    (best.transform, best.verification) = (t.normalized(), v);
                }
            } else {
                (best.transform, best.verification) = (t.normalized(), v);
            }
        }
    }
    // The answer climbs the verification score (see `crate::ascent`), unless it was polished
    // (walls that agree almost everywhere: ICP's pose is then sub-pixel, the score's counts at
    // whole cells are not) or stood out (the bars it passed are not those the score ranks).
    if let Some(ascent) = &config.ascent
        && let Some(best) = candidates
            .first_mut()
            .filter(|c| c.accepted && !c.stands_out && !clean(c))
    {
        let t0 = Instant::now();
        let (ta, tb) = rayon::join(|| wall_thickness(pa.grid), || wall_thickness(pb.grid));
        let short_range = || {
            ascent.short_range.is_some_and(|sr| {
                best.verification.wall_lift < sr.max_wall_lift && {
                    let (fa, fb) =
                        rayon::join(|| frontier_ratio(pa.grid), || frontier_ratio(pb.grid));
                    fa.min(fb) >= sr.min_frontier_ratio
                }
            })
        };
        if ta.min(tb) >= ascent.min_wall_thickness || short_range() {
            let (t, v) = ascend(&pa, &pb, &best.transform, ascent, &config.verify);
            if t != best.transform && v.accepted(&config.verify) {
                (best.transform, best.verification) = (t, v);
            }
        }
        timings.ascent_ms = ms(t0);
    }
    // Ambiguity: another accepted, clearly different placement that scores almost as well.
    // "Different" is measured where it matters: how far apart the two put B's walls (`apart`).
    let rival = candidates.first().filter(|b| b.accepted).and_then(|best| {
        candidates.iter().skip(1).find(|c| {
            rivals(&best.verification, c, &config.verify)
                && apart(&c.transform, &best.transform) > config.verify.distinct_px
                && !one_basin(&pa, &pb, &best.transform, &c.transform, &config.verify)
        })
    });
    if let (Some(best), Some(rival)) = (candidates.first(), rival) {
        let (b, r) = (&best.verification, &rival.verification);
        let reason = if fits_about_as_well(b, r, &config.verify) {
            format!(
                "ambiguous: two different placements fit almost equally well (scores {:.0} and {:.0}); the maps share too little distinctive structure",
                b.score(),
                r.score()
            )
        } else {
            format!(
                "ambiguous: the best placement fits imperfectly (wide wall lift {:.2}, score {:.0}) and a clearly different one passes too (wide wall lift {:.2}, score {:.0}); repeated structure fits more than one way",
                b.wide_wall_lift,
                b.score(),
                r.wide_wall_lift,
                r.score()
            )
        };
        return declined(reason, timings, candidates);
    }
    // An answer that leaves much of its wall in the other map's free space is declined (see
    // `VerifyConfig::max_wall_contradiction` and `crisp_wall_lift`); it has served as a rival
    // above.
    if let Some(best) = candidates.first().filter(|b| b.accepted) {
        let v = &best.verification;
        if v.wall_contradiction > config.verify.max_wall_contradiction {
            let reason = format!(
                "contradicted: {:.0} % of the best placement's compared walls lie in the other map's free space (at most {:.0} % accepted)",
                100.0 * v.wall_contradiction,
                100.0 * config.verify.max_wall_contradiction
            );
            return declined(reason, timings, candidates);
        }
        if let Some(reason) = clean_walls_misfit(v) {
            return declined(reason, timings, candidates);
        }
        if let Some(bar) = v.crisp_contradiction_bar(&config.verify)
            && v.mutual_contradiction > bar
        {
            let reason = format!(
                "contradicted: the best placement lays walls on walls crisply (wall lift {:.2}) yet each map puts {:.1} % or more of its compared walls in the other's free space (at most {:.1} % accepted at that fit); it matches part of a layout that repeats, not the overlap",
                v.wall_lift,
                100.0 * v.mutual_contradiction,
                100.0 * bar
            );
            return declined(reason, timings, candidates);
        }
        if let Some(small) = &config.verify.small_overlap
            && small.falls_short(v)
        {
            let reason = format!(
                "sliver: the best placement shares {:.0} % of the smaller map's known cells, and an overlap under {:.0} % is accepted only where the walls fit almost everywhere (wide wall lift {:.2} or more; this one {:.2})",
                100.0 * v.overlap_fraction,
                100.0 * small.below,
                small.min_wide_wall_lift,
                v.wide_wall_lift
            );
            return declined(reason, timings, candidates);
        }
        if v.too_small(&config.verify) {
            let reason = format!(
                "too small: the best placement shares {} cells known in both maps, and at least {} are needed (it covers {:.0} % of the smaller map, which fits inside the other almost anywhere)",
                v.overlap_cells,
                config.verify.min_overlap_cells,
                100.0 * v.overlap_fraction
            );
            return declined(reason, timings, candidates);
        }
    }
    match candidates.first() {
        Some(best) if best.accepted => {
            // Inliers of the final (refined) transform, so the split by kind describes the answer.
            let t = best.transform;
            let close = corrs
                .iter()
                .enumerate()
                .filter(|(_, c)| (c.a - t.apply(c.b)).length() <= config.ransac.threshold_px);
            let inliers = KindTotals::of(&corrs, close.map(|(i, _)| i));
            Registration {
                accepted: Some(best.clone()),
                reason: None,
                candidates,
                correspondences,
                inliers,
                timings,
                matches: corrs,
            }
        }
        Some(best) => {
            let reason = unverified_reason(&best.verification, &config.verify, lone_shares());
            declined(reason, timings, candidates)
        }
        None => {
            let why = match &ransac {
                Err(e) => format!("no transform hypothesis: {e}"),
                Ok(_) => "no transform hypothesis".into(),
            };
            declined(why, timings, candidates)
        }
    }
}

/// Which evidence gives the correspondences.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Intensity keypoints only (SIFT, 2-point hypotheses).
    Sift,
    /// Area keypoints only (obstacle components, 1-point hypotheses).
    Blobs,
    /// Both, scored together (the default).
    #[default]
    Hybrid,
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Method::Sift => "sift",
            Method::Blobs => "blobs",
            Method::Hybrid => "hybrid",
        })
    }
}

impl std::str::FromStr for Method {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "sift" => Ok(Method::Sift),
            "blobs" => Ok(Method::Blobs),
            "hybrid" => Ok(Method::Hybrid),
            _ => Err(format!(
                "unknown method '{s}' (expected sift, blobs or hybrid)"
            )),
        }
    }
}

/// Settings of [`register`]: the method, each source's settings and the pair settings.
#[derive(Debug, Clone, Default)]
pub struct RegisterConfig {
    /// Which correspondences to use. Default [`Method::Hybrid`].
    pub method: Method,
    /// SIFT settings (defaults of `sift-desc`).
    pub sift: SiftConfig,
    /// Component settings (defaults of `blob-features`).
    pub blobs: BlobConfig,
    /// Component matching settings.
    pub blob_matching: blob_features::MatchConfig,
    /// RANSAC, refinement, verification and global search.
    pub pair: PairConfig,
}

/// Register `b` onto `a` with the method of `config`.
///
/// Fails only for invalid settings ([`RegisterConfig::validate`]), before any work; a pair
/// without a trustworthy answer comes back with `accepted: None` and a reason.
pub fn register(
    a: &OccupancyGrid,
    b: &OccupancyGrid,
    config: &RegisterConfig,
) -> Result<Registration, Error> {
    config.validate()?;
    let sift = SiftCorrespondences::new(config.sift.clone())?;
    let blobs = BlobCorrespondences {
        blobs: Blobs::new(config.blobs),
        matching: config.blob_matching,
    };
    let sources: Vec<&(dyn CorrespondenceSource + Sync)> = match config.method {
        Method::Sift => vec![&sift],
        Method::Blobs => vec![&blobs],
        Method::Hybrid => vec![&sift, &blobs],
    };
    // `config.validate` checked the pair settings too (under their `pair.` paths).
    Ok(register_framed(a, b, &sources, &config.pair))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testmaps::{bare_room, room, room_with_wall_across};
    use grid_core::DVec2;
    use grid_core::metrics::{displacement_error, rotation_error_deg};

    /// B is `a` turned by 37 degrees and shifted onto a larger canvas; returns B and the truth.
    fn turned(a: &OccupancyGrid) -> (OccupancyGrid, Rigid2) {
        let a_to_b = Rigid2::new(37f64.to_radians(), 60.0, 20.0);
        (a.warp(&a_to_b, 200, 190).unwrap(), a_to_b.inverse())
    }

    fn pair_config(symmetry_probes: bool) -> RegisterConfig {
        RegisterConfig {
            pair: PairConfig {
                symmetry_probes,
                ..PairConfig::default()
            },
            ..RegisterConfig::default()
        }
    }

    #[test]
    fn a_frame_is_the_known_cells_grown_by_the_margin_wherever_they_lie() {
        let a = room();
        let (x0, y0, w, h) = a.known_bounds(0).unwrap();
        let (frame, offset) = framed(&a, 3);
        assert_eq!((frame.width(), frame.height()), (w + 6, h + 6));
        assert_eq!(offset, DVec2::new(x0 as f64 - 3.0, y0 as f64 - 3.0));
        // The same cells, padded unevenly first: the same frame, at the offset moved with them.
        let padded = a.region(-40, -7, a.width() + 50, a.height() + 9).unwrap();
        let (again, moved) = framed(&padded, 3);
        assert_eq!(again.cells(), frame.cells());
        assert_eq!(moved, offset + DVec2::new(40.0, 7.0));
        // A transform between frames, given in the maps' pixels.
        let t = Rigid2::new(0.7, 12.0, -5.0);
        let (oa, ob) = (DVec2::new(3.0, -4.0), DVec2::new(-10.0, 25.0));
        let p = DVec2::new(17.0, 9.0);
        let got = unframed(&t, oa, ob).apply(p);
        assert!((got - (t.apply(p - ob) + oa)).length() < 1e-12, "{got}");
        // A map with no known cell stays as it is.
        let blank = OccupancyGrid::new(10, 8, 0.05, grid_core::Pose2::default()).unwrap();
        assert_eq!(framed(&blank, 3), (blank.clone(), DVec2::ZERO));
        // The configuration's frame: the margin it names, or none.
        let config = PairConfig {
            frame_margin: Some(3),
            ..PairConfig::default()
        };
        assert_eq!(config.frame(&a), Some((frame, offset)));
        let as_given = PairConfig {
            frame_margin: None,
            ..config
        };
        assert_eq!(as_given.frame(&a), None);
    }

    #[test]
    fn turning_about_the_overlap_keeps_the_shared_walls_in_place() {
        // B holds the room's left part, moved right by 50 px; the placement puts it 60 px
        // further right on A, so only some of its walls land on A's known cells.
        let a = room();
        let b = a.warp(&Rigid2::new(0.0, 50.0, 0.0), 120, 100).unwrap();
        let vc = VerifyConfig::default();
        let (pa, pb) = (PreparedMap::new(&a, &vc), PreparedMap::new(&b, &vc));
        let placement = Rigid2::new(0.0, 10.0, 0.0);
        let t = turned_about_overlap(&pa, &pb, &placement, 0.02).unwrap();
        assert!((t.theta - 0.02).abs() < 1e-12);
        // The centre of B's walls that land on A's known cells stays where the placement put
        // it.
        let landed: Vec<DVec2> = pb
            .wall_samples
            .iter()
            .map(|p| placement.apply(*p))
            .filter(|q| {
                let (x, y) = (q.x.round(), q.y.round());
                x >= 0.0
                    && y >= 0.0
                    && x < 120.0
                    && y < 100.0
                    && a.state(x as usize, y as usize) != grid_core::CellState::Unknown
            })
            .collect();
        assert!(!landed.is_empty() && landed.len() < pb.wall_samples.len());
        let centre = landed.iter().copied().sum::<DVec2>() / landed.len() as f64;
        let centre_b = placement.inverse().apply(centre);
        assert!((t.apply(centre_b) - centre).length() < 1e-9);
        // Nothing of B on A: no pivot.
        let away = Rigid2::new(0.0, 500.0, 0.0);
        assert_eq!(turned_about_overlap(&pa, &pb, &away, 0.02), None);
    }

    #[test]
    fn a_room_that_looks_the_same_turned_is_declined_as_ambiguous() {
        let a = bare_room();
        let (b, _) = turned(&a);
        let r = register(&a, &b, &pair_config(true)).unwrap();
        assert!(r.accepted.is_none(), "accepted {:?}", r.accepted);
        let reason = r.reason.unwrap();
        assert!(reason.starts_with("ambiguous"), "{reason}");
        // The rival is a twin that passed on its own.
        assert!(
            r.candidates
                .iter()
                .any(|c| c.accepted && c.origin == Origin::Symmetry),
            "{:?}",
            r.candidates
        );
    }

    #[test]
    fn the_screen_keeps_the_placements_that_fit_once_searched() {
        // B is the room moved by (7, -4) px; the placements are the truth moved 5 px (within
        // the local search's reach), and wrong ones: a half turn, and far shifts.
        let a = room();
        let truth = Rigid2::new(0.0, -7.0, 4.0);
        let b = a.warp(&truth.inverse(), 120, 100).unwrap();
        let vc = VerifyConfig::default();
        let (pa, pb) = (PreparedMap::new(&a, &vc), PreparedMap::new(&b, &vc));
        let near = Rigid2::new(0.0, -2.0, 4.0);
        let wrong = [
            Rigid2::new(std::f64::consts::PI, 120.0, 100.0),
            Rigid2::new(0.0, 40.0, 0.0),
            Rigid2::new(0.0, -7.0, 45.0),
        ];
        let config = PairConfig::default();
        let placements = vec![wrong[0], wrong[1], near, wrong[2]];
        let poses = |kept: &[Placement]| kept.iter().map(|p| p.pose).collect::<Vec<_>>();
        let one = screen(&pa, &pb, placements.clone(), 1, &config);
        assert_eq!(poses(&one), vec![near]);
        // The screen hands over where it searched the placement: what the search gives.
        let searched = local_search(&pa, &pb, &near, &config.search.unwrap());
        let verified = verify(&pa, &pb, &searched, &config.verify);
        assert_eq!(one[0].searched, Some((searched, verified)));
        let two = screen(&pa, &pb, placements.clone(), 2, &config);
        assert_eq!((two.len(), two[0].pose), (2, near));
        // No more placements than kept: all of them, in their order, unscreened.
        let all = screen(&pa, &pb, placements.clone(), 4, &config);
        assert_eq!(poses(&all), placements);
        assert!(all.iter().all(|p| p.searched.is_none()));
    }

    #[test]
    fn the_screen_keeps_passing_placements_first() {
        let config = VerifyConfig::default();
        let scored = |lift: f64, support: usize, overlap: f64| Verification {
            wall_lift: lift,
            wall_support: support,
            acceptance_index: 0.95,
            overlap_fraction: overlap,
            ..Verification::default()
        };
        // A wide wrong placement (score 0.3 * 15000 * 0.95 = 4275), the truth's small overlap
        // (0.75 * 900 * 0.95 = 641), a wrong one that passes all but the overlap, and a
        // second wide one scoring less than the first.
        let wide = scored(0.3, 15_000, 0.9);
        let truth = scored(0.75, 900, 0.29);
        let sliver = scored(0.9, 2_000, 0.05);
        let wide2 = scored(0.25, 14_000, 0.9);
        assert!(wide.score() > truth.score() && !wide.accepted(&config));
        assert!(truth.accepted(&config) && !sliver.accepted(&config));
        assert_eq!(
            screen_order(&[wide2, wide, truth, sliver], &config),
            vec![2, 1, 0, 3]
        );
        // Ties keep the given order.
        assert_eq!(screen_order(&[truth, truth, wide], &config), vec![0, 1, 2]);
    }

    #[test]
    fn a_decline_names_the_bars_missed_and_speckle_where_both_maps_have_it() {
        let v = Verification {
            wall_lift: 0.42,
            wide_wall_lift: 0.63,
            acceptance_index: 0.96,
            overlap_fraction: 0.511,
            ..Verification::default()
        };
        let config = VerifyConfig::default();
        assert_eq!(
            unverified_reason(&v, &config, (0.151, 0.09)),
            "no hypothesis passed verification (best: wall lift 0.42 where 0.65 passes, or 0.63 at 4 px where 0.80 passes; acceptance index 0.96; overlap 51.1% of the smaller map)"
        );
        let speckled = unverified_reason(&v, &config, (0.151, 0.16));
        assert!(
            speckled.ends_with("; both maps' walls are speckle (lone wall cells 15.1 % and 16.0 %), as a range sensor with strong noise leaves them: there a right placement fits about as poorly as a wrong one"),
            "{speckled}"
        );
    }

    #[test]
    fn the_turn_scan_tries_each_step_both_ways_nearest_first() {
        let deg = |v: &[f64]| -> Vec<f64> {
            v.iter()
                .map(|r| (r.to_degrees() * 1e9).round() / 1e9)
                .collect()
        };
        let scan = TurnScan::default();
        assert_eq!(
            deg(&scan.turns()),
            vec![0.25, -0.25, 0.5, -0.5, 0.75, -0.75, 1.0, -1.0]
        );
        // A largest turn between steps stops at the last whole step.
        let scan = TurnScan {
            max_deg: 0.7,
            step_deg: 0.3,
            ..TurnScan::default()
        };
        assert_eq!(deg(&scan.turns()), vec![0.3, -0.3, 0.6, -0.6]);
        // No step, or a largest turn below one step: nothing to try.
        for (max_deg, step_deg) in [(1.0, 0.0), (0.2, 0.25), (1.0, f64::NAN)] {
            let scan = TurnScan {
                max_deg,
                step_deg,
                ..TurnScan::default()
            };
            assert!(scan.turns().is_empty());
        }
    }

    #[test]
    fn a_twin_is_a_rival_only_if_it_fits_about_as_well() {
        // The wide wall lift (walls within 4 px) as the lift: no less, and the same for walls
        // that fit within 2 px.
        let scores = |lift: f64, support: usize, contradiction: f64| Verification {
            wall_lift: lift,
            wide_wall_lift: lift,
            wall_support: support,
            wall_contradiction: contradiction,
            acceptance_index: 0.99,
            ..Verification::default()
        };
        let twin = |verification: Verification| Candidate {
            transform: Rigid2::new(1.6, 40.0, 0.0),
            ransac_inliers: 0,
            ransac_confidence: 0.0,
            verification,
            accepted: true,
            stands_out: false,
            origin: Origin::Symmetry,
            refined: true,
        };
        let config = VerifyConfig::default();
        // The exact copy of a small room (a case proptest found): the best fits every wall,
        // the quarter-turned twin passes but fits 0.90 of a smaller overlap.
        let best = scores(1.0, 622, 0.0);
        assert!(!rivals(&best, &twin(scores(0.90, 292, 0.027)), &config));
        // Scoring 0.6 of the best, or fitting as well, makes it a rival ...
        assert!(rivals(&best, &twin(scores(0.90, 430, 0.015)), &config));
        assert!(rivals(&best, &twin(scores(1.0, 200, 0.0)), &config));
        // ... unless it puts clearly more of its walls into free space: against a best that
        // puts none there, more than 0.02 ...
        assert!(!rivals(&best, &twin(scores(0.90, 430, 0.027)), &config));
        assert!(!rivals(&best, &twin(scores(1.0, 622, 0.06)), &config));
        // ... (the rule before, 0.05 whatever the best, at `clean_contradiction_excess` 0.05)
        let before = VerifyConfig {
            clean_contradiction_excess: 0.05,
            ..VerifyConfig::default()
        };
        assert!(rivals(&best, &twin(scores(0.90, 430, 0.027)), &before));
        // ... and more than the best's own share plus 0.02, up to 0.05: a rival of a best at
        // 0.01 may put up to 0.04 there, of one at 0.04 up to 0.09.
        let at = |c: f64| scores(1.0, 622, c);
        assert!(rivals(&at(0.01), &twin(scores(1.0, 622, 0.039)), &config));
        assert!(!rivals(&at(0.01), &twin(scores(1.0, 622, 0.041)), &config));
        assert!(rivals(&at(0.04), &twin(scores(1.0, 622, 0.089)), &config));
        assert!(!rivals(&at(0.04), &twin(scores(1.0, 622, 0.091)), &config));
        // ... or fails.
        let failed = Candidate {
            accepted: false,
            ..twin(best)
        };
        assert!(!rivals(&best, &failed, &config));
        // A warehouse turned by a quarter (nav2 depot, see
        // `VerifyConfig::trusted_wide_wall_lift`): the best lays twice the walls but fits them
        // imperfectly (wide wall lift 0.86), so a placement near the truth that passes at half
        // its score is a rival; against a best that fits every wall (the exact copy above,
        // wide 1.0) it is not.
        let wide = |lift: f64, support: usize, contradiction: f64, wide: f64| Verification {
            wide_wall_lift: wide,
            ..scores(lift, support, contradiction)
        };
        let near_truth = twin(wide(0.67, 485, 0.025, 0.971));
        assert!(rivals(&wide(0.77, 859, 0.121, 0.855), &near_truth, &config));
        assert!(!rivals(&wide(1.0, 1300, 0.0, 1.0), &near_truth, &config));
    }

    #[test]
    fn a_placement_stands_out_only_if_every_distinct_one_fits_clearly_worse() {
        // Candidates placed `tx` px to the right of the first; `apart` is that distance.
        let at = |tx: f64, wide: f64, acceptance_index: f64| Candidate {
            transform: Rigid2::new(0.0, tx, 0.0),
            ransac_inliers: 0,
            ransac_confidence: 0.0,
            verification: Verification {
                wall_lift: wide - 0.2,
                wide_wall_lift: wide,
                wall_support: 2000,
                acceptance_index,
                overlap_fraction: 0.4,
                wall_density: 0.05,
                ..Verification::default()
            },
            accepted: false,
            stands_out: false,
            origin: Origin::Sweep,
            refined: true,
        };
        let apart = |x: &Rigid2, y: &Rigid2| (x.tx - y.tx).abs();
        let config = VerifyConfig::default();
        let rule = StandOut::default();
        let margin = rule.margin;
        let pick = |cs: &[Candidate]| standing_out(cs, &rule, &config, &apart);
        // Below the rule's wide lift nothing is picked, however clear the margin.
        assert_eq!(pick(&[at(0.0, 0.69, 0.95), at(100.0, 0.2, 0.95)]), None);
        // A placement at 0.75 whose distinct rivals stay `margin` below stands out; a
        // placement within `distance_px` of it is the same answer and is not compared.
        let clear = [
            at(0.0, 0.75, 0.95),
            at(10.0, 0.76, 0.95),
            at(100.0, 0.75 - margin - 0.01, 0.95),
        ];
        // The better scoring of the two near ones (higher lift) is the one picked.
        assert_eq!(pick(&clear), Some(1));
        // A distinct placement within the margin: nothing stands out.
        let close = [at(0.0, 0.75, 0.95), at(100.0, 0.75 - margin + 0.01, 0.95)];
        assert_eq!(pick(&close), None);
        // ... unless that placement fails the acceptance index, and so is no placement at all.
        let failed = [at(0.0, 0.75, 0.95), at(100.0, 0.75, 0.5)];
        assert_eq!(pick(&failed), Some(0));
        // The rule's own acceptance index bar counts, not the main one: a placement between
        // the two is no placement to it, neither the one that stands out nor a rival.
        let between = (config.min_acceptance_index + rule.min_acceptance_index) / 2.0;
        assert!(config.min_acceptance_index < between && between < rule.min_acceptance_index);
        assert_eq!(
            pick(&[at(0.0, 0.75, 0.95), at(100.0, 0.75, between)]),
            Some(0)
        );
        assert_eq!(pick(&[at(0.0, 0.75, between), at(100.0, 0.2, 0.95)]), None);
        // An overlap with too little wall in it (an eroded map's border band) never stands out.
        let mut sparse = at(0.0, 0.9, 0.95);
        sparse.verification.wall_density = rule.min_wall_density * 0.9;
        assert_eq!(pick(&[sparse, at(100.0, 0.2, 0.95)]), None);
    }

    #[test]
    fn a_clean_copy_near_a_quarter_turn_is_polished() {
        // Rigid motion about two centres: `ca` of the source lands on `cb`.
        let about = |deg: f64, ca: DVec2, cb: DVec2| {
            let r = DVec2::from_angle(deg.to_radians());
            let t = cb - r.rotate(ca);
            Rigid2::new(deg.to_radians(), t.x, t.y)
        };
        // A tilted room (its walls are rasterised slopes), and a copy of it turned by 90.8
        // degrees: most of the copy's cells are those of an exact quarter turn.
        let tilt = about(20.0, DVec2::new(60.0, 50.0), DVec2::splat(80.0));
        let a = room().warp(&tilt, 160, 160).unwrap();
        let a_to_b = about(90.8, DVec2::splat(80.0), DVec2::splat(90.0));
        let b = a.warp(&a_to_b, 180, 180).unwrap();
        let truth = a_to_b.inverse();
        let r = register(&a, &b, &RegisterConfig::default()).unwrap();
        let best = r.accepted.expect("accepted");
        assert!(best.verification.wall_lift >= PolishConfig::default().min_wall_lift);
        // Without the polish this copy came out 0.21 degrees off (0.02 with it).
        let err = rotation_error_deg(&best.transform, &truth);
        assert!(err < 0.1, "{err} degrees off");
    }

    #[test]
    fn an_answer_with_much_wall_in_the_other_maps_free_space_is_declined() {
        // B saw an obstacle A's robot saw through: a line of wall cells across A's free space,
        // more than the wide tolerance from A's walls.
        // Both rooms are clean (no lone wall cell), and the obstacle leaves more of B's walls
        // beyond the wide tolerance than the clean-fit bar allows; this test is about the bar
        // on walls in free space, which holds any map, so the clean-fit bar is lifted.
        let a = room();
        let (b, truth) = turned(&room_with_wall_across(22));
        let r = register(&a, &b, &pair_config(true)).unwrap();
        let reason = r.reason.unwrap_or_default();
        assert!(reason.starts_with("misfit: "), "{reason}");
        let config = || {
            let mut config = pair_config(true);
            config.pair.verify.clean_fit = None;
            config
        };
        let with_bar = |bar: f64| {
            let mut config = config();
            config.pair.verify.max_wall_contradiction = bar;
            register(&a, &b, &config).unwrap()
        };
        let r = register(&a, &b, &config()).unwrap();
        let best = r
            .accepted
            .unwrap_or_else(|| panic!("declined: {:?}", r.reason));
        assert!(displacement_error(&b, &best.transform, &truth).unwrap() < 1.0);
        let c = best.verification.wall_contradiction;
        assert!(c > 0.05 && c < 0.21, "contradiction {c}");
        let declined = with_bar(c - 0.01);
        assert!(declined.accepted.is_none());
        let reason = declined.reason.unwrap();
        assert!(reason.starts_with("contradicted: "), "{reason}");
        assert!(with_bar(c + 0.01).accepted.is_some());
    }

    #[test]
    fn the_symmetry_probes_keep_an_asymmetric_room() {
        let a = room();
        let (b, truth) = turned(&a);
        for probes in [false, true] {
            let r = register(&a, &b, &pair_config(probes)).unwrap();
            let best = r
                .accepted
                .unwrap_or_else(|| panic!("declined: {:?}", r.reason));
            let err = displacement_error(&b, &best.transform, &truth).unwrap();
            assert!(err < 1.0, "probes {probes}: {err} px off");
        }
    }

    #[test]
    fn refining_only_the_placements_that_fit_best_keeps_the_answer() {
        // No keypoints: only the whole-map searches (the sweep and the symmetry probes; the
        // global search is off by default) propose placements.
        // Nor a last polish of the best, which would hide which placement was refined.
        let a = room();
        let (b, truth) = turned(&a);
        let register = |refined_placements| {
            let config = PairConfig {
                refined_placements,
                polish: None,
                spectrum_rotation: None,
                ..PairConfig::default()
            };
            register_with(&a, &b, &[], &config).expect("valid settings")
        };
        let all = register(None);
        let one = register(Some(1));
        // Every placement is still a candidate, most of them unrefined.
        let sweep = |r: &Registration| {
            let sweep = r.candidates.iter().filter(|c| c.origin == Origin::Sweep);
            (sweep.clone().count(), sweep.filter(|c| c.refined).count())
        };
        let (proposed, refined) = sweep(&one);
        assert_eq!(sweep(&all), (proposed, proposed));
        assert!(
            proposed > 4 && refined < proposed / 2,
            "{refined} of {proposed} refined"
        );
        // The answer is refined, and the one refining every placement gives.
        let (best, best_of_all) = (one.accepted.unwrap(), all.accepted.unwrap());
        assert!(best.refined);
        assert!(displacement_error(&b, &best.transform, &truth).unwrap() < 0.5);
        let apart = displacement_error(&b, &best.transform, &best_of_all.transform).unwrap();
        assert!(apart < 0.05, "{apart} px from refining all");
    }

    #[test]
    fn the_runner_up_is_the_best_ranked_candidate_clearly_apart_from_the_first() {
        let placed = |tx: f64, lift: f64, accepted: bool| Candidate {
            transform: Rigid2::new(0.0, tx, 0.0),
            ransac_inliers: 0,
            ransac_confidence: 0.0,
            verification: Verification {
                wall_lift: lift,
                wall_support: 400,
                acceptance_index: 0.98,
                ..Verification::default()
            },
            accepted,
            stands_out: false,
            origin: Origin::Sweep,
            refined: true,
        };
        // Best first: the answer, a placement 3 px from it (one answer), then two apart.
        let r = Registration {
            accepted: Some(placed(0.0, 0.9, true)),
            reason: None,
            candidates: vec![
                placed(0.0, 0.9, true),
                placed(3.0, 0.85, true),
                placed(40.0, 0.72, true),
                placed(80.0, 0.3, false),
            ],
            correspondences: KindTotals::default(),
            inliers: KindTotals::default(),
            timings: Timings::default(),
            matches: Vec::new(),
        };
        let b = room();
        // Translations move every wall cell by the same distance: the mean is exact.
        let u = r.runner_up(&b, 10.0).unwrap();
        assert_eq!(u.candidate, r.candidates[2]);
        assert!((u.apart_px - 40.0).abs() < 1e-9, "{}", u.apart_px);
        assert!(
            (u.score_ratio - 0.72 / 0.9).abs() < 1e-12,
            "{}",
            u.score_ratio
        );
        // The first one farther than the bar, whatever comes after.
        let u = r.runner_up(&b, 41.0).unwrap();
        assert_eq!(u.candidate, r.candidates[3]);
        assert!((u.apart_px - 80.0).abs() < 1e-9);
        assert!(r.runner_up(&b, 81.0).is_none());
        // Turned half a turn about the room's centre, B's walls move by twice their distance
        // from it: the mean over the (strided) wall cells.
        let c = DVec2::new(60.0, 60.0);
        let turned = Candidate {
            transform: Rigid2::rotation_about(std::f64::consts::PI, c),
            ..placed(0.0, 0.8, true)
        };
        let r = Registration {
            candidates: vec![placed(0.0, 0.9, true), turned],
            ..r
        };
        let probe = crate::verify::strided(&wall_cells(&b), APART_POINTS);
        let expected =
            probe.iter().map(|p| 2.0 * (*p - c).length()).sum::<f64>() / probe.len() as f64;
        let u = r.runner_up(&b, 10.0).unwrap();
        assert!(
            (u.apart_px - expected).abs() < 1e-9,
            "{} against {expected}",
            u.apart_px
        );
        // No wall cell in B, or no other candidate: no runner-up.
        let cells = vec![0; b.width() * b.height()];
        let blank = OccupancyGrid::from_cells(
            b.width(),
            b.height(),
            0.05,
            grid_core::Pose2::default(),
            cells,
        )
        .unwrap();
        assert!(r.runner_up(&blank, 10.0).is_none());
        let alone = Registration {
            candidates: vec![placed(0.0, 0.9, true)],
            ..r
        };
        assert!(alone.runner_up(&b, 10.0).is_none());
    }
}
