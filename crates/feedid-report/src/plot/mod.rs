//! SVG figures: line charts with units, legends and gaps, readable in print;
//! heat maps; min/max decimation of long series.

mod chart;
mod decimate;
mod heatmap;

pub use chart::{palette_hex, Band, LegendPosition, LineChart, Series};
pub use decimate::decimate_minmax;
pub use heatmap::HeatMap;
