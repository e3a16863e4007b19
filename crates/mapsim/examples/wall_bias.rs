//! How far the walls of simulated maps sit from the true obstacle faces, by distance to the
//! robot's path: the range bias that `mapmerge::refine::RefineConfig::range_bias` models.
//!
//! `cargo run --release -p mapsim --example wall_bias -- [NOISE] [OVERLAP] [CASES] [MAPPER]`
//! (defaults 0.1, 0.3, 4, default) generates disaster-area cases like the `overlap` suite of
//! `cargo xtask eval` at seed 7 and prints, per 10-cell band of distance from the nearest pose
//! of the path, the mean signed offset of the maps' occupied cells from the nearest face of the
//! world (positive: inside the obstacle, away from the robot) and the share farther than 3
//! cells. MAPPER is one of `cargo xtask eval --mapper`'s: default, hector, gmapping,
//! slam-toolbox (OctoMap's is `cargo xtask`'s alone).

use grid_core::{CellState, DVec2};
use mapsim::{
    CaseConfig, HitRatioModel, InverseSensorModel, MapperModel, RobotConfig, WorldConfig,
    generate_case,
};

/// Faces farther than this from a wall cell are not looked for.
const REACH: i64 = 15;

fn main() {
    let arg = |i: usize, default: f64| {
        std::env::args()
            .nth(i)
            .map(|s| s.parse().expect("a number"))
            .unwrap_or(default)
    };
    let (noise, overlap, cases) = (arg(1, 0.1), arg(2, 0.3), arg(3, 4.0) as u64);
    let name = std::env::args().nth(4).unwrap_or_else(|| "default".into());
    let mapper: MapperModel = match name.as_str() {
        "default" => InverseSensorModel::default().into(),
        "hector" => InverseSensorModel::hector().into(),
        "gmapping" => HitRatioModel::gmapping().into(),
        "slam-toolbox" => HitRatioModel::slam_toolbox().into(),
        other => panic!("unknown mapper {other}: default, hector, gmapping or slam-toolbox"),
    };
    let lidar = RobotConfig {
        noise_bound: noise,
        ..RobotConfig::default()
    };
    let config = CaseConfig {
        world: WorldConfig::default(),
        robots: vec![lidar.clone(), lidar],
        overlap,
        overlap_tolerance: f64::INFINITY,
        mapper,
        ..CaseConfig::default()
    };
    // Per band: sum of offsets, cells, cells off by more than 3.
    let mut bands = vec![(0.0f64, 0usize, 0usize); 12];
    for k in 0..cases {
        let case = generate_case(&config, 7_000_000 + k).expect("case generates");
        let world = &case.world;
        for robot in &case.robots {
            let map = &robot.map;
            for y in 0..map.height() {
                for x in 0..map.width() {
                    if map.state(x, y) != CellState::Occupied {
                        continue;
                    }
                    let q = robot.map_to_world.apply(DVec2::new(x as f64, y as f64));
                    let (qx, qy) = (q.x.round() as i64, q.y.round() as i64);
                    let inside = world.is_occupied(qx, qy);
                    // Distance to the nearest cell on the other side of a face.
                    let mut nearest = f64::INFINITY;
                    for dy in -REACH..=REACH {
                        for dx in -REACH..=REACH {
                            if world.is_occupied(qx + dx, qy + dy) != inside {
                                nearest = nearest.min(((dx * dx + dy * dy) as f64).sqrt());
                            }
                        }
                    }
                    if !nearest.is_finite() {
                        continue;
                    }
                    // The face lies half a cell before the first cell across it.
                    let offset = if inside { nearest - 0.5 } else { 0.5 - nearest };
                    let to_path = robot
                        .path
                        .iter()
                        .map(|&p| (p - q).length())
                        .fold(f64::INFINITY, f64::min);
                    let band = &mut bands[((to_path / 10.0) as usize).min(11)];
                    band.0 += offset;
                    band.1 += 1;
                    band.2 += usize::from(offset.abs() > 3.0);
                }
            }
        }
    }
    println!(
        "noise {noise}, overlap {overlap}, {cases} cases (seed 7 of the overlap suite), {name} mapper"
    );
    for (i, &(sum, n, far)) in bands.iter().enumerate() {
        if n > 0 {
            println!(
                "path distance {:3}-{:3}: {n:6} wall cells, mean offset {:+.2} px, {:.0} % off by more than 3 px",
                i * 10,
                i * 10 + 10,
                sum / n as f64,
                100.0 * far as f64 / n as f64
            );
        }
    }
}
