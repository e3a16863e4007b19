//! Test and measurement helpers: a minimal map_server PGM reader, rotated/shifted copies with
//! known truth, and a deterministic "noisy sensor" degradation.
#![allow(dead_code)]

use grid_core::{OccupancyGrid, Pose2, Rigid2, UNKNOWN};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Read a P5 PGM with map_server trinary semantics (`p = (255 - v) / 255`, occupied above
/// 0.65, free below 0.196, unknown otherwise).
pub fn read_pgm(path: &std::path::Path) -> OccupancyGrid {
    read_pgm_with(path, 0.65, 0.196)
}

/// [`read_pgm`] with the YAML's `occupied_thresh` and `free_thresh`.
pub fn read_pgm_with(path: &std::path::Path, occupied: f64, free: f64) -> OccupancyGrid {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut pos = 0;
    let mut token = || {
        loop {
            while bytes[pos].is_ascii_whitespace() {
                pos += 1;
            }
            if bytes[pos] == b'#' {
                while bytes[pos] != b'\n' {
                    pos += 1;
                }
            } else {
                break;
            }
        }
        let start = pos;
        while !bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        String::from_utf8_lossy(&bytes[start..pos]).to_string()
    };
    assert_eq!(token(), "P5", "{}: only binary PGM", path.display());
    let w: usize = token().parse().unwrap();
    let h: usize = token().parse().unwrap();
    let maxval: usize = token().parse().unwrap();
    assert!(maxval < 256);
    let data = &bytes[pos + 1..pos + 1 + w * h];
    let cells = data
        .iter()
        .map(|&v| {
            let p = (255.0 - v as f64) / 255.0;
            if p > occupied {
                100
            } else if p < free {
                0
            } else {
                UNKNOWN
            }
        })
        .collect();
    OccupancyGrid::from_cells(w, h, 0.05, Pose2::default(), cells).unwrap()
}

/// The wpi_ilab fixture shipped with the tests.
pub fn fixture() -> OccupancyGrid {
    read_pgm(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/wpi_ilab.pgm"))
}

/// A copy of `a` turned by `theta` about its centre and moved by `shift`, on a canvas large
/// enough to hold it; returns the copy and the truth `T` mapping a pixel of the copy (B) to A.
pub fn turned_copy(a: &OccupancyGrid, theta: f64, shift: (f64, f64)) -> (OccupancyGrid, Rigid2) {
    let (w, h) = (a.width() as f64, a.height() as f64);
    let side = (w * w + h * h).sqrt().ceil() as usize + 8;
    let c = side as f64 / 2.0;
    // a_to_b: rotate about A's centre, then put that centre at the canvas centre + shift.
    let rot = Rigid2::new(theta, 0.0, 0.0);
    let centre = rot.apply(grid_core::DVec2::new((w - 1.0) / 2.0, (h - 1.0) / 2.0));
    let a_to_b = Rigid2::new(theta, c + shift.0 - centre.x, c + shift.1 - centre.y);
    let b = a.warp(&a_to_b, side, side).unwrap();
    (b, a_to_b.inverse())
}

/// Degrade a map like a noisy range sensor would: every wall cell is moved by up to `jitter`
/// cells in x and y, a fraction `delete` of wall cells is dropped (becomes free), and a
/// fraction `speckle` of free cells becomes occupied. Deterministic for a seed.
pub fn degrade(
    g: &OccupancyGrid,
    jitter: i64,
    delete: f64,
    speckle: f64,
    seed: u64,
) -> OccupancyGrid {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (w, h) = (g.width() as i64, g.height() as i64);
    let src = g.cells();
    let mut cells: Vec<u8> = src
        .iter()
        .map(|&c| if (65..=100).contains(&c) { 0 } else { c })
        .collect();
    for y in 0..h {
        for x in 0..w {
            let c = src[(y * w + x) as usize];
            if !(65..=100).contains(&c) {
                continue;
            }
            if rng.random_bool(delete) {
                continue;
            }
            let (dx, dy) = if jitter > 0 {
                (
                    rng.random_range(-jitter..=jitter),
                    rng.random_range(-jitter..=jitter),
                )
            } else {
                (0, 0)
            };
            let (nx, ny) = (x + dx, y + dy);
            if nx >= 0 && ny >= 0 && nx < w && ny < h {
                cells[(ny * w + nx) as usize] = 100;
            }
        }
    }
    if speckle > 0.0 {
        for c in cells.iter_mut() {
            if *c == 0 && rng.random_bool(speckle) {
                *c = 100;
            }
        }
    }
    OccupancyGrid::from_cells(g.width(), g.height(), g.resolution(), g.origin(), cells).unwrap()
}

/// Fraction of correspondences whose A point lies within `tol` pixels of `truth(b)`.
pub fn inlier_fraction(
    c: &[grid_core::Correspondence],
    truth: &Rigid2,
    tol: f64,
) -> (usize, usize) {
    let good = c
        .iter()
        .filter(|c| (truth.apply(c.b) - c.a).length() <= tol)
        .count();
    (good, c.len())
}

/// A `side x side` "building" made of mirrored tiles of `g` (so walls continue across tile
/// borders), for speed measurements on large maps.
pub fn tiled(g: &OccupancyGrid, side: usize) -> OccupancyGrid {
    let (w, h) = (g.width(), g.height());
    let mut cells = vec![UNKNOWN; side * side];
    for y in 0..side {
        let (ty, ry) = (y / h, y % h);
        let sy = if ty % 2 == 0 { ry } else { h - 1 - ry };
        for x in 0..side {
            let (tx, rx) = (x / w, x % w);
            let sx = if tx % 2 == 0 { rx } else { w - 1 - rx };
            cells[y * side + x] = g.cells()[sy * w + sx];
        }
    }
    OccupancyGrid::from_cells(side, side, g.resolution(), g.origin(), cells).unwrap()
}
