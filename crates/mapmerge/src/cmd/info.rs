//! `mapmerge info MAP [--json]`: what a map holds.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::Args;
use serde::Serialize;

use super::{BareImageArgs, load};

const JSON_KEYS: &str = "\
With --json, prints one JSON object with the keys:
  path             the MAP argument
  image            the image file read
  mode             trinary, scale or raw
  width, height    size in cells
  resolution       metres per cell
  origin           [x, y, yaw]: metres and radians (counter-clockwise), the pose of the
                   lower-left corner of the lower-left cell (ROS convention)
  negate           true if dark pixels are free
  occupied_thresh, free_thresh   the thresholds the image was read with
  free, occupied, unknown        cell counts (cells between the thresholds are unknown)
  wall_thickness   occupied cells per side an occupied cell shares with a free one
                   (4-neighbours): about 1 for walls one cell thick seen from one side,
                   2 for walls two cells thick; `estimate` climbs its answer's score
                   when both maps reach 1.1 (see mapmerge::ascent)
  frontier_ratio   free cells beside unknown (or the map's edge) per free cell beside a
                   wall: high where a short-range sensor's beams ended in open space (the
                   smaller of the pair's two in mapsim's cases: 0.94-3.58 for its 16-beam
                   infrared ring, mostly over 1.2, and 0.65-1.19 for its lidar at 10 %
                   noise); `estimate` also climbs thinner walls when both maps reach 1.2
                   and the answer fits loosely (see mapmerge::ascent::ShortRange)
  lone_wall_share  share of occupied cells with no occupied cell among their eight
                   neighbours: speckle, which grows with a range sensor's noise (mapsim's
                   default mapper: 0.03-0.08 at 10 % noise, 0.09-0.21 at 20 %); at 0.1 or
                   more in both maps `estimate` says a decline may be the noise's doing,
                   at 0.02 or less in both it holds an answer to the clean-fit bar
                   (mapmerge::verify::CleanFit)";

/// Arguments of `mapmerge info`.
#[derive(Debug, Clone, Args)]
#[command(after_help = JSON_KEYS)]
pub struct InfoArgs {
    /// The map: a map_server YAML or a bare .pgm/.png image
    #[arg(value_name = "MAP")]
    pub map: PathBuf,
    /// Print one JSON object instead of text
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Serialize)]
struct Info {
    path: String,
    image: String,
    mode: &'static str,
    width: usize,
    height: usize,
    resolution: f64,
    origin: [f64; 3],
    negate: bool,
    occupied_thresh: f64,
    free_thresh: f64,
    free: usize,
    occupied: usize,
    unknown: usize,
    wall_thickness: f64,
    frontier_ratio: f64,
    lone_wall_share: f64,
}

/// Run `mapmerge info`.
pub fn run(args: &InfoArgs, bare: &BareImageArgs) -> anyhow::Result<ExitCode> {
    let map = load(&args.map, bare)?;
    let g = &map.grid;
    let counts = g.counts();
    let o = g.origin();
    let info = Info {
        path: args.map.display().to_string(),
        image: map.image_path.display().to_string(),
        mode: map.metadata.mode.as_str(),
        width: g.width(),
        height: g.height(),
        resolution: g.resolution(),
        origin: [o.x, o.y, o.yaw],
        negate: map.metadata.negate,
        occupied_thresh: map.metadata.occupied_thresh,
        free_thresh: map.metadata.free_thresh,
        free: counts.free,
        occupied: counts.occupied,
        unknown: counts.unknown,
        wall_thickness: mapmerge::ascent::wall_thickness(g),
        frontier_ratio: mapmerge::ascent::frontier_ratio(g),
        lone_wall_share: mapmerge::ascent::lone_wall_share(g),
    };
    let text = if args.json {
        serde_json::to_string(&info).context("cannot encode the JSON output")? + "\n"
    } else {
        human(&info)
    };
    std::io::stdout()
        .lock()
        .write_all(text.as_bytes())
        .context("cannot write to standard output")?;
    Ok(ExitCode::SUCCESS)
}

fn human(i: &Info) -> String {
    let total = (i.width * i.height) as f64;
    let pct = |n: usize| 100.0 * n as f64 / total;
    let known = i.free + i.occupied;
    let min_cells = mapmerge::verify::VerifyConfig::default().min_overlap_cells;
    let note = if known < min_cells {
        format!(
            "note:       only {known} known cells, fewer than the {min_cells} a registered pair must share (estimate|merge --min-overlap-cells): with the default settings no pair with this map is accepted\n"
        )
    } else if i.occupied == 0 {
        "note:       no occupied cell: walls are what a placement is judged by, so no pair with this map is accepted\n".to_string()
    } else {
        String::new()
    };
    let text = format!(
        "map:        {path}\n\
         image:      {image} (mode {mode}, negate {negate}, occupied_thresh {occ}, free_thresh {free_t})\n\
         size:       {w} x {h} cells ({wm:.2} x {hm:.2} m)\n\
         resolution: {r} m/cell\n\
         origin:     x {ox} m, y {oy} m, yaw {oyaw} rad\n\
         free:       {free} ({free_p:.1}%)\n\
         occupied:   {occupied} ({occ_p:.1}%)\n\
         unknown:    {unknown} ({unk_p:.1}%)\n\
         walls:      {thick:.2} cells thick (occupied cells per side facing free space)\n\
         frontier:   {frontier:.2} free cells beside unknown per free cell beside a wall (high for a short-range sensor)\n\
         speckle:    {lone:.1}% of occupied cells lone (no occupied neighbour; grows with range noise)\n",
        path = i.path,
        image = i.image,
        mode = i.mode,
        negate = u8::from(i.negate),
        occ = i.occupied_thresh,
        free_t = i.free_thresh,
        w = i.width,
        h = i.height,
        wm = i.width as f64 * i.resolution,
        hm = i.height as f64 * i.resolution,
        r = i.resolution,
        ox = i.origin[0],
        oy = i.origin[1],
        oyaw = i.origin[2],
        free = i.free,
        free_p = pct(i.free),
        occupied = i.occupied,
        occ_p = pct(i.occupied),
        unknown = i.unknown,
        unk_p = pct(i.unknown),
        thick = i.wall_thickness,
        frontier = i.frontier_ratio,
        lone = 100.0 * i.lone_wall_share,
    );
    text + &note
}
