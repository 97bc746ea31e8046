// Shared by the scene fuzz targets: after a successful read, run what `tangents` runs (every
// primitive decoded, tangents generated on all of them, the result encoded in memory) and check
// that every tangent written obeys the conventions.

use bumpbake::format::WriteOptions;
use bumpbake::scene::ReadOptions;
use bumpbake::tangent::apply::{apply, ApplyOptions};
use std::path::Path;

pub fn exercise(path: &str, data: &[u8]) {
    // A folder that does not exist: relative URIs the input names resolve to nothing.
    let path = Path::new(path);
    let Ok(mut scene) = bumpbake::format::read_bytes(path, data, &ReadOptions::default()) else { return };
    for r in scene.primitives() {
        let _ = scene.primitive(r);
    }
    let opts = ApplyOptions { all: true, ..Default::default() };
    if apply(&mut scene, &opts).is_err() {
        return;
    }
    for r in scene.primitives() {
        let Ok(p) = scene.primitive(r) else { continue };
        let (Some(t), Some(n)) = (p.attr("TANGENT"), p.attr("NORMAL")) else { continue };
        if t.format.component_type != 5126 || t.format.ty != "VEC4" || n.format.component_type != 5126 {
            continue;
        }
        for (k, (t, n)) in t.to_f32::<4>().iter().zip(n.to_f32::<3>()).enumerate() {
            let v = glam::Vec3::new(t[0], t[1], t[2]);
            let n = glam::Vec3::from(n).normalize_or_zero();
            assert!(
                v.is_finite() && (v.length() - 1.0).abs() < 1e-4 && (t[3] == 1.0 || t[3] == -1.0),
                "vertex {k}: bad tangent {t:?}"
            );
            if n != glam::Vec3::ZERO {
                assert!(v.dot(n).abs() < 1e-3, "vertex {k}: tangent {t:?} not orthogonal to {n:?}");
            }
        }
    }
    let _ = bumpbake::format::write(&scene, Path::new("/nonexistent-bumpbake-fuzz/out.glb"), &WriteOptions::default());
}
