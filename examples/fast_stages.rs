//! Per-stage timing of the fast MikkTSpace engine on the bench's wavy grid.
//! `cargo run --release --example fast_stages -- 1000000 [threads]`
use bumpbake::analytic::tangents::{build, Surface};

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
            let mut t = bumpbake::timings::Timings::default();
            let s0 = schedstat();
            let t0 = std::time::Instant::now();
            let out = bumpbake::tangent::fast::generate_timed(&case.mesh(), &mut t).expect("valid");
            let total = t0.elapsed().as_secs_f64() * 1e3;
            let s1 = schedstat();
            let stages: Vec<String> = t.stages.iter().map(|(k, v)| format!("{k} {v:.1}")).collect();
            // On one thread: CPU time of this thread and time it waited for a core.
            println!(
                "{} tris: wall {total:.1} ms (this thread: cpu {:.1} ms, runqueue {:.1} ms) | {} | {}",
                case.triangles(),
                (s1.0 - s0.0) as f64 * 1e-6,
                (s1.1 - s0.1) as f64 * 1e-6,
                stages.join(", "),
                out.values.len()
            );
        }
    });
}

/// (ns on cpu, ns waiting on the run queue) of the calling thread.
fn schedstat() -> (u64, u64) {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").unwrap_or_default();
    let mut it = s.split_whitespace().map(|x| x.parse::<u64>().unwrap_or(0));
    (it.next().unwrap_or(0), it.next().unwrap_or(0))
}
