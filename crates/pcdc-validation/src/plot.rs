//! Minimal PNG line/scatter plotting for validation figures.
//!
//! Draws "numerical points over the analytic curve" style figures: any number
//! of line and/or point series, a title, axis labels, a mesh grid and a legend.
//! Text is rendered with the DejaVu Sans font embedded in the binary, so no
//! system fonts or font libraries are needed at build or run time.
//!
//! ```no_run
//! use pcdc_validation::plot::Plot;
//! let x: Vec<f64> = (0..=50).map(|i| i as f64 * 0.1).collect();
//! let y: Vec<f64> = x.iter().map(|t| t.sin()).collect();
//! Plot::new("Sine", "t [s]", "u [m]")
//!     .line("analytic", x.clone(), y.clone())
//!     .points("numerical", x, y)
//!     .save_png("target/figures/sine.png")?;
//! # Ok::<(), pcdc_validation::plot::PlotError>(())
//! ```

use std::path::Path;
use std::sync::OnceLock;

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

/// Errors produced while validating or rendering a [`Plot`].
#[derive(Debug, thiserror::Error)]
#[allow(missing_docs)] // variant fields are named after what they hold
pub enum PlotError {
    /// The plot has no series at all.
    #[error("plot has no series")]
    NoSeries,
    /// The named series has no points.
    #[error("series '{0}' is empty")]
    EmptySeries(String),
    /// The named series has `x_len` x values but `y_len` y values.
    #[error("series '{label}': x has {x_len} values but y has {y_len}")]
    LengthMismatch {
        label: String,
        x_len: usize,
        y_len: usize,
    },
    /// `axis[index]` of the named series is NaN or infinite.
    #[error("series '{label}': {axis}[{index}] = {value} is not finite")]
    NonFinite {
        label: String,
        axis: &'static str,
        index: usize,
        value: f64,
    },
    /// `axis[index]` of the named series is `<= 0` on a logarithmic axis.
    #[error("series '{label}': {axis}[{index}] = {value} is not positive on a log axis")]
    NonPositiveLog {
        label: String,
        axis: &'static str,
        index: usize,
        value: f64,
    },
    /// The data range `[lo, hi]` of `axis` is too wide to plot in `f64`.
    #[error("{axis} data range [{lo}, {hi}] is too wide to plot")]
    Range {
        axis: &'static str,
        lo: f64,
        hi: f64,
    },
    /// Width or height is zero or larger than 16384 pixels.
    #[error("invalid image size {0}x{1}")]
    InvalidSize(u32, u32),
    /// The output path does not end in `.png`.
    #[error("output path '{0}' must have a .png extension")]
    NotPng(String),
    /// The embedded font could not be registered.
    #[error("failed to register embedded font")]
    Font,
    /// Creating the output directory failed.
    #[error("i/o error: {0}")]
    Io(#[from] std::io::Error),
    /// Rendering or PNG encoding failed.
    #[error("drawing error: {0}")]
    Drawing(String),
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeriesStyle {
    /// Connected line (e.g. an analytic solution).
    Line,
    /// Unconnected circular markers (e.g. numerical samples).
    Points,
    /// Line with markers at the data points.
    LinePoints,
}

/// One data series of a [`Plot`].
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Abscissae.
    pub x: Vec<f64>,
    /// Ordinates; must have the same length as `x`.
    pub y: Vec<f64>,
    /// Drawing style.
    pub style: SeriesStyle,
}

/// A 2-D line/scatter figure rendered to PNG.
#[derive(Debug, Clone)]
pub struct Plot {
    /// Figure title.
    pub title: String,
    /// X axis label.
    pub x_label: String,
    /// Y axis label.
    pub y_label: String,
    /// Series in drawing order (later series are drawn on top).
    pub series: Vec<Series>,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Logarithmic x axis.
    pub log_x: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
}

const FONT: &str = "sans-serif";
/// Largest accepted image side in pixels (guards against huge allocations).
const MAX_SIDE: u32 = 16_384;

/// More series than this get their legend in a column beside the chart instead of
/// inside it, where it would hide the data.
const LEGEND_INSIDE_MAX: usize = 8;

/// Marker of series `i`: the colours cycle every ten series and the shape (circle,
/// triangle, square) changes with each cycle, so up to 30 series stay distinct.
fn marker_shape(i: usize) -> usize {
    (i / COLORS.len()) % 3
}

/// Distinct colours (matplotlib "tab10"); cycled for more series.
const COLORS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Registers the embedded DejaVu fonts once per process.
fn ensure_fonts() -> Result<(), PlotError> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE.get_or_init(|| {
        register_font(FONT, FontStyle::Normal, dejavu::sans::regular()).is_ok()
            && register_font(FONT, FontStyle::Bold, dejavu::sans::bold()).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(PlotError::Font)
    }
}

/// Padded axis range for `[lo, hi]` (in log space when `log` is set), or
/// `None` when the range cannot be represented.
fn padded(lo: f64, hi: f64, log: bool) -> Option<(f64, f64)> {
    if log {
        let (la, lb) = (lo.log10(), hi.log10());
        let pad = if lb > la { 0.05 * (lb - la) } else { 0.5 };
        let (a, b) = (10f64.powf(la - pad), 10f64.powf(lb + pad));
        let a = if a.is_normal() { a } else { lo };
        let b = if b.is_normal() { b } else { hi };
        // plotters' log ticks loop (practically) forever once b / a overflows.
        return (a.is_normal() && b.is_normal() && b / a < 1e300).then_some((a, b));
    }
    let span = hi - lo;
    let pad = if span > 0.0 {
        0.05 * span
    } else if lo != 0.0 {
        0.1 * lo.abs()
    } else {
        1.0
    };
    let (a, b) = (lo - pad, hi + pad);
    (a.is_finite() && b.is_finite() && (b - a).is_finite()).then_some((a, b))
}

impl Plot {
    /// Creates an empty 900x600 plot with linear axes.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series: Vec::new(),
            width: 900,
            height: 600,
            log_x: false,
            log_y: false,
        }
    }

    /// Adds a series with the given style.
    pub fn series(
        mut self,
        label: impl Into<String>,
        x: Vec<f64>,
        y: Vec<f64>,
        style: SeriesStyle,
    ) -> Self {
        self.series.push(Series {
            label: label.into(),
            x,
            y,
            style,
        });
        self
    }

    /// Adds a line series (e.g. the analytic curve).
    pub fn line(self, label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        self.series(label, x, y, SeriesStyle::Line)
    }

    /// Adds a marker-only series (e.g. numerical results).
    pub fn points(self, label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        self.series(label, x, y, SeriesStyle::Points)
    }

    /// Adds a line series with markers at the data points.
    pub fn line_points(self, label: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        self.series(label, x, y, SeriesStyle::LinePoints)
    }

    /// Uses a logarithmic x axis; all x values must then be positive.
    pub fn log_x(mut self, yes: bool) -> Self {
        self.log_x = yes;
        self
    }

    /// Uses a logarithmic y axis; all y values must then be positive.
    pub fn log_y(mut self, yes: bool) -> Self {
        self.log_y = yes;
        self
    }

    /// Sets the image size in pixels.
    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.width = width;
        self.height = height;
        self
    }

    /// Validates the data and returns the padded x and y axis ranges.
    fn ranges(&self) -> Result<[(f64, f64); 2], PlotError> {
        if self.series.is_empty() {
            return Err(PlotError::NoSeries);
        }
        let mut bounds = [(f64::INFINITY, f64::NEG_INFINITY); 2];
        for s in &self.series {
            let (label, x_len, y_len) = (s.label.clone(), s.x.len(), s.y.len());
            if x_len != y_len {
                return Err(PlotError::LengthMismatch {
                    label,
                    x_len,
                    y_len,
                });
            }
            if x_len == 0 {
                return Err(PlotError::EmptySeries(label));
            }
            let axes = [("x", &s.x, self.log_x), ("y", &s.y, self.log_y)];
            for ((axis, data, log), bound) in axes.into_iter().zip(&mut bounds) {
                for (index, &value) in data.iter().enumerate() {
                    let label = s.label.clone();
                    if !value.is_finite() {
                        return Err(PlotError::NonFinite {
                            label,
                            axis,
                            index,
                            value,
                        });
                    }
                    if log && value <= 0.0 {
                        return Err(PlotError::NonPositiveLog {
                            label,
                            axis,
                            index,
                            value,
                        });
                    }
                    *bound = (bound.0.min(value), bound.1.max(value));
                }
            }
        }
        let mut out = [(0.0, 0.0); 2];
        for (k, (axis, log)) in [("x", self.log_x), ("y", self.log_y)]
            .into_iter()
            .enumerate()
        {
            let (lo, hi) = bounds[k];
            out[k] = padded(lo, hi, log).ok_or(PlotError::Range { axis, lo, hi })?;
        }
        Ok(out)
    }

    /// Picks the legend corner covering the fewest data points.
    fn legend_corner(&self, [xr, yr]: [(f64, f64); 2]) -> SeriesLabelPosition {
        let norm = |v: f64, (lo, hi): (f64, f64), log: bool| match log {
            true => (v / lo).ln() / (hi / lo).ln(),
            false => (v - lo) / (hi - lo),
        };
        let mut counts = [0usize; 4]; // upper-right, upper-left, lower-right, lower-left
        for s in &self.series {
            for (&x, &y) in s.x.iter().zip(&s.y) {
                let (u, v) = (norm(x, xr, self.log_x), norm(y, yr, self.log_y));
                let (right, left, top, bottom) = (u > 0.6, u < 0.4, v > 0.65, v < 0.35);
                counts[0] += usize::from(right && top);
                counts[1] += usize::from(left && top);
                counts[2] += usize::from(right && bottom);
                counts[3] += usize::from(left && bottom);
            }
        }
        match (0..4).min_by_key(|&i| counts[i]) {
            Some(1) => SeriesLabelPosition::UpperLeft,
            Some(2) => SeriesLabelPosition::LowerRight,
            Some(3) => SeriesLabelPosition::LowerLeft,
            _ => SeriesLabelPosition::UpperRight,
        }
    }

    /// Renders the plot to a PNG file, creating parent directories as needed.
    pub fn save_png(&self, path: impl AsRef<Path>) -> Result<(), PlotError> {
        let path = path.as_ref();
        if !(1..=MAX_SIDE).contains(&self.width) || !(1..=MAX_SIDE).contains(&self.height) {
            return Err(PlotError::InvalidSize(self.width, self.height));
        }
        let is_png = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        if !is_png {
            return Err(PlotError::NotPng(path.display().to_string()));
        }
        let ranges = self.ranges()?;
        let [(x0, x1), (y0, y1)] = ranges;
        ensure_fonts()?;
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        let root = BitMapBackend::new(path, (self.width, self.height)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        // Many series: the legend gets its own column on the right.
        let (area, side) = if self.series.len() > LEGEND_INSIDE_MAX {
            let text = self.text_size() * 0.8;
            let longest = self.series.iter().map(|s| s.label.chars().count()).max();
            let want = (longest.unwrap_or(0) as f64 * 0.55 + 4.0) * text;
            let w = (want as u32).min(self.width / 2);
            let (a, b) = root.split_horizontally(self.width - w);
            (a, Some(b))
        } else {
            (root.clone(), None)
        };
        let pos = self.legend_corner(ranges);
        let inside = side.is_none();
        match (self.log_x, self.log_y) {
            (false, false) => self.draw(&area, pos, inside, x0..x1, y0..y1),
            (true, false) => self.draw(&area, pos, inside, (x0..x1).log_scale(), y0..y1),
            (false, true) => self.draw(&area, pos, inside, x0..x1, (y0..y1).log_scale()),
            (true, true) => self.draw(
                &area,
                pos,
                inside,
                (x0..x1).log_scale(),
                (y0..y1).log_scale(),
            ),
        }?;
        if let Some(side) = side {
            self.draw_side_legend(&side)?;
        }
        root.present().map_err(draw_err)
    }

    /// Base text size (px) for the figure's size.
    fn text_size(&self) -> f64 {
        (self.width.min(self.height) as f64 / 30.0).clamp(10.0, 40.0)
    }

    /// Legend in its own column: a line and marker per series, then its label.
    fn draw_side_legend(
        &self,
        area: &DrawingArea<BitMapBackend<'_>, Shift>,
    ) -> Result<(), PlotError> {
        let short = self.width.min(self.height) as f64;
        let top = short / 40.0 + self.text_size() * 2.0;
        // Every entry fits in the height: the rows (and the text) shrink if needed.
        let room = (self.height as f64 - top - short / 40.0).max(1.0);
        let n = self.series.len().max(1) as f64;
        let step_f = (self.text_size() * 0.8 * 1.35).min(room / n);
        let text = step_f / 1.35;
        let marker = ((short / 150.0).clamp(2.0, 8.0) as i32).min((step_f / 3.0) as i32);
        let stroke = (short / 300.0).clamp(1.0, 4.0) as u32;
        let (step, top) = (step_f as i32, top as i32);
        let line_w = (text * 1.6) as i32;
        let font = (FONT, text).into_font();
        for (i, s) in self.series.iter().enumerate() {
            let color = COLORS[i % COLORS.len()];
            let y = top + i as i32 * step;
            let x = (text * 0.5) as i32;
            if matches!(s.style, SeriesStyle::Line | SeriesStyle::LinePoints) {
                area.draw(&PathElement::new(
                    [(x, y), (x + line_w, y)],
                    color.stroke_width(stroke),
                ))
                .map_err(draw_err)?;
            }
            if matches!(s.style, SeriesStyle::Points | SeriesStyle::LinePoints) {
                draw_marker(area, (x + line_w / 2, y), marker, color, marker_shape(i))?;
            }
            area.draw(&Text::new(
                s.label.as_str(),
                (x + line_w + (text * 0.5) as i32, y - (text * 0.55) as i32),
                font.clone(),
            ))
            .map_err(draw_err)?;
        }
        Ok(())
    }

    /// Draws everything onto `root` with the given axis specifications; the legend goes
    /// inside the chart at `pos` when `legend_inside`.
    fn draw<X, Y>(
        &self,
        root: &DrawingArea<BitMapBackend<'_>, Shift>,
        pos: SeriesLabelPosition,
        legend_inside: bool,
        xs: X,
        ys: Y,
    ) -> Result<(), PlotError>
    where
        X: AsRangedCoord<Value = f64>,
        Y: AsRangedCoord<Value = f64>,
        X::CoordDescType: ValueFormatter<f64>,
        Y::CoordDescType: ValueFormatter<f64>,
    {
        let short = self.width.min(self.height) as f64;
        let text = self.text_size();
        let mut chart = ChartBuilder::on(root)
            .caption(
                &self.title,
                (FONT, text * 1.3).into_font().style(FontStyle::Bold),
            )
            .margin((short / 40.0) as u32)
            .x_label_area_size((text * 3.0) as u32)
            .y_label_area_size((text * 4.5) as u32)
            .build_cartesian_2d(xs, ys)
            .map_err(draw_err)?;
        let mut mesh = chart.configure_mesh();
        mesh.x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .axis_desc_style((FONT, text))
            .label_style((FONT, text * 0.85))
            .light_line_style(BLACK.mix(0.05))
            .bold_line_style(BLACK.mix(0.15));
        if self.log_x {
            mesh.x_label_formatter(&log_label);
        }
        if self.log_y {
            mesh.y_label_formatter(&log_label);
        }
        mesh.draw().map_err(draw_err)?;

        let marker = (short / 150.0).clamp(2.0, 8.0) as i32;
        let stroke = (short / 300.0).clamp(1.0, 4.0) as u32;
        for (i, s) in self.series.iter().enumerate() {
            let color = COLORS[i % COLORS.len()];
            let pts = || s.x.iter().copied().zip(s.y.iter().copied());
            let line = matches!(s.style, SeriesStyle::Line | SeriesStyle::LinePoints);
            let dots = matches!(s.style, SeriesStyle::Points | SeriesStyle::LinePoints);
            if line {
                chart
                    .draw_series(LineSeries::new(pts(), color.stroke_width(stroke)))
                    .map_err(draw_err)?;
            }
            if dots {
                let (r, style) = (marker, color.filled());
                match marker_shape(i) {
                    1 => chart.draw_series(pts().map(|p| TriangleMarker::new(p, r + 1, style))),
                    2 => {
                        chart.draw_series(pts().map(|p| {
                            EmptyElement::at(p) + Rectangle::new([(-r, -r), (r, r)], style)
                        }))
                    }
                    _ => chart.draw_series(pts().map(|p| Circle::new(p, r, style))),
                }
                .map_err(draw_err)?;
            }
            if !legend_inside {
                continue;
            }
            // Attach a zero-element series that only carries the legend entry.
            let legend_size = text as i32;
            chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                .map_err(draw_err)?
                .label(s.label.as_str())
                .legend(move |(x, y)| {
                    let (ls, ms): (ShapeStyle, ShapeStyle) = (
                        if line {
                            color.stroke_width(stroke)
                        } else {
                            TRANSPARENT.into()
                        },
                        if dots {
                            color.filled()
                        } else {
                            TRANSPARENT.into()
                        },
                    );
                    EmptyElement::at((x, y))
                        + PathElement::new([(0, 0), (legend_size, 0)], ls)
                        + Circle::new((legend_size / 2, 0), marker, ms)
                });
        }
        if !legend_inside {
            return Ok(());
        }
        chart
            .configure_series_labels()
            .label_font((FONT, text * 0.9))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.5))
            .position(pos)
            .draw()
            .map_err(draw_err)
    }
}

/// Tick label for a log axis: `1e-5`, `0.01`, `100`, `2.5e6`, free of
/// floating-point noise such as `9.999999999e-5`.
fn log_label(v: &f64) -> String {
    let sci = format!("{:.3e}", v);
    let (mantissa, exp) = sci.split_once('e').unwrap_or((sci.as_str(), "0"));
    let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
    match exp.parse::<i32>() {
        Ok(e) if (-2..=3).contains(&e) => match format!("{mantissa}e{e}").parse::<f64>() {
            Ok(x) => x.to_string(),
            Err(_) => sci,
        },
        _ => format!("{mantissa}e{exp}"),
    }
}

/// Draws a filled marker of `shape` ([`marker_shape`]: 0 circle, 1 triangle, 2 square)
/// centred at pixel `at` with size `r`.
fn draw_marker(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    at: (i32, i32),
    r: i32,
    color: RGBColor,
    shape: usize,
) -> Result<(), PlotError> {
    let (x, y) = at;
    match shape {
        1 => area.draw(&Polygon::new(
            vec![(x, y - r - 1), (x - r - 1, y + r), (x + r + 1, y + r)],
            color.filled(),
        )),
        2 => area.draw(&Rectangle::new(
            [(x - r, y - r), (x + r, y + r)],
            color.filled(),
        )),
        _ => area.draw(&Circle::new((x, y), r, color.filled())),
    }
    .map_err(draw_err)
}

fn draw_err(e: impl std::fmt::Display) -> PlotError {
    PlotError::Drawing(e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> std::path::PathBuf {
        std::env::temp_dir()
            .join(format!("pcdc_plot_test_{}", std::process::id()))
            .join(name)
    }

    /// Checks the PNG signature and returns the IHDR width and height.
    fn png_size(path: &Path) -> (u32, u32) {
        let b = std::fs::read(path).unwrap();
        assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n");
        assert_eq!(&b[12..16], b"IHDR");
        let be = |i: usize| u32::from_be_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
        (be(16), be(20))
    }

    fn sample() -> (Vec<f64>, Vec<f64>) {
        let x: Vec<f64> = (1..=40).map(|i| i as f64 * 0.25).collect();
        let y = x.iter().map(|t| (-0.3 * t).exp()).collect();
        (x, y)
    }

    #[test]
    fn saves_png_with_requested_size() {
        let (x, y) = sample();
        let path = tmp("nested/dir/linear.png");
        Plot::new("Decay", "t [s]", "u [m]")
            .line("analytic", x.clone(), y.clone())
            .points("numerical", x, y)
            .size(640, 480)
            .save_png(&path)
            .unwrap();
        assert_eq!(png_size(&path), (640, 480));
    }

    #[test]
    fn log_axes_and_degenerate_range() {
        let (x, y) = sample();
        let path = tmp("log.png");
        Plot::new("Error", "t", "err")
            .line_points("error", x, y)
            .points("flat", vec![2.0, 2.0], vec![0.5, 0.5])
            .log_x(true)
            .log_y(true)
            .save_png(&path)
            .unwrap();
        assert_eq!(png_size(&path), (900, 600));
        let path = tmp("single.png");
        Plot::new("One", "x", "y")
            .points("p", vec![0.0], vec![0.0])
            .save_png(&path)
            .unwrap();
        assert_eq!(png_size(&path), (900, 600));
    }

    #[test]
    fn edge_cases_do_not_panic() {
        for (w, h) in [(1, 1), (40, 30), (200, 2000)] {
            let path = tmp(&format!("edge_{w}x{h}.png"));
            let p = Plot::new("", "", "").line("", vec![0.0, 1e-300], vec![1e300, 1.0]);
            p.size(w, h).save_png(&path).unwrap();
            assert_eq!(png_size(&path), (w, h));
        }
        let wide = Plot::new("t", "x", "y").line("w", vec![-1e308, 1e308], vec![1.0, 2.0]);
        let err = wide.save_png(tmp("wide.png")).unwrap_err();
        assert!(matches!(err, PlotError::Range { axis: "x", .. }));
        let decades = Plot::new("t", "x", "y").line("d", vec![1.0, 2.0], vec![1e-300, 1e300]);
        let err = decades
            .log_y(true)
            .save_png(tmp("decades.png"))
            .unwrap_err();
        assert!(matches!(err, PlotError::Range { axis: "y", .. }));
    }

    #[test]
    fn log_labels_are_clean() {
        assert_eq!(log_label(&9.999999999e-5), "1e-4");
        assert_eq!(log_label(&0.025000000001), "0.025");
        assert_eq!(log_label(&1000.0), "1000");
        assert_eq!(log_label(&2.5e6), "2.5e6");
    }

    #[test]
    fn mismatched_lengths_error_names_series() {
        let err = Plot::new("t", "x", "y")
            .line("bad", vec![1.0, 2.0], vec![1.0])
            .save_png(tmp("mismatch.png"))
            .unwrap_err();
        assert!(
            matches!(err, PlotError::LengthMismatch { ref label, x_len: 2, y_len: 1 } if label == "bad")
        );
        assert!(err.to_string().contains("bad"));
    }

    #[test]
    fn nan_is_rejected() {
        let err = Plot::new("t", "x", "y")
            .points("num", vec![1.0, 2.0, 3.0], vec![1.0, f64::NAN, 3.0])
            .save_png(tmp("nan.png"))
            .unwrap_err();
        assert!(matches!(
            err,
            PlotError::NonFinite {
                axis: "y",
                index: 1,
                ..
            }
        ));
    }

    #[test]
    fn log_axis_rejects_non_positive() {
        let err = Plot::new("t", "x", "y")
            .line("e", vec![0.0, 1.0], vec![1.0, 2.0])
            .log_x(true)
            .save_png(tmp("logbad.png"))
            .unwrap_err();
        assert!(matches!(
            err,
            PlotError::NonPositiveLog {
                axis: "x",
                index: 0,
                ..
            }
        ));
    }

    #[test]
    fn empty_and_invalid_inputs() {
        let p = Plot::new("t", "x", "y");
        assert!(matches!(p.save_png(tmp("a.png")), Err(PlotError::NoSeries)));
        let p = p.line("e", vec![], vec![]);
        assert!(matches!(
            p.save_png(tmp("b.png")),
            Err(PlotError::EmptySeries(_))
        ));
        let p = Plot::new("t", "x", "y").line("l", vec![1.0], vec![1.0]);
        assert!(matches!(
            p.save_png(tmp("c.txt")),
            Err(PlotError::NotPng(_))
        ));
        let p = p.size(0, 10);
        assert!(matches!(
            p.save_png(tmp("d.png")),
            Err(PlotError::InvalidSize(0, 10))
        ));
    }
}

#[cfg(test)]
mod legend_tests {
    use super::*;

    #[test]
    fn many_series_get_distinct_markers_and_a_side_legend() {
        // Same colour every ten series, so the shape must differ.
        for i in 0..20 {
            assert_ne!(marker_shape(i), marker_shape(i + COLORS.len()));
        }
        let dir = std::env::temp_dir().join(format!("pcdc_legend_{}", std::process::id()));
        let path = dir.join("many.png");
        let mut p = Plot::new("many", "x", "y").log_y(true).size(800, 500);
        for k in 0..30 {
            let x: Vec<f64> = (1..=5).map(|i| i as f64).collect();
            let y = x.iter().map(|t| (k as f64 + 1.0) * t).collect();
            p = p.line_points(format!("a rather long series label number {k}"), x, y);
        }
        p.save_png(&path).unwrap();
        let b = std::fs::read(&path).unwrap();
        let be = |i: usize| u32::from_be_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
        assert_eq!((be(16), be(20)), (800, 500));
        let _ = std::fs::remove_dir_all(dir);
    }
}
