//! SVG figures: line charts with units, legends and gaps, readable in print.

mod chart;

pub use chart::{palette_hex, LineChart, Series};
