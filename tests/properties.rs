//! Property tests of the invariants (256 cases each, a few seconds in all):
//! - every frame that leaves the tangent stage is finite, unit, orthogonal to its normal, w = +-1,
//!   for arbitrary finite meshes (degenerate, tiny, huge, repeated indices, any normals);
//! - split/merge (`weld`/`unweld`) keeps every corner's attributes.

use bumpbake::scene::weld::{split_corners, unweld, weld, CornerStream, CornerValues};
use bumpbake::scene::{Primitive, Stream};
use bumpbake::tangent::{primitive_with_stats, Options};
use glam::Vec3;
use proptest::prelude::*;

fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![
        // Few distinct values: shared positions, zero areas, collinear points.
        (-2i32..3).prop_map(|i| i as f32),
        -1.0e3f32..1.0e3,
        (-1.0f32..1.0).prop_map(|x| x * 1e-6),
        (-1.0f32..1.0).prop_map(|x| 1.0e6 + x * 1e-2),
    ]
}

/// Positions, optional normals, UVs, indices.
type Mesh = (Vec<[f32; 3]>, Option<Vec<[f32; 3]>>, Vec<[f32; 2]>, Vec<u32>);

fn mesh() -> impl Strategy<Value = Mesh> {
    (1usize..24).prop_flat_map(|n| {
        (
            prop::collection::vec([coord(), coord(), coord()], n),
            prop::option::of(prop::collection::vec([coord(), coord(), coord()], n)),
            prop::collection::vec([coord(), coord()], n),
            prop::collection::vec(0..n as u32, 3..90),
        )
    })
}

/// Normals as a reader delivers them (unit, +Z where the data has none).
fn unit_normals(ns: &[[f32; 3]]) -> Vec<[f32; 3]> {
    ns.iter()
        .map(|n| {
            let v = Vec3::from(*n);
            let m = v.abs().max_element();
            if m == 0.0 {
                [0.0, 0.0, 1.0]
            } else {
                (v / m).normalize().to_array()
            }
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn frames_are_finite_unit_orthogonal((pos, nrm, uv, idx) in mesh()) {
        let idx = idx[..idx.len() / 3 * 3].to_vec();
        let mut attributes = vec![("POSITION".to_string(), Stream::from_f32("VEC3", &pos))];
        if let Some(n) = &nrm {
            attributes.push(("NORMAL".to_string(), Stream::from_f32("VEC3", &unit_normals(n))));
        }
        attributes.push(("TEXCOORD_0".to_string(), Stream::from_f32("VEC2", &uv)));
        let p = Primitive { attributes, targets: vec![], indices: idx.clone(), mode: 4 };
        let (out, stats) = primitive_with_stats(p, 0, &Options::default());
        prop_assert_eq!(out.indices.len(), idx.len());
        prop_assert!(stats.fallback.total() <= idx.len());
        let t: Vec<[f32; 4]> = out.attr("TANGENT").unwrap().to_f32();
        let n: Vec<[f32; 3]> = out.attr("NORMAL").unwrap().to_f32();
        let op: Vec<[f32; 3]> = out.attr("POSITION").unwrap().to_f32();
        let ouv: Vec<[f32; 2]> = out.attr("TEXCOORD_0").unwrap().to_f32();
        for (c, &v) in out.indices.iter().enumerate() {
            let v = v as usize;
            let tv = Vec3::new(t[v][0], t[v][1], t[v][2]);
            let nv = Vec3::from(n[v]);
            prop_assert!(tv.is_finite() && (tv.length() - 1.0).abs() < 1e-4, "corner {}: {:?}", c, t[v]);
            prop_assert!(t[v][3] == 1.0 || t[v][3] == -1.0);
            prop_assert!(nv.is_finite() && (nv.length() - 1.0).abs() < 1e-3, "corner {}: normal {:?}", c, nv);
            prop_assert!(tv.dot(nv).abs() < 1e-3, "corner {}: {:?} . {:?}", c, tv, nv);
            prop_assert_eq!(op[v], pos[idx[c] as usize]);
            prop_assert_eq!(ouv[v], uv[idx[c] as usize]);
        }
    }

    #[test]
    fn weld_and_unweld_keep_every_corner(
        (vals, idx) in (1usize..16).prop_flat_map(|n| (
            prop::collection::vec((0u8..3, 0u8..3, any::<u16>()), n),
            prop::collection::vec(0..n as u32, 0..60),
        ))
    ) {
        // Attributes with few distinct values (so corners merge) and one raw-byte stream.
        let a: Vec<[f32; 3]> = vals.iter().map(|v| [v.0 as f32, v.1 as f32, 0.0]).collect();
        let b: Vec<[f32; 2]> = vals.iter().map(|v| [v.1 as f32, -0.0]).collect();
        let raw = Stream {
            format: bumpbake::scene::Format { component_type: 5123, ty: "SCALAR".into(), normalized: true },
            data: vals.iter().flat_map(|v| (v.2 % 3).to_le_bytes()).collect(),
            template: None,
        };
        let p = Primitive {
            attributes: vec![("POSITION".into(), Stream::from_f32("VEC3", &a)), ("TEXCOORD_0".into(), Stream::from_f32("VEC2", &b)), ("_RAW".into(), raw)],
            targets: vec![vec![("POSITION".into(), Stream::from_f32("VEC3", &a))]],
            indices: idx.clone(),
            mode: 4,
        };
        let (corners, targets) = unweld(&p);
        let w = weld(corners.clone(), targets.clone(), 4);
        prop_assert_eq!(w.indices.len(), idx.len());
        prop_assert!(w.vertex_count() <= idx.len());
        let (again, again_t) = unweld(&w);
        for ((n1, s1), (n2, s2)) in corners.iter().zip(&again) {
            prop_assert_eq!(n1, n2);
            prop_assert_eq!(&s1.data, &s2.data, "{} per corner", n1);
        }
        prop_assert_eq!(targets[0][0].1.data.clone(), again_t[0][0].1.data.clone());
        // Adding per-corner streams without unwelding gives what welding everything gives.
        let tan: Vec<[f32; 4]> = idx.iter().enumerate().map(|(c, &v)| [(v % 2) as f32, (c % 3 == 0) as u8 as f32, 0.0, 1.0]).collect();
        let nrm: Vec<[f32; 3]> = idx.iter().map(|&v| [0.0, (v % 3) as f32, 1.0]).collect();
        let mut all = corners.clone();
        all.insert(1, ("NORMAL".into(), Stream::from_f32("VEC3", &nrm)));
        all.push(("TANGENT".into(), Stream::from_f32("VEC4", &tan)));
        let split = split_corners(&p, &[], &[
            CornerStream { at: 1, name: "NORMAL", ty: "VEC3", values: CornerValues::Flat(nrm.as_flattened()) },
            CornerStream { at: usize::MAX, name: "TANGENT", ty: "VEC4", values: CornerValues::Flat(tan.as_flattened()) },
        ]);
        prop_assert_eq!(&split, &weld(all, targets.clone(), 4));
        // Merged: no two output vertices are equal in every attribute.
        let mut seen = std::collections::HashSet::new();
        for v in 0..w.vertex_count() {
            let key: Vec<u8> = w.attributes.iter().flat_map(|(_, s)| s.elem(v).to_vec()).chain(w.targets[0][0].1.elem(v).to_vec()).collect();
            prop_assert!(seen.insert(key), "vertex {} duplicates another", v);
        }
    }
}
