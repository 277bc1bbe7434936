//! Line charts rendered to self-contained SVG (no fonts or scripts needed).
//!
//! ```
//! use feedid::plot::{LineChart, Series};
//! let mut c = LineChart::new("Ramp", "time [ms]", "position [µm]");
//! c.push(Series::new("measured", vec![0.0, 1.0, 2.0], vec![0.0, 1.0, 4.0]));
//! let svg = c.to_svg().unwrap();
//! assert!(svg.starts_with("<svg"));
//! ```

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
    fn segments(&self) -> Vec<Vec<(f64, f64)>> {
        let mut out = Vec::new();
        let mut cur = Vec::new();
        for (&x, &y) in self.x.iter().zip(&self.y) {
            if x.is_finite() && y.is_finite() {
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

/// Palette readable in print and by colour-blind readers (Okabe–Ito).
const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 0, 0),
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(240, 228, 66),
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
        }
    }

    /// Add a line.
    pub fn push(&mut self, s: Series) {
        self.series.push(s);
    }

    fn data_range(&self, pick_x: bool) -> (f64, f64) {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for s in &self.series {
            for (&x, &y) in s.x.iter().zip(&s.y) {
                if !(x.is_finite() && y.is_finite()) {
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
        if !lo.is_finite() || !hi.is_finite() {
            return (0.0, 1.0);
        }
        if hi - lo <= f64::EPSILON * hi.abs().max(1.0) {
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

    fn draw(&self, out: &mut String) -> std::result::Result<(), Box<dyn std::error::Error>> {
        let (x0, x1) = self.x_range.unwrap_or_else(|| self.data_range(true));
        let (y0, y1) = match self.y_range {
            Some(r) => r,
            None => {
                let (a, b) = self.data_range(false);
                let m = 0.05 * (b - a);
                (a - m, b + m)
            }
        };
        let root = SVGBackend::with_string(out, (self.width, self.height)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut builder = ChartBuilder::on(&root);
        builder
            .caption(&self.title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(78);
        let label_style = ("sans-serif", 14);
        if self.log_x {
            let lo = if x0 > 0.0 { x0 } else { 1e-3 };
            let mut chart =
                builder.build_cartesian_2d((lo..x1.max(lo * 10.0)).log_scale(), y0..y1)?;
            chart
                .configure_mesh()
                .x_desc(&self.x_label)
                .y_desc(&self.y_label)
                .label_style(label_style)
                .light_line_style(RGBColor(235, 235, 235))
                .draw()?;
            self.draw_series(&mut chart)?;
        } else {
            let mut chart = builder.build_cartesian_2d(x0..x1, y0..y1)?;
            chart
                .configure_mesh()
                .x_desc(&self.x_label)
                .y_desc(&self.y_label)
                .label_style(label_style)
                .light_line_style(RGBColor(235, 235, 235))
                .draw()?;
            self.draw_series(&mut chart)?;
        }
        root.present()?;
        Ok(())
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
            for seg in s.segments() {
                let anno = if s.dashed {
                    chart.draw_series(DashedLineSeries::new(seg, 6, 4, style))?
                } else {
                    chart.draw_series(LineSeries::new(seg, style))?
                };
                if first {
                    anno.label(s.label.clone())
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
                    first = false;
                }
            }
        }
        if self.series.iter().any(|s| !s.label.is_empty()) {
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
    fn empty_chart_renders() {
        let c = LineChart::new("empty", "x", "y");
        assert!(c.to_svg().unwrap().contains("</svg>"));
    }
}
