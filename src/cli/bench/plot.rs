//! A hand-written SVG scatter plot on log axes, shared by the benches that plot error against
//! time. Small enough that a plotting crate would cost more to build than this costs to read.

use std::fmt::Write;

const COLOURS: [&str; 8] = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#17becf", "#7f7f7f"];

/// One labelled point, coloured by its series.
pub struct Point {
    pub x: f64,
    pub y: f64,
    pub series: usize,
    pub label: String,
}

/// A plot: title, axis names, the series' names (the legend) and the points.
pub struct Scatter {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<String>,
    pub points: Vec<Point>,
}

/// The SVG of `p`, both axes in whole decades.
pub fn svg(p: &Scatter) -> String {
    let (w, h, ml, mr, mt, mb) = (760.0, 520.0, 70.0, 150.0, 30.0, 50.0);
    let pts: Vec<(f64, f64, usize, &str)> =
        p.points.iter().map(|q| (q.x.max(1e-9), q.y.max(1e-6), q.series, q.label.as_str())).collect();
    let decades = |f: fn(f64, f64) -> f64, init: f64, sel: fn(&(f64, f64, usize, &str)) -> f64| {
        pts.iter().map(sel).fold(init, f).log10()
    };
    let (x0, x1) = (decades(f64::min, f64::MAX, |p| p.0).floor(), decades(f64::max, 0.0, |p| p.0).ceil().max(1.0));
    let (y0, y1) = (decades(f64::min, f64::MAX, |p| p.1).floor(), decades(f64::max, 0.0, |p| p.1).ceil());
    let (x1, y1) = (x1.max(x0 + 1.0), y1.max(y0 + 1.0));
    let px = |v: f64| ml + (v.log10() - x0) / (x1 - x0) * (w - ml - mr);
    let py = |v: f64| h - mb - (v.log10() - y0) / (y1 - y0) * (h - mt - mb);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="11">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="18" text-anchor="middle" font-size="13">{}</text>"#,
        (ml + w - mr) / 2.0,
        p.title
    );
    for d in x0 as i32..=x1 as i32 {
        let x = px(10f64.powi(d));
        let _ = writeln!(
            s,
            r##"<line x1="{x:.1}" y1="{mt}" x2="{x:.1}" y2="{}" stroke="#ddd"/><text x="{x:.1}" y="{}" text-anchor="middle">{}</text>"##,
            h - mb,
            h - mb + 15.0,
            10f64.powi(d)
        );
    }
    for d in y0 as i32..=y1 as i32 {
        let y = py(10f64.powi(d));
        let _ = writeln!(
            s,
            r##"<line x1="{ml}" y1="{y:.1}" x2="{}" y2="{y:.1}" stroke="#ddd"/><text x="{}" y="{:.1}" text-anchor="end">{}</text>"##,
            w - mr,
            ml - 5.0,
            y + 4.0,
            10f64.powi(d)
        );
    }
    let _ =
        writeln!(s, r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#, (ml + w - mr) / 2.0, h - 12.0, p.x_label);
    let _ = writeln!(
        s,
        r#"<text transform="translate(16 {}) rotate(-90)" text-anchor="middle">{}</text>"#,
        (mt + h - mb) / 2.0,
        p.y_label
    );
    for (x, y, si, name) in &pts {
        let c = COLOURS[si % COLOURS.len()];
        let _ = writeln!(
            s,
            r#"<circle cx="{:.1}" cy="{:.1}" r="4" fill="{c}"/><text x="{:.1}" y="{:.1}" fill="{c}" font-size="9">{name}</text>"#,
            px(*x),
            py(*y),
            px(*x) + 6.0,
            py(*y) + 3.0
        );
    }
    for (i, name) in p.series.iter().enumerate() {
        let (x, y) = (w - mr + 15.0, mt + 20.0 + 18.0 * i as f64);
        let _ = writeln!(
            s,
            r#"<circle cx="{x}" cy="{y}" r="5" fill="{}"/><text x="{}" y="{}">{name}</text>"#,
            COLOURS[i % COLOURS.len()],
            x + 10.0,
            y + 4.0
        );
    }
    s.push_str("</svg>\n");
    s
}
