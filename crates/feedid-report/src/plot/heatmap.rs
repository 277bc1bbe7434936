//! Heat maps: a table of values drawn as coloured cells with the number in
//! each cell and a colour bar (hand-written SVG, no fonts or scripts needed).
//!
//! Colour: the perceptually uniform *viridis* map (dark = small, yellow =
//! large), readable in grey-scale print. With a logarithmic scale the colour
//! position of a value `v` is
//!
//! ```text
//! t = (ln v − ln v_min) / (ln v_max − ln v_min) ∈ [0, 1]
//! ```
//!
//! (linear: `(v − v_min)/(v_max − v_min)`). Missing values (non-finite, or
//! ≤ 0 on a log scale) are grey cells with a dash. Marked cells get a thick
//! outline (e.g. the best combination).
//!
//! Reference: S. van der Walt, N. Smith, "mpl colormaps" (viridis), 2015.
//!
//! ```
//! use feedid_report::plot::HeatMap;
//! let mut h = HeatMap::new("rms error", "window W [samples]", "method", "rms [µm]");
//! h.columns = vec!["10".into(), "20".into()];
//! h.rows = vec!["paper".into(), "arx".into()];
//! h.values = vec![180.0, 40.0, 0.5, 0.4];
//! h.marked = vec![(1, 1)];
//! let svg = h.to_svg().unwrap();
//! assert_eq!(svg.matches("class=\"cell\"").count(), 4);
//! ```

use std::fmt::Write as _;

use crate::error::{Error, Result};
use feedid::stats::sig3;

/// A heat map of `rows × columns` values.
#[derive(Debug, Clone, PartialEq)]
pub struct HeatMap {
    /// Title above the map.
    pub title: String,
    /// Label of the column axis (with unit).
    pub x_label: String,
    /// Label of the row axis.
    pub y_label: String,
    /// Label of the colour bar (with unit).
    pub value_label: String,
    /// Column labels (left to right).
    pub columns: Vec<String>,
    /// Row labels (top to bottom).
    pub rows: Vec<String>,
    /// Values, row-major `rows.len() × columns.len()`; non-finite = missing.
    pub values: Vec<f64>,
    /// Logarithmic colour scale (default true).
    pub log_scale: bool,
    /// Cells `(row, column)` drawn with a thick outline.
    pub marked: Vec<(usize, usize)>,
}

/// Viridis anchors at t = 0, 1/8, …, 1.
const VIRIDIS: [(f64, f64, f64); 9] = [
    (68.0, 1.0, 84.0),
    (71.0, 44.0, 122.0),
    (59.0, 81.0, 139.0),
    (44.0, 113.0, 142.0),
    (33.0, 144.0, 141.0),
    (39.0, 173.0, 129.0),
    (92.0, 200.0, 99.0),
    (170.0, 220.0, 50.0),
    (253.0, 231.0, 37.0),
];

/// Viridis colour at `t ∈ [0, 1]` (clamped) as `(r, g, b)`.
fn viridis(t: f64) -> (u8, u8, u8) {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * 8.0;
    let i = (x.floor() as usize).min(7);
    let f = x - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let mix = |p: f64, q: f64| (p + f * (q - p)).round().clamp(0.0, 255.0) as u8;
    (mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// XML-escape text for SVG.
fn xml(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// `3.00` → `3`, `30.0` → `30`, `0.250` → `0.25` (tick labels).
fn trim_zeros(s: &str) -> String {
    if s.contains('.') && !s.contains('e') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s.to_string()
    }
}

const CELL_W: f64 = 92.0;
const TOP: f64 = 84.0;

impl HeatMap {
    /// An empty heat map with a logarithmic colour scale.
    pub fn new(title: &str, x_label: &str, y_label: &str, value_label: &str) -> Self {
        Self {
            title: title.to_string(),
            x_label: x_label.to_string(),
            y_label: y_label.to_string(),
            value_label: value_label.to_string(),
            columns: Vec::new(),
            rows: Vec::new(),
            values: Vec::new(),
            log_scale: true,
            marked: Vec::new(),
        }
    }

    fn usable(&self, v: f64) -> bool {
        v.is_finite() && (!self.log_scale || v > 0.0)
    }

    /// Smallest and largest usable value.
    fn range(&self) -> Option<(f64, f64)> {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for &v in &self.values {
            if self.usable(v) {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        (lo <= hi).then_some((lo, hi))
    }

    /// Colour position of `v` in `[0, 1]`.
    fn position(&self, v: f64, lo: f64, hi: f64) -> f64 {
        if hi <= lo {
            return 0.5;
        }
        if self.log_scale {
            (v.ln() - lo.ln()) / (hi.ln() - lo.ln())
        } else {
            (v - lo) / (hi - lo)
        }
    }

    /// Render to an SVG document; errors if `values` does not have `rows × columns` entries.
    pub fn to_svg(&self) -> Result<String> {
        let (nr, nc) = (self.rows.len(), self.columns.len());
        if self.values.len() != nr * nc {
            return Err(Error::Core(feedid::Error::LengthMismatch {
                what: "heat map values",
                expected: nr * nc,
                actual: self.values.len(),
            }));
        }
        let label_w = self
            .rows
            .iter()
            .map(|r| r.chars().count())
            .max()
            .unwrap_or(0) as f64
            * 7.6
            + 44.0;
        let left = label_w.max(90.0);
        // few rows get taller cells so the map is not a thin strip
        let cell_h = (150.0 / nr.max(1) as f64).clamp(34.0, 56.0);
        let map_w = CELL_W * nc as f64;
        let map_h = cell_h * nr as f64;
        let bar_h = map_h.max(120.0);
        let bar_x = left + map_w + 28.0;
        let width = (bar_x + 20.0 + 90.0).max(left + self.title.chars().count() as f64 * 9.5);
        let height = TOP + bar_h + 24.0;
        let mut s = String::new();
        let _ = write!(
            s,
            r#"<svg width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.0} {h:.0}" xmlns="http://www.w3.org/2000/svg" font-family="sans-serif">"#,
            w = width,
            h = height
        );
        let _ = write!(
            s,
            r##"<rect x="0" y="0" width="{width:.0}" height="{height:.0}" fill="#ffffff"/>"##
        );
        let _ = write!(
            s,
            r#"<text x="{:.1}" y="24" font-size="18" text-anchor="middle">{}</text>"#,
            width / 2.0,
            xml(&self.title)
        );
        // column labels and axis label above the map
        let _ = write!(
            s,
            r#"<text x="{:.1}" y="{:.1}" font-size="14" text-anchor="middle">{}</text>"#,
            left + map_w / 2.0,
            TOP - 30.0,
            xml(&self.x_label)
        );
        for (j, c) in self.columns.iter().enumerate() {
            let _ = write!(
                s,
                r#"<text x="{:.1}" y="{:.1}" font-size="13" text-anchor="middle">{}</text>"#,
                left + CELL_W * (j as f64 + 0.5),
                TOP - 7.0,
                xml(c)
            );
        }
        // row axis label (vertical) and row labels
        let _ = write!(
            s,
            r#"<text transform="translate(16 {:.1}) rotate(-90)" font-size="14" text-anchor="middle">{}</text>"#,
            TOP + map_h / 2.0,
            xml(&self.y_label)
        );
        let range = self.range();
        for (i, r) in self.rows.iter().enumerate() {
            let y = TOP + cell_h * i as f64;
            let _ = write!(
                s,
                r#"<text x="{:.1}" y="{:.1}" font-size="13" text-anchor="end">{}</text>"#,
                left - 8.0,
                y + cell_h / 2.0 + 4.5,
                xml(r)
            );
            for (j, c) in self.columns.iter().enumerate() {
                let v = self.values[i * nc + j];
                let x = left + CELL_W * j as f64;
                let (fill, text_color, text) = match range {
                    Some((lo, hi)) if self.usable(v) => {
                        let (r8, g8, b8) = viridis(self.position(v, lo, hi));
                        let lum = 0.2126 * r8 as f64 + 0.7152 * g8 as f64 + 0.0722 * b8 as f64;
                        let tc = if lum < 140.0 { "#ffffff" } else { "#000000" };
                        (format!("#{r8:02x}{g8:02x}{b8:02x}"), tc, sig3(v))
                    }
                    _ => ("#e6e6e6".to_string(), "#444444", "–".to_string()),
                };
                let _ = write!(
                    s,
                    r##"<rect class="cell" x="{x:.1}" y="{y:.1}" width="{CELL_W:.1}" height="{cell_h:.1}" fill="{fill}" stroke="#ffffff" stroke-width="1"><title>{} · {}: {}</title></rect>"##,
                    xml(r),
                    xml(c),
                    text
                );
                let _ = write!(
                    s,
                    r#"<text x="{:.1}" y="{:.1}" font-size="13" text-anchor="middle" fill="{text_color}">{}</text>"#,
                    x + CELL_W / 2.0,
                    y + cell_h / 2.0 + 4.5,
                    text
                );
            }
        }
        for &(i, j) in &self.marked {
            if i < nr && j < nc {
                let _ = write!(
                    s,
                    r##"<rect class="mark" x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="none" stroke="#d55e00" stroke-width="3.5"/>"##,
                    left + CELL_W * j as f64 + 1.75,
                    TOP + cell_h * i as f64 + 1.75,
                    CELL_W - 3.5,
                    cell_h - 3.5
                );
            }
        }
        self.colour_bar(&mut s, bar_x, bar_h, range);
        s.push_str("</svg>\n");
        Ok(s)
    }

    /// Vertical colour bar with ticks and its label.
    fn colour_bar(&self, s: &mut String, x: f64, h: f64, range: Option<(f64, f64)>) {
        const STEPS: usize = 32;
        for k in 0..STEPS {
            let t0 = k as f64 / STEPS as f64;
            let (r, g, b) = viridis(t0 + 0.5 / STEPS as f64);
            let y = TOP + h * (1.0 - t0 - 1.0 / STEPS as f64);
            let _ = write!(
                s,
                r##"<rect x="{x:.1}" y="{y:.2}" width="20" height="{:.2}" fill="#{r:02x}{g:02x}{b:02x}"/>"##,
                h / STEPS as f64 + 0.5
            );
        }
        let _ = write!(
            s,
            r##"<rect x="{x:.1}" y="{TOP:.1}" width="20" height="{h:.1}" fill="none" stroke="#000000" stroke-width="1"/>"##
        );
        let _ = write!(
            s,
            r#"<text transform="translate({:.1} {:.1}) rotate(-90)" font-size="13" text-anchor="middle">{}</text>"#,
            x + 84.0,
            TOP + h / 2.0,
            xml(&self.value_label)
        );
        let Some((lo, hi)) = range else {
            return;
        };
        for v in self.ticks(lo, hi) {
            let t = self.position(v, lo, hi);
            let y = TOP + h * (1.0 - t.clamp(0.0, 1.0));
            let _ = write!(
                s,
                r##"<line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#000000"/><text x="{:.1}" y="{:.1}" font-size="12">{}</text>"##,
                x + 20.0,
                x + 25.0,
                x + 28.0,
                y + 4.0,
                trim_zeros(&sig3(v))
            );
        }
    }

    /// Tick values inside `[lo, hi]`: 1-2-5 per decade (log) or 5 even steps.
    fn ticks(&self, lo: f64, hi: f64) -> Vec<f64> {
        if hi <= lo {
            return vec![lo];
        }
        if !self.log_scale {
            return (0..=4).map(|k| lo + (hi - lo) * k as f64 / 4.0).collect();
        }
        let mut out = vec![lo];
        let decades = (hi / lo).log10();
        let mults: &[f64] = if decades > 3.0 {
            &[1.0]
        } else if decades > 1.2 {
            &[1.0, 3.0]
        } else {
            &[1.0, 2.0, 5.0]
        };
        let mut e = lo.log10().floor() as i32;
        while 10f64.powi(e) <= hi {
            for m in mults {
                let v = m * 10f64.powi(e);
                // keep clear of the end labels
                if v > lo * 1.15 && v < hi / 1.15 {
                    out.push(v);
                }
            }
            e += 1;
        }
        out.push(hi);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(rows: usize, cols: usize) -> HeatMap {
        let mut h = HeatMap::new("t", "window W [samples]", "method", "rms [µm]");
        h.columns = (0..cols).map(|j| format!("{}", 10 << j)).collect();
        h.rows = (0..rows).map(|i| format!("m<{i}>")).collect();
        h.values = (0..rows * cols)
            .map(|k| 0.1 * 3f64.powi(k as i32))
            .collect();
        h
    }

    #[test]
    fn one_cell_per_combination_with_its_number() {
        let h = map(3, 5);
        let svg = h.to_svg().unwrap();
        assert_eq!(svg.matches("class=\"cell\"").count(), 15);
        assert!(svg.contains(">0.100<"), "smallest value printed");
        assert!(svg.contains(&format!(">{}<", sig3(0.1 * 3f64.powi(14)))));
        assert!(svg.contains("m&lt;2&gt;"), "labels are escaped");
        assert!(!svg.contains("NaN"));
    }

    #[test]
    fn missing_values_are_grey_and_marks_are_drawn() {
        let mut h = map(2, 2);
        h.values[1] = f64::NAN;
        h.values[2] = 0.0; // not drawable on a log scale
        h.marked = vec![(1, 1), (5, 5)];
        let svg = h.to_svg().unwrap();
        assert_eq!(svg.matches("fill=\"#e6e6e6\"").count(), 2);
        assert_eq!(svg.matches("class=\"mark\"").count(), 1);
        assert!(!svg.contains("NaN"));
    }

    #[test]
    fn log_colour_scale_puts_the_geometric_mean_in_the_middle() {
        let h = map(1, 3);
        let (lo, hi) = (1.0, 100.0);
        assert!((h.position(10.0, lo, hi) - 0.5).abs() < 1e-12);
        assert_eq!(trim_zeros("3.00"), "3");
        assert_eq!(trim_zeros("30.0"), "30");
        assert_eq!(trim_zeros("0.250"), "0.25");
        assert_eq!(trim_zeros("270"), "270");
        assert_eq!(viridis(0.0), (68, 1, 84));
        assert_eq!(viridis(1.0), (253, 231, 37));
        assert_eq!(viridis(0.5), (33, 144, 141));
    }

    #[test]
    fn wrong_value_count_is_an_error() {
        let mut h = map(2, 2);
        h.values.pop();
        assert!(h.to_svg().is_err());
    }
}
