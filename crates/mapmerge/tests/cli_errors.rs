//! Bad input and bad usage: exit code 2 and exactly one line on stderr that names the file and
//! says what is wrong. Nothing on stdout, never a panic.

use std::path::{Path, PathBuf};

use tempfile::TempDir;

mod common;
use common::fails;

fn write(dir: &TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

fn info_fails(path: &Path) -> String {
    fails(&["info", path.to_str().unwrap()])
}

fn expect(path: &Path, reason: &str) -> String {
    format!("mapmerge: error: {}: {reason}", path.display())
}

const GOOD_KEYS: &str = "image: map.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";

/// `map.yaml` with `key`'s line replaced by `line` (removed if empty), beside a valid image.
fn yaml_with(dir: &TempDir, key: &str, line: &str) -> PathBuf {
    write(dir, "map.pgm", b"P5 2 1 255\n\x00\xfe");
    let text: String = GOOD_KEYS
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
        .collect();
    write(dir, "map.yaml", text.as_bytes())
}

#[test]
fn missing_file() {
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("absent.yaml");
    assert_eq!(
        info_fails(&path),
        expect(&path, "No such file or directory (os error 2)")
    );
}

#[test]
fn unreadable_file() {
    // A directory named like a map: opening works on Linux, reading does not.
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("folder.yaml");
    std::fs::create_dir(&path).unwrap();
    assert_eq!(
        info_fails(&path),
        expect(&path, "Is a directory (os error 21)")
    );
}

#[test]
fn unknown_extension() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "map.jpg", b"\xff\xd8\xff");
    assert_eq!(
        info_fails(&path),
        expect(
            &path,
            "unknown file extension `.jpg`: expected a map_server .yaml/.yml file or a .pgm/.png image"
        )
    );
}

#[test]
fn truncated_pgm() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "t.pgm", b"P5\n4 4\n255\n\x00\x00\x00");
    assert_eq!(
        info_fails(&path),
        expect(&path, "truncated: expected 16 bytes of pixel data, found 3")
    );
}

#[test]
fn corrupt_png() {
    let dir = TempDir::new().unwrap();
    // A PNG signature followed by garbage instead of an IHDR chunk.
    let path = write(
        &dir,
        "c.png",
        b"\x89PNG\r\n\x1a\nthis is not a chunk at all",
    );
    let line = info_fails(&path);
    assert!(
        line.starts_with(&expect(&path, "not a valid PNG image: ")),
        "{line}"
    );
}

#[test]
fn header_claiming_a_huge_image() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "huge.pgm", b"P5\n1000000 1000000\n255\n\x00");
    assert_eq!(
        info_fails(&path),
        expect(
            &path,
            "image is 1000000 x 1000000 pixels (1000000000000 cells), more than the limit of 100000000 cells"
        )
    );
}

#[test]
fn zero_size_image() {
    let dir = TempDir::new().unwrap();
    let path = write(&dir, "z.pgm", b"P5\n0 0\n255\n");
    assert_eq!(
        info_fails(&path),
        expect(&path, "image is empty (0 x 0 pixels)")
    );
}

#[test]
fn yaml_missing_key() {
    let dir = TempDir::new().unwrap();
    let path = yaml_with(&dir, "resolution", "");
    assert_eq!(
        info_fails(&path),
        expect(&path, "missing key `resolution` (metres per cell)")
    );
}

#[test]
fn yaml_wrong_type() {
    let dir = TempDir::new().unwrap();
    let path = yaml_with(&dir, "origin", "origin: here");
    assert_eq!(
        info_fails(&path),
        expect(
            &path,
            "key `origin` must be a list of 3 numbers [x, y, yaw], found the text \"here\""
        )
    );
}

#[test]
fn yaml_threshold_outside_0_1() {
    let dir = TempDir::new().unwrap();
    let path = yaml_with(&dir, "occupied_thresh", "occupied_thresh: 65");
    assert_eq!(
        info_fails(&path),
        expect(&path, "occupied_thresh must be between 0 and 1, found 65")
    );
}

#[test]
fn yaml_free_thresh_not_below_occupied_thresh() {
    let dir = TempDir::new().unwrap();
    let path = yaml_with(&dir, "free_thresh", "free_thresh: 0.8");
    assert_eq!(
        info_fails(&path),
        expect(
            &path,
            "free_thresh (0.8) must be less than occupied_thresh (0.65)"
        )
    );
}

#[test]
fn image_named_in_yaml_is_missing() {
    let dir = TempDir::new().unwrap();
    let yaml = yaml_with(&dir, "image", "image: elsewhere.pgm");
    let image = dir.path().join("elsewhere.pgm");
    assert_eq!(
        info_fails(&yaml),
        expect(
            &image,
            &format!(
                "No such file or directory (os error 2) (image named in {})",
                yaml.display()
            )
        )
    );
}

#[test]
fn nan_inf_and_out_of_range_flags() {
    let dir = TempDir::new().unwrap();
    let pgm = write(&dir, "m.pgm", b"P5 2 1 255\n\x00\xfe");
    let pgm = pgm.to_str().unwrap();
    for (flag, value, reason) in [
        (
            "--resolution",
            "NaN",
            "must be a finite number greater than 0",
        ),
        (
            "--resolution",
            "inf",
            "must be a finite number greater than 0",
        ),
        (
            "--resolution",
            "-0.05",
            "must be a finite number greater than 0",
        ),
        ("--resolution", "fast", "not a number"),
        (
            "--occupied-thresh",
            "nan",
            "must be a number between 0 and 1",
        ),
        ("--free-thresh", "1.5", "must be a number between 0 and 1"),
    ] {
        let placeholder = if flag == "--resolution" { "M" } else { "P" };
        assert_eq!(
            fails(&["info", pgm, &format!("{flag}={value}")]),
            format!(
                "mapmerge: error: invalid value '{value}' for '{flag} <{placeholder}>': {reason} \
                 (see 'mapmerge --help')"
            )
        );
    }
    assert_eq!(
        fails(&["info", pgm, "--free-thresh", "0.7"]),
        "mapmerge: error: the free threshold (0.7) must be less than the occupied threshold \
         (0.65); check --free-thresh and --occupied-thresh"
    );
}

#[test]
fn clap_usage_errors_exit_2_in_one_line() {
    assert_eq!(
        fails(&["info"]),
        "mapmerge: error: the following required arguments were not provided: <MAP> \
         (see 'mapmerge --help')"
    );
    assert_eq!(
        fails(&["frobnicate"]),
        "mapmerge: error: unrecognized subcommand 'frobnicate' (see 'mapmerge --help')"
    );
}
