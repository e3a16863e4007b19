//! End-to-end registration of a 2048 x 2048 real-building pair, and each stage on its own.
//!
//! A = the Osnabrueck CIC floor (fixtures/maps/uos_cic, 980 x 1477) on a 2048 x 2048 canvas,
//! B = the same floor turned by 30 degrees and shifted, on another 2048 x 2048 canvas: a pair
//! whose keypoints agree, registered by RANSAC alone.
//!
//! `end_to_end_partial_maps`: two simulated robots' partial maps of the same floor (10 % and
//! 20 % range noise, half of each map shared: case 7_014_000 of `cargo xtask eval --suites
//! overlap,zero,paper,real,noise --seed 7`), each on a 2048 x 2048 canvas. Few keypoints agree
//! there, so the rotation sweep and the symmetry probes run: the hard case.
//!
//! `end_to_end_partial_maps_declined`: the same robots' partial maps of that floor sharing
//! nothing (case 7_014_000 of the same floor with overlap 0), which must be declined: every
//! stage runs, the sweep both ways round (`SweepConfig::reverse`), and nothing passes.
//!
//! `end_to_end_overlapping_crops`: two crops of the same floor, the western three quarters
//! and the eastern three quarters (half of the floor's width shared), the second turned by 30
//! degrees, each on a 2048 x 2048 canvas: a real-building pair that overlaps only in part but
//! whose keypoints agree, so RANSAC answers.
//!
//! `end_to_end_warehouse`: the nav2 warehouse (fixtures/maps/nav2_warehouse, 1006 x 1674, 1.45
//! million known cells, 2.6 times the CIC floor's) on a 2048 x 2048 canvas and the same map
//! turned by 30 degrees on another, which it nearly fills: the most known cells a 2048 x 2048
//! pair of real-building maps here has, answered by RANSAC like `end_to_end`.
//!
//! `partial_maps/*`: the stages that dominate that hard pair, each on its own, on the same
//! pair framed (`PairConfig::frame`) and prepared once: the rotation sweep
//! (`sweep_placements`), the symmetry probes' correlations of one placement (`twins`), one
//! correlative local search over +-2 degrees (the turn search each whole-map placement gets),
//! one refinement and scoring of a placement (`refine_and_score`: ICP with the range-bias
//! offsets, then verification), one verification alone, the score ascent of an answer
//! (`mapmerge::ascent`, which the hard pair's thin walls do not take) and its gate, the
//! thickness of both maps' walls, and both maps' shares of lone wall cells (the clean-walls
//! bar's and the turn scan's measure). The end-to-end time is about one sweep and the probes'
//! correlations plus a few dozen placements each searched, refined and scored (see
//! `timings_ms` of `mapmerge estimate --json`). A pair where nothing passes pays for a second
//! sweep, the other way round (`SweepConfig::reverse`): the declined pair.
//!
//! Run: `cargo bench -p mapmerge --bench register`. The pairs are built in `pairs/mod.rs`;
//! `cargo run --release -p mapmerge --example bench_pair -- NAME` registers one of them in a
//! process of its own, for a profiler (callgrind's instruction counts do not depend on how
//! busy the machine is, unlike these times).

use criterion::{Criterion, criterion_group, criterion_main};
use grid_core::{CorrespondenceSource, OccupancyGrid};
use mapmerge::ascent::{ascend, frontier_ratio, lone_wall_share, wall_thickness};
use mapmerge::global::{sweep_placements, twins};
use mapmerge::search::local_search;
use mapmerge::verify::{PreparedMap, VerifyConfig, verify};
use mapmerge::{RegisterConfig, refine_and_score, register};

mod pairs;
use pairs::{overlapping_crops, pair, partial_pair, warehouse_pair};

fn bench(c: &mut Criterion) {
    let (a, b) = pair();
    let config = RegisterConfig::default();
    let mut g = c.benchmark_group("register_2048");
    g.sample_size(10);
    g.bench_function("end_to_end", |bn| {
        bn.iter(|| register(&a, &b, &config).expect("valid config"))
    });
    let (wa, wb) = warehouse_pair();
    // The bench times the answered path: check once that it is answered.
    let answer = register(&wa, &wb, &config).expect("valid config");
    assert!(answer.accepted.is_some(), "{:?}", answer.reason);
    g.bench_function("end_to_end_warehouse", |bn| {
        bn.iter(|| register(&wa, &wb, &config).expect("valid config"))
    });
    let (ca, cb) = overlapping_crops();
    // The bench times the answered path: check once that it is answered.
    let answer = register(&ca, &cb, &config).expect("valid config");
    assert!(answer.accepted.is_some(), "{:?}", answer.reason);
    g.bench_function("end_to_end_overlapping_crops", |bn| {
        bn.iter(|| register(&ca, &cb, &config).expect("valid config"))
    });
    let (pa, pb) = partial_pair(0.5);
    g.bench_function("end_to_end_partial_maps", |bn| {
        bn.iter(|| register(&pa, &pb, &config).expect("valid config"))
    });
    let (za, zb) = partial_pair(0.0);
    // The bench times the declined path: check once that it is declined.
    let answer = register(&za, &zb, &config).expect("valid config");
    assert!(answer.accepted.is_none(), "accepted {:?}", answer.accepted);
    g.bench_function("end_to_end_partial_maps_declined", |bn| {
        bn.iter(|| register(&za, &zb, &config).expect("valid config"))
    });
    // The same pair with the deep screen on (`mapmerge --deep-screen`): what a declined pair
    // pays for it, since only pairs where nothing passed run it.
    let mut deep = config.clone();
    if let Some(sweep) = deep.pair.sweep.as_mut() {
        sweep.deep_screened = 1000;
    }
    let answer = register(&za, &zb, &deep).expect("valid config");
    assert!(answer.accepted.is_none(), "accepted {:?}", answer.accepted);
    g.bench_function("end_to_end_partial_maps_declined_deep_screen", |bn| {
        bn.iter(|| register(&za, &zb, &deep).expect("valid config"))
    });
    let sift = sift_desc::SiftCorrespondences::new(config.sift.clone()).expect("valid config");
    g.bench_function("sift_correspondences", |bn| {
        bn.iter(|| {
            let mut out = Vec::new();
            sift.correspondences(&a, &b, &mut out);
            out
        })
    });
    let blobs = blob_features::BlobCorrespondences {
        blobs: blob_features::Blobs::new(config.blobs),
        matching: config.blob_matching,
    };
    g.bench_function("blob_correspondences", |bn| {
        bn.iter(|| {
            let mut out = Vec::new();
            blobs.correspondences(&a, &b, &mut out);
            out
        })
    });
    g.bench_function("prepare_both_maps", |bn| {
        bn.iter(|| {
            (
                PreparedMap::new(&a, &VerifyConfig::default()).known_cells,
                PreparedMap::new(&b, &VerifyConfig::default()).known_cells,
            )
        })
    });
    g.finish();

    // The hard pair's stages, on the maps framed and prepared as `register` frames and
    // prepares them.
    let pair_config = &config.pair;
    let frame = |m: &OccupancyGrid| pair_config.frame(m).map_or_else(|| m.clone(), |(f, _)| f);
    let (fa, fb) = (frame(&pa), frame(&pb));
    let (ppa, ppb) = (
        PreparedMap::new(&fa, &pair_config.verify),
        PreparedMap::new(&fb, &pair_config.verify),
    );
    let sweep = pair_config.sweep.expect("the default runs the sweep");
    // The symmetry probes take the global search's settings, or their defaults when it is off
    // (the default).
    let global = pair_config.global.unwrap_or_default();
    let turn = pair_config
        .turn_search
        .expect("the default searches whole-map placements over rotation");
    // As many of the normalised ranking's placements as `register_with` asks for (to screen,
    // and deeper down when nothing passed).
    let normalized = sweep
        .screened
        .max(sweep.keep_normalized)
        .max(sweep.deep_screened);
    // A placement as the sweep proposes it: where the local search, ICP and verification
    // start for every whole-map candidate.
    let start = sweep_placements(&ppa, &ppb, &sweep, normalized).plain[0];
    let mut g = c.benchmark_group("partial_maps");
    g.sample_size(10);
    g.bench_function("rotation_sweep", |bn| {
        bn.iter(|| sweep_placements(&ppa, &ppb, &sweep, normalized))
    });
    g.bench_function("symmetry_twins", |bn| {
        bn.iter(|| {
            let mut out = Vec::new();
            twins(&ppa, &ppb, &start, &global, &mut out);
            out
        })
    });
    g.bench_function("turn_search_one_placement", |bn| {
        bn.iter(|| local_search(&ppa, &ppb, &start, &turn))
    });
    g.bench_function("refine_and_score_one_placement", |bn| {
        bn.iter(|| refine_and_score(&ppa, &ppb, &start, &pair_config.global_refine, pair_config))
    });
    g.bench_function("verify_one_placement", |bn| {
        bn.iter(|| verify(&ppa, &ppb, &start, &pair_config.verify))
    });
    // The score ascent and its gates. The hard pair's walls are thin (0.87 and 0.57, below
    // `AscentConfig::min_wall_thickness`) and its maps are a lidar's, so `register` does not
    // climb its answer; here the ascent runs from the sweep's first placement refined, as it
    // would on thicker walls.
    let ascent = pair_config.ascent.expect("the default climbs the answer");
    let refined = refine_and_score(&ppa, &ppb, &start, &pair_config.global_refine, pair_config).0;
    g.bench_function("score_ascent_one_answer", |bn| {
        bn.iter(|| ascend(&ppa, &ppb, &refined, &ascent, &pair_config.verify))
    });
    g.bench_function("wall_thickness_both_maps", |bn| {
        bn.iter(|| (wall_thickness(&fa), wall_thickness(&fb)))
    });
    // The frontier ratios of the short-range rule (`ascent::ShortRange`), which `register`
    // reads when an answer fits loosely on thin walls, as the hard pair's does.
    g.bench_function("frontier_ratio_both_maps", |bn| {
        bn.iter(|| rayon::join(|| frontier_ratio(&fa), || frontier_ratio(&fb)))
    });
    // The shares of lone wall cells that the clean-walls bar and the turn scan's gate read,
    // side by side as `register` scans them.
    g.bench_function("lone_wall_share_both_maps", |bn| {
        bn.iter(|| rayon::join(|| lone_wall_share(&fa), || lone_wall_share(&fb)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
