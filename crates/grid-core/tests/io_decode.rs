//! Decoding: every image kind and mode, each pixel's expected cell worked out by hand from
//! map_server's rule `p = (255 - v) / 255`, occupied if `p > occ`, free if `p < free`.

use std::path::{Path, PathBuf};

use grid_core::io::{BareImageDefaults, LoadOptions, MapMode, load_map, load_map_with_metadata};
use grid_core::{OccupancyGrid, Pose2, UNKNOWN};
use image::ImageEncoder;
use image::codecs::png::PngEncoder;
use tempfile::TempDir;

const U: u8 = UNKNOWN;

fn write(dir: &TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

fn png(width: u32, height: u32, colour: image::ExtendedColorType, pixels: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    PngEncoder::new(&mut out)
        .write_image(pixels, width, height, colour)
        .unwrap();
    out
}

fn yaml_for(dir: &TempDir, image: &str, extra: &str) -> PathBuf {
    write(
        dir,
        "map.yaml",
        format!(
            "image: {image}\nresolution: 0.1\norigin: [1.5, -2.0, 0.25]\n{extra}\n\
             occupied_thresh: 0.65\nfree_thresh: 0.196\n"
        )
        .as_bytes(),
    )
}

fn load(path: &Path) -> OccupancyGrid {
    load_map(path, &LoadOptions::default()).unwrap()
}

/// Grey values and their cells with thresholds 0.65 / 0.196, no negation:
/// 0 → p=1 occupied; 254 → p=0.0039 free; 205 → p=0.19608 (not < 0.196) unknown;
/// 255 → p=0 free; 89 → p=166/255=0.651 occupied; 90 → p=0.647 unknown;
/// 206 → p=49/255=0.192 free; 128 → p=0.498 unknown.
const GREY: [u8; 8] = [0, 254, 205, 255, 89, 90, 206, 128];
const GREY_TRINARY: [u8; 8] = [100, 0, U, 0, 100, U, 0, U];

#[test]
fn p5_trinary_with_yaml_geometry() {
    let dir = TempDir::new().unwrap();
    let mut pgm = b"P5\n# a comment\n4 2\n255\n".to_vec();
    pgm.extend_from_slice(&GREY);
    write(&dir, "map.pgm", &pgm);
    let m = load_map_with_metadata(
        yaml_for(&dir, "map.pgm", "negate: 0"),
        &LoadOptions::default(),
    )
    .unwrap();
    assert_eq!(m.grid.cells(), &GREY_TRINARY);
    assert_eq!((m.grid.width(), m.grid.height()), (4, 2));
    assert_eq!(m.grid.resolution(), 0.1);
    assert_eq!(m.grid.origin(), Pose2::new(1.5, -2.0, 0.25));
    assert_eq!(m.metadata.mode, MapMode::Trinary);
    assert_eq!(m.image_path, dir.path().join("map.pgm"));
}

#[test]
fn p2_ascii_with_comments_and_ragged_whitespace() {
    let dir = TempDir::new().unwrap();
    let text = "P2 4\n# width above, height next\n2 255\n0 254   205\n255\t89 # comment in raster\n90 206\n128\n";
    let path = write(&dir, "map.pgm", text.as_bytes());
    assert_eq!(load(&path).cells(), &GREY_TRINARY);
}

#[test]
fn bare_pgm_uses_the_documented_defaults() {
    let dir = TempDir::new().unwrap();
    let mut pgm = b"P5 4 2 255\n".to_vec();
    pgm.extend_from_slice(&GREY);
    let path = write(&dir, "bare.pgm", &pgm);
    let m = load_map_with_metadata(&path, &LoadOptions::default()).unwrap();
    assert_eq!(m.grid.cells(), &GREY_TRINARY);
    assert_eq!(m.grid.resolution(), 0.05);
    assert_eq!(m.grid.origin(), Pose2::new(0.0, 0.0, 0.0));
    assert_eq!(m.yaml_path, None);
    assert_eq!(m.metadata.occupied_thresh, 0.65);
    assert_eq!(m.metadata.free_thresh, 0.196);
}

#[test]
fn bare_image_defaults_can_be_overridden() {
    let dir = TempDir::new().unwrap();
    let mut pgm = b"P5 4 2 255\n".to_vec();
    pgm.extend_from_slice(&GREY);
    let path = write(&dir, "bare.pnm", &pgm);
    let options = LoadOptions {
        bare_image: BareImageDefaults {
            resolution: 0.25,
            origin: Pose2::new(-3.0, 4.0, 0.5),
            // occ 0.4: 128 (p=0.498) becomes occupied; free 0.25: 205 (p=0.196) becomes free.
            occupied_thresh: 0.4,
            free_thresh: 0.25,
            ..BareImageDefaults::default()
        },
        ..LoadOptions::default()
    };
    let g = load_map(&path, &options).unwrap();
    assert_eq!(g.cells(), &[100, 0, 0, 0, 100, 100, 0, 100]);
    assert_eq!(g.resolution(), 0.25);
    assert_eq!(g.origin(), Pose2::new(-3.0, 4.0, 0.5));
}

#[test]
fn negate_reads_dark_as_free() {
    // negate: p = v / 255. 0 → free; 254 → p=0.996 occupied; 205 → 0.804 occupied;
    // 255 → occupied; 89 → 0.349 unknown; 90 → 0.353 unknown; 206 → 0.808 occupied;
    // 128 → 0.502 unknown; 50 → 0.19608 unknown; 49 → 0.192 free.
    let dir = TempDir::new().unwrap();
    let mut pgm = b"P5 5 2 255\n".to_vec();
    pgm.extend_from_slice(&GREY);
    pgm.extend_from_slice(&[50, 49]);
    write(&dir, "map.pgm", &pgm);
    let g = load(&yaml_for(&dir, "map.pgm", "negate: 1"));
    assert_eq!(g.cells(), &[0, 100, 100, 100, U, U, 100, U, U, 0]);
}

#[test]
fn scale_mode_keeps_the_probability_between_thresholds() {
    // 128 → p=0.498 → 50 %; 205 → p=0.19608 → 20 %; 90 → p=0.647 → 65 %.
    let dir = TempDir::new().unwrap();
    let mut pgm = b"P5 4 2 255\n".to_vec();
    pgm.extend_from_slice(&GREY);
    write(&dir, "map.pgm", &pgm);
    let g = load(&yaml_for(&dir, "map.pgm", "negate: 0\nmode: scale"));
    assert_eq!(g.cells(), &[100, 0, 20, 0, 100, 65, 0, 50]);
}

#[test]
fn raw_mode_takes_values_as_percent_and_ignores_negate() {
    let dir = TempDir::new().unwrap();
    let mut pgm = b"P5 6 1 255\n".to_vec();
    pgm.extend_from_slice(&[0, 1, 50, 100, 101, 255]);
    write(&dir, "map.pgm", &pgm);
    let want = [0, 1, 50, 100, U, U];
    assert_eq!(
        load(&yaml_for(&dir, "map.pgm", "negate: 0\nmode: raw")).cells(),
        &want
    );
    assert_eq!(
        load(&yaml_for(&dir, "map.pgm", "negate: 1\nmode: raw")).cells(),
        &want
    );
}

#[test]
fn sixteen_bit_and_small_maxval_are_scaled_to_8_bits() {
    let dir = TempDir::new().unwrap();
    // maxval 65535: 0 → 0 occupied; 65535 → 255 free; 205 * 257 → 205 unknown; 89 * 257 → 89.
    let mut pgm = b"P5 4 1 65535\n".to_vec();
    for v in [0u16, 65535, 205 * 257, 89 * 257] {
        pgm.extend_from_slice(&v.to_be_bytes());
    }
    let path = write(&dir, "deep.pgm", &pgm);
    assert_eq!(load(&path).cells(), &[100, 0, U, 100]);
    // maxval 15: 15 → 255 free; 12 → 204 → p=0.2 unknown; 13 → 221 → p=0.133 free; 0 occupied.
    let path = write(&dir, "small.pgm", b"P2 4 1 15 15 12 13 0\n");
    assert_eq!(load(&path).cells(), &[0, U, 0, 100]);
}

#[test]
fn ppm_colour_is_averaged() {
    // (255, 0, 0): v=85, p=0.667 occupied; (255, 255, 200): v=236.7, p=0.072 free;
    // (100, 200, 255): v=185, p=0.275 unknown.
    let dir = TempDir::new().unwrap();
    let mut ppm = b"P6 3 1 255\n".to_vec();
    ppm.extend_from_slice(&[255, 0, 0, 255, 255, 200, 100, 200, 255]);
    let p6 = write(&dir, "c.ppm", &ppm);
    let p3 = write(
        &dir,
        "c3.pnm",
        b"P3 3 1 255\n255 0 0  255 255 200  100 200 255\n",
    );
    assert_eq!(load(&p6).cells(), &[100, 0, U]);
    assert_eq!(load(&p3).cells(), &[100, 0, U]);
}

#[test]
fn png_grey_matches_pgm() {
    let dir = TempDir::new().unwrap();
    let path = write(
        &dir,
        "g.png",
        &png(4, 2, image::ExtendedColorType::L8, &GREY),
    );
    assert_eq!(load(&path).cells(), &GREY_TRINARY);
}

#[test]
fn png_grey_16_bit() {
    let dir = TempDir::new().unwrap();
    let mut px = Vec::new();
    for v in [0u16, 65535, 205 * 257, 89 * 257] {
        // The encoder takes 16-bit samples in native byte order.
        px.extend_from_slice(&v.to_ne_bytes());
    }
    let path = write(
        &dir,
        "g16.png",
        &png(4, 1, image::ExtendedColorType::L16, &px),
    );
    assert_eq!(load(&path).cells(), &[100, 0, U, 100]);
}

#[test]
fn png_rgb_averages_the_channels() {
    // (0,0,0) occupied; (254,254,254) free; (255,0,0) v=85 occupied; (205,205,205) unknown;
    // (100,200,255) v=185 unknown; (255,255,200) v=236.7 free.
    let dir = TempDir::new().unwrap();
    let px = [
        0, 0, 0, 254, 254, 254, 255, 0, 0, 205, 205, 205, 100, 200, 255, 255, 255, 200,
    ];
    let path = write(
        &dir,
        "c.png",
        &png(3, 2, image::ExtendedColorType::Rgb8, &px),
    );
    assert_eq!(load(&path).cells(), &[100, 0, 100, U, U, 0]);
}

#[test]
fn png_rgba_alpha_is_ignored_in_trinary_and_means_unknown_in_scale() {
    let dir = TempDir::new().unwrap();
    let px = [
        0, 0, 0, 255, // opaque black
        0, 0, 0, 128, // half-transparent black
        128, 128, 128, 255, // opaque mid grey: p=0.498
        254, 254, 254, 0, // fully transparent white
        205, 205, 205, 255, // opaque map_saver unknown
        255, 255, 255, 254, // nearly opaque white
    ];
    write(
        &dir,
        "c.png",
        &png(3, 2, image::ExtendedColorType::Rgba8, &px),
    );
    let trinary = load(&yaml_for(&dir, "c.png", "negate: 0"));
    assert_eq!(trinary.cells(), &[100, 100, U, 0, U, 0]);
    let scale = load(&yaml_for(&dir, "c.png", "negate: 0\nmode: scale"));
    assert_eq!(scale.cells(), &[100, U, 50, U, 20, U]);
}

#[test]
fn png_grey_alpha() {
    let dir = TempDir::new().unwrap();
    let px = [0, 255, 0, 100, 254, 255, 128, 255];
    write(
        &dir,
        "ga.png",
        &png(4, 1, image::ExtendedColorType::La8, &px),
    );
    assert_eq!(
        load(&yaml_for(&dir, "ga.png", "negate: 0")).cells(),
        &[100, 100, 0, U]
    );
    assert_eq!(
        load(&yaml_for(&dir, "ga.png", "negate: 0\nmode: scale")).cells(),
        &[100, U, 0, 50]
    );
}

#[test]
fn image_format_follows_content_not_name() {
    // map_server decodes by content: a PNG named .pgm still loads.
    let dir = TempDir::new().unwrap();
    let path = write(
        &dir,
        "really_png.pgm",
        &png(4, 2, image::ExtendedColorType::L8, &GREY),
    );
    assert_eq!(load(&path).cells(), &GREY_TRINARY);
}

#[test]
fn absolute_image_path_in_yaml() {
    let dir = TempDir::new().unwrap();
    let img_dir = TempDir::new().unwrap();
    let mut pgm = b"P5 4 2 255\n".to_vec();
    pgm.extend_from_slice(&GREY);
    let img = write(&img_dir, "elsewhere.pgm", &pgm);
    let g = load(&yaml_for(&dir, img.to_str().unwrap(), "negate: 0"));
    assert_eq!(g.cells(), &GREY_TRINARY);
}

#[test]
fn all_unknown_map_loads_and_require_known_cells_refuses_it() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "u.pgm", b"P5 2 2 255\n\xcd\xcd\xcd\xcd");
    let g = load(&path);
    assert_eq!(g.cells(), &[U; 4]);
    let err = grid_core::io::require_known_cells(&g, &path).unwrap_err();
    assert_eq!(
        err.to_string(),
        format!(
            "{}: the map has no free or occupied cell (every cell is unknown)",
            path.display()
        )
    );
    let known = write(&dir, "k.pgm", b"P5 2 2 255\n\xcd\xcd\xcd\x00");
    assert!(grid_core::io::require_known_cells(&load(&known), &known).is_ok());
}
