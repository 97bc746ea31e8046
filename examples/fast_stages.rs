//! Per-stage timing of the fast MikkTSpace engine on the bench's wavy grid.
//! `cargo run --release --example fast_stages -- 1000000 [threads]`
use bumpbake::bench::tangents::{build, Surface};

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(1_000_000);
    let threads: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(0);
    let surface = match args.next().as_deref() {
        Some("fan") => Surface::Fan,
        Some("sphere") => Surface::Sphere,
        _ => Surface::WavyGrid,
    };
    let case = build(surface, n);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
    pool.install(|| {
        for _ in 0..5 {
            let mut t = bumpbake::report::Timings::default();
            let t0 = std::time::Instant::now();
            let out = bumpbake::tangent::fast::generate_timed(&case.mesh(), &mut t).expect("valid");
            let total = t0.elapsed().as_secs_f64() * 1e3;
            let stages: Vec<String> = t.stages.iter().map(|(k, v)| format!("{k} {v:.1}")).collect();
            println!("{} tris: total {total:.1} ms | {} | {}", case.triangles(), stages.join(", "), out.len());
        }
    });
}
