//! A small PNM (PGM/PPM) reader and the P5 writer of map_saver.
//!
//! Written by hand rather than through the `image` crate so that a header claiming a huge image
//! is refused before any pixel buffer exists, and so that truncation is reported exactly.

use std::io::{BufRead, Read};
use std::path::Path;

use super::format_error;
use super::raster::Raster;
use crate::{CellState, Error, OccupancyGrid, Result};

/// map_saver's grey values.
const SAVED_OCCUPIED: u8 = 0;
const SAVED_FREE: u8 = 254;
const SAVED_UNKNOWN: u8 = 205;

/// Longest header number we read (u32::MAX has 10 digits); stops a stream of digits early.
const MAX_DIGITS: usize = 10;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    Ascii,
    Binary,
}

/// Read a PNM image (P2, P5 greyscale; P3, P6 colour) from `r`, positioned at the magic number.
pub(super) fn read_pnm(r: &mut impl BufRead, path: &Path, max_cells: usize) -> Result<Raster> {
    let mut magic = [0u8; 2];
    r.read_exact(&mut magic)
        .map_err(|_| format_error(path, "truncated: the file ends inside the PNM magic number"))?;
    let (channels, encoding) = match &magic {
        b"P2" => (1u8, Encoding::Ascii),
        b"P5" => (1, Encoding::Binary),
        b"P3" => (3, Encoding::Ascii),
        b"P6" => (3, Encoding::Binary),
        [b'P', d] if d.is_ascii_digit() => {
            return Err(format_error(
                path,
                format!(
                    "unsupported PNM type P{}: expected a greymap (P2/P5) or pixmap (P3/P6)",
                    *d as char
                ),
            ));
        }
        _ => {
            return Err(format_error(
                path,
                "not a PGM/PNM image (missing the P5/P2 magic number)",
            ));
        }
    };
    let mut header = HeaderReader { r, path };
    let width = header.number("width")?;
    let height = header.number("height")?;
    let maxval = header.number("maxval")?;
    header.single_whitespace_after_maxval()?;

    check_size(path, width, height, max_cells)?;
    if !(1..=65535).contains(&maxval) {
        return Err(format_error(
            path,
            format!("bad PNM header: maxval {maxval} is outside 1..=65535"),
        ));
    }
    let (width, height, maxval) = (width as usize, height as usize, maxval as u32);
    let samples = width * height * channels as usize;

    let data = match encoding {
        Encoding::Binary => {
            let bytes_per_sample = if maxval < 256 { 1 } else { 2 };
            let expected = samples * bytes_per_sample;
            let mut raw = Vec::with_capacity(expected);
            r.take(expected as u64)
                .read_to_end(&mut raw)
                .map_err(|source| Error::Io {
                    path: path.to_path_buf(),
                    source,
                })?;
            if raw.len() < expected {
                return Err(format_error(
                    path,
                    format!(
                        "truncated: expected {expected} bytes of pixel data, found {}",
                        raw.len()
                    ),
                ));
            }
            if bytes_per_sample == 1 {
                if maxval != 255 {
                    raw.iter_mut().for_each(|v| *v = to_8bit(*v as u32, maxval));
                }
                raw
            } else {
                raw.chunks_exact(2)
                    .map(|b| to_8bit(u16::from_be_bytes([b[0], b[1]]) as u32, maxval))
                    .collect()
            }
        }
        Encoding::Ascii => {
            let mut data = Vec::with_capacity(samples);
            let mut text = HeaderReader { r, path };
            while data.len() < samples {
                match text.ascii_sample(data.len())? {
                    Some(v) => data.push(to_8bit(v, maxval)),
                    None => {
                        return Err(format_error(
                            path,
                            format!(
                                "truncated: expected {samples} pixel values, found {}",
                                data.len()
                            ),
                        ));
                    }
                }
            }
            data
        }
    };
    Ok(Raster {
        width,
        height,
        channels,
        data,
    })
}

/// Longest side of a map the pipeline accepts, in cells (2^20: 52 km at 5 cm). The distance
/// transforms index cells with 32-bit integers and square coordinates in 64-bit ones.
pub const MAX_SIDE: usize = 1 << 20;

/// Refuse zero-size and too large images, before anything is allocated for them.
pub(super) fn check_size(path: &Path, width: u64, height: u64, max_cells: usize) -> Result<()> {
    if width == 0 || height == 0 {
        return Err(format_error(
            path,
            format!("image is empty ({width} x {height} pixels)"),
        ));
    }
    if width.max(height) > MAX_SIDE as u64 {
        return Err(format_error(
            path,
            format!(
                "image is {width} x {height} pixels, a side longer than the limit of {MAX_SIDE} \
                 pixels"
            ),
        ));
    }
    let cells = width.saturating_mul(height);
    if cells > max_cells as u64 {
        return Err(format_error(
            path,
            format!(
                "image is {width} x {height} pixels ({cells} cells), more than the limit of \
                 {max_cells} cells"
            ),
        ));
    }
    Ok(())
}

/// Scale a sample of `0..=maxval` to `0..=255`, rounding; values above `maxval` (invalid, but
/// seen in the wild) count as `maxval`, as image viewers show them.
fn to_8bit(v: u32, maxval: u32) -> u8 {
    let v = v.min(maxval);
    ((v * 255 + maxval / 2) / maxval) as u8
}

/// Byte-wise reading of the header tokens and of ASCII samples.
struct HeaderReader<'a, R> {
    r: &'a mut R,
    path: &'a Path,
}

impl<R: BufRead> HeaderReader<'_, R> {
    fn peek(&mut self) -> Result<Option<u8>> {
        let buf = self.r.fill_buf().map_err(|source| Error::Io {
            path: self.path.to_path_buf(),
            source,
        })?;
        Ok(buf.first().copied())
    }

    /// Skip whitespace and `#` comments (to the end of the line).
    fn skip_space(&mut self) -> Result<()> {
        while let Some(b) = self.peek()? {
            if b == b'#' {
                while let Some(c) = self.peek()? {
                    self.r.consume(1);
                    if c == b'\n' || c == b'\r' {
                        break;
                    }
                }
            } else if b.is_ascii_whitespace() {
                self.r.consume(1);
            } else {
                break;
            }
        }
        Ok(())
    }

    /// Up to [`MAX_DIGITS`] + 1 decimal digits; `None` if there is no digit here.
    fn digits(&mut self) -> Result<Option<(u64, usize)>> {
        let (mut value, mut n) = (0u64, 0usize);
        while let Some(b) = self.peek()? {
            if !b.is_ascii_digit() || n > MAX_DIGITS {
                break;
            }
            value = value * 10 + (b - b'0') as u64;
            n += 1;
            self.r.consume(1);
        }
        Ok((n > 0).then_some((value, n)))
    }

    fn number(&mut self, field: &str) -> Result<u64> {
        self.skip_space()?;
        match self.digits()? {
            Some((_, n)) if n > MAX_DIGITS => Err(format_error(
                self.path,
                format!("bad PNM header: {field} is too large"),
            )),
            Some((v, _)) => match self.peek()? {
                Some(b) if !(b.is_ascii_whitespace() || b == b'#') => Err(format_error(
                    self.path,
                    format!(
                        "bad PNM header: {field} is not a number (followed by {:?})",
                        b as char
                    ),
                )),
                _ => Ok(v),
            },
            None => match self.peek()? {
                None => Err(format_error(
                    self.path,
                    format!("truncated: the file ends before the {field} in the PNM header"),
                )),
                Some(b) => Err(format_error(
                    self.path,
                    format!(
                        "bad PNM header: expected the {field} as a number, found {:?}",
                        b as char
                    ),
                )),
            },
        }
    }

    /// The netpbm format puts exactly one whitespace byte between maxval and the raster (a
    /// second one would already be pixel data).
    fn single_whitespace_after_maxval(&mut self) -> Result<()> {
        match self.peek()? {
            Some(b) if b.is_ascii_whitespace() => {
                self.r.consume(1);
                Ok(())
            }
            None => Err(format_error(
                self.path,
                "truncated: the file ends right after the PNM header, before the pixel data",
            )),
            Some(_) => Err(format_error(
                self.path,
                "bad PNM header: expected whitespace after maxval",
            )),
        }
    }

    /// The next ASCII sample (number `index` counting from 0), `None` at the end of the file.
    fn ascii_sample(&mut self, index: usize) -> Result<Option<u32>> {
        self.skip_space()?;
        match self.digits()? {
            // Over 10 digits can only be garbage; saturate so that it is clamped to maxval.
            Some((v, _)) => Ok(Some(v.min(u32::MAX as u64) as u32)),
            None => match self.peek()? {
                None => Ok(None),
                Some(b) => Err(format_error(
                    self.path,
                    format!(
                        "pixel value {} is not a number (found {:?})",
                        index + 1,
                        b as char
                    ),
                )),
            },
        }
    }
}

/// The P5 file map_saver writes: 0 occupied, 254 free, 205 unknown, classified with
/// [`OccupancyGrid::state`].
pub(super) fn encode_p5(grid: &OccupancyGrid) -> Vec<u8> {
    let header = format!("P5\n{} {}\n255\n", grid.width(), grid.height());
    let mut out = Vec::with_capacity(header.len() + grid.cells().len());
    out.extend_from_slice(header.as_bytes());
    out.extend(
        grid.cells()
            .iter()
            .map(|&c| match OccupancyGrid::classify(c) {
                CellState::Occupied => SAVED_OCCUPIED,
                CellState::Free => SAVED_FREE,
                CellState::Unknown => SAVED_UNKNOWN,
            }),
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scaling_to_8bit_rounds_and_clamps() {
        assert_eq!(to_8bit(0, 65535), 0);
        assert_eq!(to_8bit(65535, 65535), 255);
        assert_eq!(to_8bit(257 * 205, 65535), 205);
        assert_eq!(to_8bit(1, 1), 255);
        assert_eq!(to_8bit(50, 100), 128); // 127.5 rounds up
        assert_eq!(to_8bit(300, 255), 255);
    }
}
