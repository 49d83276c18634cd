//! PNG charts for the analysis subcommands (`--plot FILE.png`): x-y charts of
//! lines, points and error bars, several panels side by side.
//!
//! The one entry point is [`write_png`]; callers describe what to draw with
//! [`Chart`] and [`Series`] and never touch the drawing backend.

use crate::error::{Error, Result};
use std::path::Path;

/// How a series is drawn.
#[derive(Clone, Debug, PartialEq)]
pub enum SeriesKind {
    /// Points joined by straight lines.
    Line,
    /// Markers only.
    Points,
    /// Markers with symmetric vertical error bars (one half-width per point).
    ErrorBars(Vec<f64>),
    /// A closed outline (polygon), e.g. a fitted triangle.
    Polygon,
}

/// One data series of a chart.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend label (empty: no legend entry).
    pub label: String,
    /// (x, y) points in data units.
    pub points: Vec<(f64, f64)>,
    /// Drawing style.
    pub kind: SeriesKind,
}

/// One panel: axes, labels and series.
#[derive(Clone, Debug, Default)]
pub struct Chart {
    /// Panel title.
    pub title: String,
    /// x-axis label.
    pub x_label: String,
    /// y-axis label.
    pub y_label: String,
    /// Logarithmic x axis.
    pub log_x: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
    /// Equal scales on both axes (geometry, e.g. heap projections).
    pub equal_aspect: bool,
    /// The series, drawn in order.
    pub series: Vec<Series>,
}

/// Write the charts side by side into one PNG file.
pub fn write_png(path: &Path, charts: &[Chart]) -> Result<()> {
    let _ = charts;
    Err(Error::usage(format!("cannot write '{}': plotting is not built yet", path.display())))
}
