//! Figure description: series of (x, y) data with a style, axis labels and a title.

use plotters::style::RGBColor;

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SeriesStyle {
    /// Filled markers (measurements): the first `Points` series of a figure gets circles, the
    /// next smaller triangles, squares and diamonds, so coincident series stay visible.
    Points,
    /// Larger hollow circles, drawn after every filled marker and line so they are never
    /// hidden (a second measured series over the first).
    OpenPoints,
    /// Solid line (simulation, theory).
    Line,
    /// Dashed line (second model, limits).
    DashedLine,
}

/// One data series; its colour is `PALETTE[index % PALETTE.len()]` by position in the figure.
/// Non-finite points are skipped (lines break there).
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend text; an empty name gives no legend entry.
    pub name: String,
    /// Drawing style.
    pub style: SeriesStyle,
    /// Abscissae (same length as `ys`; extra values of the longer one are ignored).
    pub xs: Vec<f64>,
    /// Ordinates.
    pub ys: Vec<f64>,
}

impl Series {
    /// A series from owned data.
    pub fn new(name: impl Into<String>, style: SeriesStyle, xs: Vec<f64>, ys: Vec<f64>) -> Self {
        Series {
            name: name.into(),
            style,
            xs,
            ys,
        }
    }
}

/// A 2-D figure. `width_px`/`height_px` are used by [`render_png`](crate::render_png); panels of
/// [`render_panels_png`](crate::render_panels_png) take their size from the grid.
#[derive(Clone, Debug)]
pub struct Figure {
    /// Title above the plot (empty: none).
    pub title: String,
    /// X-axis label including its unit, e.g. `"Frequency (Hz)"`.
    pub x_label: String,
    /// Y-axis label including its unit.
    pub y_label: String,
    /// Series in drawing (and colour) order.
    pub series: Vec<Series>,
    /// Image width.
    pub width_px: u32,
    /// Image height.
    pub height_px: u32,
    /// Logarithmic x axis (decades labelled 10^n; values <= 0 are skipped).
    pub x_log: bool,
    /// Logarithmic y axis, for quantities spanning decades (spectra, Allan deviation).
    pub y_log: bool,
    /// Labelled vertical lines at known abscissae (a carrier, its sidebands).
    pub markers: Vec<Marker>,
}

/// A dashed vertical line at `x` with a short label at the top of the plot.
#[derive(Clone, Debug, PartialEq)]
pub struct Marker {
    /// Abscissa, in data units.
    pub x: f64,
    /// Text drawn beside the line's top (empty: none).
    pub label: String,
}

impl Figure {
    /// An empty 900 x 650 px figure.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Figure {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series: Vec::new(),
            width_px: 900,
            height_px: 650,
            x_log: false,
            y_log: false,
            markers: Vec::new(),
        }
    }

    /// A logarithmic x axis (builder style).
    pub fn log_x(mut self) -> Self {
        self.x_log = true;
        self
    }

    /// A logarithmic y axis (builder style).
    pub fn log_y(mut self) -> Self {
        self.y_log = true;
        self
    }

    /// Adds a labelled vertical marker (builder style).
    pub fn with_marker(mut self, x: f64, label: impl Into<String>) -> Self {
        self.markers.push(Marker {
            x,
            label: label.into(),
        });
        self
    }

    /// Adds a series (builder style).
    pub fn with(mut self, s: Series) -> Self {
        self.series.push(s);
        self
    }
}

/// Fixed series colours (matplotlib's "tab10" order, black last): distinct in print and for
/// the common colour-vision deficiencies between neighbours.
pub const PALETTE: [RGBColor; 9] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(23, 190, 207),
    RGBColor(127, 127, 127),
    RGBColor(0, 0, 0),
];
