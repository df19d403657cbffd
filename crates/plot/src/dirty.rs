//! Which stretches of a white canvas a figure's drawing may have touched, so that the 2 x 2
//! average reads only those: the rest is still white, and most of a figure is background (38
//! to 73 % of the stretches of `reproduce`'s figures stay white), while reading a 26 to 35 MB
//! canvas back from memory was most of the average's cost.
//!
//! A cell is [`STRETCH`] canvas pixels wide and two rows tall: one stretch of one pair of rows
//! of the average. Every draw call that reaches the bitmap marks the cells of a box holding
//! every pixel it can set (a pixel's own cell, a rectangle's, a line's box widened by its
//! width), so the marks cover the drawing: an unmarked cell was never written.

/// Canvas pixels per cell, across: the average's stretch (`render::WHITE_RUN`).
pub(crate) const STRETCH: usize = 64;

/// The cells of a `w` x `h` canvas that drawing may have touched.
pub(crate) struct Dirty {
    w: i32,
    h: i32,
    across: usize,
    cells: Vec<bool>,
}

impl Dirty {
    /// A canvas nothing has touched yet.
    pub(crate) fn new(w: u32, h: u32) -> Self {
        let across = (w as usize).div_ceil(STRETCH);
        Self {
            w: w as i32,
            h: h as i32,
            across,
            cells: vec![false; across * (h as usize).div_ceil(2)],
        }
    }

    /// Marks the cell of pixel `(x, y)` (none off the canvas, where the bitmap draws nothing).
    #[inline]
    pub(crate) fn pixel(&mut self, (x, y): (i32, i32)) {
        if (0..self.w).contains(&x) && (0..self.h).contains(&y) {
            let i = (y as usize / 2) * self.across + x as usize / STRETCH;
            self.cells[i] = true;
        }
    }

    /// Marks every cell meeting the box with corners `a` and `b` (inclusive, in any order)
    /// widened by `margin` pixels on every side, clipped to the canvas.
    pub(crate) fn rect(&mut self, a: (i32, i32), b: (i32, i32), margin: i32) {
        let lo = |p: i32, q: i32| i64::from(p.min(q)) - i64::from(margin);
        let hi = |p: i32, q: i32| i64::from(p.max(q)) + i64::from(margin);
        let (x0, x1) = (lo(a.0, b.0).max(0), hi(a.0, b.0).min(i64::from(self.w) - 1));
        let (y0, y1) = (lo(a.1, b.1).max(0), hi(a.1, b.1).min(i64::from(self.h) - 1));
        if x0 > x1 || y0 > y1 {
            return;
        }
        let (c0, c1) = (x0 as usize / STRETCH, x1 as usize / STRETCH);
        for pair in y0 as usize / 2..=y1 as usize / 2 {
            self.cells[pair * self.across..][c0..=c1].fill(true);
        }
    }

    /// Marks the whole canvas (a draw call whose extent is not known here).
    pub(crate) fn all(&mut self) {
        self.cells.fill(true);
    }

    /// Whether stretch `k` of row pair `pair` may have been drawn on.
    #[inline]
    pub(crate) fn touched(&self, pair: usize, k: usize) -> bool {
        self.cells[pair * self.across + k]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The marked cells as (pair, stretch) pairs.
    fn marked(d: &Dirty) -> Vec<(usize, usize)> {
        let pairs = d.cells.len() / d.across;
        (0..pairs)
            .flat_map(|p| (0..d.across).map(move |k| (p, k)))
            .filter(|&(p, k)| d.touched(p, k))
            .collect()
    }

    #[test]
    fn pixels_mark_their_cell_and_nothing_off_the_canvas() {
        // 130 x 5: three stretches across (64, 64, 2), three pairs down (the last one row).
        let mut d = Dirty::new(130, 5);
        for p in [(-1, 0), (0, -1), (130, 0), (0, 5), (i32::MIN, i32::MAX)] {
            d.pixel(p);
        }
        assert!(marked(&d).is_empty());
        d.pixel((63, 1));
        d.pixel((64, 2));
        d.pixel((129, 4));
        assert_eq!(marked(&d), vec![(0, 0), (1, 1), (2, 2)]);
    }

    #[test]
    fn boxes_mark_every_cell_they_meet_widened_and_clipped() {
        let mut d = Dirty::new(200, 10);
        // Corners in any order; 63..=64 spans two stretches, rows 3..=4 two pairs.
        d.rect((64, 4), (63, 3), 0);
        assert_eq!(marked(&d), vec![(1, 0), (1, 1), (2, 0), (2, 1)]);
        let mut d = Dirty::new(200, 10);
        // A margin of 2 takes 130 to 128 (stretch 2) and row 5 to rows 3..=7.
        d.rect((130, 5), (130, 5), 2);
        assert_eq!(marked(&d), vec![(1, 2), (2, 2), (3, 2)]);
        // Off the canvas: nothing; across it, extreme coordinates: clipped, no overflow.
        let mut d = Dirty::new(200, 10);
        d.rect((-50, -50), (-2, -1), 1);
        d.rect((300, 0), (400, 9), 5);
        assert!(marked(&d).is_empty());
        d.rect((i32::MIN, i32::MIN), (i32::MAX, i32::MAX), i32::MAX);
        assert_eq!(marked(&d).len(), 4 * 5);
        let mut d = Dirty::new(200, 10);
        d.all();
        assert_eq!(marked(&d).len(), 4 * 5);
    }
}
