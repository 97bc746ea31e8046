//! The `bench textures` tables and plot.

use super::super::plot::{self, Point, Scatter};
use super::{Report, Row, Run};
use std::fmt::Write;

/// The mean error of level 0 (the level seen close up) and the worst level's mean.
fn level0_and_worst(r: &Run) -> (f64, f64) {
    let l0 = r.levels.first().map_or(0.0, |l| l.mean_deg);
    (l0, r.levels.iter().map(|l| l.mean_deg).fold(0.0, f64::max))
}

pub fn render_text(r: &Report) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "KTX2 normal maps with mips: bumpbake against {} ({}), {} threads, medians of {} interleaved runs\nmap: {}\n",
        r.basisu, r.basisu_version, r.threads, r.runs, r.map
    );
    if let Some(f) = r.specular_aa {
        let _ = writeln!(s, "bumpbake's times include the specular-AA roughness texture (roughness factor {f})\n");
    }
    let _ = writeln!(
        s,
        "| size | setting | bumpbake s | basisu s | time ratio | bumpbake bytes | basisu bytes | size ratio | level 0 mean ° (ours / basisu) | worst level mean ° (ours / basisu) | worst excess mean / p99 ° |"
    );
    let _ = writeln!(s, "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for row in &r.rows {
        let (o0, ow) = level0_and_worst(&row.bumpbake);
        let (b0, bw) = level0_and_worst(&row.basisu);
        let _ = writeln!(
            s,
            "| {} | {} | {:.2} | {:.2} | {:.2} | {} | {} | {:.2} | {o0:.3} / {b0:.3} | {ow:.3} / {bw:.3} | {:+.3} / {:+.3} |",
            row.size,
            row.setting,
            row.bumpbake.median_s,
            row.basisu.median_s,
            row.time_ratio,
            row.bumpbake.bytes,
            row.basisu.bytes,
            row.size_ratio,
            row.worst_mean_excess_deg,
            row.worst_p99_excess_deg
        );
    }
    for row in &r.rows {
        let _ = writeln!(s, "\n{}x{} {}: per level, mean / p99 degrees", row.size, row.size, row.setting);
        let _ = writeln!(s, "| level | bumpbake | basisu |\n|---:|---:|---:|");
        for (a, b) in row.bumpbake.levels.iter().zip(&row.basisu.levels) {
            let _ = writeln!(
                s,
                "| {} | {:.3} / {:.3} | {:.3} / {:.3} |",
                a.level, a.mean_deg, a.p99_deg, b.mean_deg, b.p99_deg
            );
        }
        let stages: Vec<String> = row.bumpbake.stages_ms.iter().map(|(n, ms)| format!("{n} {ms:.0}")).collect();
        let _ = writeln!(s, "bumpbake stages (ms): {}", stages.join(", "));
        let _ = writeln!(s, "median of the runs' own time ratios: {:.3}", row.paired_time_ratio);
        if let (Some(a), Some(b), Some(r)) = (row.bumpbake.cpu_median_s, row.basisu.cpu_median_s, row.cpu_ratio) {
            let _ = writeln!(s, "CPU time, median s: bumpbake {a:.2}, basisu {b:.2}, ratio {r:.3}");
        }
    }
    s
}

/// Level 0's mean error against median time, one point per tool, map size and setting.
pub fn error_vs_time_svg(r: &Report) -> String {
    let mut sizes: Vec<usize> = r.rows.iter().map(|row| row.size).collect();
    sizes.dedup();
    let series: Vec<String> = sizes.iter().flat_map(|n| [format!("bumpbake {n}²"), format!("basisu {n}²")]).collect();
    let point = |row: &Row, run: &Run, tool: usize| Point {
        x: run.median_s,
        y: level0_and_worst(run).0,
        series: 2 * sizes.iter().position(|&n| n == row.size).unwrap_or(0) + tool,
        label: row.setting.clone(),
    };
    plot::svg(&Scatter {
        title: "KTX2 normal maps with mips: level-0 mean angular error against time".into(),
        x_label: format!("seconds, whole map with mips, {} threads (median)", r.threads),
        y_label: "level 0 mean error, degrees".into(),
        series,
        points: r.rows.iter().flat_map(|row| [point(row, &row.bumpbake, 0), point(row, &row.basisu, 1)]).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::super::{parse_setting, setting_name, LevelStat, Report, Row, Run};
    use bumpbake::format::image::ktx2::Codec;

    fn run(s: f64, e: f64) -> Run {
        Run {
            median_s: s,
            min_s: s,
            max_s: s,
            cpu_median_s: None,
            bytes: 1000,
            levels: vec![LevelStat { level: 0, mean_deg: e, p99_deg: 2.0 * e }],
            stages_ms: vec![("encode".into(), s * 1e3)],
        }
    }

    #[test]
    fn settings_read_back_their_names() {
        for n in ["uastc0", "uastc4", "uastc2-rdo", "etc1s1", "etc1s255"] {
            assert_eq!(setting_name(parse_setting(n).unwrap()), n);
        }
        assert_eq!(parse_setting("uastc2-rdo"), Some(Codec::Uastc { level: 2, rdo: Some(1.0) }));
        for bad in ["uastc5", "etc1s0", "etc1s256", "astc", "uastc-rdo"] {
            assert_eq!(parse_setting(bad), None, "{bad}");
        }
    }

    #[test]
    fn the_table_and_plot_carry_every_row() {
        let row = Row {
            size: 256,
            setting: "uastc2".into(),
            bumpbake: run(1.5, 0.25),
            basisu: run(3.0, 0.5),
            time_ratio: 0.5,
            paired_time_ratio: 0.45,
            runs_s: vec![(1.5, 3.0)],
            cpu_ratio: None,
            size_ratio: 1.0,
            worst_mean_excess_deg: -0.25,
            worst_p99_excess_deg: -0.5,
        };
        let r = Report {
            map: "m".into(),
            runs: 1,
            threads: 2,
            basisu: "basisu".into(),
            basisu_version: "v1.16.3".into(),
            specular_aa: None,
            rows: vec![row],
        };
        let t = super::render_text(&r);
        assert!(t.contains("| 256 | uastc2 | 1.50 | 3.00 | 0.50 | 1000 | 1000 | 1.00 | 0.250 / 0.500 |"), "{t}");
        assert!(t.contains("| 0 | 0.250 / 0.500 | 0.500 / 1.000 |"), "{t}");
        assert!(t.contains("time ratios: 0.450"), "{t}");
        let svg = super::error_vs_time_svg(&r);
        assert_eq!(svg.matches("<circle").count(), 2 + 2, "two points and two legend entries");
        assert!(svg.contains("bumpbake 256²") && svg.contains(">uastc2</text>"));
    }
}
