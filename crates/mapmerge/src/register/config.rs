//! The settings of one pair's registration ([`PairConfig`] and the answer's stages) and of
//! [`super::register`] ([`RegisterConfig`]), each with its documented default.

use blob_features::BlobConfig;
use grid_core::{DVec2, OccupancyGrid};
use ransac_rigid::RansacConfig;
use sift_desc::SiftConfig;

use super::framed;
use crate::ascent::AscentConfig;
use crate::global::{GlobalConfig, SweepConfig};
use crate::refine::RefineConfig;
use crate::search::SearchConfig;
use crate::verify::VerifyConfig;

/// Everything that tunes [`register_with`](super::register_with), with documented defaults.
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
    /// ([`Candidate::refined`](super::Candidate::refined) false), and one is refined only if it comes to rank first or
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

/// Settings of [`register`](super::register): the method, each source's settings and the pair settings.
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
