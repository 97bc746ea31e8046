//! The metallic-roughness texture specular antialiasing gives a material: at the normal map's
//! resolution and with its mip chain, G the widened roughness of each level, R and B (occlusion,
//! often packed in R, and metalness) averaged over the same footprints.
//!
//! The material's roughness factor moves into the texture (level 0 is `roughnessFactor x G`, the
//! factor becomes 1), so level 0 renders as before. The old texture is sampled at the normal
//! map's texel centres; it must be read through the same UV set and transform as the normal
//! texture, or its texels do not correspond and the material is left as it was.

use super::{decodable, decode, encode_levels, ktx2_of, EncodeOptions, RoughnessReport};
use crate::error::{Error, Result};
use crate::format::image::ktx2::Codec;
use crate::normalmap::mips::{self, MipLevel};
use crate::normalmap::specular_aa::{added, roughness_levels, RoughnessLevel};
use crate::normalmap::DEFAULT_UASTC_LEVEL;
use crate::scene::material::TextureUse;
use crate::scene::{Scene, Slot};

/// The UASTC pack level of a roughness chain made from factors alone. Its level 0 is one value
/// and its lower levels the widening, a smooth function of the normals' spread: pack level 0
/// stores it as well as level 2 (on the 2048² fractal bench map at roughness 0.15, mean error
/// 0.03-0.43 against 0.04-0.41 of 255 per level, at most 2/255 either way) in about a fifteenth
/// of the time. A material's own roughness texture keeps the normal maps' level: its detail is
/// what the slower levels are for.
const WIDENING_ONLY_UASTC_LEVEL: u32 = 0;

/// The codec of a roughness chain, given the normal maps' codec and whether the chain carries
/// the material's own roughness texture. Roughness is data, not colour: UASTC (linear) whatever
/// the normal maps' codec.
pub fn codec_for(normal: Codec, from_texture: bool) -> Codec {
    match (normal, from_texture) {
        (Codec::Uastc { rdo, .. }, false) => Codec::Uastc { level: WIDENING_ONLY_UASTC_LEVEL, rdo },
        (c @ Codec::Uastc { .. }, true) => c,
        (Codec::Etc1s { .. }, false) => Codec::Uastc { level: WIDENING_ONLY_UASTC_LEVEL, rdo: None },
        (Codec::Etc1s { .. }, true) => Codec::Uastc { level: DEFAULT_UASTC_LEVEL, rdo: None },
    }
}

/// The widened levels of a material over `normal`'s chain and their RGB8 texels (R and B from
/// `planes`, G the widened roughness, `roughness_factor x` the planes' G at level 0).
fn widened_chain(
    normal: &[MipLevel],
    planes: &Planes,
    roughness_factor: f32,
    threshold: f32,
) -> (Vec<RoughnessLevel>, Vec<Vec<u8>>) {
    let (w, h) = (normal[0].width, normal[0].height);
    let r0: Vec<f32> = planes.g.iter().map(|g| roughness_factor * g).collect();
    let levels = roughness_levels(normal, &r0, threshold);
    let (rs, bs) = (mips::scalar_levels(&planes.r, w, h), mips::scalar_levels(&planes.b, w, h));
    let rgb = levels
        .iter()
        .zip(rs.iter().zip(&bs))
        .map(|(l, (r, b))| {
            (0..l.roughness.len()).flat_map(|i| [byte(r[i]), byte(l.roughness[i]), byte(b[i])]).collect()
        })
        .collect();
    (levels, rgb)
}

/// The metallic-roughness KTX2 that specular antialiasing gives a material with factors only
/// (`roughness_factor`, metalness kept in B as 255), over `normal`'s chain: what `textures`
/// writes for it, for timing it (`bench textures --specular-aa`).
pub fn factors_only_ktx2(
    normal: &[MipLevel],
    roughness_factor: f32,
    threshold: f32,
    normal_codec: Codec,
) -> crate::error::Faulty<Vec<u8>> {
    let ones = Planes::ones(normal[0].width * normal[0].height);
    let (levels, rgb) = widened_chain(normal, &ones, roughness_factor.clamp(0.0, 1.0), threshold);
    ktx2_of(&as_chain(&levels, &rgb), codec_for(normal_codec, false))
}

/// (width, height, texels) of each widened level.
fn as_chain<'a>(levels: &[RoughnessLevel], rgb: &'a [Vec<u8>]) -> Vec<(usize, usize, &'a [u8])> {
    levels.iter().zip(rgb).map(|(l, rgb)| (l.width, l.height, rgb.as_slice())).collect()
}

/// A material's new texture, and what it replaced (for dropping once nothing else shows it).
pub(super) struct Widened {
    pub report: RoughnessReport,
    pub old_texture: Option<usize>,
    pub old_images: Vec<usize>,
}

/// The three planes of an RGB image, in [0, 1], resampled to `w` x `h`.
struct Planes {
    r: Vec<f32>,
    g: Vec<f32>,
    b: Vec<f32>,
}

impl Planes {
    fn ones(n: usize) -> Planes {
        Planes { r: vec![1.0; n], g: vec![1.0; n], b: vec![1.0; n] }
    }
}

/// Bilinear at the destination texel centres, edges clamped. At equal sizes every centre falls
/// on a source centre, so the texels are taken exactly.
fn resample(img: &image::RgbImage, w: usize, h: usize) -> Planes {
    let (sw, sh) = (img.width() as usize, img.height() as usize);
    let raw = img.as_raw();
    let axis = |d: usize, n: usize, m: usize| -> (usize, usize, f32) {
        let x = ((d as f64 + 0.5) * m as f64 / n as f64 - 0.5).clamp(0.0, (m - 1) as f64);
        let i = x.floor() as usize;
        (i, (i + 1).min(m - 1), (x - i as f64) as f32)
    };
    let mut p = Planes { r: Vec::with_capacity(w * h), g: Vec::with_capacity(w * h), b: Vec::with_capacity(w * h) };
    for y in 0..h {
        let (y0, y1, fy) = axis(y, h, sh);
        for x in 0..w {
            let (x0, x1, fx) = axis(x, w, sw);
            let at = |xx: usize, yy: usize, c: usize| raw[(yy * sw + xx) * 3 + c] as f32 / 255.0;
            let mix = |c: usize| {
                let top = at(x0, y0, c) * (1.0 - fx) + at(x1, y0, c) * fx;
                let bottom = at(x0, y1, c) * (1.0 - fx) + at(x1, y1, c) * fx;
                top * (1.0 - fy) + bottom * fy
            };
            p.r.push(mix(0));
            p.g.push(mix(1));
            p.b.push(mix(2));
        }
    }
    p
}

fn byte(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

fn png(w: usize, h: usize, rgb: &[u8]) -> crate::error::Faulty<Vec<u8>> {
    let img = image::RgbImage::from_raw(w as u32, h as u32, rgb.to_vec()).ok_or("a level of the wrong size")?;
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .map_err(|e| crate::error::Fault::caused_by(format!("cannot encode as PNG: {e}"), e))?;
    Ok(out.into_inner())
}

/// Gives material `m`, whose normal texture `n` was encoded as `normal`'s levels, its widened
/// metallic-roughness texture. `Ok(Err(why))`: the material is left as it was.
pub(super) fn widen_material(
    scene: &mut Scene,
    m: usize,
    n: &TextureUse,
    normal: &[MipLevel],
    opts: &EncodeOptions,
) -> Result<std::result::Result<Widened, String>> {
    if scene.is_specular_glossiness(m) {
        return Ok(Err(
            "a specular-glossiness material (KHR_materials_pbrSpecularGlossiness) reads no roughness".into()
        ));
    }
    let info = scene.materials().get(m).cloned();
    let mr = info.as_ref().and_then(|i| i.texture(Slot::MetallicRoughness)).cloned();
    if let Some(mr) = mr.as_ref().filter(|mr| mr.tex_coord != n.tex_coord || mr.transform != n.transform) {
        let how = |t: &TextureUse| match t.transform {
            Some(_) => format!("TEXCOORD_{} through KHR_texture_transform", t.tex_coord),
            None => format!("TEXCOORD_{} untransformed", t.tex_coord),
        };
        return Ok(Err(format!(
            "its metallicRoughnessTexture reads {} and its normal texture {}, so their texels do not correspond",
            how(mr),
            how(n)
        )));
    }
    let (w, h) = (normal[0].width, normal[0].height);
    let planes = match &mr {
        Some(t) => match decodable(scene, t)? {
            Some((image, bytes)) => resample(&decode(scene, image, &bytes)?.to_rgb8(), w, h),
            None => return Ok(Err("its metallicRoughnessTexture has no image bumpbake decodes".into())),
        },
        // Factors only: metalness 1 (times the factor, unchanged), roughness 1 (times the factor,
        // moved into G below); R is unread.
        None => Planes::ones(w * h),
    };
    let factor = scene.pbr_factors(m).roughness.clamp(0.0, 1.0);
    let (levels, rgb) = widened_chain(normal, &planes, factor, opts.threshold);
    let ktx = encode_levels(scene, &as_chain(&levels, &rgb), codec_for(opts.codec, mr.is_some()))?;
    let name = info.as_ref().and_then(|i| i.name.clone()).unwrap_or_else(|| format!("material{m}"));
    let name = format!("{name}_metallicRoughness");
    let image = scene.push_image(&ktx, "image/ktx2", Some(&name));
    let fallback = if opts.fallback {
        let bytes = png(w, h, &rgb[0]).map_err(|e| Error::in_file(&scene.source, e))?;
        Some(scene.push_image(&bytes, "image/png", Some(&name)))
    } else {
        None
    };
    let t = scene.push_basisu_texture(image, fallback, n.sampler);
    scene.set_metallic_roughness(m, t, &n.pointer);
    Ok(Ok(Widened {
        report: RoughnessReport {
            roughness_factor: factor,
            from_texture: mr.is_some(),
            added: added(&levels),
            bytes: ktx.len(),
        },
        old_texture: mr.as_ref().map(|t| t.texture),
        old_images: mr.iter().flat_map(|t| t.images.iter().map(|i| i.image)).collect(),
    }))
}
