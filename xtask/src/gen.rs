//! `cargo xtask gen`: write simulated cases (robot maps as map_saver PGM + YAML, truth.json,
//! preview.png) for evaluation and for looking at.

use std::fs;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::ValueEnum;
use grid_core::{CellState, DVec2, GridGeometry, Pose2};
use image::{Rgb, RgbImage};
use indicatif::{ProgressBar, ProgressStyle};
use mapsim::{
    Case, CaseConfig, HitRatioModel, InverseSensorModel, MapperModel, WorldKind, generate_case,
};
use serde_json::json;

/// Base settings a case starts from before the individual flags apply.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Preset {
    /// 150 x 150 disaster area, 2 robots, 16-beam infrared rings, noise 10 % / 15 %.
    Paper,
    /// 400 x 400 disaster area, 2 lidar robots.
    Disaster,
    /// 400 x 400 indoor floor, 2 lidar robots.
    Indoor,
}

/// The robots' mapper: how beams are folded into each grid (`mapsim::MapperModel`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum Mapper {
    /// mapsim's default: a pass adds log-odds -1.4, a hit 2.2. Clears hard: under strong range
    /// noise, obstacles that beams read past fade from the map.
    #[default]
    Default,
    /// Hector mapping's defaults: a pass adds log-odds -0.41 (probability 0.4), a hit 2.2
    /// (0.9). Clears gently: under strong noise a wall stays as a band of speckle, and a cell
    /// needs several passes to read free.
    Hector,
    /// OctoMap's defaults: a pass adds log-odds -0.41 (probability 0.4), a hit 0.85 (0.7),
    /// clamped at 3.5. A hit outweighs two passes, but a cell hit once and passed once reads
    /// unknown: under strong noise walls fade about as with the default.
    Octomap,
    /// GMapping's (`occ_thresh` 0.25): hit and pass counts per cell, occupied when more than a
    /// quarter of the beams that reached a cell ended in it. Of a noisy wall's band the last
    /// few cells stay, behind the wall's face as with the default.
    Gmapping,
    /// Karto's, the mapper of ROS 2's slam_toolbox (`occupancy_threshold` 0.1,
    /// `min_pass_through` 2): occupied when more than a tenth of the beams that reached a cell
    /// ended in it, known once three beams reached it. A noisy wall stays as a wide band over
    /// its face.
    SlamToolbox,
}

impl Mapper {
    /// The model this mapper folds beams with.
    pub fn model(self) -> MapperModel {
        match self {
            Mapper::Default => InverseSensorModel::default().into(),
            Mapper::Hector => InverseSensorModel::hector().into(),
            Mapper::Octomap => InverseSensorModel::octomap().into(),
            Mapper::Gmapping => HitRatioModel::gmapping().into(),
            Mapper::SlamToolbox => HitRatioModel::slam_toolbox().into(),
        }
    }

    /// The mapper's name on the command line.
    pub fn name(self) -> String {
        self.to_possible_value()
            .expect("no variant is skipped")
            .get_name()
            .to_owned()
    }
}

/// Flags of `cargo xtask gen`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Base settings.
    #[arg(long, value_enum, default_value = "paper")]
    preset: Preset,
    /// Seed of the first case; case k uses seed + k.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output directory (created); case k goes to OUT/case_<k>/.
    #[arg(long, default_value = "target/sim")]
    out: PathBuf,
    /// Number of cases.
    #[arg(long, default_value_t = 1)]
    count: usize,
    /// World side in cells (square world).
    #[arg(long)]
    size: Option<usize>,
    /// Number of robots (extra robots copy the last robot's sensor).
    #[arg(long)]
    robots: Option<usize>,
    /// Beams per robot.
    #[arg(long)]
    beams: Option<usize>,
    /// Maximum range in cells.
    #[arg(long)]
    range: Option<f64>,
    /// Range noise bounds, one per robot (the last one repeats), e.g. 0.1,0.15.
    #[arg(long, value_delimiter = ',')]
    noise: Option<Vec<f64>>,
    /// Requested overlap fraction of the explored areas (0 = disjoint).
    #[arg(long)]
    overlap: Option<f64>,
    /// Probability that a beam returns nothing, one per robot (the last one repeats).
    #[arg(long, value_delimiter = ',')]
    dropout: Option<Vec<f64>>,
    /// Indices of failed beams (never return a reading) of the LAST robot, e.g. 0,1,2,3: the
    /// paper's "failed sensor" robot.
    #[arg(long, value_delimiter = ',')]
    failed_beams: Option<Vec<usize>>,
    /// A real map (map_server YAML, or a PGM/PNG image) to explore instead of a generated
    /// world: its free cells are free space, everything else is obstacle. Overrides --size.
    #[arg(long, value_name = "MAP")]
    world: Option<PathBuf>,
    /// How each robot folds its beams into its map.
    #[arg(long, value_enum, default_value = "default")]
    mapper: Mapper,
}

/// The case config the flags describe.
fn config(args: &Args) -> Result<CaseConfig> {
    let mut c = match args.preset {
        Preset::Paper => CaseConfig::paper(),
        Preset::Disaster => CaseConfig::default(),
        Preset::Indoor => CaseConfig::indoor(400),
    };
    if let Some(s) = args.size {
        c.world.width = s;
        c.world.height = s;
    }
    if let Some(n) = args.robots {
        if n < 2 {
            bail!("--robots {n}: need at least 2");
        }
        let last = c.robots.last().cloned().unwrap_or_default();
        c.robots.resize(n, last);
    }
    for r in &mut c.robots {
        if let Some(b) = args.beams {
            r.beams = b;
        }
        if let Some(m) = args.range {
            r.max_range = m;
        }
    }
    if let Some(noise) = &args.noise {
        if noise.is_empty() {
            bail!("--noise needs at least one value");
        }
        for (i, r) in c.robots.iter_mut().enumerate() {
            r.noise_bound = noise[i.min(noise.len() - 1)];
        }
    }
    if let Some(dropout) = &args.dropout {
        if dropout.is_empty() {
            bail!("--dropout needs at least one value");
        }
        for (i, r) in c.robots.iter_mut().enumerate() {
            r.dropout = dropout[i.min(dropout.len() - 1)];
        }
    }
    if let Some(failed) = &args.failed_beams
        && let Some(last) = c.robots.last_mut()
    {
        last.failed_beams = failed.clone();
    }
    if let Some(o) = args.overlap {
        c.overlap = o;
    }
    c.mapper = args.mapper.model();
    if let Some(path) = &args.world {
        let grid = grid_core::io::load_map(path, &grid_core::io::LoadOptions::default())
            .with_context(|| format!("--world {}", path.display()))?;
        c.world.resolution = grid.resolution();
        c.world.kind = WorldKind::Grid(grid);
    }
    c.validate()?;
    Ok(c)
}

/// Run the command.
pub fn run(args: Args) -> Result<()> {
    let config = config(&args)?;
    fs::create_dir_all(&args.out).with_context(|| format!("{}", args.out.display()))?;
    let bar = (args.count > 1).then(|| {
        let b = ProgressBar::new(args.count as u64);
        b.set_style(
            ProgressStyle::with_template(
                "{bar:40} {pos}/{len} cases, {elapsed} elapsed, eta {eta}",
            )
            .expect("static template"),
        );
        b
    });
    for k in 0..args.count {
        let seed = args.seed + k as u64;
        let case =
            generate_case(&config, seed).with_context(|| format!("case {k} (seed {seed})"))?;
        let dir = args.out.join(format!("case_{k}"));
        write_case(&case, &format!("{:?}", args.preset).to_lowercase(), &dir)?;
        match &bar {
            Some(b) => b.inc(1),
            None => eprintln!(
                "{}: {} robots, overlap {:.3} (requested {})",
                dir.display(),
                case.robots.len(),
                case.achieved_overlap,
                config.overlap
            ),
        }
    }
    if let Some(b) = bar {
        b.finish();
    }
    Ok(())
}

/// Write `case` into `dir` (created): each robot's map as map_saver writes it
/// (`robot_K.yaml` and `.pgm`), `truth.json` (every pair's transform, the configuration;
/// `preset` names where it came from) and `preview.png`.
pub(crate) fn write_case(case: &Case, preset: &str, dir: &Path) -> Result<()> {
    fs::create_dir_all(dir).with_context(|| format!("{}", dir.display()))?;
    let world_geo = GridGeometry {
        width: case.world.width(),
        height: case.world.height(),
        resolution: case.world.resolution(),
        origin: Pose2::default(),
    };
    let mut robots = Vec::new();
    for (i, r) in case.robots.iter().enumerate() {
        // map_saver's trinary PGM (0 occupied, 254 free, 205 unknown) and its YAML.
        let image = format!("robot_{i}.pgm");
        grid_core::io::save_map(&r.map, &dir.join(format!("robot_{i}.yaml")))?;
        let pose = r.map_to_world.to_world(&world_geo, &r.map.geometry());
        robots.push(json!({
            "image": image,
            "width": r.map.width(),
            "height": r.map.height(),
            "map_to_world": r.map_to_world,
            "world_pose": {"x": pose.tx, "y": pose.ty, "yaw": pose.theta},
            "path_poses": r.path.len(),
        }));
    }
    let mut pairs = Vec::new();
    for i in 0..case.robots.len() {
        for j in 0..case.robots.len() {
            if i != j {
                pairs.push(json!({"a": i, "b": j, "transform": case.truth(i, j)}));
            }
        }
    }
    let c = &case.config;
    let kind = match c.world.kind {
        WorldKind::Disaster => "disaster",
        WorldKind::Indoor => "indoor",
        WorldKind::Grid(_) => "grid",
    };
    let truth = json!({
        "seed": case.seed,
        "preset": preset,
        "convention": "transform maps a pixel of map b onto map a (x column, y row from top); \
                       map_to_world maps a map pixel to a world-raster pixel; world_pose is the \
                       map frame in the world frame (metres, yaw ccw, world origin 0)",
        "requested_overlap": c.overlap,
        "achieved_overlap": case.achieved_overlap,
        "overlaps": case.overlaps,
        "world": {"kind": kind, "width": case.world.width(), "height": case.world.height(),
                  "resolution": case.world.resolution(), "clutter": c.world.clutter},
        "config": {
            "robots": c.robots,
            "overlap_tolerance": c.overlap_tolerance,
            "max_rotation": c.max_rotation,
            "margin": c.margin,
            "extra_margin": c.extra_margin,
            "pose_step": c.pose_step,
            "clearance": c.clearance,
            "waypoint_spacing": c.waypoint_spacing,
            "mapper": mapper_json(&c.mapper),
        },
        "robots": robots,
        "pairs": pairs,
    });
    let mut text = serde_json::to_string_pretty(&truth)?;
    text.push('\n');
    grid_core::io::write_atomic(&dir.join("truth.json"), text.as_bytes())?;
    let mut png = Vec::new();
    preview(case)
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .context("encoding preview.png")?;
    grid_core::io::write_atomic(&dir.join("preview.png"), &png)?;
    Ok(())
}

/// The mapper of a case as truth.json records it, its numbers as written in the source (an
/// `f32` widened to `f64` would print as 0.10000000149011612).
fn mapper_json(mapper: &MapperModel) -> serde_json::Value {
    let number = |v: f32| v.to_string().parse::<f64>().unwrap_or(f64::from(v));
    match mapper {
        MapperModel::LogOdds(m) => json!({"log_odds": {
            "free": number(m.free),
            "occupied": number(m.occupied),
            "clamp": number(m.clamp),
        }}),
        MapperModel::HitRatio(m) => json!({"hit_ratio": {
            "occupied_above": number(m.occupied_above),
            "min_passes": m.min_passes,
        }}),
    }
}

const COLOURS: [[u8; 3]; 6] = [
    [220, 40, 40],
    [40, 90, 230],
    [30, 160, 60],
    [230, 140, 20],
    [160, 50, 190],
    [20, 170, 180],
];

/// The world with the robots' paths, then every robot's map with its path, side by side.
fn preview(case: &Case) -> RgbImage {
    let side = case.world.width().max(case.world.height());
    // Integer scaling keeps single-cell walls crisp: up for small worlds, down for huge ones.
    let (up, down) = if side < 300 {
        (300_usize.div_ceil(side), 1)
    } else {
        (1, side.div_ceil(1200))
    };
    let scale = |v: usize| v * up / down;
    let gap = 8;
    let mut panels: Vec<RgbImage> = Vec::new();
    let world = &case.world;
    let mut wimg = RgbImage::from_fn(
        scale(world.width()) as u32,
        scale(world.height()) as u32,
        |x, y| {
            let (wx, wy) = (x as usize * down / up, y as usize * down / up);
            if world.is_occupied(wx as i64, wy as i64) {
                Rgb([0, 0, 0])
            } else {
                Rgb([255, 255, 255])
            }
        },
    );
    for (i, r) in case.robots.iter().enumerate() {
        draw_path(&mut wimg, &r.path, COLOURS[i % COLOURS.len()], up, down);
    }
    panels.push(wimg);
    for (i, r) in case.robots.iter().enumerate() {
        let m = &r.map;
        let mut img =
            RgbImage::from_fn(scale(m.width()) as u32, scale(m.height()) as u32, |x, y| {
                let (mx, my) = (x as usize * down / up, y as usize * down / up);
                let v = match m.state(mx, my) {
                    CellState::Occupied => 0,
                    CellState::Free => 254,
                    CellState::Unknown => 205,
                };
                Rgb([v, v, v])
            });
        draw_path(
            &mut img,
            &r.path_in_map(),
            COLOURS[i % COLOURS.len()],
            up,
            down,
        );
        panels.push(img);
    }
    let w: u32 = panels.iter().map(|p| p.width()).sum::<u32>() + gap * (panels.len() as u32 + 1);
    let h = panels.iter().map(|p| p.height()).max().unwrap_or(1) + 2 * gap;
    let mut out = RgbImage::from_pixel(w, h, Rgb([60, 60, 60]));
    let mut x0 = gap;
    for p in &panels {
        image::imageops::replace(&mut out, p, x0 as i64, gap as i64);
        x0 += p.width() + gap;
    }
    out
}

fn draw_path(img: &mut RgbImage, path: &[DVec2], colour: [u8; 3], up: usize, down: usize) {
    let f = up as f64 / down as f64;
    for p in path {
        let q = (*p + DVec2::splat(0.5)) * f;
        let (x, y) = (q.x as i64, q.y as i64);
        if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
            img.put_pixel(x as u32, y as u32, Rgb(colour));
        }
    }
}
