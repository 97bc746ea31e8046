//! Error against time for the normal-map filters, drawn by the shared scatter plot.

use super::super::plot::{self, Point, Scatter};
use super::Report;

/// Mean angular error (degrees) against single-thread time per pixel (ns), one point per filter
/// and surface, coloured by surface and labelled by filter.
pub fn error_vs_time_svg(r: &Report) -> String {
    plot::svg(&Scatter {
        title: format!("normal-map filters: mean angular error against time ({}x{})", r.size, r.size),
        x_label: "ns per pixel, one thread (filter + 8-bit encode)".into(),
        y_label: "mean error, degrees".into(),
        series: r.surfaces.iter().map(|s| s.0.to_string()).collect(),
        points: r
            .rows
            .iter()
            .map(|row| Point {
                x: 1e3 / row.mpx_s_1t.max(1e-9),
                y: row.error.mean_deg,
                series: r.surfaces.iter().position(|s| s.0 == row.surface).unwrap_or(0),
                label: row.filter.name().to_string(),
            })
            .collect(),
    })
}
