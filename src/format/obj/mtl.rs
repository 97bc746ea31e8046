//! MTL libraries, read through `tobj`, as glTF materials: base colour, roughness from `Ns`,
//! and a bump map told apart as a normal map or a height map by its pixels.

use crate::error::{Error, Result};
use crate::scene::{array_mut, set_key, HeightMapRef, ReadOptions, Scene};
use serde_json::json;
use std::collections::HashMap;
use std::io::BufReader;
use std::path::Path;

/// Materials in order, their index by name, and the MTL files read.
type Materials = (Vec<tobj::Material>, HashMap<String, usize>, Vec<std::path::PathBuf>);

/// The MTL libraries an OBJ names, in order, merged as `tobj` merges them (a later definition
/// of a name wins); also the files read, for depfiles.
pub(super) fn load_materials(path: &Path, base_dir: &Path, libs: &[String], opts: &ReadOptions) -> Result<Materials> {
    let (mut materials, mut map, mut files, mut failed) = (Vec::new(), HashMap::new(), Vec::new(), None);
    for name in libs {
        files.push(base_dir.join(name));
        let bytes = crate::format::gltf::uri::read(name, base_dir, path, opts.allow_outside)?;
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

pub(super) fn add_material(scene: &mut Scene, index: usize, m: &tobj::Material) -> Result<()> {
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
/// more pixels than [`crate::format::image::Limits::TEXTURE`] allows, checked from the header before anything is
/// allocated) count as heights, with a note saying why; `bake` reports them when it needs them.
fn looks_like_normal_map(scene: &mut Scene, file: &str) -> bool {
    let bytes = match crate::format::gltf::uri::read(file, &scene.base_dir, &scene.source, scene.allow_outside) {
        Ok(b) => b,
        Err(e) => {
            scene
                .notes
                .push(format!("bump map '{file}' could not be read to classify it ({e}); taken as a height map"));
            return false;
        }
    };
    let img = match crate::format::image::decode(&bytes) {
        Ok(i) => i,
        Err(e) => {
            scene.notes.push(format!("bump map '{file}': {e}; taken as a height map"));
            return false;
        }
    };
    classify_normal_map(&img)
}

/// The colour test of [`looks_like_normal_map`], on at most about a million sampled pixels.
fn classify_normal_map(img: &image::DynamicImage) -> bool {
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
