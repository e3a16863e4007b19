//! Writing a map the way map_saver does, atomically.

use std::fs::OpenOptions;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use super::{MapMetadata, MapMode, format_error, pnm};
use crate::{Error, OccupancyGrid, Result};

/// The PGM written beside the YAML `yaml_path` by [`save_map`]: same folder and stem, `.pgm`.
pub fn image_path_for(yaml_path: &Path) -> PathBuf {
    yaml_path.with_extension("pgm")
}

/// Write `grid` as map_saver does: a P5 PGM (0 occupied, 254 free, 205 unknown, classified with
/// [`OccupancyGrid::state`]) at [`image_path_for`]`(yaml_path)` and a YAML at `yaml_path`
/// (`mode: trinary`, `negate: 0`, `occupied_thresh: 0.65`, `free_thresh: 0.196`, the grid's
/// resolution and origin).
///
/// Each file is written to a temporary file in its folder and renamed into place, so a reader
/// never sees a partial file. `yaml_path` must end in `.yaml` or `.yml`. Existing files are
/// replaced; refusing to overwrite an input is the caller's decision.
pub fn save_map(grid: &OccupancyGrid, yaml_path: &Path) -> Result<()> {
    let ext = yaml_path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    if !matches!(ext.as_deref(), Some("yaml" | "yml")) {
        return Err(format_error(
            yaml_path,
            "the output map must be a .yaml or .yml file (its PGM is written beside it)",
        ));
    }
    let image_path = image_path_for(yaml_path);
    let image_name = image_path
        .file_name()
        .and_then(|n| n.to_str())
        .ok_or_else(|| format_error(yaml_path, "the output file name is not valid UTF-8"))?;
    let metadata = MapMetadata {
        image: PathBuf::from(image_name),
        resolution: grid.resolution(),
        origin: grid.origin(),
        negate: false,
        occupied_thresh: 0.65,
        free_thresh: 0.196,
        mode: MapMode::Trinary,
    };
    // The grid does not check its origin; a NaN written here could not be read back.
    metadata.validate(yaml_path)?;
    write_atomic(&image_path, &pnm::encode_p5(grid))?;
    write_atomic(yaml_path, metadata.to_yaml().as_bytes())
}

/// Write `bytes` to a new temporary file beside `path`, flush it to disk, rename it to `path`.
/// On failure the temporary file is removed and `path` is untouched: readers never see a
/// partial file. Used for every output the tools write (maps, JSON, pictures).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let io_err = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| format_error(path, "not a file name"))?
        .to_string_lossy();
    let (tmp, mut file) = loop {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let tmp = dir.join(format!(".{name}.{}.{n}.tmp", std::process::id()));
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(f) => break (tmp, f),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(io_err(e)),
        }
    };
    let written = file
        .write_all(bytes)
        .and_then(|()| file.sync_all())
        .and_then(|()| {
            drop(file);
            std::fs::rename(&tmp, path)
        });
    written.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io_err(e)
    })
}
