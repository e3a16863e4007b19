//! Decoded 8-bit pixels, PNG decoding, and the map_server pixel-to-occupancy rule.

use std::io::{BufRead, Seek};
use std::path::Path;

use image::codecs::png::PngDecoder;
use image::{DynamicImage, ImageDecoder};

use super::format_error;
use super::pnm::check_size;
use super::{MapMetadata, MapMode};
use crate::{OccupancyGrid, Result, UNKNOWN};

/// 8-bit pixels, row-major from the top row: 1 (grey), 2 (grey, alpha), 3 (RGB) or 4 (RGBA)
/// interleaved channels.
pub(super) struct Raster {
    pub width: usize,
    pub height: usize,
    pub channels: u8,
    pub data: Vec<u8>,
}

/// Decode a PNG, checking its header's size before the pixels are decoded.
pub(super) fn read_png(
    reader: impl BufRead + Seek,
    path: &Path,
    max_cells: usize,
) -> Result<Raster> {
    let bad = |e: image::ImageError| format_error(path, format!("not a valid PNG image: {e}"));
    let decoder = PngDecoder::new(reader).map_err(bad)?;
    let (w, h) = decoder.dimensions();
    check_size(path, w as u64, h as u64, max_cells)?;
    let img = DynamicImage::from_decoder(decoder).map_err(bad)?;
    let (width, height) = (w as usize, h as usize);
    let colour = img.color();
    let (channels, data) = match img {
        DynamicImage::ImageLuma8(b) => (1, b.into_raw()),
        DynamicImage::ImageLumaA8(b) => (2, b.into_raw()),
        DynamicImage::ImageRgb8(b) => (3, b.into_raw()),
        DynamicImage::ImageRgba8(b) => (4, b.into_raw()),
        // 16-bit (or float) images: scale to 8 bits keeping the channel layout. `to_luma8` of
        // a grey image only rescales; colour images are not reduced to luma here because
        // map_server averages R, G, B with equal weights (done in `to_grid`).
        other => match (colour.has_color(), colour.has_alpha()) {
            (false, false) => (1, other.to_luma8().into_raw()),
            (false, true) => (2, other.to_luma_alpha8().into_raw()),
            (true, false) => (3, other.to_rgb8().into_raw()),
            (true, true) => (4, other.to_rgba8().into_raw()),
        },
    };
    Ok(Raster {
        width,
        height,
        channels,
        data,
    })
}

impl Raster {
    /// Apply map_server's rule to every pixel (see the module docs of [`crate::io`]).
    pub(super) fn to_grid(&self, meta: &MapMetadata, path: &Path) -> Result<OccupancyGrid> {
        let n = self.channels as usize;
        let (colour_channels, has_alpha) = match n {
            1 => (1, false),
            2 => (1, true),
            3 => (3, false),
            _ => (3, true),
        };
        // The cell depends only on the sum of the colour channels and on whether the pixel is
        // opaque: a lookup table makes the per-pixel work one load.
        let max_sum = 255 * colour_channels;
        let lut = |opaque: bool| -> Vec<u8> {
            (0..=max_sum)
                .map(|sum| cell_value(sum as f64 / colour_channels as f64, opaque, meta))
                .collect()
        };
        let (lut_opaque, lut_transparent) = (lut(true), lut(false));
        let cells = self
            .data
            .chunks_exact(n)
            .map(|px| {
                let sum: usize = px[..colour_channels].iter().map(|&c| c as usize).sum();
                let opaque = !has_alpha || px[n - 1] == 255;
                if opaque {
                    lut_opaque[sum]
                } else {
                    lut_transparent[sum]
                }
            })
            .collect();
        OccupancyGrid::from_cells(self.width, self.height, meta.resolution, meta.origin, cells)
            .map_err(|e| format_error(path, e.to_string()))
    }
}

/// map_server's rule for one pixel whose colour channels average to `v` (0..=255).
fn cell_value(v: f64, opaque: bool, meta: &MapMetadata) -> u8 {
    if meta.mode == MapMode::Raw {
        // nav2: the value itself is the percentage; negate does not apply.
        let r = v.round();
        return if r <= 100.0 { r as u8 } else { UNKNOWN };
    }
    if meta.mode == MapMode::Scale && !opaque {
        return UNKNOWN;
    }
    // Written as map_server writes it, (255 - v) / 255, so that a pixel exactly on a
    // threshold falls on the same side as there.
    let p = if meta.negate {
        v / 255.0
    } else {
        (255.0 - v) / 255.0
    };
    if p > meta.occupied_thresh {
        100
    } else if p < meta.free_thresh {
        0
    } else if meta.mode == MapMode::Scale {
        (p * 100.0).round() as u8
    } else {
        UNKNOWN
    }
}
