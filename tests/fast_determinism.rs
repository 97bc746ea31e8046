//! The fast engine's output must not depend on the number of threads.

use bumpbake::analytic::tangents::{build, Surface};
use bumpbake::tangent::mikk::{generate, Engine};

fn bits(v: &[Option<[f32; 4]>]) -> Vec<Option<[u32; 4]>> {
    v.iter().map(|o| o.map(|t| t.map(f32::to_bits))).collect()
}

#[test]
fn same_output_on_1_2_and_3_threads() {
    let cases = [build(Surface::Torus, 60_000), build(Surface::WavyGrid, 40_000), build(Surface::Fan, 3_000)];
    for case in &cases {
        let mesh = case.mesh();
        let run = |n: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(n).build().expect("thread pool");
            pool.install(|| bits(&generate(&mesh, Engine::Fast)))
        };
        let one = run(1);
        assert_eq!(one.len(), case.indices.len());
        assert!(one.iter().all(|o| o.is_some()));
        assert_eq!(one, run(2), "{:?}: 1 vs 2 threads", case.surface);
        assert_eq!(one, run(3), "{:?}: 1 vs 3 threads", case.surface);
    }
}
