//! ROS map_server I/O: read a map (YAML + PGM/PNG, or a bare image) into an [`OccupancyGrid`]
//! and write one back the way `map_saver` does.
//!
//! Reading follows map_server's rules (see `/work/shared/CONVENTIONS.md`):
//! the colour channels of a pixel are averaged into `v` (alpha is not averaged in),
//! `p = (255 - v) / 255` (or `v / 255` with `negate`), and then, per [`MapMode`]:
//! - `trinary`: `p > occupied_thresh` → occupied (100 %), `p < free_thresh` → free (0 %),
//!   otherwise unknown;
//! - `scale`: like trinary, but a pixel between the thresholds keeps `round(p * 100)` percent,
//!   and a pixel whose alpha is below 255 is unknown;
//! - `raw`: `round(v)` in `0..=100` is taken as the percentage, anything else is unknown
//!   (as nav2 does; `negate` does not apply).
//!
//! Two deliberate differences from map_server, both chosen by the project: in `scale` mode
//! map_server (ROS 1 and nav2) stretches `(p - free_thresh) / (occupied_thresh - free_thresh)`
//! onto `0..=100`, while we keep `p` itself, since a cell here holds an occupancy probability;
//! and map_server averages the alpha channel in with R, G, B in `trinary` mode (an opaque
//! `(205, 205, 205, 255)` pixel then reads as free), while we average R, G, B only.
//!
//! Every error names the file it is about and says what is wrong in a user's words, so that a
//! command-line tool can print it as one line. Nothing is allocated for pixels before the image
//! header has been checked against [`LoadOptions::max_cells`].

mod pnm;
mod raster;
mod save;
mod yaml;

use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use crate::{Error, OccupancyGrid, Pose2, Result};

pub use pnm::MAX_SIDE;
pub use save::{image_path_for, save_map, write_atomic};
pub use yaml::{MapMetadata, MapMode};

/// Default for [`LoadOptions::max_cells`]: 100 million cells (10 km x 10 km at 1 m, or
/// 500 m x 500 m at 5 cm). The grid then takes 100 MB; larger headers are refused before any
/// pixel buffer is allocated.
pub const DEFAULT_MAX_CELLS: usize = 100_000_000;

/// How to read a bare image given without a YAML file.
///
/// The defaults are map_server's usual values: trinary mode, 0.05 m/cell, origin `[0, 0, 0]`,
/// `occupied_thresh` 0.65, `free_thresh` 0.196, no negation.
#[derive(Debug, Clone, PartialEq)]
pub struct BareImageDefaults {
    /// Metres per cell; default 0.05.
    pub resolution: f64,
    /// Pose of the lower-left corner of the lower-left cell; default `[0, 0, 0]`.
    pub origin: Pose2,
    /// Read dark pixels as free instead of occupied; default `false`.
    pub negate: bool,
    /// `p` above this is occupied; default 0.65.
    pub occupied_thresh: f64,
    /// `p` below this is free; default 0.196.
    pub free_thresh: f64,
    /// How pixel values become occupancy; default [`MapMode::Trinary`].
    pub mode: MapMode,
}

impl Default for BareImageDefaults {
    fn default() -> Self {
        Self {
            resolution: 0.05,
            origin: Pose2::default(),
            negate: false,
            occupied_thresh: 0.65,
            free_thresh: 0.196,
            mode: MapMode::Trinary,
        }
    }
}

impl BareImageDefaults {
    /// The metadata a bare image at `image` is read with.
    pub fn metadata(&self, image: &Path) -> MapMetadata {
        MapMetadata {
            image: image.to_path_buf(),
            resolution: self.resolution,
            origin: self.origin,
            negate: self.negate,
            occupied_thresh: self.occupied_thresh,
            free_thresh: self.free_thresh,
            mode: self.mode,
        }
    }
}

/// Options of [`load_map`].
#[derive(Debug, Clone, PartialEq)]
pub struct LoadOptions {
    /// Refuse images with more cells than this, before allocating; default
    /// [`DEFAULT_MAX_CELLS`] (100 million).
    pub max_cells: usize,
    /// How to read a bare image (no YAML); default [`BareImageDefaults::default`].
    pub bare_image: BareImageDefaults,
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self {
            max_cells: DEFAULT_MAX_CELLS,
            bare_image: BareImageDefaults::default(),
        }
    }
}

/// A map as read from disk: the grid and where it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadedMap {
    /// The cells, resolution and origin.
    pub grid: OccupancyGrid,
    /// The YAML content (for a bare image: the [`BareImageDefaults`] it was read with). Its
    /// `image` is as written in the YAML, possibly relative.
    pub metadata: MapMetadata,
    /// The YAML file, `None` for a bare image.
    pub yaml_path: Option<PathBuf>,
    /// The image file actually read (relative `image:` entries resolved against the YAML's
    /// folder).
    pub image_path: PathBuf,
}

/// Read a map: a map_server YAML (`.yaml`, `.yml`) or a bare image (`.pgm`, `.pnm`, `.ppm`,
/// `.png`).
pub fn load_map(path: impl AsRef<Path>, options: &LoadOptions) -> Result<OccupancyGrid> {
    load_map_with_metadata(path, options).map(|m| m.grid)
}

/// Like [`load_map`], but also returns the metadata and the resolved file names.
pub fn load_map_with_metadata(path: impl AsRef<Path>, options: &LoadOptions) -> Result<LoadedMap> {
    let path = path.as_ref();
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match ext.as_deref() {
        Some("yaml" | "yml") => {
            let metadata = MapMetadata::read_yaml(path)?;
            let image_path = metadata.image_path(path);
            let grid = read_image(&image_path, &metadata, options, Some(path))?;
            Ok(LoadedMap {
                grid,
                metadata,
                yaml_path: Some(path.to_path_buf()),
                image_path,
            })
        }
        Some("pgm" | "pnm" | "ppm" | "png") => {
            let metadata = options.bare_image.metadata(path);
            metadata.validate(path)?;
            let grid = read_image(path, &metadata, options, None)?;
            Ok(LoadedMap {
                grid,
                metadata,
                yaml_path: None,
                image_path: path.to_path_buf(),
            })
        }
        other => Err(format_error(
            path,
            match other {
                Some(e) => format!(
                    "unknown file extension `.{e}`: expected a map_server .yaml/.yml file or a .pgm/.png image"
                ),
                None => {
                    "no file extension: expected a map_server .yaml/.yml file or a .pgm/.png image"
                        .into()
                }
            },
        )),
    }
}

/// Read the image at `image_path` and turn it into a grid with `metadata`'s resolution, origin,
/// thresholds and mode. The image format is recognised from the content (PNM or PNG), not from
/// the name. `yaml` is the YAML that named the image, for error messages.
pub fn read_image(
    image_path: &Path,
    metadata: &MapMetadata,
    options: &LoadOptions,
    yaml: Option<&Path>,
) -> Result<OccupancyGrid> {
    let read = || -> Result<OccupancyGrid> {
        let io_error = |source: std::io::Error| Error::Io {
            path: image_path.to_path_buf(),
            source,
        };
        let file = File::open(image_path).map_err(io_error)?;
        let mut reader = BufReader::new(file);
        // A directory opens, and fails on the first read.
        let head = reader.fill_buf().map_err(io_error)?;
        let raster = if head.is_empty() {
            return Err(format_error(image_path, "empty file (0 bytes)"));
        } else if head.starts_with(b"\x89PNG") {
            raster::read_png(reader, image_path, options.max_cells)?
        } else if head[0] == b'P' {
            pnm::read_pnm(&mut reader, image_path, options.max_cells)?
        } else {
            return Err(format_error(
                image_path,
                "not a PGM/PNM or PNG image (unrecognised file signature)",
            ));
        };
        raster.to_grid(metadata, image_path)
    };
    read().map_err(|e| match yaml {
        Some(y) => named_in(e, y),
        None => e,
    })
}

/// `e`, an error about an image that `yaml` named, saying so: the user typed the YAML's name,
/// not the image's. Every error of [`read_image`] that names a file names the image.
fn named_in(e: Error, yaml: &Path) -> Error {
    let also = format!("(image named in {})", yaml.display());
    match e {
        Error::Io { path, source } => Error::Io {
            path,
            source: std::io::Error::new(source.kind(), format!("{source} {also}")),
        },
        Error::Format { path, reason } => Error::Format {
            path,
            reason: format!("{reason} {also}"),
        },
        e => e,
    }
}

/// `Err(Error::AllUnknown)` when `grid` has no free or occupied cell: a map that cannot be
/// registered or merged. `path` names the map in the error.
pub fn require_known_cells(grid: &OccupancyGrid, path: &Path) -> Result<()> {
    let counts = grid.counts();
    if counts.free + counts.occupied == 0 {
        return Err(Error::AllUnknown {
            path: path.to_path_buf(),
        });
    }
    Ok(())
}

/// A [`Error::Format`] about `path`.
pub(crate) fn format_error(path: &Path, reason: impl Into<String>) -> Error {
    Error::Format {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}
