//! The screen coverage structure of the front-to-back renderer: one bit a pixel in row spans of 64, plus
//! a count of uncovered pixels per row and in all. A node whose screen rectangle is wholly covered is
//! skipped with its subtree; once every pixel is covered the traversal stops.
//!
//! ```
//! use ktree::display::Coverage;
//! let mut c = Coverage::new(4, 2);
//! assert_eq!(c.uncovered(), 8);
//! c.cover(1, 0);
//! c.cover(2, 0);
//! // Rectangles are inclusive: [1, 2] × [0, 0] is covered, [0, 2] × [0, 0] is not.
//! assert!(c.is_covered(1, 0) && c.rect_covered(1, 2, 0, 0) && !c.rect_covered(0, 2, 0, 0));
//! assert_eq!(c.uncovered(), 6);
//! ```

/// Which pixels of a `width × height` screen have been painted.
#[derive(Debug, Clone)]
pub struct Coverage {
    width: u32,
    height: u32,
    words_per_row: usize,
    bits: Vec<u64>,
    row_uncovered: Vec<u32>,
    uncovered: u64,
}

impl Coverage {
    /// A screen with nothing covered.
    pub fn new(width: u32, height: u32) -> Self {
        let words_per_row = (width as usize).div_ceil(64);
        Self {
            width,
            height,
            words_per_row,
            bits: vec![0; words_per_row * height as usize],
            row_uncovered: vec![width; height as usize],
            uncovered: u64::from(width) * u64::from(height),
        }
    }

    /// Pixels not yet covered.
    pub fn uncovered(&self) -> u64 {
        self.uncovered
    }

    /// Whether pixel `(x, y)` is covered.
    #[inline]
    pub fn is_covered(&self, x: u32, y: u32) -> bool {
        let w = self.bits[y as usize * self.words_per_row + (x / 64) as usize];
        w >> (x % 64) & 1 == 1
    }

    /// Marks pixel `(x, y)` covered (it must not be yet).
    #[inline]
    pub fn cover(&mut self, x: u32, y: u32) {
        let i = y as usize * self.words_per_row + (x / 64) as usize;
        debug_assert!(self.bits[i] >> (x % 64) & 1 == 0);
        self.bits[i] |= 1 << (x % 64);
        self.row_uncovered[y as usize] -= 1;
        self.uncovered -= 1;
    }

    /// Whether every pixel of the rectangle `[x0, x1] × [y0, y1]` (inclusive, inside the screen) is covered.
    pub fn rect_covered(&self, x0: u32, x1: u32, y0: u32, y1: u32) -> bool {
        debug_assert!(x1 < self.width && y1 < self.height);
        let (w0, w1) = ((x0 / 64) as usize, (x1 / 64) as usize);
        let first_mask = !0u64 << (x0 % 64);
        let last_mask = !0u64 >> (63 - x1 % 64);
        for y in y0..=y1 {
            if self.row_uncovered[y as usize] == 0 {
                continue;
            }
            let row = &self.bits[y as usize * self.words_per_row..];
            if w0 == w1 {
                let m = first_mask & last_mask;
                if row[w0] & m != m {
                    return false;
                }
            } else {
                if row[w0] & first_mask != first_mask || row[w1] & last_mask != last_mask {
                    return false;
                }
                if row[w0 + 1..w1].iter().any(|&w| w != !0) {
                    return false;
                }
            }
        }
        true
    }

    /// Calls `hit(x)` for every uncovered pixel of row `y` in `[x0, x1]`, in order, and covers the pixels
    /// for which it returns `true`. Returns how many were covered.
    #[inline]
    pub fn cover_where(
        &mut self,
        y: u32,
        x0: u32,
        x1: u32,
        mut hit: impl FnMut(u32) -> bool,
    ) -> u32 {
        if self.row_uncovered[y as usize] == 0 {
            return 0;
        }
        let (w0, w1) = ((x0 / 64) as usize, (x1 / 64) as usize);
        let base = y as usize * self.words_per_row;
        let mut count = 0;
        for w in w0..=w1 {
            let mut free = !self.bits[base + w];
            if w == w0 {
                free &= !0u64 << (x0 % 64);
            }
            if w == w1 {
                free &= !0u64 >> (63 - x1 % 64);
            }
            let mut set = 0u64;
            while free != 0 {
                let bit = free.trailing_zeros();
                free &= free - 1;
                if hit(w as u32 * 64 + bit) {
                    set |= 1 << bit;
                }
            }
            self.bits[base + w] |= set;
            count += set.count_ones();
        }
        self.row_uncovered[y as usize] -= count;
        self.uncovered -= u64::from(count);
        count
    }

    /// Calls `visit(x)` for every uncovered pixel of row `y` in `[x0, x1]`, in order. `visit` may cover
    /// pixels of the row (the ones it is given).
    #[inline]
    pub fn for_each_uncovered(&self, y: u32, x0: u32, x1: u32, mut visit: impl FnMut(u32) -> bool) {
        if self.row_uncovered[y as usize] == 0 {
            return;
        }
        let (w0, w1) = ((x0 / 64) as usize, (x1 / 64) as usize);
        let base = y as usize * self.words_per_row;
        for w in w0..=w1 {
            let mut free = !self.bits[base + w];
            if w == w0 {
                free &= !0u64 << (x0 % 64);
            }
            if w == w1 {
                free &= !0u64 >> (63 - x1 % 64);
            }
            while free != 0 {
                let bit = free.trailing_zeros();
                free &= free - 1;
                if !visit(w as u32 * 64 + bit) {
                    return;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coverage_matches_a_plain_bitmap() {
        let (w, h) = (130u32, 5u32);
        let mut c = Coverage::new(w, h);
        let mut plain = vec![false; (w * h) as usize];
        let mut x = 7u32;
        for _ in 0..400 {
            x = x.wrapping_mul(1103515245).wrapping_add(12345);
            let (px, py) = ((x >> 8) % w, (x >> 20) % h);
            if !plain[(py * w + px) as usize] {
                plain[(py * w + px) as usize] = true;
                c.cover(px, py);
            }
            let (a, b) = ((x >> 3) % w, (x >> 13) % w);
            let (x0, x1) = (a.min(b), a.max(b));
            let all = (0..h).all(|y| (x0..=x1).all(|x| plain[(y * w + x) as usize]));
            assert_eq!(c.rect_covered(x0, x1, 0, h - 1), all);
            let mut seen = Vec::new();
            c.for_each_uncovered(2, x0, x1, |x| {
                seen.push(x);
                true
            });
            let want: Vec<u32> = (x0..=x1)
                .filter(|&x| !plain[(2 * w + x) as usize])
                .collect();
            assert_eq!(seen, want);
        }
        let n = plain.iter().filter(|&&p| !p).count() as u64;
        assert_eq!(c.uncovered(), n);
    }
}
