//! Obstacle masks: which cells take part in connected components, and morphological closing so
//! that a wall drawn with gaps by a noisy sensor stays one component.

use grid_core::{CellState, OccupancyGrid};

use crate::{BlobError, Result};

/// Write the obstacle mask of `grid` into `out` (cleared first): `1` where
/// [`OccupancyGrid::state`] is [`CellState::Occupied`], `0` elsewhere; row-major like the grid.
pub fn obstacle_mask(grid: &OccupancyGrid, out: &mut Vec<u8>) {
    out.clear();
    out.extend(
        grid.cells()
            .iter()
            .map(|&c| u8::from(OccupancyGrid::classify(c) == CellState::Occupied)),
    );
}

/// Write the "not free" mask of `grid` into `out` (cleared first): `1` where
/// [`OccupancyGrid::state`] is occupied or unknown, `0` where free.
///
/// In a partial map an obstacle is mostly its visible surface (thin, noisy and different for each
/// robot) around an unknown interior; the not-free island enclosed by free space is the
/// obstacle's whole footprint, which two robots that both drove around it agree on.
pub fn not_free_mask(grid: &OccupancyGrid, out: &mut Vec<u8>) {
    out.clear();
    out.extend(
        grid.cells()
            .iter()
            .map(|&c| u8::from(OccupancyGrid::classify(c) != CellState::Free)),
    );
}

/// Morphological closing (dilation then erosion) of a `0`/`1` mask by a `(2r+1) x (2r+1)` square,
/// in place; `scratch` is a caller-owned buffer. `radius == 0` leaves the mask unchanged.
///
/// The mask is closed as if surrounded by background, so closing never thickens an obstacle
/// that runs along the border. A square element (not a disk) keeps the passes separable: the
/// cost is about `4 r` vectorised byte passes over the image; for the radii that matter here
/// (1-2 px) a disk would differ by a handful of corner pixels.
///
/// Fails with [`BlobError::MaskSize`] when `mask.len() != width * height`.
pub fn close(
    mask: &mut [u8],
    width: usize,
    height: usize,
    radius: usize,
    scratch: &mut Vec<u8>,
) -> Result<()> {
    if width.checked_mul(height) != Some(mask.len()) {
        return Err(BlobError::MaskSize {
            got: mask.len(),
            width,
            height,
        });
    }
    if radius == 0 || mask.is_empty() {
        return Ok(());
    }
    // Pad by the radius so the dilation may spill over the border and the erosion can take it
    // back; then work on the padded copy.
    let (pw, ph) = (width + 2 * radius, height + 2 * radius);
    scratch.clear();
    scratch.resize(2 * pw * ph, 0);
    let (padded, tmp) = scratch.split_at_mut(pw * ph);
    for (y, row) in mask.chunks_exact(width).enumerate() {
        let at = (y + radius) * pw + radius;
        padded[at..at + width].copy_from_slice(row);
    }
    dilate(padded, tmp, pw, ph, radius);
    // Erosion = complement of the dilation of the complement. Outside the padding counts as
    // foreground here, which only matters for padding pixels, never read back.
    for m in padded.iter_mut() {
        *m ^= 1;
    }
    dilate(padded, tmp, pw, ph, radius);
    for (y, row) in mask.chunks_exact_mut(width).enumerate() {
        let at = (y + radius) * pw + radius;
        for (m, &p) in row.iter_mut().zip(&padded[at..at + width]) {
            *m = p ^ 1;
        }
    }
    Ok(())
}

/// Dilation of a `0`/`1` mask by a `(2r+1)` square, in place (outside counts as background);
/// `tmp` has the mask's size. Each pass ORs whole shifted rows, which the compiler vectorises:
/// O(r) byte passes, far cheaper than a per-pixel window for the small radii used here.
fn dilate(mask: &mut [u8], tmp: &mut [u8], width: usize, height: usize, r: usize) {
    // Rows: tmp[x] = OR of mask[x-r ..= x+r].
    for (src, dst) in mask.chunks_exact(width).zip(tmp.chunks_exact_mut(width)) {
        dst.copy_from_slice(src);
        for d in 1..=r.min(width.saturating_sub(1)) {
            or_into(&mut dst[d..], &src[..width - d]);
            or_into(&mut dst[..width - d], &src[d..]);
        }
    }
    // Columns: mask row y = OR of tmp rows y-r ..= y+r.
    for y in 0..height {
        let row = &mut mask[y * width..(y + 1) * width];
        row.copy_from_slice(&tmp[y * width..(y + 1) * width]);
        for yy in y.saturating_sub(r)..(y + r + 1).min(height) {
            if yy != y {
                or_into(row, &tmp[yy * width..(yy + 1) * width]);
            }
        }
    }
}

#[inline]
fn or_into(dst: &mut [u8], src: &[u8]) {
    for (d, &s) in dst.iter_mut().zip(src) {
        *d |= s;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closing by brute force: dilation then erosion with explicit window loops.
    fn close_oracle(mask: &[u8], w: usize, h: usize, r: usize) -> Vec<u8> {
        let get = |m: &[u8], x: isize, y: isize, outside: u8| {
            if x < 0 || y < 0 || x >= w as isize || y >= h as isize {
                outside
            } else {
                m[y as usize * w + x as usize]
            }
        };
        let r = r as isize;
        // Closing on the infinite plane of background: the dilation is evaluated outside the
        // image too (the erosion of an in-image pixel reads it there).
        let mut out = vec![0u8; w * h];
        for y in 0..h as isize {
            for x in 0..w as isize {
                let mut all = true;
                for dy in -r..=r {
                    for dx in -r..=r {
                        let mut any = false;
                        for ey in -r..=r {
                            for ex in -r..=r {
                                any |= get(mask, x + dx + ex, y + dy + ey, 0) != 0;
                            }
                        }
                        all &= any;
                    }
                }
                out[y as usize * w + x as usize] = u8::from(all);
            }
        }
        out
    }

    #[test]
    fn closing_matches_brute_force() {
        let (w, h) = (23, 17);
        let mut s = 12345u64;
        for r in 0..4 {
            let mask: Vec<u8> = (0..w * h)
                .map(|_| {
                    s = s
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    u8::from((s >> 33).is_multiple_of(5))
                })
                .collect();
            let mut m = mask.clone();
            close(&mut m, w, h, r, &mut Vec::new()).unwrap();
            assert_eq!(m, close_oracle(&mask, w, h, r), "radius {r}");
        }
    }

    #[test]
    fn closing_rejects_a_wrong_mask_size() {
        let err = close(&mut [1, 0, 1], 2, 2, 1, &mut Vec::new()).unwrap_err();
        assert_eq!(
            err,
            BlobError::MaskSize {
                got: 3,
                width: 2,
                height: 2
            }
        );
    }

    #[test]
    fn closing_bridges_a_one_pixel_gap() {
        // A horizontal wall with a gap at x = 5: radius 1 bridges it.
        let (w, h) = (11, 3);
        let mut m = vec![0u8; w * h];
        for x in (0..w).filter(|&x| x != 5) {
            m[w + x] = 1;
        }
        close(&mut m, w, h, 1, &mut Vec::new()).unwrap();
        assert!(m[w..2 * w].iter().all(|&v| v == 1));
        assert!(
            m[..w].iter().all(|&v| v == 0),
            "closing must not thicken the wall"
        );
    }
}
