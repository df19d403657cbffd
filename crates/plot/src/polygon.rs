//! plotters' polygon fill (`plotters_backend::rasterizer::fill_polygon`, 0.3.7) without its
//! per-row costs: it allocated a new list of active edges for every sweep line and sorted the
//! list with a comparison that divides twice per call. The figures' data lines (wide paths
//! made polygons of thousands of vertices) spent about 1 % of a `reproduce` there. This is
//! the same sweep, the same edges in the same order and the same draw calls with the same
//! arguments in the same order: the lists are kept between sweep lines and each edge's
//! position on the line is computed once before a stable sort, which orders as the
//! comparison did (a stable sort's result depends only on its comparisons). Tested against
//! plotters' own fill on seeded polygons.

use plotters_backend::{BackendCoord, BackendStyle, DrawingBackend, DrawingErrorKind};

/// An edge on the sweep: plotters' `Edge`, with its position on the current sweep line.
#[derive(Clone, Copy)]
struct Edge {
    epoch: u32,
    total_epoch: u32,
    slave_begin: i32,
    slave_end: i32,
    /// [`Edge::slave_pos`] at the current epoch.
    pos: f64,
}

impl Edge {
    fn horizontal_sweep(mut from: BackendCoord, mut to: BackendCoord) -> Option<Edge> {
        if from.0 == to.0 {
            return None;
        }
        if from.0 > to.0 {
            std::mem::swap(&mut from, &mut to);
        }
        let mut e = Edge {
            epoch: 0,
            total_epoch: (to.0 - from.0) as u32,
            slave_begin: from.1,
            slave_end: to.1,
            pos: 0.0,
        };
        e.pos = e.slave_pos();
        Some(e)
    }

    fn vertical_sweep(from: BackendCoord, to: BackendCoord) -> Option<Edge> {
        Edge::horizontal_sweep((from.1, from.0), (to.1, to.0))
    }

    fn master_pos(&self) -> i32 {
        (self.total_epoch - self.epoch) as i32
    }

    fn inc_epoch(&mut self) {
        self.epoch += 1;
        self.pos = self.slave_pos();
    }

    /// plotters' `get_slave_pos`, the same expression.
    fn slave_pos(&self) -> f64 {
        f64::from(self.slave_begin)
            + (i64::from(self.slave_end - self.slave_begin) * i64::from(self.epoch)) as f64
                / f64::from(self.total_epoch)
    }
}

/// plotters' `rasterizer::fill_polygon` on `back`: the same pixels, drawn by the same calls.
pub(crate) fn fill_polygon<DB: DrawingBackend, S: BackendStyle>(
    back: &mut DB,
    vertices: &[BackendCoord],
    style: &S,
) -> Result<(), DrawingErrorKind<DB::ErrorType>> {
    let Some(((x_lo, x_hi), (y_lo, y_hi))) =
        vertices
            .iter()
            .fold(None, |res: Option<((i32, i32), (i32, i32))>, &(x, y)| {
                Some(
                    res.map(|((min_x, max_x), (min_y, max_y))| {
                        ((min_x.min(x), max_x.max(x)), (min_y.min(y), max_y.max(y)))
                    })
                    .unwrap_or(((x, x), (y, y))),
                )
            })
    else {
        return Ok(());
    };
    // Every point on one vertical or horizontal line.
    if x_lo == x_hi || y_lo == y_hi {
        return back.draw_line((x_lo, y_lo), (x_hi, y_hi), style);
    }
    let horizontal_sweep = x_hi - x_lo > y_hi - y_lo;
    let mut edges: Vec<(BackendCoord, BackendCoord)> = vertices
        .iter()
        .zip(vertices.iter().skip(1))
        .map(|(a, b)| (*a, *b))
        .collect();
    edges.push((vertices[vertices.len() - 1], vertices[0]));
    edges.sort_by_key(|((x1, y1), (x2, y2))| {
        if horizontal_sweep {
            *x1.min(x2)
        } else {
            *y1.min(y2)
        }
    });
    for edge in &mut edges {
        if horizontal_sweep {
            if (edge.0).0 > (edge.1).0 {
                std::mem::swap(&mut edge.0, &mut edge.1);
            }
        } else if (edge.0).1 > (edge.1).1 {
            std::mem::swap(&mut edge.0, &mut edge.1);
        }
    }
    let (low, high) = if horizontal_sweep {
        (x_lo, x_hi)
    } else {
        (y_lo, y_hi)
    };
    let color = style.color();
    let mut idx = 0;
    let mut active: Vec<Edge> = Vec::new();
    for sweep_line in low..=high {
        // The edges that go on, one epoch further, in their order.
        active.retain_mut(|e| {
            let on = e.master_pos() > 0;
            if on {
                e.inc_epoch();
            }
            on
        });
        while idx < edges.len() {
            let line = if horizontal_sweep {
                (edges[idx].0).0
            } else {
                (edges[idx].0).1
            };
            if line > sweep_line {
                break;
            }
            let e = if horizontal_sweep {
                Edge::horizontal_sweep(edges[idx].0, edges[idx].1)
            } else {
                Edge::vertical_sweep(edges[idx].0, edges[idx].1)
            };
            active.extend(e);
            idx += 1;
        }
        // plotters' `sort()` on `Ord` by the position (`partial_cmp().unwrap()`; never NaN:
        // `total_epoch` > 0): stable, as this is.
        active.sort_by(|a, b| a.pos.partial_cmp(&b.pos).unwrap());
        let mut first: Option<Edge> = None;
        let mut second: Option<Edge> = None;
        for &edge in &active {
            if first.is_none() {
                first = Some(edge)
            } else if second.is_none() {
                second = Some(edge)
            }
            if let (Some(a), Some(b)) = (first, second) {
                if a.master_pos() == 0 && b.master_pos() != 0 {
                    first = Some(b);
                    second = None;
                    continue;
                }
                if a.master_pos() != 0 && b.master_pos() == 0 {
                    first = Some(a);
                    second = None;
                    continue;
                }
                let (from, to) = (a.pos, b.pos);
                if a.master_pos() == 0 && b.master_pos() == 0 && to - from > 1.0 {
                    first = None;
                    second = None;
                    continue;
                }
                if horizontal_sweep {
                    back.draw_line(
                        (sweep_line, from.ceil() as i32),
                        (sweep_line, to.floor() as i32),
                        &color,
                    )?;
                    back.draw_pixel(
                        (sweep_line, from.floor() as i32),
                        color.mix(from.ceil() - from),
                    )?;
                    back.draw_pixel((sweep_line, to.ceil() as i32), color.mix(to - to.floor()))?;
                } else {
                    back.draw_line(
                        (from.ceil() as i32, sweep_line),
                        (to.floor() as i32, sweep_line),
                        &color,
                    )?;
                    back.draw_pixel(
                        (from.floor() as i32, sweep_line),
                        color.mix(from.ceil() - from),
                    )?;
                    back.draw_pixel((to.ceil() as i32, sweep_line), color.mix(to.floor() - to))?;
                }
                first = None;
                second = None;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::fast_lines::FastLines;
    use plotters::prelude::*;
    use plotters_backend::{BackendCoord, DrawingBackend};

    const W: u32 = 64;
    const H: u32 = 48;

    #[test]
    fn fills_as_plotters_fills() {
        // Seeded: polygons of 0 to 40 vertices in and around the canvas (degenerate ones,
        // self-crossing ones, repeated points), and the polygons plotters makes of wide
        // paths (the figures' data lines), opaque and translucent: the pixels of plotters'
        // own `fill_polygon` on the bitmap, and the same on a canvas drawn over twice.
        let mut next = crate::seeded(0xA076_1D64_78BD_642F);
        for case in 0..3000 {
            let mut point = || (next(W as i32 + 30) - 15, next(H as i32 + 30) - 15);
            let polygon: Vec<BackendCoord> = if case % 3 == 0 {
                let path: Vec<BackendCoord> = (0..2 + case % 30).map(|_| point()).collect();
                plotters_backend::rasterizer::polygonize(&path, 2 + (case % 7) as u32)
            } else {
                (0..case % 41).map(|_| point()).collect()
            };
            let colour = RGBColor(next(256) as u8, next(256) as u8, 200);
            let c = if case % 4 == 3 {
                colour.mix(0.45)
            } else {
                colour.to_rgba()
            };
            let mut plain = vec![255u8; (W * H * 3) as usize];
            let mut fast = plain.clone();
            {
                let mut p = BitMapBackend::with_buffer(&mut plain, (W, H));
                let mut f = FastLines(BitMapBackend::with_buffer(&mut fast, (W, H)), None);
                for _ in 0..2 {
                    plotters_backend::rasterizer::fill_polygon(&mut p, &polygon, &c).unwrap();
                    f.fill_polygon(polygon.iter().copied(), &c).unwrap();
                }
            }
            assert!(plain == fast, "case {case}: {polygon:?}, colour {c:?}");
        }
    }
}
