//! How a group of primitives and the materials they share can renumber their UV sets
//! (`TEXCOORD_n`) so that only the read ones remain, numbered from 0 without gaps (glTF wants
//! `TEXCOORD_0..n`).

use super::material::MaterialInfo;
use serde_json::{json, Value};
use std::collections::{BTreeMap, BTreeSet};

/// What renumbering needs to know of one primitive.
#[derive(Debug, Clone, Default)]
pub struct PrimSets {
    /// Every material the primitive can be drawn with (its own and its variants').
    pub materials: Vec<usize>,
    /// The `n` of each `TEXCOORD_n` it has.
    pub sets: BTreeSet<u32>,
}

/// Old set -> new set for what keeps its sets; a set of a primitive missing from its map goes.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Renumbering {
    /// Per primitive (as given), `None` where nothing changes.
    pub primitives: Vec<Option<BTreeMap<u32, u32>>>,
    /// Per material, `None` where nothing changes.
    pub materials: Vec<Option<BTreeMap<u32, u32>>>,
}

/// Plans the renumbering. `named[m]` is every set material `m`'s textures name
/// (see [`named_sets`]). Primitives that share a material (directly or through another
/// primitive) form a group that must agree; a group is renumbered when every primitive in it has
/// every set its materials name, so that no texture loses its coordinates.
pub fn plan(prims: &[PrimSets], named: &[BTreeSet<u32>]) -> Renumbering {
    let mut out = Renumbering { primitives: vec![None; prims.len()], materials: vec![None; named.len()] };
    // Union-find over primitives and materials: node p for primitive p, prims.len() + m for material m.
    let mut parent: Vec<usize> = (0..prims.len() + named.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for (p, ps) in prims.iter().enumerate() {
        for &m in ps.materials.iter().filter(|&&m| m < named.len()) {
            let (a, b) = (root(&mut parent, p), root(&mut parent, prims.len() + m));
            parent[a] = b;
        }
    }
    let mut groups: BTreeMap<usize, (Vec<usize>, Vec<usize>)> = BTreeMap::new();
    for (p, ps) in prims.iter().enumerate() {
        if !ps.materials.is_empty() {
            groups.entry(root(&mut parent, p)).or_default().0.push(p);
        }
    }
    for m in 0..named.len() {
        let r = root(&mut parent, prims.len() + m);
        if let Some(g) = groups.get_mut(&r) {
            g.1.push(m);
        }
    }
    for (ps, ms) in groups.values() {
        let wanted: BTreeSet<u32> = ms.iter().flat_map(|&m| named[m].iter().copied()).collect();
        if wanted.is_empty() || ps.iter().any(|&p| !wanted.is_subset(&prims[p].sets)) {
            continue;
        }
        let map: BTreeMap<u32, u32> = wanted.iter().enumerate().map(|(new, &old)| (old, new as u32)).collect();
        let changes = ps.iter().any(|&p| prims[p].sets != wanted) || map.iter().any(|(o, n)| o != n);
        if !changes {
            continue;
        }
        for &p in ps {
            out.primitives[p] = Some(map.clone());
        }
        if map.iter().any(|(o, n)| o != n) {
            for &m in ms {
                out.materials[m] = Some(map.clone());
            }
        }
    }
    out
}

/// Every set a material's textures name (see [`plan`]): the set each reads and, under a
/// `KHR_texture_transform` override, the `texCoord` that clients without the extension read.
pub fn named_sets(material: &MaterialInfo) -> BTreeSet<u32> {
    material.textures.iter().flat_map(|t| [t.base_tex_coord, t.tex_coord]).collect()
}

/// Rewrites the `texCoord`s (and overrides) of `material`, the JSON `info` was read from,
/// through `map`.
pub fn renumber_material(material: &mut Value, info: &MaterialInfo, map: &BTreeMap<u32, u32>) {
    let to = |set: u32| map.get(&set).copied().unwrap_or(set);
    for t in &info.textures {
        let Some(ti) = material.pointer_mut(&t.pointer) else { continue };
        match to(t.base_tex_coord) {
            0 => {
                ti.as_object_mut().map(|o| o.remove("texCoord"));
            }
            new => super::set_key(ti, "texCoord", json!(new)),
        }
        if let Some(c) = ti.pointer_mut("/extensions/KHR_texture_transform/texCoord") {
            *c = json!(to(t.tex_coord));
        }
    }
}

/// Renames a primitive's `TEXCOORD_n` attributes (and its morph targets') through `map`, removing
/// the sets the map does not keep. Returns the accessor indices of the removed sets, by name.
pub fn renumber_primitive(prim: &mut Value, map: &BTreeMap<u32, u32>) -> Vec<(String, Option<u64>)> {
    let mut removed = Vec::new();
    let rename = |attrs: &mut serde_json::Map<String, Value>, removed: Option<&mut Vec<(String, Option<u64>)>>| {
        let sets: Vec<(String, u32)> =
            attrs.keys().filter_map(|k| Some((k.clone(), k.strip_prefix("TEXCOORD_")?.parse().ok()?))).collect();
        let mut taken = Vec::new();
        for (name, _) in &sets {
            taken.push((name.clone(), attrs.remove(name)));
        }
        let mut gone = Vec::new();
        for ((name, old), (_, value)) in sets.into_iter().zip(taken) {
            let Some(value) = value else { continue };
            match map.get(&old) {
                Some(new) => {
                    attrs.insert(format!("TEXCOORD_{new}"), value);
                }
                None => gone.push((name, value.as_u64())),
            }
        }
        if let Some(r) = removed {
            r.extend(gone);
        }
    };
    if let Some(a) = prim.get_mut("attributes").and_then(|a| a.as_object_mut()) {
        rename(a, Some(&mut removed));
    }
    for t in prim.get_mut("targets").and_then(|t| t.as_array_mut()).into_iter().flatten() {
        if let Some(a) = t.as_object_mut() {
            rename(a, None);
        }
    }
    removed
}

#[cfg(test)]
mod tests {
    use super::*;

    fn prim(materials: &[usize], sets: &[u32]) -> PrimSets {
        PrimSets { materials: materials.to_vec(), sets: sets.iter().copied().collect() }
    }
    fn sets(s: &[u32]) -> BTreeSet<u32> {
        s.iter().copied().collect()
    }

    #[test]
    fn a_group_reading_only_set_1_moves_it_to_0() {
        let plan = plan(&[prim(&[0], &[0, 1]), prim(&[0], &[0, 1])], &[sets(&[1])]);
        let want = BTreeMap::from([(1, 0)]);
        assert_eq!(plan.primitives, vec![Some(want.clone()), Some(want.clone())]);
        assert_eq!(plan.materials, vec![Some(want)]);
    }

    #[test]
    fn a_primitive_lacking_a_read_set_holds_its_whole_group() {
        // Material 1 links primitive 1 to primitive 0 through primitive 2's variants.
        let plan = plan(&[prim(&[0], &[0, 1]), prim(&[1], &[0]), prim(&[0, 1], &[0, 1])], &[sets(&[1]), sets(&[1])]);
        assert_eq!(plan, Renumbering { primitives: vec![None; 3], materials: vec![None; 2] });
    }

    #[test]
    fn sets_already_in_order_change_nothing_but_trailing_ones_go() {
        let plan = plan(&[prim(&[0], &[0]), prim(&[1], &[0, 1, 2])], &[sets(&[0]), sets(&[0, 1])]);
        assert_eq!(plan.primitives, vec![None, Some(BTreeMap::from([(0, 0), (1, 1)]))]);
        assert_eq!(plan.materials, vec![None, None]);
    }

    #[test]
    fn renaming_moves_attributes_and_texcoords() {
        let mut p = json!({ "attributes": { "POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 2 }, "targets": [{ "TEXCOORD_1": 5 }] });
        let map = BTreeMap::from([(1, 0)]);
        assert_eq!(renumber_primitive(&mut p, &map), vec![("TEXCOORD_0".to_string(), Some(1))]);
        assert_eq!(p, json!({ "attributes": { "POSITION": 0, "TEXCOORD_0": 2 }, "targets": [{ "TEXCOORD_0": 5 }] }));
        let mut m = json!({ "normalTexture": { "index": 0, "texCoord": 1 }, "occlusionTexture": { "index": 1, "texCoord": 1, "extensions": { "KHR_texture_transform": { "texCoord": 1 } } } });
        let mut doc = json!({ "asset": { "version": "2.0" }, "materials": [m] });
        crate::scene::shape::pad_references(&mut doc);
        let scene = crate::format::read_bytes(
            std::path::Path::new("m.gltf"),
            &serde_json::to_vec(&doc).unwrap(),
            &crate::scene::ReadOptions::default(),
        )
        .unwrap();
        let info = &scene.materials().list[0];
        assert_eq!(named_sets(info), sets(&[1]));
        renumber_material(&mut m, info, &map);
        assert_eq!(
            m,
            json!({ "normalTexture": { "index": 0 }, "occlusionTexture": { "index": 1, "extensions": { "KHR_texture_transform": { "texCoord": 0 } } } })
        );
    }
}
