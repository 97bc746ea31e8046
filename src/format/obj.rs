//! Reading Wavefront OBJ (+ MTL) into the glTF model.
//!
//! OBJ's UVs run v up; they are turned into glTF's v down here, once, so no stage after the
//! reader knows the mesh came from an OBJ (MikkTSpace's sign flips with v, and the glTF `w` rule,
//! the reference sign negated, flips it back: the frames are the same).

use crate::error::{Error, Result};
use crate::scene::normals::{flat_normals, smooth_normals, unit_or_up};
use crate::scene::weld::weld;
use crate::scene::{array_mut, HeightMapRef, NormalMode, PrimRef, Primitive, ReadOptions, Scene, SourceFormat, Stream};
use serde_json::{json, Value};
use std::cell::RefCell;
use std::io::BufReader;
use std::path::Path;

pub fn read(path: &Path, bytes: &[u8], opts: &ReadOptions) -> Result<Scene> {
    let base_dir = path.parent().map(|p| p.to_path_buf()).unwrap_or_default();
    let mtl_error: RefCell<Option<Error>> = RefCell::new(None);
    let mtl_files: RefCell<Vec<std::path::PathBuf>> = RefCell::new(Vec::new());
    let load = tobj::LoadOptions { triangulate: true, single_index: false, ignore_points: true, ignore_lines: true };
    let (models, materials) = tobj::load_obj_buf(&mut BufReader::new(bytes), &load, |mtl: &Path| {
        let name = mtl.to_string_lossy();
        mtl_files.borrow_mut().push(base_dir.join(mtl));
        match super::uri::read(&name, &base_dir, path, opts.allow_outside) {
            Ok(b) => tobj::load_mtl_buf(&mut BufReader::new(b.as_slice())),
            Err(e) => {
                *mtl_error.borrow_mut() = Some(e);
                Err(tobj::LoadError::OpenFileFailed)
            }
        }
    })
    .map_err(|e| Error::input(path, format!("malformed OBJ: {e}")))?;
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    let materials = materials.map_err(|e| Error::input(path, format!("malformed MTL: {e}")))?;

    let mut scene = Scene {
        json: json!({ "asset": { "version": "2.0", "generator": concat!("bumpbake ", env!("CARGO_PKG_VERSION")) } }),
        buffers: Vec::new(),
        source: path.to_path_buf(),
        base_dir: base_dir.clone(),
        allow_outside: opts.allow_outside,
        source_format: SourceFormat::Obj,
        notes: Vec::new(),
        deps: mtl_files.into_inner(),
        height_maps: Vec::new(),
        ledger: Default::default(),
        own_images: true,
    };
    for (i, m) in materials.iter().enumerate() {
        add_material(&mut scene, i, m)?;
    }

    let mut nodes = Vec::new();
    for model in &models {
        if model.mesh.indices.is_empty() {
            continue;
        }
        let mesh_idx = match scene.json.get("meshes").and_then(|m| m.as_array()).and_then(|m| m.last()) {
            Some(last) if last["name"] == json!(model.name) => scene.json["meshes"].as_array().unwrap().len() - 1,
            _ => {
                let meshes = array_mut(&mut scene.json, "meshes");
                meshes.push(json!({ "name": model.name, "primitives": [] }));
                nodes.push(json!({ "name": model.name, "mesh": meshes.len() - 1 }));
                meshes.len() - 1
            }
        };
        let mut prim = build_primitive(path, &model.mesh, opts.obj_normals, &mut scene.notes, &model.name)?;
        uvs_to_gltf(&mut prim);
        let mut pj = json!({ "attributes": {} });
        if let Some(m) = model.mesh.material_id.filter(|&m| m < materials.len()) {
            pj["material"] = json!(m);
        }
        let prims = scene.json["meshes"][mesh_idx]["primitives"].as_array_mut().expect("primitives array");
        prims.push(pj);
        let r = PrimRef { mesh: mesh_idx, primitive: prims.len() - 1 };
        scene.put_primitive(r, prim);
    }
    if nodes.is_empty() {
        return Err(Error::input(path, "OBJ has no faces"));
    }
    let roots: Vec<usize> = (0..nodes.len()).collect();
    scene.json["nodes"] = Value::Array(nodes);
    scene.json["scenes"] = json!([{ "nodes": roots }]);
    scene.json["scene"] = json!(0);
    Ok(scene)
}

fn build_primitive(
    path: &Path,
    m: &tobj::Mesh,
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
    let img = match images.iter().position(|i| i["uri"] == json!(uri)) {
        Some(i) => i,
        None => {
            images.push(json!({ "uri": uri }));
            images.len() - 1
        }
    };
    let textures = array_mut(&mut scene.json, "textures");
    match textures.iter().position(|t| t["source"] == json!(img)) {
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
        mat["alphaMode"] = json!("BLEND");
    }
    if let Some(t) = &m.diffuse_texture {
        let t = add_texture(scene, &parse_tex(t).file);
        mat["pbrMetallicRoughness"]["baseColorTexture"] = json!({ "index": t });
    }
    let norm = m.unknown_param.get("norm").map(|s| (parse_tex(s), true));
    let bump = m.normal_texture.as_ref().map(|s| (parse_tex(s), false));
    if let Some((tex, always_normal)) = norm.or(bump) {
        let is_normal = always_normal || looks_like_normal_map(scene, &tex.file);
        if is_normal {
            let t = add_texture(scene, &tex.file);
            mat["normalTexture"] = json!({ "index": t });
            if tex.bm != 1.0 {
                mat["normalTexture"]["scale"] = json!(tex.bm);
            }
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
