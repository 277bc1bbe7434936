//! Line charts rendered to self-contained SVG (no fonts or scripts needed).
//!
//! Options: logarithmic x and/or y axes (Bode plots, error magnitudes),
//! shaded horizontal bands (confidence bands), and the legend inside the
//! plot (upper right), below it (never covering data) or none.
//!
//! ```
//! use feedid_report::plot::{LineChart, Series};
//! let mut c = LineChart::new("Ramp", "time [ms]", "position [µm]");
//! c.push(Series::new("measured", vec![0.0, 1.0, 2.0], vec![0.0, 1.0, 4.0]));
//! let svg = c.to_svg().unwrap();
//! assert!(svg.starts_with("<svg"));
//! ```

use plotters::coord::ranged1d::ValueFormatter;
use plotters::prelude::*;

use crate::error::{Error, Result};

/// One line of a chart. A non-finite `y` value breaks the line (a gap).
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Abscissae.
    pub x: Vec<f64>,
    /// Ordinates; non-finite values are gaps, never drawn.
    pub y: Vec<f64>,
    /// Draw as a dashed line.
    pub dashed: bool,
    /// Colour index into the chart palette; `None` = next in order.
    pub color: Option<usize>,
}

impl Series {
    /// A solid line with the next palette colour.
    pub fn new(label: &str, x: Vec<f64>, y: Vec<f64>) -> Self {
        Self {
            label: label.to_string(),
            x,
            y,
            dashed: false,
            color: None,
        }
    }

    /// The same series drawn dashed.
    pub fn dashed(mut self) -> Self {
        self.dashed = true;
        self
    }

    /// The same series with palette colour `k`.
    pub fn with_color(mut self, k: usize) -> Self {
        self.color = Some(k);
        self
    }

    /// Runs of consecutive finite points.
    #[cfg(test)]
    fn segments(&self) -> Vec<Vec<(f64, f64)>> {
        self.segments_where(|x, y| x.is_finite() && y.is_finite())
    }

    /// Runs of consecutive points that satisfy `ok`.
    fn segments_where(&self, ok: impl Fn(f64, f64) -> bool) -> Vec<Vec<(f64, f64)>> {
        let mut out = Vec::new();
        let mut cur = Vec::new();
        for (&x, &y) in self.x.iter().zip(&self.y) {
            if ok(x, y) {
                cur.push((x, y));
            } else if !cur.is_empty() {
                out.push(std::mem::take(&mut cur));
            }
        }
        if !cur.is_empty() {
            out.push(cur);
        }
        out
    }
}

/// Palette readable in print and by colour-blind readers (Okabe–Ito), plus grey.
const PALETTE: [RGBColor; 9] = [
    RGBColor(0, 0, 0),
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(240, 228, 66),
    RGBColor(150, 150, 150),
];

/// Palette colour `k` as a CSS hex string.
pub fn palette_hex(k: usize) -> String {
    let c = PALETTE[k % PALETTE.len()];
    format!("#{:02x}{:02x}{:02x}", c.0, c.1, c.2)
}

/// A 2-D line chart with title, axis labels (with units) and a legend.
#[derive(Debug, Clone, PartialEq)]
pub struct LineChart {
    /// Title above the plot.
    pub title: String,
    /// X-axis label with unit.
    pub x_label: String,
    /// Y-axis label with unit.
    pub y_label: String,
    /// The lines.
    pub series: Vec<Series>,
    /// Width \[px\]; default 900.
    pub width: u32,
    /// Height \[px\]; default 420.
    pub height: u32,
    /// Fixed x range; `None` = data range.
    pub x_range: Option<(f64, f64)>,
    /// Fixed y range; `None` = data range with a margin.
    pub y_range: Option<(f64, f64)>,
    /// Logarithmic x axis (frequency plots).
    pub log_x: bool,
    /// Logarithmic y axis; values ≤ 0 are gaps. Default false.
    pub log_y: bool,
    /// Where the legend goes; default [`LegendPosition::Inside`].
    pub legend: LegendPosition,
    /// Shaded horizontal bands drawn under the lines (e.g. confidence bands).
    pub bands: Vec<Band>,
    /// With a fixed y range: a line that leaves through the top or bottom
    /// and comes back through the same edge runs along that edge (one
    /// polyline instead of many; for dense curves). Default false: the line
    /// is cut where it leaves.
    pub pin_to_edges: bool,
}

/// Placement of a chart's legend.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LegendPosition {
    /// Upper right, inside the plot area (may cover data).
    #[default]
    Inside,
    /// In rows under the plot area (never covers data).
    Below,
    /// No legend (single-line charts whose title says it all).
    Hidden,
}

/// A shaded horizontal band `y0 ≤ y ≤ y1` across the whole x range.
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    /// Lower edge (y units).
    pub y0: f64,
    /// Upper edge (y units).
    pub y1: f64,
    /// Legend label (empty: none).
    pub label: String,
}

impl LineChart {
    /// An empty chart.
    pub fn new(title: &str, x_label: &str, y_label: &str) -> Self {
        Self {
            title: title.to_string(),
            x_label: x_label.to_string(),
            y_label: y_label.to_string(),
            series: Vec::new(),
            width: 900,
            height: 420,
            x_range: None,
            y_range: None,
            log_x: false,
            log_y: false,
            legend: LegendPosition::Inside,
            bands: Vec::new(),
            pin_to_edges: false,
        }
    }

    /// The same chart with the legend at `pos`.
    pub fn with_legend(mut self, pos: LegendPosition) -> Self {
        self.legend = pos;
        self
    }

    /// The same chart with the given size \[px\].
    pub fn with_size(mut self, width: u32, height: u32) -> Self {
        self.width = width;
        self.height = height;
        self
    }

    /// Add a line.
    pub fn push(&mut self, s: Series) {
        self.series.push(s);
    }

    /// Whether a point can be drawn on this chart's axes.
    fn drawable(&self, x: f64, y: f64) -> bool {
        x.is_finite() && y.is_finite() && (!self.log_x || x > 0.0) && (!self.log_y || y > 0.0)
    }

    /// Cut a polyline at the fixed axis ranges (exact intersections, in the
    /// axes' linear or log coordinates) so out-of-range data leave the plot
    /// where they really do; with [`LineChart::pin_to_edges`], between leaving
    /// and coming back through the same top or bottom edge the line runs
    /// along that edge.
    fn clip(&self, seg: Vec<(f64, f64)>) -> Vec<Vec<(f64, f64)>> {
        if self.x_range.is_none() && self.y_range.is_none() {
            return vec![seg];
        }
        let fx = |v: f64| if self.log_x { v.ln() } else { v };
        let fy = |v: f64| if self.log_y { v.ln() } else { v };
        let gx = |v: f64| if self.log_x { v.exp() } else { v };
        let gy = |v: f64| if self.log_y { v.exp() } else { v };
        let (xa, xb) = self
            .x_range
            .map_or((f64::NEG_INFINITY, f64::INFINITY), |(a, b)| (fx(a), fx(b)));
        let (ya, yb) = self
            .y_range
            .map_or((f64::NEG_INFINITY, f64::INFINITY), |(a, b)| (fy(a), fy(b)));
        let inside = |x: f64, y: f64| x >= xa && x <= xb && y >= ya && y <= yb;
        // Points far outside (up to ±f64::MAX: a diverging simulation) would
        // overflow the differences below; they are first brought into a box a
        // million times the range around it (the line's crossing of the frame
        // moves by far less than a pixel).
        let near = |v: f64, a: f64, b: f64| {
            if a.is_finite() && b.is_finite() {
                let m = (1e6 * (b - a).abs()).clamp(f64::MIN_POSITIVE, 1e300);
                v.clamp(a - m, b + m)
            } else {
                v
            }
        };
        let seg: Vec<(f64, f64)> = seg
            .into_iter()
            .map(|(x, y)| (gx(near(fx(x), xa, xb)), gy(near(fy(y), ya, yb))))
            .collect();
        let mut out = Vec::new();
        let mut cur: Vec<(f64, f64)> = Vec::new();
        if seg.len() == 1 {
            let (x, y) = seg[0];
            if inside(fx(x), fy(y)) {
                out.push(seg);
            }
            return out;
        }
        // A line that leaves through the top or bottom edge and comes back
        // through the same edge continues along that edge (one polyline,
        // drawn as if pinned there) instead of starting a new polyline.
        let mut parked: Option<usize> = None;
        for w in seg.windows(2) {
            let (p, q) = ((fx(w[0].0), fy(w[0].1)), (fx(w[1].0), fy(w[1].1)));
            // Liang–Barsky: p + t·(q − p), t ∈ [t0, t1]; edges 0 left, 1 right, 2 bottom, 3 top
            let (dx, dy) = (q.0 - p.0, q.1 - p.1);
            let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
            let (mut e0, mut e1) = (usize::MAX, usize::MAX);
            let mut visible = true;
            for (edge, (pk, qk)) in [
                (-dx, p.0 - xa),
                (dx, xb - p.0),
                (-dy, p.1 - ya),
                (dy, yb - p.1),
            ]
            .into_iter()
            .enumerate()
            {
                if pk == 0.0 {
                    if qk < 0.0 {
                        visible = false;
                    }
                } else {
                    let r = qk / pk;
                    if pk < 0.0 && r > t0 {
                        t0 = r;
                        e0 = edge;
                    } else if pk > 0.0 && r < t1 {
                        t1 = r;
                        e1 = edge;
                    }
                }
            }
            if !visible || t0 > t1 {
                if parked.is_none() && !cur.is_empty() {
                    out.push(std::mem::take(&mut cur));
                }
                continue;
            }
            let at = |t: f64| (gx(p.0 + t * dx), gy(p.1 + t * dy));
            if t0 > 0.0 && !cur.is_empty() && parked != Some(e0) {
                out.push(std::mem::take(&mut cur));
            }
            parked = None;
            if cur.is_empty() || t0 > 0.0 {
                cur.push(if t0 > 0.0 { at(t0) } else { w[0] });
            }
            cur.push(if t1 < 1.0 { at(t1) } else { w[1] });
            if t1 < 1.0 {
                if e1 >= 2 && self.pin_to_edges {
                    parked = Some(e1);
                } else {
                    out.push(std::mem::take(&mut cur));
                }
            }
        }
        if !cur.is_empty() {
            out.push(cur);
        }
        out
    }

    fn data_range(&self, pick_x: bool) -> (f64, f64) {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for s in &self.series {
            for (&x, &y) in s.x.iter().zip(&s.y) {
                if !self.drawable(x, y) {
                    continue;
                }
                if let Some((a, b)) = self.x_range {
                    if !pick_x && (x < a || x > b) {
                        continue;
                    }
                }
                let v = if pick_x { x } else { y };
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        if !pick_x {
            for b in &self.bands {
                for v in [b.y0, b.y1] {
                    if v.is_finite() && (!self.log_y || v > 0.0) {
                        lo = lo.min(v);
                        hi = hi.max(v);
                    }
                }
            }
        }
        let log = if pick_x { self.log_x } else { self.log_y };
        if !lo.is_finite() || !hi.is_finite() {
            return if log { (1.0, 10.0) } else { (0.0, 1.0) };
        }
        if hi - lo <= f64::EPSILON * hi.abs().max(1.0) {
            if log {
                return (lo / 2.0, hi * 2.0);
            }
            let pad = if hi.abs() > 0.0 { 0.05 * hi.abs() } else { 1.0 };
            return (lo - pad, hi + pad);
        }
        (lo, hi)
    }

    /// Render to an SVG document.
    pub fn to_svg(&self) -> Result<String> {
        let mut out = String::new();
        self.draw(&mut out).map_err(|e| Error::Plot {
            reason: e.to_string(),
        })?;
        Ok(out)
    }

    /// Legend entries: bands first, then labelled series.
    fn legend_items(&self) -> Vec<LegendItem> {
        let bands = self
            .bands
            .iter()
            .filter(|b| !b.label.is_empty())
            .map(|b| LegendItem {
                label: b.label.clone(),
                color: BAND_COLOR,
                dashed: false,
                band: true,
            });
        let lines = self
            .series
            .iter()
            .enumerate()
            .filter(|(_, s)| !s.label.is_empty())
            .map(|(k, s)| LegendItem {
                label: s.label.clone(),
                color: PALETTE[s.color.unwrap_or(k) % PALETTE.len()],
                dashed: s.dashed,
                band: false,
            });
        bands.chain(lines).collect()
    }

    fn draw(&self, out: &mut String) -> std::result::Result<(), Box<dyn std::error::Error>> {
        let (x0, x1) = self.x_range.unwrap_or_else(|| self.data_range(true));
        let (y0, y1) = match self.y_range {
            Some(r) => r,
            None => {
                let (a, b) = self.data_range(false);
                if self.log_y {
                    (a / 1.5, b * 1.5)
                } else {
                    let m = 0.05 * (b - a);
                    (a - m, b + m)
                }
            }
        };
        let items = self.legend_items();
        let rows = if self.legend == LegendPosition::Below {
            legend_rows(&items, self.width.saturating_sub(PLOT_LEFT + 12))
        } else {
            Vec::new()
        };
        let legend_h = if rows.is_empty() {
            0
        } else {
            LEGEND_ROW * rows.len() as u32 + 8
        };
        let root =
            SVGBackend::with_string(out, (self.width, self.height + legend_h)).into_drawing_area();
        root.fill(&WHITE)?;
        let (plot, below) = root.split_vertically(self.height);
        let mut builder = ChartBuilder::on(&plot);
        builder
            .caption(&self.title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(PLOT_LEFT - 12);
        let positive = |lo: f64, hi: f64| {
            let lo = if lo > 0.0 { lo } else { 1e-3 };
            (lo, hi.max(lo * 10.0))
        };
        match (self.log_x, self.log_y) {
            (false, false) => {
                let mut chart = builder.build_cartesian_2d(x0..x1, y0..y1)?;
                self.finish(&mut chart, (x0, x1))?;
            }
            (true, false) => {
                let (a, b) = positive(x0, x1);
                let mut chart = builder.build_cartesian_2d((a..b).log_scale(), y0..y1)?;
                self.finish(&mut chart, (a, b))?;
            }
            (false, true) => {
                let (c, d) = positive(y0, y1);
                let mut chart = builder.build_cartesian_2d(x0..x1, (c..d).log_scale())?;
                self.finish(&mut chart, (x0, x1))?;
            }
            (true, true) => {
                let (a, b) = positive(x0, x1);
                let (c, d) = positive(y0, y1);
                let mut chart =
                    builder.build_cartesian_2d((a..b).log_scale(), (c..d).log_scale())?;
                self.finish(&mut chart, (a, b))?;
            }
        }
        draw_legend_below(&below, &items, &rows)?;
        root.present()?;
        Ok(())
    }

    /// Mesh, bands, lines and the inside legend of a built chart.
    fn finish<'a, DB, X, Y>(
        &self,
        chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
        x_span: (f64, f64),
    ) -> std::result::Result<(), Box<dyn std::error::Error>>
    where
        DB: DrawingBackend + 'a,
        DB::ErrorType: 'static,
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        // linear axes: labels rounded relative to the axis span; log axes: to the value
        let span = |r: std::ops::Range<f64>, log: bool| (!log).then(|| (r.end - r.start).abs());
        let x_tick_span = span(chart.x_range(), self.log_x);
        let y_tick_span = span(chart.y_range(), self.log_y);
        chart
            .configure_mesh()
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .label_style(("sans-serif", 14))
            .x_label_formatter(&|v| tick_label(*v, x_tick_span))
            .y_label_formatter(&|v| tick_label(*v, y_tick_span))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()?;
        for b in &self.bands {
            if !(b.y0.is_finite() && b.y1.is_finite()) {
                continue;
            }
            let anno = chart.draw_series(std::iter::once(Rectangle::new(
                [(x_span.0, b.y0), (x_span.1, b.y1)],
                BAND_COLOR.filled(),
            )))?;
            if !b.label.is_empty() {
                anno.label(b.label.clone()).legend(|(x, y)| {
                    Rectangle::new([(x, y - 5), (x + 20, y + 5)], BAND_COLOR.filled())
                });
            }
        }
        self.draw_series(chart)
    }

    fn draw_series<'a, DB, CT>(
        &self,
        chart: &mut ChartContext<'a, DB, CT>,
    ) -> std::result::Result<(), Box<dyn std::error::Error>>
    where
        DB: DrawingBackend + 'a,
        DB::ErrorType: 'static,
        CT: CoordTranslate<From = (f64, f64)>,
    {
        for (k, s) in self.series.iter().enumerate() {
            let color = PALETTE[s.color.unwrap_or(k) % PALETTE.len()];
            let style = ShapeStyle {
                color: color.to_rgba(),
                filled: false,
                stroke_width: if s.dashed { 1 } else { 2 },
            };
            let mut first = true;
            let segments = s
                .segments_where(|x, y| self.drawable(x, y))
                .into_iter()
                .flat_map(|seg| self.clip(seg));
            for seg in segments {
                let anno = if s.dashed {
                    chart.draw_series(DashedLineSeries::new(seg, 6, 4, style))?
                } else {
                    chart.draw_series(LineSeries::new(seg, style))?
                };
                if first && !s.label.is_empty() {
                    anno.label(s.label.clone())
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
                    first = false;
                }
            }
        }
        if self.legend == LegendPosition::Inside && !self.legend_items().is_empty() {
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .label_font(("sans-serif", 13))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .draw()?;
        }
        Ok(())
    }
}

/// An axis tick label: the shortest form of the value rounded to 1e-6 of the
/// axis span on a linear axis (`span = Some`), or to 12 significant digits on
/// a log axis (so 0.30000000000000004 reads 0.3 and −5e−17 reads 0), with an
/// exponent only for very large or small magnitudes.
pub(crate) fn tick_label(v: f64, span: Option<f64>) -> String {
    if !v.is_finite() {
        return String::new();
    }
    if v == 0.0 || span.is_some_and(|s| v.abs() < 1e-9 * s) {
        return "0".into();
    }
    let e = match span {
        Some(s) if s > 0.0 && s.is_finite() => s.log10().floor() as i32 - 6,
        _ => v.abs().log10().floor() as i32 - 11,
    };
    let scale = 10f64.powi(-e);
    let r = (v * scale).round() / scale;
    if r == 0.0 {
        return "0".into();
    }
    if !(1e-4..1e7).contains(&r.abs()) {
        return format!("{r:e}");
    }
    format!("{r}")
}

/// Width of the y-label area plus the left margin \[px\].
const PLOT_LEFT: u32 = 90;
/// Height of one legend row below the plot \[px\].
const LEGEND_ROW: u32 = 20;
/// Fill of confidence bands.
const BAND_COLOR: RGBColor = RGBColor(222, 226, 232);

/// One legend entry.
struct LegendItem {
    label: String,
    color: RGBColor,
    dashed: bool,
    band: bool,
}

/// Approximate rendered width of a label in 13 px sans-serif \[px\].
fn text_width(s: &str) -> u32 {
    (s.chars().count() as f64 * 7.0).ceil() as u32
}

/// Entries per row (with their x offsets) so that no row is wider than `width`.
fn legend_rows(items: &[LegendItem], width: u32) -> Vec<Vec<(usize, u32)>> {
    let mut rows: Vec<Vec<(usize, u32)>> = Vec::new();
    let mut x = 0;
    for (i, it) in items.iter().enumerate() {
        let w = 28 + text_width(&it.label) + 22;
        match rows.last_mut() {
            Some(row) if x + w <= width => {
                row.push((i, x));
                x += w;
            }
            _ => {
                rows.push(vec![(i, 0)]);
                x = w;
            }
        }
    }
    rows
}

fn draw_legend_below<DB>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    items: &[LegendItem],
    rows: &[Vec<(usize, u32)>],
) -> std::result::Result<(), Box<dyn std::error::Error>>
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
{
    let font = ("sans-serif", 13).into_font().color(&BLACK);
    for (r, row) in rows.iter().enumerate() {
        let y = (r as u32 * LEGEND_ROW + 10) as i32;
        for &(i, dx) in row {
            let it = &items[i];
            let x = (PLOT_LEFT + dx) as i32;
            let style = ShapeStyle {
                color: it.color.to_rgba(),
                filled: it.band,
                stroke_width: if it.dashed { 1 } else { 2 },
            };
            if it.band {
                area.draw(&Rectangle::new([(x, y - 5), (x + 22, y + 5)], style))?;
            } else if it.dashed {
                for (a, b) in [(0, 6), (10, 16), (20, 22)] {
                    area.draw(&PathElement::new(vec![(x + a, y), (x + b, y)], style))?;
                }
            } else {
                area.draw(&PathElement::new(vec![(x, y), (x + 22, y)], style))?;
            }
            area.draw(&Text::new(it.label.clone(), (x + 28, y - 7), font.clone()))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaps_split_a_series_into_segments() {
        let s = Series::new(
            "p",
            vec![0.0, 1.0, 2.0, 3.0, 4.0],
            vec![1.0, f64::NAN, 2.0, 3.0, f64::INFINITY],
        );
        let seg = s.segments();
        assert_eq!(seg, vec![vec![(0.0, 1.0)], vec![(2.0, 2.0), (3.0, 3.0)]]);
    }

    #[test]
    fn svg_contains_labels_and_no_nan() {
        let mut c = LineChart::new("T", "time [ms]", "error [µm]");
        c.push(Series::new(
            "a",
            vec![0.0, 1.0, 2.0],
            vec![0.0, f64::NAN, 1.0],
        ));
        c.push(Series::new("b", vec![0.0, 2.0], vec![1.0, 0.5]).dashed());
        let svg = c.to_svg().unwrap();
        assert!(svg.contains("time [ms]"));
        assert!(svg.contains("error [µm]"));
        assert!(!svg.contains("NaN"));
    }

    #[test]
    fn lines_leave_a_fixed_range_at_the_true_intersection() {
        let mut c = LineChart::new("T", "x", "y");
        c.y_range = Some((0.0, 1.0));
        let seg = vec![(0.0, 0.5), (1.0, 100.0), (2.0, 0.5), (3.0, 0.25)];
        // default: cut where the line leaves, a new polyline where it comes back
        let parts = c.clip(seg.clone());
        assert_eq!(parts.len(), 2);
        let exit = parts[0][1];
        assert!((exit.0 - 0.5 / 99.5).abs() < 1e-12 && (exit.1 - 1.0).abs() < 1e-12);
        let back = parts[1][0];
        assert!((back.0 - (2.0 - 0.5 / 99.5)).abs() < 1e-12);
        assert_eq!(parts[1][2], (3.0, 0.25));
        c.pin_to_edges = true;
        let parts = c.clip(seg);
        // one polyline: leaves at y = 1 (x = 0.5/99.5), runs along the top, comes back
        assert_eq!(parts.len(), 1);
        let p = &parts[0];
        assert_eq!(p.len(), 5, "{p:?}");
        assert!((p[1].0 - 0.5 / 99.5).abs() < 1e-12 && (p[1].1 - 1.0).abs() < 1e-12);
        assert!((p[2].0 - (2.0 - 0.5 / 99.5)).abs() < 1e-12 && (p[2].1 - 1.0).abs() < 1e-12);
        assert_eq!(p[3], (2.0, 0.5));
        assert_eq!(p[4], (3.0, 0.25));
        // a steep line crossing the plot from top to bottom is drawn where it crosses
        let parts = c.clip(vec![(0.0, 0.5), (1.0, 100.0), (2.0, -100.0), (3.0, 0.5)]);
        assert_eq!(parts.len(), 1);
        assert_eq!(parts[0].len(), 6, "{parts:?}");
        assert!((parts[0][2].0 - 1.495).abs() < 1e-12 && (parts[0][3].0 - 1.5).abs() < 1e-12);
        // leaving through the right edge ends the polyline
        c.x_range = Some((0.0, 1.0));
        let parts = c.clip(vec![(0.5, 0.5), (2.0, 0.5), (3.0, 0.5)]);
        assert_eq!(parts, vec![vec![(0.5, 0.5), (1.0, 0.5)]]);
        c.x_range = None;
        assert!(parts
            .iter()
            .flatten()
            .all(|&(_, y)| (-1e-12..=1.0 + 1e-12).contains(&y)));
        // log axis: clipped in log coordinates
        c.log_y = true;
        c.y_range = Some((1.0, 100.0));
        let parts = c.clip(vec![(0.0, 1.0), (1.0, 1e4)]);
        assert!((parts[0][1].0 - 0.5).abs() < 1e-12);
    }

    #[test]
    fn legend_below_wraps_and_adds_height() {
        let mut c = LineChart::new("T", "time [ms]", "y [µm]").with_legend(LegendPosition::Below);
        for k in 0..12 {
            c.push(Series::new(
                &format!("a rather long label number {k}"),
                vec![0.0, 1.0],
                vec![0.0, k as f64],
            ));
        }
        c.bands.push(Band {
            y0: -1.0,
            y1: 1.0,
            label: "99 % band".into(),
        });
        let svg = c.to_svg().unwrap();
        let rows = legend_rows(&c.legend_items(), c.width - PLOT_LEFT - 12);
        assert!(rows.len() >= 3, "{}", rows.len());
        let h = c.height + LEGEND_ROW * rows.len() as u32 + 8;
        assert!(svg.contains(&format!("height=\"{h}\"")), "{}", &svg[..200]);
        assert!(svg.contains("a rather long label number 11"));
        assert!(svg.contains("99 % band"));
    }

    #[test]
    fn log_axes_drop_non_positive_points() {
        let mut c = LineChart::new("T", "f [Hz]", "|e| [µm]");
        c.log_x = true;
        c.log_y = true;
        c.push(Series::new(
            "a",
            vec![1.0, 10.0, 100.0],
            vec![1.0, 0.0, 3.0],
        ));
        let svg = c.to_svg().unwrap();
        assert!(!svg.contains("NaN") && !svg.contains("inf"));
    }

    #[test]
    fn tick_labels_are_short_and_never_negative_zero() {
        let lin = Some(2.1);
        assert_eq!(tick_label(0.1 + 0.2, lin), "0.3");
        assert_eq!(tick_label(-0.0, lin), "0");
        assert_eq!(tick_label(-5.551115123125783e-17, lin), "0");
        assert_eq!(tick_label(-0.25, lin), "-0.25");
        assert_eq!(tick_label(2500.0, Some(3000.0)), "2500");
        assert_eq!(tick_label(1000.0, None), "1000");
        assert_eq!(tick_label(0.1, None), "0.1");
        assert_eq!(tick_label(3e7, Some(4e7)), "3e7");
        assert_eq!(tick_label(2e-5, Some(1e-4)), "2e-5");
        assert_eq!(tick_label(f64::NAN, lin), "");
    }

    #[test]
    fn empty_chart_renders() {
        let c = LineChart::new("empty", "x", "y");
        assert!(c.to_svg().unwrap().contains("</svg>"));
    }

    #[test]
    fn points_near_the_float_limits_are_clipped_to_the_frame() {
        let mut c = LineChart::new("t", "x", "y");
        c.y_range = Some((0.0, 1.0));
        for pin in [false, true] {
            c.pin_to_edges = pin;
            let seg = vec![
                (0.0, 0.5),
                (1.0, -1e308),
                (2.0, 1e308),
                (3.0, f64::MAX),
                (4.0, 0.5),
            ];
            let parts = c.clip(seg);
            assert!(!parts.is_empty());
            for (x, y) in parts.iter().flatten() {
                assert!((0.0..=4.0).contains(x), "{x}");
                assert!((-1e-9..=1.0 + 1e-9).contains(y), "{pin}: {y}");
            }
        }
    }
}
