//! Reading Wavefront OBJ (+ MTL) into the glTF model: the geometry through the parallel parser
//! in `obj_parse.rs`, the MTL libraries through `tobj` (the only part of it still used).
//!
//! OBJ's UVs run v up; they are turned into glTF's v down here, once, so no stage after the
//! reader knows the mesh came from an OBJ (MikkTSpace's sign flips with v, and the glTF `w` rule,
//! the reference sign negated, flips it back: the frames are the same).

use super::obj_parse::{self, ObjData, Statement, MISSING};
use crate::error::{Error, Result};
use crate::scene::normals::{flat_normals, smooth_normals, unit_or_up};
use crate::scene::weld::weld;
use crate::scene::{
    array_mut, set_key, HeightMapRef, NormalMode, PrimRef, Primitive, ReadOptions, Scene, SourceFormat, Stream,
};
use serde_json::{json, Value};
use std::collections::HashMap;
use std::io::BufReader;
use std::path::Path;

/// Reads the OBJ file at `path`, streaming it through the parallel parser.
pub fn read_file(path: &Path, opts: &ReadOptions) -> Result<Scene> {
    let data = obj_parse::parse_file(path, &opts.progress)?;
    build_scene(path, data, opts)
}

pub fn read(path: &Path, bytes: &[u8], opts: &ReadOptions) -> Result<Scene> {
    let data = obj_parse::parse_bytes(path, bytes, &opts.progress)?;
    build_scene(path, data, opts)
}

/// Materials in order, their index by name, and the MTL files read.
type Materials = (Vec<tobj::Material>, HashMap<String, usize>, Vec<std::path::PathBuf>);

/// The MTL libraries an OBJ names, in order, merged as `tobj` merges them (a later definition
/// of a name wins); also the files read, for depfiles.
fn load_materials(path: &Path, base_dir: &Path, libs: &[String], opts: &ReadOptions) -> Result<Materials> {
    let (mut materials, mut map, mut files, mut failed) = (Vec::new(), HashMap::new(), Vec::new(), None);
    for name in libs {
        files.push(base_dir.join(name));
        let bytes = super::uri::read(name, base_dir, path, opts.allow_outside)?;
        match tobj::load_mtl_buf(&mut BufReader::new(bytes.as_slice())) {
            Ok((mut mats, names)) => {
                let offset = materials.len();
                materials.append(&mut mats);
                map.extend(names.into_iter().map(|(k, v)| (k, v + offset)));
            }
            Err(e) => failed = Some(e),
        }
    }
    match failed {
        Some(e) if materials.is_empty() => Err(Error::input(path, format!("malformed MTL: {e}"))),
        _ => Ok((materials, map, files)),
    }
}

fn build_scene(path: &Path, data: ObjData, opts: &ReadOptions) -> Result<Scene> {
    let base_dir = path.parent().map(|p| p.to_path_buf()).unwrap_or_default();
    let (materials, material_ids, mtl_files) = load_materials(path, &base_dir, &data.mtllibs, opts)?;

    let mut scene = empty_scene(path, opts, SourceFormat::Obj, mtl_files);
    for (i, m) in materials.iter().enumerate() {
        add_material(&mut scene, i, m)?;
    }

    let mut nodes = Vec::new();
    let mut remap = Remaps::new(&data);
    for run in runs(&data, &material_ids) {
        let name = &run.name;
        let meshes = scene.array("meshes");
        let mesh_idx = match meshes.last() {
            Some(last) if last.get("name") == Some(&json!(name)) => meshes.len() - 1,
            _ => {
                let meshes = array_mut(&mut scene.json, "meshes");
                meshes.push(json!({ "name": name, "primitives": [] }));
                nodes.push(json!({ "name": name, "mesh": meshes.len() - 1 }));
                meshes.len() - 1
            }
        };
        let model = remap.model(&data, run.tris.clone());
        let mut prim = build_primitive(path, &model, opts.obj_normals, &mut scene.notes, name)?;
        uvs_to_gltf(&mut prim);
        let mut pj = json!({ "attributes": {} });
        if let Some(m) = run.material.filter(|&m| m < materials.len()) {
            set_key(&mut pj, "material", json!(m));
        }
        let mesh = array_mut(&mut scene.json, "meshes").get_mut(mesh_idx);
        let prims = array_mut(mesh.ok_or_else(|| Error::input(path, "OBJ mesh vanished"))?, "primitives");
        prims.push(pj);
        let r = PrimRef { mesh: mesh_idx, primitive: prims.len() - 1 };
        scene.put_primitive(r, prim);
    }
    if nodes.is_empty() {
        return Err(Error::input(path, "OBJ has no faces"));
    }
    set_nodes(&mut scene, nodes);
    Ok(scene)
}

/// A scene with no meshes yet, read from the OBJ or PLY file at `path`.
fn empty_scene(path: &Path, opts: &ReadOptions, format: SourceFormat, deps: Vec<std::path::PathBuf>) -> Scene {
    Scene {
        json: json!({ "asset": { "version": "2.0", "generator": concat!("bumpbake ", env!("CARGO_PKG_VERSION")) } }),
        buffers: Vec::new(),
        source: path.to_path_buf(),
        base_dir: path.parent().map(|p| p.to_path_buf()).unwrap_or_default(),
        allow_outside: opts.allow_outside,
        source_format: format,
        notes: Vec::new(),
        deps,
        height_maps: Vec::new(),
        ledger: Default::default(),
        material_cache: Default::default(),
        absent_buffers: Default::default(),
        own_images: true,
    }
}

fn set_nodes(scene: &mut Scene, nodes: Vec<Value>) {
    let roots: Vec<usize> = (0..nodes.len()).collect();
    set_key(&mut scene.json, "nodes", Value::Array(nodes));
    set_key(&mut scene.json, "scenes", json!([{ "nodes": roots }]));
    set_key(&mut scene.json, "scene", json!(0));
}

/// A PLY mesh as a scene: one node and mesh named after the file, one primitive built exactly
/// as an OBJ face list with the same corners would be.
pub fn ply_scene(path: &Path, ply: super::ply::PlyMesh, opts: &ReadOptions) -> Result<Scene> {
    if ply.triangles.is_empty() {
        return Err(Error::input(path, "PLY has no faces (a point cloud cannot be used as a mesh)"));
    }
    let name = path.file_stem().map_or("mesh".into(), |s| s.to_string_lossy().into_owned());
    let indices: Vec<u32> = ply.triangles.into_flattened();
    let with = |present: bool| if present { indices.clone() } else { Vec::new() };
    let model = Model {
        normal_indices: with(!ply.normals.is_empty()),
        texcoord_indices: with(!ply.uvs.is_empty()),
        positions: ply.positions.into_flattened(),
        normals: ply.normals.into_flattened(),
        texcoords: ply.uvs.into_flattened(),
        indices,
    };
    let mut scene = empty_scene(path, opts, SourceFormat::Ply, Vec::new());
    let mut prim = build_primitive(path, &model, opts.obj_normals, &mut scene.notes, &name)?;
    uvs_to_gltf(&mut prim);
    set_key(&mut scene.json, "meshes", json!([{ "name": name, "primitives": [{ "attributes": {} }] }]));
    scene.put_primitive(PrimRef { mesh: 0, primitive: 0 }, prim);
    set_nodes(&mut scene, vec![json!({ "name": name, "mesh": 0 })]);
    Ok(scene)
}

/// A run of triangles with one name and one material: one glTF primitive.
struct Run {
    name: String,
    material: Option<usize>,
    tris: std::ops::Range<usize>,
}

/// Splits the triangles where tobj split its models: at every `o`/`g`, and at a `usemtl` that
/// changes the material; runs without triangles are dropped.
fn runs(data: &ObjData, ids: &HashMap<String, usize>) -> Vec<Run> {
    let mut out = Vec::new();
    let (mut name, mut material, mut start) = ("unnamed_object".to_string(), None, 0usize);
    fn close(name: &str, material: Option<usize>, start: usize, at: usize, out: &mut Vec<Run>) {
        if at > start {
            out.push(Run { name: name.to_string(), material, tris: start..at });
        }
    }
    for (at, s) in &data.statements {
        let at = *at as usize;
        match s {
            Statement::Name(n) => {
                close(&name, material, start, at, &mut out);
                start = at;
                name = n.clone();
            }
            Statement::Material(m) => {
                let id = ids.get(m).copied();
                if id != material {
                    close(&name, material, start, at, &mut out);
                    start = at;
                    material = id;
                }
            }
        }
    }
    close(&name, material, start, data.tri_v.len(), &mut out);
    out
}

/// One run's corners with each attribute renumbered in first-use order, as tobj numbered a
/// model's (so smooth normals and welding see what they always saw).
#[derive(Default)]
struct Model {
    positions: Vec<f32>,
    indices: Vec<u32>,
    normals: Vec<f32>,
    normal_indices: Vec<u32>,
    texcoords: Vec<f32>,
    texcoord_indices: Vec<u32>,
}

/// Global-to-local index maps, one per attribute, reset between runs by what they touched.
struct Remaps {
    maps: [Vec<u32>; 3],
    touched: Vec<(usize, u32)>,
}

impl Remaps {
    fn new(d: &ObjData) -> Remaps {
        let m = |n: usize| vec![MISSING; n];
        Remaps { maps: [m(d.positions.len()), m(d.uvs.len()), m(d.normals.len())], touched: Vec::new() }
    }

    /// The local index of global `g` of attribute `a`, and whether it is new.
    fn local(&mut self, a: usize, g: u32, next: usize) -> (u32, bool) {
        let slot = &mut self.maps[a][g as usize];
        if *slot == MISSING {
            *slot = next as u32;
            self.touched.push((a, g));
            (*slot, true)
        } else {
            (*slot, false)
        }
    }

    fn model(&mut self, d: &ObjData, tris: std::ops::Range<usize>) -> Model {
        let mut m = Model::default();
        for t in &d.tri_v[tris.clone()] {
            for &g in t {
                let (l, new) = self.local(0, g, m.positions.len() / 3);
                if new {
                    m.positions.extend_from_slice(&d.positions[g as usize]);
                }
                m.indices.push(l);
            }
        }
        // A corner without `vt` (`vn`) in a run where others have one takes the previous
        // corner's (the first one's: the file's first), as tobj did.
        let attrs: [(&[[u32; 3]], usize); 2] = [(&d.tri_t, 1), (&d.tri_n, 2)];
        for (tri, a) in attrs {
            let Some(run) = tri.get(tris.clone()) else { continue };
            if run.iter().flatten().all(|&i| i == MISSING) {
                continue;
            }
            let mut prev = 0;
            for &g in run.iter().flatten() {
                let g = if g == MISSING { prev } else { g };
                prev = g;
                let (values, indices) = if a == 1 {
                    (&mut m.texcoords, &mut m.texcoord_indices)
                } else {
                    (&mut m.normals, &mut m.normal_indices)
                };
                let (l, new) = self.local(a, g, values.len() / (a + 1));
                if new {
                    if a == 1 {
                        values.extend_from_slice(&d.uvs[g as usize]);
                    } else {
                        values.extend_from_slice(&d.normals[g as usize]);
                    }
                }
                indices.push(l);
            }
        }
        for (a, g) in self.touched.drain(..) {
            self.maps[a][g as usize] = MISSING;
        }
        m
    }
}

fn build_primitive(
    path: &Path,
    m: &Model,
    normals: NormalMode,
    notes: &mut Vec<String>,
    name: &str,
) -> Result<crate::scene::Primitive> {
    let np = m.positions.len() / 3;
    if let Some(i) = m.positions.iter().position(|x| !x.is_finite()) {
        return Err(Error::input(path, format!("object '{name}': vertex {} has a non-finite coordinate", i / 3 + 1)));
    }
    let corners = m.indices.len();
    let check = |idx: &[u32], n: usize, what: &str| -> Result<()> {
        match idx.iter().find(|&&i| i as usize >= n) {
            Some(bad) => Err(Error::input(
                path,
                format!("object '{name}': {what} index {} is out of range ({n} defined)", bad + 1),
            )),
            None => Ok(()),
        }
    };
    check(&m.indices, np, "vertex")?;
    let pos: Vec<[f32; 3]> = m
        .indices
        .iter()
        .map(|&i| {
            let i = i as usize * 3;
            [m.positions[i], m.positions[i + 1], m.positions[i + 2]]
        })
        .collect();
    let has_n = m.normal_indices.len() == corners && !m.normals.is_empty();
    let nrm: Vec<[f32; 3]> = if has_n {
        check(&m.normal_indices, m.normals.len() / 3, "normal")?;
        m.normal_indices
            .iter()
            .map(|&i| {
                let i = i as usize * 3;
                unit_or_up([m.normals[i], m.normals[i + 1], m.normals[i + 2]])
            })
            .collect()
    } else {
        let (n, fixed) = match normals {
            NormalMode::Smooth => smooth_normals(&m.positions, &m.indices),
            NormalMode::Flat => flat_normals(&pos),
        };
        if fixed > 0 {
            notes.push(format!(
                "object '{name}': {fixed} corners had no defined normal (degenerate faces); they point along +Z"
            ));
        }
        n
    };
    let mut attrs = vec![
        ("POSITION".to_string(), Stream::from_f32("VEC3", &pos)),
        ("NORMAL".to_string(), Stream::from_f32("VEC3", &nrm)),
    ];
    if m.texcoord_indices.len() == corners && !m.texcoords.is_empty() {
        check(&m.texcoord_indices, m.texcoords.len() / 2, "texture coordinate")?;
        let uv: Vec<[f32; 2]> = m
            .texcoord_indices
            .iter()
            .map(|&i| [m.texcoords[i as usize * 2], m.texcoords[i as usize * 2 + 1]])
            .collect();
        if uv.iter().flatten().any(|x| !x.is_finite()) {
            return Err(Error::input(path, format!("object '{name}': a texture coordinate is not finite")));
        }
        attrs.push(("TEXCOORD_0".to_string(), Stream::from_f32("VEC2", &uv)));
    }
    Ok(weld(attrs, vec![], 4))
}

/// An MTL texture statement: options (`-bm 0.5`, `-o u v w`, ...) and the file name.
struct TexStatement {
    file: String,
    bm: f32,
}

fn parse_tex(s: &str) -> TexStatement {
    let toks: Vec<&str> = s.split_whitespace().collect();
    let mut i = 0;
    let mut bm = 1.0;
    while i < toks.len() && toks[i].starts_with('-') && toks[i].len() > 1 {
        let opt = toks[i];
        i += 1;
        let fixed = match opt {
            "-bm" => {
                bm = toks.get(i).and_then(|t| t.parse().ok()).unwrap_or(1.0);
                1
            }
            "-o" | "-s" | "-t" => {
                let mut n = 0;
                while n < 3 && toks.get(i + n).map(|t| t.parse::<f32>().is_ok()).unwrap_or(false) {
                    n += 1;
                }
                n
            }
            "-mm" => 2,
            _ => 1,
        };
        i += fixed;
    }
    TexStatement { file: toks.get(i..).map(|t| t.join(" ")).unwrap_or_default(), bm }
}

fn add_texture(scene: &mut Scene, file: &str) -> usize {
    let uri: String = file.replace('\\', "/").split('/').map(encode_segment).collect::<Vec<_>>().join("/");
    let images = array_mut(&mut scene.json, "images");
    let img = match images.iter().position(|i| i.get("uri") == Some(&json!(uri))) {
        Some(i) => i,
        None => {
            images.push(json!({ "uri": uri }));
            images.len() - 1
        }
    };
    let textures = array_mut(&mut scene.json, "textures");
    match textures.iter().position(|t| t.get("source") == Some(&json!(img))) {
        Some(t) => t,
        None => {
            textures.push(json!({ "source": img }));
            textures.len() - 1
        }
    }
}

fn encode_segment(s: &str) -> String {
    s.bytes()
        .map(|b| match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' | b'~' => (b as char).to_string(),
            _ => format!("%{b:02X}"),
        })
        .collect()
}

fn add_material(scene: &mut Scene, index: usize, m: &tobj::Material) -> Result<()> {
    let kd = m.diffuse.unwrap_or([0.8, 0.8, 0.8]);
    let alpha = m.dissolve.unwrap_or(1.0).clamp(0.0, 1.0);
    let roughness = m.shininess.map(|ns| (2.0 / (ns.max(0.0) + 2.0)).sqrt()).unwrap_or(1.0);
    let mut mat = json!({
        "name": m.name,
        "pbrMetallicRoughness": {
            "baseColorFactor": [kd[0].clamp(0.0, 1.0), kd[1].clamp(0.0, 1.0), kd[2].clamp(0.0, 1.0), alpha],
            "metallicFactor": 0.0,
            "roughnessFactor": roughness.clamp(0.0, 1.0),
        }
    });
    if alpha < 1.0 {
        set_key(&mut mat, "alphaMode", json!("BLEND"));
    }
    if let Some(t) = &m.diffuse_texture {
        let t = add_texture(scene, &parse_tex(t).file);
        if let Some(pbr) = mat.get_mut("pbrMetallicRoughness") {
            set_key(pbr, "baseColorTexture", json!({ "index": t }));
        }
    }
    let norm = m.unknown_param.get("norm").map(|s| (parse_tex(s), true));
    let bump = m.normal_texture.as_ref().map(|s| (parse_tex(s), false));
    if let Some((tex, always_normal)) = norm.or(bump) {
        let is_normal = always_normal || looks_like_normal_map(scene, &tex.file);
        if is_normal {
            let t = add_texture(scene, &tex.file);
            let mut info = json!({ "index": t });
            if tex.bm != 1.0 {
                set_key(&mut info, "scale", json!(tex.bm));
            }
            set_key(&mut mat, "normalTexture", info);
        } else {
            scene.height_maps.push(HeightMapRef {
                material: index,
                path: scene.base_dir.join(&tex.file),
                multiplier: tex.bm,
            });
        }
    }
    array_mut(&mut scene.json, "materials").push(mat);
    Ok(())
}

/// A bump texture is a normal map when its pixels are coloured and lean towards +Z (blue);
/// grey pixels are heights. Images that cannot be read or decoded (missing, corrupt, or claiming
/// more pixels than [`super::image::Limits::TEXTURE`] allows, checked from the header before anything is
/// allocated) count as heights, with a note saying why; `bake` reports them when it needs them.
fn looks_like_normal_map(scene: &mut Scene, file: &str) -> bool {
    let bytes = match super::uri::read(file, &scene.base_dir, &scene.source, scene.allow_outside) {
        Ok(b) => b,
        Err(e) => {
            scene
                .notes
                .push(format!("bump map '{file}' could not be read to classify it ({e}); taken as a height map"));
            return false;
        }
    };
    let img = match super::image::decode(&bytes) {
        Ok(i) => i,
        Err(e) => {
            scene.notes.push(format!("bump map '{file}': {e}; taken as a height map"));
            return false;
        }
    };
    classify_normal_map(&img)
}

/// The colour test of [`looks_like_normal_map`], on at most about a million sampled pixels.
pub(crate) fn classify_normal_map(img: &image::DynamicImage) -> bool {
    use image::GenericImageView as _;
    if !img.color().has_color() {
        return false;
    }
    let (w, h) = img.dimensions();
    let step = ((w as u64 * h as u64) as f64 / 1_048_576.0).sqrt().ceil().max(1.0) as u32;
    let (mut sr, mut sg, mut sb, mut grey, mut n) = (0.0, 0.0, 0.0, 0u64, 0u64);
    for y in (0..h).step_by(step as usize) {
        for x in (0..w).step_by(step as usize) {
            let p = img.get_pixel(x, y);
            // 8-bit view of any sample type.
            let (r, g, b) = (p[0], p[1], p[2]);
            sr += r as f64;
            sg += g as f64;
            sb += b as f64;
            n += 1;
            if r == g && g == b {
                grey += 1;
            }
        }
    }
    let n = n.max(1) as f64;
    let (r, g, b) = (sr / n / 255.0, sg / n / 255.0, sb / n / 255.0);
    (grey as f64) < 0.9 * n && b > 0.6 && (r - 0.5).abs() < 0.2 && (g - 0.5).abs() < 0.2
}

/// Every TEXCOORD of `p` flipped from v up (OBJ) to v down (glTF), per welded vertex.
fn uvs_to_gltf(p: &mut Primitive) {
    for (name, s) in p.attributes.iter_mut() {
        if name.starts_with("TEXCOORD_") && s.format.component_type == crate::scene::accessor::FLOAT {
            let uv: Vec<[f32; 2]> = s.to_f32::<2>().into_iter().map(|[u, v]| [u, 1.0 - v]).collect();
            let template = s.template.take();
            *s = Stream::from_f32("VEC2", &uv);
            s.template = template;
        }
    }
}

#[cfg(test)]
#[path = "obj_tests.rs"]
mod tests;
