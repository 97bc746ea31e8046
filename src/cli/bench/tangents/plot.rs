//! SVG plots of a tangent benchmark: error against run time, and run time against mesh size.

use super::{Report, Row, Surface};

/// A log-log plot area: the SVG header, title, decade grid lines, frame and axis labels, and the
/// mapping from data to pixels.
struct LogLog {
    w: f64,
    h: f64,
    ml: f64,
    mr: f64,
    mt: f64,
    mb: f64,
    /// Decades shown: `10^x0 ..= 10^x1` across, `10^y0 ..= 10^y1` up.
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
}

impl LogLog {
    /// Fits whole decades around `pts` (x, y > 0); `mr` is the room for the legend.
    fn new(pts: impl Iterator<Item = (f64, f64)>, mr: f64) -> LogLog {
        let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for (x, y) in pts {
            (x0, x1, y0, y1) = (x0.min(x.log10()), x1.max(x.log10()), y0.min(y.log10()), y1.max(y.log10()));
        }
        if x0 > x1 {
            (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
        }
        let (x0, y0) = (x0.floor(), y0.floor());
        LogLog {
            w: 760.0,
            h: 480.0,
            ml: 70.0,
            mr,
            mt: 30.0,
            mb: 50.0,
            x0,
            x1: x1.ceil().max(x0 + 1.0),
            y0,
            y1: y1.ceil().max(y0 + 1.0),
        }
    }
    fn px(&self, v: f64) -> f64 {
        self.ml + (v.log10() - self.x0) / (self.x1 - self.x0) * (self.w - self.ml - self.mr)
    }
    fn py(&self, v: f64) -> f64 {
        self.h - self.mb - (v.log10() - self.y0) / (self.y1 - self.y0) * (self.h - self.mt - self.mb)
    }
    /// Everything but the data, legend and closing tag.
    fn start(&self, title: &str, (x_unit, x_label): (&str, &str), (y_unit, y_label): (&str, &str)) -> String {
        let LogLog { w, h, ml, mr, mt, mb, .. } = *self;
        let mut s = format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"11\">\n\
             <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n\
             <text x=\"{}\" y=\"18\" text-anchor=\"middle\" font-size=\"13\">{title}</text>\n",
            (w - mr + ml) / 2.0
        );
        for e in (self.x0 as i32)..=(self.x1 as i32) {
            let x = self.px(10f64.powi(e));
            s += &format!(
                "<line x1=\"{x:.1}\" y1=\"{mt}\" x2=\"{x:.1}\" y2=\"{}\" stroke=\"#ddd\"/><text x=\"{x:.1}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n",
                h - mb,
                h - mb + 15.0,
                fmt_pow(e, x_unit)
            );
        }
        for e in (self.y0 as i32)..=(self.y1 as i32) {
            let y = self.py(10f64.powi(e));
            s += &format!(
                "<line x1=\"{ml}\" y1=\"{y:.1}\" x2=\"{}\" y2=\"{y:.1}\" stroke=\"#ddd\"/><text x=\"{}\" y=\"{:.1}\" text-anchor=\"end\">{}</text>\n",
                w - mr,
                ml - 5.0,
                y + 4.0,
                fmt_pow(e, y_unit)
            );
        }
        s += &format!(
            "<rect x=\"{ml}\" y=\"{mt}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"black\"/>\n\
             <text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{x_label}</text>\n\
             <text transform=\"translate(16 {}) rotate(-90)\" text-anchor=\"middle\">{y_label}</text>\n",
            w - ml - mr,
            h - mt - mb,
            (w - mr + ml) / 2.0,
            h - 12.0,
            (h - mb + mt) / 2.0
        );
        s
    }
}

/// Error (p99 against the exact tangent) versus run time, one point per row, log-log axes.
pub fn svg(r: &Report) -> String {
    let pts: Vec<(f64, f64, &Row)> = r
        .rows
        .iter()
        .filter_map(|x| Some((x.median_ms.max(1e-3), x.vs_exact.as_ref()?.p99_deg.max(1e-4), x)))
        .collect();
    let f = LogLog::new(pts.iter().map(|&(x, y, _)| (x, y)), 170.0);
    let (px, py) = (|v| f.px(v), |v| f.py(v));
    let mut s = f.start(
        &format!("Tangent error (p99 vs exact) against run time ({} threads)", r.threads),
        ("ms", "median time per call (log)"),
        ("°", "p99 angular error, degrees (log)"),
    );
    let (w, mr, mt) = (f.w, f.mr, f.mt);
    let colour = |e: &str| if e == "fast" { "#d62728" } else { "#1f77b4" };
    let marker = |sf: Surface, x: f64, y: f64, c: &str| match sf {
        Surface::Sphere => format!("<circle cx=\"{x:.1}\" cy=\"{y:.1}\" r=\"4\" fill=\"{c}\" fill-opacity=\"0.7\"/>"),
        Surface::Torus => format!(
            "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"8\" height=\"8\" fill=\"{c}\" fill-opacity=\"0.7\"/>",
            x - 4.0,
            y - 4.0
        ),
        Surface::WavyGrid => format!(
            "<path d=\"M{x:.1} {:.1} L{:.1} {:.1} L{:.1} {:.1} Z\" fill=\"{c}\" fill-opacity=\"0.7\"/>",
            y - 5.0,
            x + 5.0,
            y + 4.0,
            x - 5.0,
            y + 4.0
        ),
        Surface::Fan => format!(
            "<path d=\"M{:.1} {y:.1} h10 M{x:.1} {:.1} v10\" stroke=\"{c}\" stroke-width=\"2\"/>",
            x - 5.0,
            y - 5.0
        ),
        // Meshes have no exact tangent, so no point on this plot.
        Surface::Mesh => String::new(),
    };
    for &(x, y, row) in &pts {
        s += &marker(row.surface, px(x), py(y), colour(row.engine));
        s += "\n";
    }
    let lx0 = w - mr + 15.0;
    let mut ly = mt + 10.0;
    for e in ["fast", "bevy_mikktspace"] {
        s += &format!("<rect x=\"{lx0}\" y=\"{:.1}\" width=\"10\" height=\"10\" fill=\"{}\"/><text x=\"{}\" y=\"{:.1}\">{e}</text>\n", ly - 9.0, colour(e), lx0 + 15.0, ly);
        ly += 18.0;
    }
    for sf in [Surface::Sphere, Surface::Torus, Surface::WavyGrid, Surface::Fan] {
        s += &marker(sf, lx0 + 5.0, ly - 4.0, "#444");
        s += &format!("<text x=\"{}\" y=\"{ly:.1}\">{}</text>\n", lx0 + 15.0, sf.name());
        ly += 18.0;
    }
    s += "</svg>\n";
    s
}

fn fmt_pow(e: i32, unit: &str) -> String {
    let v = 10f64.powi(e);
    if (-3..=4).contains(&e) {
        format!("{}{unit}", trim(v))
    } else {
        format!("1e{e}{unit}")
    }
}

fn trim(v: f64) -> String {
    let s = format!("{v:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Median time against triangle count, both on log axes, one line per surface and engine (each
/// point a case), with a dotted line of slope 1 (time proportional to size) through the fast
/// engine's largest case for comparison.
pub fn scaling_svg(r: &Report) -> String {
    let rows: Vec<&Row> = r.rows.iter().filter(|x| x.surface != Surface::Mesh && x.surface != Surface::Fan).collect();
    let f = LogLog::new(rows.iter().map(|x| (x.triangles.max(1) as f64, x.median_ms.max(1e-3))), 190.0);
    let (px, py) = (|v| f.px(v), |v| f.py(v));
    let mut s = f.start(
        &format!("Tangent stage time against mesh size ({} threads)", r.threads),
        ("", "triangles (log)"),
        (" ms", "median time per call (log)"),
    );
    let (w, mr, mt, x0, y0) = (f.w, f.mr, f.mt, f.x0, f.y0);
    let mut series: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for x in &rows {
        let key = format!("{} {}", x.surface.name(), x.engine);
        let p = (x.triangles as f64, x.median_ms.max(1e-3));
        match series.iter_mut().find(|(k, _)| *k == key) {
            Some((_, v)) => v.push(p),
            None => series.push((key, vec![p])),
        }
    }
    const COLOURS: [&str; 8] = ["#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#17becf", "#7f7f7f"];
    let mut ly = mt + 10.0;
    for (i, (key, pts)) in series.iter().enumerate() {
        let c = COLOURS[i % COLOURS.len()];
        let path: Vec<String> = pts.iter().map(|&(t, ms)| format!("{:.1},{:.1}", px(t), py(ms))).collect();
        s += &format!("<polyline points=\"{}\" fill=\"none\" stroke=\"{c}\" stroke-width=\"2\"/>\n", path.join(" "));
        for &(t, ms) in pts {
            s += &format!("<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"3\" fill=\"{c}\"/>\n", px(t), py(ms));
        }
        s += &format!("<rect x=\"{}\" y=\"{:.1}\" width=\"10\" height=\"10\" fill=\"{c}\"/><text x=\"{}\" y=\"{ly:.1}\">{key}</text>\n", w - mr + 15.0, ly - 9.0, w - mr + 30.0);
        ly += 18.0;
    }
    // Slope 1 through the fast engine's largest case: where the points follow it, time is
    // proportional to size.
    if let Some(&(t, ms)) =
        series.iter().filter(|(k, _)| k.ends_with(" fast")).flat_map(|(_, v)| v).max_by(|a, b| a.0.total_cmp(&b.0))
    {
        // Starts where it enters the plot: at the left edge or the bottom, whichever comes later.
        let t0 = 10f64.powf(x0).max(t * 10f64.powf(y0) / ms);
        s += &format!(
            "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"#444\" stroke-dasharray=\"3 3\"/>\n",
            px(t0),
            py(ms * t0 / t),
            px(t),
            py(ms)
        );
        s += &format!("<text x=\"{}\" y=\"{ly:.1}\">dotted: slope 1 (linear)</text>\n", w - mr + 15.0);
    }
    s += "</svg>\n";
    s
}
