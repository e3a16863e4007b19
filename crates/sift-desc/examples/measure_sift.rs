//! Measure how SIFT parameters affect correspondence quality on real maps with known truth.
//!
//! For every map (PGM + YAML directory, default: the shared development maps) and every
//! scenario, map B is a turned and shifted copy of A (optionally degraded like a noisy sensor,
//! optionally overlapping A only in part); each configuration's correspondences are scored by
//! how many agree with the true transform within 2 px.
//!
//! Run: `cargo run --release -p sift-desc --example measure_sift -- [MAP_DIR...]`

#[path = "../tests/common/mod.rs"]
mod common;

use std::path::{Path, PathBuf};
use std::time::Instant;

use grid_core::{CorrespondenceSource, OccupancyGrid, UNKNOWN};
use sift_desc::{IntensityMapping, SiftConfig, SiftCorrespondences};

/// A map_server directory: `<dir>/<name>.yaml` beside `<name>.pgm` (thresholds from the YAML).
fn load(dir: &Path) -> Option<OccupancyGrid> {
    let name = dir.file_name()?.to_str()?;
    let pgm = dir.join(format!("{name}.pgm"));
    if !pgm.exists() {
        return None;
    }
    let yaml = std::fs::read_to_string(dir.join(format!("{name}.yaml"))).ok()?;
    let field = |key: &str, default: f64| {
        yaml.lines()
            .find_map(|l| {
                l.trim()
                    .strip_prefix(key)?
                    .trim()
                    .strip_prefix(':')?
                    .trim()
                    .parse()
                    .ok()
            })
            .unwrap_or(default)
    };
    Some(common::read_pgm_with(
        &pgm,
        field("occupied_thresh", 0.65),
        field("free_thresh", 0.196),
    ))
}

/// Keep only the columns `lo..hi` (fractions of the width) known; the rest becomes unknown.
fn keep_columns(g: &OccupancyGrid, lo: f64, hi: f64) -> OccupancyGrid {
    let mut out = g.clone();
    let w = g.width();
    let (x0, x1) = ((lo * w as f64) as usize, (hi * w as f64) as usize);
    for row in out.cells_mut().chunks_exact_mut(w) {
        for (x, c) in row.iter_mut().enumerate() {
            if x < x0 || x >= x1 {
                *c = UNKNOWN;
            }
        }
    }
    out
}

struct Pair {
    label: String,
    a: OccupancyGrid,
    b: OccupancyGrid,
    truth: grid_core::Rigid2,
}

fn pairs(maps: &[(String, OccupancyGrid)]) -> Vec<Pair> {
    let mut out = Vec::new();
    for (name, g) in maps {
        // One angle by default keeps a full run at a few minutes; ANGLES=2 adds a second one.
        let angles: &[f64] = if std::env::var("ANGLES").as_deref() == Ok("2") {
            &[27.0, -136.0]
        } else {
            &[27.0]
        };
        for (k, &theta_deg) in angles.iter().enumerate() {
            let theta = theta_deg.to_radians();
            let shift = (5.5 - 3.0 * k as f64, -7.0 + 4.0 * k as f64);
            // Clean: exact copy, only resampled.
            let (b, truth) = common::turned_copy(g, theta, shift);
            out.push(Pair {
                label: format!("{name} clean {theta_deg}"),
                a: g.clone(),
                b,
                truth,
            });
            // Noisy: both maps degraded independently (wall jitter 1 px, 30 % of wall cells
            // missing, 0.5 % speckle in free space).
            let seed = k as u64 * 1000;
            let a = common::degrade(g, 1, 0.3, 0.005, seed + 1);
            let (b, truth) =
                common::turned_copy(&common::degrade(g, 1, 0.3, 0.005, seed + 2), theta, shift);
            out.push(Pair {
                label: format!("{name} noisy {theta_deg}"),
                a,
                b,
                truth,
            });
            // Partial: noisy, and A knows only the left 65 %, B only the right 65 % of the map.
            let a = keep_columns(&common::degrade(g, 1, 0.3, 0.005, seed + 3), 0.0, 0.65);
            let b_src = keep_columns(&common::degrade(g, 1, 0.3, 0.005, seed + 4), 0.35, 1.0);
            let (b, truth) = common::turned_copy(&b_src, theta, shift);
            out.push(Pair {
                label: format!("{name} partial {theta_deg}"),
                a,
                b,
                truth,
            });
        }
    }
    out
}

fn variants() -> Vec<(&'static str, SiftConfig)> {
    let base = SiftConfig::default();
    let with = |f: &dyn Fn(&mut SiftConfig)| {
        let mut c = base.clone();
        f(&mut c);
        c
    };
    let all = std::env::var("VARIANTS").as_deref() != Ok("short");
    let mut v = vec![("default", base.clone())];
    if all {
        v.extend([
            (
                "unknown=free",
                with(&|c| c.mapping = IntensityMapping::UNKNOWN_AS_FREE),
            ),
            (
                "unknown=0.5",
                with(&|c| c.mapping = IntensityMapping::UNKNOWN_GREY),
            ),
            (
                "free=1 occ=0.5 unk=0",
                with(&|c| {
                    c.mapping = IntensityMapping {
                        free: 1.0,
                        occupied: 0.5,
                        unknown: 0.0,
                    }
                }),
            ),
            ("delta_min=0.5", with(&|c| c.scale_space.delta_min = 0.5)),
            ("sigma_min=1.6", with(&|c| c.scale_space.sigma_min = 1.6)),
            ("c_dog=0.02", with(&|c| c.scale_space.c_dog = 0.02)),
            ("c_dog=0.0067", with(&|c| c.scale_space.c_dog = 0.04 / 6.0)),
            ("no crop", with(&|c| c.scale_space.crop_margin = None)),
            ("max_keypoints=4000", with(&|c| c.max_keypoints = 4000)),
            ("max_keypoints=1000", with(&|c| c.max_keypoints = 1000)),
            ("ratio=0.8", with(&|c| c.ratio = 0.8)),
        ]);
    }
    v.extend([
        ("no cross_check", with(&|c| c.cross_check = false)),
        ("sigma_min=1.2", with(&|c| c.scale_space.sigma_min = 1.2)),
        (
            "crop_margin=4",
            with(&|c| c.scale_space.crop_margin = Some(4)),
        ),
        (
            "crop_margin=16",
            with(&|c| c.scale_space.crop_margin = Some(16)),
        ),
    ]);
    v
}

fn main() {
    let args: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    let dirs = if args.is_empty() {
        let mut d: Vec<PathBuf> = std::fs::read_dir("/work/shared/maps")
            .map(|r| r.filter_map(|e| e.ok().map(|e| e.path())).collect())
            .unwrap_or_default();
        d.sort();
        d
    } else {
        args
    };
    let maps: Vec<(String, OccupancyGrid)> = dirs
        .iter()
        .filter_map(|d| Some((d.file_name()?.to_str()?.to_string(), load(d)?)))
        .collect();
    eprintln!(
        "maps: {}",
        maps.iter()
            .map(|m| m.0.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let pairs = pairs(&maps);
    println!(
        "| config | scenario | pairs | corr. | inliers | pooled inlier % | mean inlier % | pairs with >= 8 inliers and >= 25 % | ms/pair |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for (name, config) in variants() {
        let source = SiftCorrespondences::new(config).unwrap();
        for scenario in ["clean", "noisy", "partial"] {
            let (mut n, mut corr, mut inl, mut frac_sum, mut usable) = (0, 0, 0, 0.0, 0);
            let start = Instant::now();
            for p in pairs.iter().filter(|p| p.label.contains(scenario)) {
                let mut out = Vec::new();
                source.correspondences(&p.a, &p.b, &mut out);
                let (good, total) = common::inlier_fraction(&out, &p.truth, 2.0);
                if std::env::var_os("VERBOSE").is_some() {
                    eprintln!("{name:>20} {:<32} {good:>5} / {total:>5}", p.label);
                }
                n += 1;
                corr += total;
                inl += good;
                let f = if total > 0 {
                    good as f64 / total as f64
                } else {
                    0.0
                };
                frac_sum += f;
                if good >= 8 && f >= 0.25 {
                    usable += 1;
                }
            }
            let ms = start.elapsed().as_secs_f64() * 1e3 / n.max(1) as f64;
            println!(
                "| {name} | {scenario} | {n} | {corr} | {inl} | {:.1} | {:.1} | {usable} | {ms:.0} |",
                100.0 * inl as f64 / corr.max(1) as f64,
                100.0 * frac_sum / n.max(1) as f64
            );
        }
    }
}
