//! Two-pass connected-component labelling with union-find.
//!
//! The image is cut into horizontal strips labelled in parallel (rayon), each strip with its own
//! range of provisional labels; the strips are then joined at their seams, the equivalence table
//! is flattened to consecutive labels, and a second parallel pass writes the final labels. No
//! recursion anywhere, so a map that is one huge component costs what any other map costs.

use rayon::prelude::*;

use crate::{BlobError, Result};

/// Which neighbours make two foreground pixels part of the same component.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Connectivity {
    /// Edge neighbours only.
    Four,
    /// Edge and corner neighbours: a diagonal wall stays one component.
    #[default]
    Eight,
}

/// Rows below which a strip is not worth a task of its own.
const MIN_STRIP_ROWS: usize = 64;
/// Images with fewer pixels are labelled in one strip (thread hand-off would dominate).
const MIN_PARALLEL_PIXELS: usize = 1 << 18;

/// Connected-component labeller holding its scratch buffers, so repeated calls do not allocate.
#[derive(Debug, Clone, Default)]
pub struct Labeler {
    connectivity: Connectivity,
    /// Union-find parents of the provisional labels (index = label; 0 unused).
    parent: Vec<u32>,
    /// Force a number of strips (tests of the seam merge); `None` picks from the thread count.
    strips: Option<usize>,
}

impl Labeler {
    /// A labeller with the given connectivity.
    pub fn new(connectivity: Connectivity) -> Self {
        Self {
            connectivity,
            ..Self::default()
        }
    }

    /// The same labeller cutting the image into exactly `strips` strips (at least one, at most
    /// one per row), whatever the image size or the thread count: to test or tune the seam merge.
    pub fn with_strips(mut self, strips: usize) -> Self {
        self.strips = Some(strips.max(1));
        self
    }

    /// Change the connectivity, keeping the scratch buffers.
    pub fn set_connectivity(&mut self, connectivity: Connectivity) {
        self.connectivity = connectivity;
    }

    /// The connectivity in use.
    pub fn connectivity(&self) -> Connectivity {
        self.connectivity
    }

    /// Label the foreground (non-zero) pixels of the row-major `mask`. On return `out_labels`
    /// holds `width * height` labels: `0` for background and `1..=n` for the `n` components,
    /// numbered in raster order of their first (top-left-most) pixel. Returns `n`.
    pub fn label(
        &mut self,
        mask: &[u8],
        width: usize,
        height: usize,
        out_labels: &mut Vec<u32>,
    ) -> Result<usize> {
        let n_pix = width
            .checked_mul(height)
            .ok_or(BlobError::TooLarge { width, height })?;
        if mask.len() != n_pix {
            return Err(BlobError::MaskSize {
                got: mask.len(),
                width,
                height,
            });
        }
        // Pass 1 writes every pixel, so a reused buffer of the right size needs no clearing.
        if out_labels.len() != n_pix {
            out_labels.clear();
            out_labels.resize(n_pix, 0);
        }
        if n_pix == 0 {
            return Ok(0);
        }

        let n_strips = match self.strips {
            Some(s) => s.min(height),
            None if n_pix < MIN_PARALLEL_PIXELS => 1,
            None => (rayon::current_num_threads() * 2)
                .min(height / MIN_STRIP_ROWS)
                .max(1),
        };
        let rows_per = height.div_ceil(n_strips);
        // Capacity of provisional labels per strip: a new label needs a background pixel (or
        // the image edge) on its left, so a row starts at most ceil(w / 2) labels.
        let mut bases = Vec::with_capacity(n_strips + 1);
        let mut total = 1usize;
        let mut strip_rows = Vec::with_capacity(n_strips);
        let mut r0 = 0;
        while r0 < height {
            let r1 = (r0 + rows_per).min(height);
            bases.push(total);
            strip_rows.push((r0, r1));
            total += width.div_ceil(2) * (r1 - r0);
            r0 = r1;
        }
        if total > u32::MAX as usize {
            return Err(BlobError::TooLarge { width, height });
        }
        if self.parent.len() < total {
            self.parent.resize(total, 0);
        }

        // Pass 1: each strip on its own slice of labels and of the parent table.
        let mut tasks = Vec::with_capacity(strip_rows.len());
        {
            let mut labels_rest: &mut [u32] = out_labels;
            let mut parent_rest: &mut [u32] = &mut self.parent[1..total];
            for (k, &(r0, r1)) in strip_rows.iter().enumerate() {
                let (l, lr) = labels_rest.split_at_mut(width * (r1 - r0));
                let cap = bases.get(k + 1).copied().unwrap_or(total) - bases[k];
                let (p, pr) = parent_rest.split_at_mut(cap);
                labels_rest = lr;
                parent_rest = pr;
                tasks.push((l, p, &mask[width * r0..width * r1], bases[k] as u32));
            }
        }
        let conn = self.connectivity;
        let used: Vec<u32> = tasks
            .into_par_iter()
            .map(|(labels, parent, mask, base)| match conn {
                Connectivity::Eight => strip_pass8(mask, width, labels, parent, base),
                Connectivity::Four => strip_pass4(mask, width, labels, parent, base),
            })
            .collect();

        // Seams: join the first row of each strip to the last row of the strip above.
        let parent = &mut self.parent[..total];
        for &(r0, _) in strip_rows.iter().skip(1) {
            let (above, here) = (&out_labels[(r0 - 1) * width..r0 * width], r0 * width);
            for x in 0..width {
                let l = out_labels[here + x];
                if l == 0 {
                    continue;
                }
                let lo = if conn == Connectivity::Eight {
                    x.saturating_sub(1)
                } else {
                    x
                };
                let hi = if conn == Connectivity::Eight {
                    (x + 1).min(width - 1)
                } else {
                    x
                };
                for &m in &above[lo..=hi] {
                    if m != 0 {
                        union(parent, l, m);
                    }
                }
            }
        }

        // Flatten: every parent is below its child, so one ascending sweep turns roots into
        // consecutive labels and every other entry into its root's label.
        let mut n = 0u32;
        for (k, &u) in used.iter().enumerate() {
            let base = bases[k];
            for l in base..base + u as usize {
                let p = parent[l] as usize;
                parent[l] = if p == l {
                    n += 1;
                    n
                } else {
                    parent[p]
                };
            }
        }

        // Pass 2: final labels, in parallel over strips, skipping background words of the mask.
        let parent: &[u32] = parent;
        let chunk = width * rows_per.max(1);
        out_labels
            .par_chunks_mut(chunk)
            .zip(mask.par_chunks(chunk))
            .for_each(|(labels, mask)| {
                let mut i = 0;
                while i < labels.len() {
                    if i + WORD <= labels.len() && is_zero_word(&mask[i..i + WORD]) {
                        i += WORD;
                        continue;
                    }
                    if mask[i] != 0 {
                        labels[i] = parent[labels[i] as usize];
                    }
                    i += 1;
                }
            });
        Ok(n as usize)
    }
}

/// Bytes of mask tested at once when skipping background (most of a map is not an obstacle).
pub(crate) const WORD: usize = 16;

/// Whether the `WORD` bytes of `m` are all zero (one 128-bit load instead of 16 branches).
#[inline]
pub(crate) fn is_zero_word(m: &[u8]) -> bool {
    m.try_into()
        .is_ok_and(|b: [u8; WORD]| u128::from_ne_bytes(b) == 0)
}

/// Root of `l` in the global table, halving the path on the way.
#[inline]
fn find(parent: &mut [u32], mut l: u32) -> u32 {
    loop {
        let p = parent[l as usize];
        if p == l {
            return l;
        }
        let gp = parent[p as usize];
        parent[l as usize] = gp;
        l = gp;
    }
}

/// Join the sets of `a` and `b`, linking the larger root under the smaller so that every parent
/// stays below its child (the flatten sweep relies on it). Returns the root.
#[inline]
fn union(parent: &mut [u32], a: u32, b: u32) -> u32 {
    let (ra, rb) = (find(parent, a), find(parent, b));
    let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
    parent[hi as usize] = lo;
    lo
}

/// Strip-local table: labels are global, the slice starts at label `base`.
struct Local<'a> {
    parent: &'a mut [u32],
    base: u32,
    next: u32,
}

impl Local<'_> {
    #[inline]
    fn new_label(&mut self) -> u32 {
        let l = self.base + self.next;
        self.parent[self.next as usize] = l;
        self.next += 1;
        l
    }

    #[inline]
    fn find(&mut self, mut l: u32) -> u32 {
        loop {
            let p = self.parent[(l - self.base) as usize];
            if p == l {
                return l;
            }
            let gp = self.parent[(p - self.base) as usize];
            self.parent[(l - self.base) as usize] = gp;
            l = gp;
        }
    }

    #[inline]
    fn union(&mut self, a: u32, b: u32) -> u32 {
        if a == b {
            return a;
        }
        let (ra, rb) = (self.find(a), self.find(b));
        let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
        self.parent[(hi - self.base) as usize] = lo;
        lo
    }
}

/// First pass over one strip: skips empty words, and labels each set pixel with
/// `decide(tree, west, above, x)` from its west neighbour's label and the row above (`None` on
/// the strip's first row). Returns labels used.
#[inline(always)]
fn strip_pass(
    mask: &[u8],
    w: usize,
    labels: &mut [u32],
    parent: &mut [u32],
    base: u32,
    decide: impl Fn(&mut Local, u32, Option<&[u32]>, usize) -> u32,
) -> u32 {
    let mut t = Local {
        parent,
        base,
        next: 0,
    };
    for (y, row) in mask.chunks_exact(w).enumerate() {
        let (done, rest) = labels.split_at_mut(y * w);
        let cur = &mut rest[..w];
        let above: Option<&[u32]> = (y > 0).then(|| &done[(y - 1) * w..]);
        let mut x = 0;
        while x < w {
            if x + WORD <= w && is_zero_word(&row[x..x + WORD]) {
                cur[x..x + WORD].fill(0);
                x += WORD;
                continue;
            }
            if row[x] == 0 {
                cur[x] = 0;
                x += 1;
                continue;
            }
            let west = if x > 0 { cur[x - 1] } else { 0 };
            cur[x] = decide(&mut t, west, above, x);
            x += 1;
        }
    }
    t.next
}

/// First pass with 8-connectivity (Wu's decision tree: the pixel above touches all other
/// scanned neighbours, so when it is set no union is needed).
fn strip_pass8(mask: &[u8], w: usize, labels: &mut [u32], parent: &mut [u32], base: u32) -> u32 {
    strip_pass(mask, w, labels, parent, base, |t, west, above, x| {
        let Some(up) = above else {
            return if west != 0 { west } else { t.new_label() };
        };
        let n = up[x];
        if n != 0 {
            return n;
        }
        let ne = if x + 1 < w { up[x + 1] } else { 0 };
        let nw = if x > 0 { up[x - 1] } else { 0 };
        if ne != 0 {
            if west != 0 {
                t.union(ne, west)
            } else if nw != 0 {
                t.union(ne, nw)
            } else {
                ne
            }
        } else if west != 0 {
            west
        } else if nw != 0 {
            nw
        } else {
            t.new_label()
        }
    })
}

/// First pass with 4-connectivity.
fn strip_pass4(mask: &[u8], w: usize, labels: &mut [u32], parent: &mut [u32], base: u32) -> u32 {
    strip_pass(mask, w, labels, parent, base, |t, west, above, x| {
        let north = above.map_or(0, |up| up[x]);
        match (west != 0, north != 0) {
            (true, true) => t.union(west, north),
            (true, false) => west,
            (false, true) => north,
            (false, false) => t.new_label(),
        }
    })
}
