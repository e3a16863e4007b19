//! Damaged files, generated: a valid PGM (P5 and P2), PNG or map_server YAML cut short or with
//! bytes changed must load as a consistent grid or fail with an error that names a file of the
//! map, never panic. The hand-written cases of `io_errors.rs` pin the exact messages; these
//! cover the damage nobody thought to write down.

use std::path::{Path, PathBuf};

use grid_core::OccupancyGrid;
use grid_core::io::{LoadOptions, load_map};
use image::ImageEncoder;
use image::codecs::png::PngEncoder;
use proptest::prelude::*;
use tempfile::TempDir;

const YAML: &str = "image: map.pgm\nresolution: 0.05\norigin: [-1.5, 2.0, 0.3]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n";

/// How a file is damaged.
#[derive(Debug, Clone)]
enum Damage {
    /// Keep the first `len` bytes (`len` below the file's length).
    Cut(usize),
    /// Replace the byte at `at` (modulo the length) with `value`.
    Set { at: usize, value: u8 },
    /// Both, in that order: a write cut short over a corrupted file.
    SetThenCut { at: usize, value: u8, len: usize },
}

impl Damage {
    fn apply(&self, bytes: &[u8]) -> Vec<u8> {
        let mut out = bytes.to_vec();
        let set = |out: &mut Vec<u8>, at: usize, value: u8| {
            let i = at % out.len();
            out[i] = value;
        };
        match *self {
            Damage::Cut(len) => out.truncate(len % bytes.len()),
            Damage::Set { at, value } => set(&mut out, at, value),
            Damage::SetThenCut { at, value, len } => {
                set(&mut out, at, value);
                out.truncate(len % bytes.len());
            }
        }
        out
    }
}

fn damage() -> impl Strategy<Value = Damage> {
    prop_oneof![
        any::<usize>().prop_map(Damage::Cut),
        (any::<usize>(), any::<u8>()).prop_map(|(at, value)| Damage::Set { at, value }),
        (any::<usize>(), any::<u8>(), any::<usize>())
            .prop_map(|(at, value, len)| Damage::SetThenCut { at, value, len }),
    ]
}

/// A small image's pixels: map_server's three values and a few in between.
fn pixels() -> impl Strategy<Value = (u32, u32, Vec<u8>)> {
    (1u32..9, 1u32..7).prop_flat_map(|(w, h)| {
        let value = prop_oneof![Just(0u8), Just(205u8), Just(254u8), any::<u8>()];
        (
            Just(w),
            Just(h),
            prop::collection::vec(value, (w * h) as usize),
        )
    })
}

fn p5(w: u32, h: u32, px: &[u8]) -> Vec<u8> {
    let mut out = format!("P5\n# a comment\n{w} {h}\n255\n").into_bytes();
    out.extend_from_slice(px);
    out
}

fn p2(w: u32, h: u32, px: &[u8]) -> Vec<u8> {
    let body: Vec<String> = px.iter().map(u8::to_string).collect();
    format!("P2\n{w} {h}\n255\n{}\n", body.join(" ")).into_bytes()
}

fn png(w: u32, h: u32, px: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    PngEncoder::new(&mut out)
        .write_image(px, w, h, image::ExtendedColorType::L8)
        .unwrap();
    out
}

fn write(dir: &TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// Loading `path` gives a grid whose cells fill its size, or a one-line error whose message
/// begins with one of `files` (the file at fault) and, when `yaml` is given, ends by naming it
/// unless the YAML itself is at fault: a damaged YAML may name an image that is not there.
fn check(
    path: &Path,
    files: &[&Path],
    yaml: Option<&Path>,
) -> Result<Option<OccupancyGrid>, TestCaseError> {
    match load_map(path, &LoadOptions::default()) {
        Ok(grid) => {
            prop_assert!(grid.width() > 0 && grid.height() > 0);
            prop_assert_eq!(grid.cells().len(), grid.width() * grid.height());
            Ok(Some(grid))
        }
        Err(e) => {
            let msg = e.to_string();
            prop_assert!(
                files
                    .iter()
                    .any(|f| msg.starts_with(&format!("{}: ", f.display())))
                    || yaml.is_some_and(
                        |y| msg.ends_with(&format!("(image named in {})", y.display()))
                    ),
                "the error names no file of the map: {msg}"
            );
            prop_assert!(!msg.contains('\n'), "not one line: {msg}");
            if let Some(y) = yaml {
                let yaml_at_fault = msg.starts_with(&format!("{}: ", y.display()));
                prop_assert!(
                    yaml_at_fault || msg.ends_with(&format!("(image named in {})", y.display())),
                    "an image's error that does not name the YAML: {msg}"
                );
            }
            Ok(None)
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn a_damaged_p5_loads_consistently_or_names_itself((w, h, px) in pixels(), d in damage()) {
        let dir = TempDir::new().unwrap();
        let path = write(&dir, "map.pgm", &d.apply(&p5(w, h, &px)));
        check(&path, &[&path], None)?;
    }

    #[test]
    fn a_damaged_p2_loads_consistently_or_names_itself((w, h, px) in pixels(), d in damage()) {
        let dir = TempDir::new().unwrap();
        let path = write(&dir, "map.pgm", &d.apply(&p2(w, h, &px)));
        check(&path, &[&path], None)?;
    }

    #[test]
    fn a_damaged_png_loads_consistently_or_names_itself((w, h, px) in pixels(), d in damage()) {
        let dir = TempDir::new().unwrap();
        let path = write(&dir, "map.png", &d.apply(&png(w, h, &px)));
        check(&path, &[&path], None)?;
    }

    /// A YAML cut short or with a byte changed, beside an intact image.
    #[test]
    fn a_damaged_yaml_loads_consistently_or_names_a_file((w, h, px) in pixels(), d in damage()) {
        let dir = TempDir::new().unwrap();
        let image = write(&dir, "map.pgm", &p5(w, h, &px));
        let yaml = write(&dir, "map.yaml", &d.apply(YAML.as_bytes()));
        check(&yaml, &[&yaml, &image], Some(&yaml))?;
    }

    /// An intact YAML over a damaged image: the error names the image (and, after it, the
    /// YAML that named it).
    #[test]
    fn a_yaml_over_a_damaged_image_names_the_image((w, h, px) in pixels(), d in damage()) {
        let dir = TempDir::new().unwrap();
        let image = write(&dir, "map.pgm", &d.apply(&p5(w, h, &px)));
        let yaml = write(&dir, "map.yaml", YAML.as_bytes());
        if check(&yaml, &[&image], Some(&yaml))?.is_none() {
            let msg = load_map(&yaml, &LoadOptions::default()).unwrap_err().to_string();
            prop_assert!(msg.starts_with(&format!("{}: ", image.display())), "{}", msg);
        }
    }

    /// Without damage every form loads to the same cells: the damage tests above start from
    /// files that are valid.
    #[test]
    fn the_undamaged_forms_agree((w, h, px) in pixels()) {
        let dir = TempDir::new().unwrap();
        let forms = [
            write(&dir, "a.pgm", &p5(w, h, &px)),
            write(&dir, "b.pgm", &p2(w, h, &px)),
            write(&dir, "c.png", &png(w, h, &px)),
        ];
        let grids: Vec<OccupancyGrid> = forms
            .iter()
            .map(|p| load_map(p, &LoadOptions::default()).unwrap())
            .collect();
        for g in &grids {
            prop_assert_eq!((g.width(), g.height()), (w as usize, h as usize));
            prop_assert_eq!(g.cells(), grids[0].cells());
        }
    }
}
