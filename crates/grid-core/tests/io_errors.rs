//! Bad input: every case is refused with a message that names the file and says what is wrong.

use std::path::{Path, PathBuf};

use grid_core::Error;
use grid_core::io::{LoadOptions, load_map};
use image::ImageEncoder;
use image::codecs::png::PngEncoder;
use tempfile::TempDir;

fn write(dir: &TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// The error's message for loading `path` with default options.
fn err(path: &Path) -> String {
    load_map(path, &LoadOptions::default())
        .unwrap_err()
        .to_string()
}

/// Assert that loading `path` fails with exactly `"{path}: {reason}"`.
fn assert_fails(path: &Path, reason: &str) {
    assert_eq!(err(path), format!("{}: {reason}", path.display()));
}

const GOOD_KEYS: &str = "image: map.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";

/// A folder with a valid 2 x 1 image `map.pgm` and `map.yaml` holding `yaml`.
fn yaml_case(yaml: &str) -> (TempDir, PathBuf) {
    let dir = TempDir::new().unwrap();
    write(&dir, "map.pgm", b"P5 2 1 255\n\x00\xfe");
    let path = write(&dir, "map.yaml", yaml.as_bytes());
    (dir, path)
}

fn replace_key(key: &str, line: &str) -> String {
    GOOD_KEYS
        .lines()
        .map(|l| {
            if l.starts_with(&format!("{key}:")) {
                line
            } else {
                l
            }
        })
        .filter(|l| !l.is_empty())
        .map(|l| format!("{l}\n"))
        .collect()
}

#[test]
fn the_good_yaml_loads() {
    let (_dir, path) = yaml_case(GOOD_KEYS);
    assert_eq!(
        load_map(&path, &LoadOptions::default()).unwrap().cells(),
        &[100, 0]
    );
}

#[test]
fn missing_file() {
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("nope.yaml");
    let e = load_map(&path, &LoadOptions::default()).unwrap_err();
    assert!(
        matches!(&e, Error::Io { path: p, source } if p == &path && source.kind() == std::io::ErrorKind::NotFound)
    );
    assert!(e.to_string().starts_with(&format!("{}: ", path.display())));
}

/// The error of a YAML in `dir` whose image line names `image`: it starts with the image's
/// path and ends with what the OS said, then the YAML that named it.
fn assert_names_both_files(dir: &TempDir, image: &str, os_says: &str) {
    let yaml = write(
        dir,
        "map.yaml",
        replace_key("image", &format!("image: {image}")).as_bytes(),
    );
    let msg = err(&yaml);
    let image = dir.path().join(image);
    assert!(msg.starts_with(&format!("{}: ", image.display())), "{msg}");
    assert!(
        msg.ends_with(&format!("{os_says} (image named in {})", yaml.display())),
        "{msg}"
    );
}

#[test]
fn missing_image_named_in_yaml_names_both_files() {
    let dir = TempDir::new().unwrap();
    assert_names_both_files(&dir, "gone.pgm", "No such file or directory (os error 2)");
}

/// A directory opens on Unix and fails on the first read (EISDIR, 21 on Linux and macOS).
#[cfg(unix)]
#[test]
fn an_image_name_that_is_a_directory_names_both_files() {
    let dir = TempDir::new().unwrap();
    std::fs::create_dir(dir.path().join("maps")).unwrap();
    assert_names_both_files(&dir, "maps", "Is a directory (os error 21)");
}

#[test]
fn unknown_extension() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "map.bmp", b"BM");
    assert_fails(
        &path,
        "unknown file extension `.bmp`: expected a map_server .yaml/.yml file or a .pgm/.png image",
    );
    let path = write(&dir, "map", b"P5");
    assert_fails(
        &path,
        "no file extension: expected a map_server .yaml/.yml file or a .pgm/.png image",
    );
}

#[test]
fn empty_and_unrecognised_images() {
    let dir = TempDir::new().unwrap();
    assert_fails(&write(&dir, "e.pgm", b""), "empty file (0 bytes)");
    assert_fails(
        &write(&dir, "x.png", b"GIF89a...."),
        "not a PGM/PNM or PNG image (unrecognised file signature)",
    );
    assert_fails(
        &write(&dir, "b.pgm", b"P4 8 1\n\xff"),
        "unsupported PNM type P4: expected a greymap (P2/P5) or pixmap (P3/P6)",
    );
}

#[test]
fn truncated_p5() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "t.pgm", b"P5\n3 2\n255\n\x00\x00\x00\x00");
    assert_fails(&path, "truncated: expected 6 bytes of pixel data, found 4");
    // 16-bit samples take two bytes each.
    let path = write(&dir, "t16.pgm", b"P5\n3 2\n65535\n\x00\x00\x00");
    assert_fails(&path, "truncated: expected 12 bytes of pixel data, found 3");
}

/// A damaged image named by a YAML: the error names the image, what is wrong with it, and the
/// YAML the user typed, as a missing image's does.
#[test]
fn a_damaged_image_named_in_yaml_names_both_files() {
    let (dir, yaml) = yaml_case(GOOD_KEYS);
    let image = write(&dir, "map.pgm", b"P5\n3 2\n255\n\x00\x00\x00\x00");
    assert_eq!(
        err(&yaml),
        format!(
            "{}: truncated: expected 6 bytes of pixel data, found 4 (image named in {})",
            image.display(),
            yaml.display()
        )
    );
    let image = write(&dir, "map.pgm", b"");
    assert_eq!(
        err(&yaml),
        format!(
            "{}: empty file (0 bytes) (image named in {})",
            image.display(),
            yaml.display()
        )
    );
}

#[test]
fn truncated_header() {
    let dir = TempDir::new().unwrap();
    assert_fails(
        &write(&dir, "h.pgm", b"P5\n3 "),
        "truncated: the file ends before the height in the PNM header",
    );
    assert_fails(
        &write(&dir, "h2.pgm", b"P5\n3 2\n255"),
        "truncated: the file ends right after the PNM header, before the pixel data",
    );
    assert_fails(
        &write(&dir, "h3.pgm", b"P5\n3 x\n255\n"),
        "bad PNM header: expected the height as a number, found 'x'",
    );
    assert_fails(
        &write(&dir, "h4.pgm", b"P5\n3 2\n0\n\x00"),
        "bad PNM header: maxval 0 is outside 1..=65535",
    );
}

#[test]
fn truncated_p2() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "t.pgm", b"P2\n3 2\n255\n0 0 0\n254 254\n");
    assert_fails(&path, "truncated: expected 6 pixel values, found 5");
    let path = write(&dir, "bad.pgm", b"P2\n3 2\n255\n0 0 zero\n");
    assert_fails(&path, "pixel value 3 is not a number (found 'z')");
}

#[test]
fn header_claiming_a_huge_image_is_refused_before_allocating() {
    let dir = TempDir::new().unwrap();
    // Were the buffer allocated first, 10^10 bytes would abort the test process.
    let path = write(&dir, "huge.pgm", b"P5\n100000 100000\n255\n\x00\x00");
    assert_fails(
        &path,
        "image is 100000 x 100000 pixels (10000000000 cells), more than the limit of 100000000 cells",
    );
    // Few cells but one very long side: refused too (the pipeline indexes rows and columns
    // with 20 bits).
    let path = write(&dir, "long.pgm", b"P5\n2000000 1\n255\n\x00");
    assert_fails(
        &path,
        "image is 2000000 x 1 pixels, a side longer than the limit of 1048576 pixels",
    );
    let path = write(&dir, "digits.pgm", b"P5\n99999999999999999999 1\n255\n");
    assert_fails(&path, "bad PNM header: width is too large");
    // The limit is an option.
    let small = LoadOptions {
        max_cells: 5,
        ..LoadOptions::default()
    };
    let path = write(&dir, "six.pgm", b"P5 3 2 255\n\x00\x00\x00\x00\x00\x00");
    assert_eq!(
        load_map(&path, &small).unwrap_err().to_string(),
        format!(
            "{}: image is 3 x 2 pixels (6 cells), more than the limit of 5 cells",
            path.display()
        )
    );
}

#[test]
fn zero_size_image() {
    let dir = TempDir::new().unwrap();
    assert_fails(
        &write(&dir, "z.pgm", b"P5\n0 5\n255\n"),
        "image is empty (0 x 5 pixels)",
    );
    assert_fails(
        &write(&dir, "z2.pgm", b"P2\n7 0\n255\n"),
        "image is empty (7 x 0 pixels)",
    );
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xffff_ffffu32;
    for &b in bytes {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xedb8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

fn tiny_png() -> Vec<u8> {
    let mut out = Vec::new();
    PngEncoder::new(&mut out)
        .write_image(&[0, 254, 205, 255], 2, 2, image::ExtendedColorType::L8)
        .unwrap();
    out
}

#[test]
fn png_header_claiming_a_huge_image() {
    // Rewrite IHDR's width and height (bytes 16..24) and its CRC (bytes 29..33), so that the
    // header is valid and only the size is absurd.
    let mut png = tiny_png();
    png[16..20].copy_from_slice(&50_000u32.to_be_bytes());
    png[20..24].copy_from_slice(&50_000u32.to_be_bytes());
    let crc = crc32(&png[12..29]);
    png[29..33].copy_from_slice(&crc.to_be_bytes());
    let dir = TempDir::new().unwrap();
    assert_fails(
        &write(&dir, "huge.png", &png),
        "image is 50000 x 50000 pixels (2500000000 cells), more than the limit of 100000000 cells",
    );
}

#[test]
fn corrupt_png() {
    let dir = TempDir::new().unwrap();
    let good = tiny_png();
    // Flip a byte of the compressed data: the chunk CRC no longer matches.
    let mut bad = good.clone();
    let idat = bad.windows(4).position(|w| w == b"IDAT").unwrap();
    bad[idat + 6] ^= 0xff;
    let msg = err(&write(&dir, "crc.png", &bad));
    let prefix = format!(
        "{}: not a valid PNG image: ",
        dir.path().join("crc.png").display()
    );
    assert!(msg.starts_with(&prefix), "{msg}");
    assert!(!msg.contains('\n'), "{msg}");
    // Cut off in the middle of the data.
    let path = write(&dir, "cut.png", &good[..idat + 4]);
    let msg = err(&path);
    assert!(
        msg.starts_with(&format!("{}: not a valid PNG image: ", path.display())),
        "{msg}"
    );
}

#[test]
fn yaml_missing_key() {
    for (key, what) in [
        ("image", "the image file name"),
        ("resolution", "metres per cell"),
        ("origin", "[x, y, yaw] of the lower-left corner"),
        ("negate", "0 or 1"),
        ("occupied_thresh", "a probability in [0, 1]"),
        ("free_thresh", "a probability in [0, 1]"),
    ] {
        let (_dir, path) = yaml_case(&replace_key(key, ""));
        assert_fails(&path, &format!("missing key `{key}` ({what})"));
    }
}

#[test]
fn yaml_wrong_types() {
    for (line, reason) in [
        (
            "resolution: abc",
            "key `resolution` must be a number, found the text \"abc\"",
        ),
        (
            "origin: [0.0, 0.0]",
            "key `origin` must be a list of 3 numbers [x, y, yaw], found a list of 2 items",
        ),
        (
            "origin: 5",
            "key `origin` must be a list of 3 numbers [x, y, yaw], found 5",
        ),
        (
            "origin: [0.0, x, 0.0]",
            "key `origin` must be a list of 3 numbers [x, y, yaw], found the text \"x\"",
        ),
        ("negate: 2", "key `negate` must be 0 or 1, found 2"),
        (
            "image: [a, b]",
            "key `image` must be an image file name, found a list of 2 items",
        ),
        (
            "occupied_thresh: high",
            "key `occupied_thresh` must be a number, found the text \"high\"",
        ),
    ] {
        let key = line.split(':').next().unwrap();
        let (_dir, path) = yaml_case(&replace_key(key, line));
        assert_fails(&path, reason);
    }
    let (_dir, path) = yaml_case(&format!("{GOOD_KEYS}mode: fancy\n"));
    assert_fails(
        &path,
        "key `mode` must be trinary, scale or raw, found the text \"fancy\"",
    );
}

#[test]
fn yaml_values_out_of_range() {
    for (line, reason) in [
        (
            "resolution: 0",
            "resolution must be a positive number of metres per cell, found 0",
        ),
        (
            "resolution: -0.05",
            "resolution must be a positive number of metres per cell, found -0.05",
        ),
        (
            "resolution: .inf",
            "resolution must be a positive number of metres per cell, found inf",
        ),
        (
            "origin: [0.0, .nan, 0.0]",
            "origin must be 3 finite numbers [x, y, yaw], found [0, NaN, 0]",
        ),
        (
            "occupied_thresh: 1.5",
            "occupied_thresh must be between 0 and 1, found 1.5",
        ),
        (
            "free_thresh: -0.1",
            "free_thresh must be between 0 and 1, found -0.1",
        ),
        (
            "free_thresh: .nan",
            "free_thresh must be between 0 and 1, found NaN",
        ),
        (
            "free_thresh: 0.7",
            "free_thresh (0.7) must be less than occupied_thresh (0.65)",
        ),
        (
            "free_thresh: 0.65",
            "free_thresh (0.65) must be less than occupied_thresh (0.65)",
        ),
    ] {
        let key = line.split(':').next().unwrap();
        let (_dir, path) = yaml_case(&replace_key(key, line));
        assert_fails(&path, reason);
    }
}

#[test]
fn yaml_that_is_not_a_map_server_file() {
    let (_dir, path) = yaml_case("- a\n- b\n");
    assert_fails(
        &path,
        "expected a map_server YAML (keys image, resolution, origin, negate, occupied_thresh, free_thresh), found a list of 2 items",
    );
    let (_dir, path) = yaml_case("");
    assert_fails(&path, "empty YAML file");
    let (_dir, path) = yaml_case("image: [unclosed\nresolution: 0.05\n");
    let msg = err(&path);
    assert!(
        msg.starts_with(&format!("{}: invalid YAML: ", path.display())),
        "{msg}"
    );
    assert!(!msg.contains('\n'), "{msg}");
    let (_dir, path) = yaml_case(&format!("{GOOD_KEYS}resolution: 0.1\n"));
    assert_fails(&path, "key `resolution` appears more than once");
    let (_dir, path) = yaml_case("");
    std::fs::write(&path, b"image: \xff\xfe.pgm\n").unwrap();
    assert_fails(&path, "not a text file (invalid UTF-8)");
}

#[test]
fn yaml_accepts_map_server_spellings() {
    // Integers where floats are expected, `negate: true`, extra keys, a relative sub-folder.
    let dir = TempDir::new().unwrap();
    std::fs::create_dir(dir.path().join("img")).unwrap();
    write(&dir, "img/m.pgm", b"P5 2 1 255\n\x00\xfe");
    let path = write(
        &dir,
        "m.yml",
        b"image: img/m.pgm\nresolution: 1\norigin: [0, -3, 0]\nnegate: false\n\
          occupied_thresh: 1\nfree_thresh: 0\nmode: trinary\nextra: ignored\n",
    );
    let g = load_map(&path, &LoadOptions::default()).unwrap();
    // occ 1: nothing is above it; free 0: nothing is below it → all unknown.
    assert_eq!(g.cells(), &[255, 255]);
    assert_eq!(g.resolution(), 1.0);
    assert_eq!(g.origin().y, -3.0);
}
