#![no_main]
//! The tangent generator on arbitrary finite triangle meshes: every frame that comes out is
//! finite, unit, orthogonal to its normal and has w = +-1, and every corner keeps its position.
use arbitrary::Arbitrary;
use bumpbake::scene::{Primitive, Stream};
use bumpbake::tangent::{primitive_with_stats, Options};
use libfuzzer_sys::fuzz_target;

#[derive(Arbitrary, Debug)]
struct Mesh {
    positions: Vec<[f32; 3]>,
    normals: Option<Vec<[f32; 3]>>,
    uvs: Vec<[f32; 2]>,
    indices: Vec<u16>,
    /// Scale applied to positions, as a power of ten, to reach tiny and huge meshes.
    scale_exp: i8,
}

fn finite<const N: usize>(v: [f32; N]) -> [f32; N] {
    v.map(|x| if x.is_finite() { x } else { 0.0 })
}

fuzz_target!(|m: Mesh| {
    let n = m.positions.len().min(512);
    if n == 0 {
        return;
    }
    let scale = 10f32.powi((m.scale_exp as i32).clamp(-12, 12));
    let pos: Vec<[f32; 3]> = m.positions[..n].iter().map(|p| finite(finite(*p).map(|x| x * scale))).collect();
    let uv: Vec<[f32; 2]> = (0..n).map(|i| m.uvs.get(i).copied().map(finite).unwrap_or([0.0, 0.0])).collect();
    let idx: Vec<u32> = m.indices.iter().take(3 * 1024).map(|&i| i as u32 % n as u32).collect();
    let idx = idx[..idx.len() / 3 * 3].to_vec();
    if idx.is_empty() {
        return;
    }
    let mut attributes = vec![("POSITION".to_string(), Stream::from_f32("VEC3", &pos))];
    let has_normals = m.normals.is_some();
    if let Some(ns) = &m.normals {
        // Normals as a tool would read them: finite, normalised, +Z where undefined.
        let nv: Vec<[f32; 3]> = (0..n)
            .map(|i| {
                // Scaled by the largest component first: squaring 1e-20 gives a denormal with a
                // few bits left, and a "normalised" vector 2% too long (this harness's first crash).
                let v = glam::Vec3::from(ns.get(i).copied().map(finite).unwrap_or([0.0, 0.0, 1.0]));
                let m = v.abs().max_element();
                if m == 0.0 {
                    [0.0, 0.0, 1.0]
                } else {
                    (v / m).normalize().to_array()
                }
            })
            .collect();
        attributes.push(("NORMAL".to_string(), Stream::from_f32("VEC3", &nv)));
    }
    attributes.push(("TEXCOORD_0".to_string(), Stream::from_f32("VEC2", &uv)));
    let p = Primitive { attributes, targets: vec![], indices: idx.clone(), mode: 4 };
    let (out, stats) = primitive_with_stats(p, 0, &Options { bitangents: true, ..Default::default() });
    assert_eq!(stats.triangles, idx.len() / 3);
    assert_eq!(out.indices.len(), idx.len());
    let t: Vec<[f32; 4]> = out.attr("TANGENT").expect("tangents").to_f32();
    let nn: Vec<[f32; 3]> = out.attr("NORMAL").expect("normals").to_f32();
    let op: Vec<[f32; 3]> = out.attr("POSITION").expect("positions").to_f32();
    for (c, &v) in out.indices.iter().enumerate() {
        let v = v as usize;
        assert_eq!(op[v], pos[idx[c] as usize], "corner {c} keeps its position");
        let tv = glam::Vec3::new(t[v][0], t[v][1], t[v][2]);
        let nv = glam::Vec3::from(nn[v]);
        assert!(tv.is_finite(), "corner {c}: {:?}", t[v]);
        assert!((tv.length() - 1.0).abs() < 1e-4, "corner {c}: not unit {:?}", t[v]);
        assert!(t[v][3] == 1.0 || t[v][3] == -1.0, "corner {c}: w {:?}", t[v]);
        assert!(nv.is_finite() && (nv.length() - 1.0).abs() < 1e-3, "corner {c}: normal {nv:?} (given: {has_normals})");
        assert!(tv.dot(nv).abs() < 1e-3, "corner {c}: {:?} vs normal {nv:?}", t[v]);
    }
});
