//! Whether a material's roughness, level by level, carries what its KTX2 normal map's mips lose.
//!
//! A level-k normal texel averages the level-0 normals under it into a mean of length `L < 1`;
//! renderers normalise it again and draw the surface smoother and shinier than it is. Specular
//! antialiasing (`normalmap::specular_aa`) moves that lost spread into the roughness of the same
//! level. Here the roughness each level should have (the material's own, widened by the normal
//! level's variance) is compared with the roughness the material gives at that level: its factor
//! times the G channel of its metallicRoughness texture's matching level, or the factor alone.
//! Both textures are assumed to be placed by the same UVs.

use super::mip_levels::Level;
use super::{Code, Example, Finding, Subject};
use crate::format::image::{self as img, ktx2, Kind, Limits};
use crate::normalmap::{mips, specular_aa};
use crate::scene::material::{MaterialInfo, Slot};
use crate::scene::Scene;

/// A texel counts as under when the variance adds more than this to its roughness and the
/// material gives it more than this less than the widened value: a 0.05 step in perceptual
/// roughness is about the smallest change of a highlight's size one can see, and stays clear of
/// 8-bit and codec rounding of the G channel (0.004 to 0.02).
pub const MARGIN: f32 = 0.05;
/// A level is reported when more than this share of its texels are under: "most of the level".
pub const SHARE: f64 = 0.5;

/// The material's roughness at every level of its metallicRoughness texture's chain (factor
/// included), or the factor alone.
enum Roughness {
    Factor(f32),
    Chain(Vec<(usize, usize, Vec<f32>)>),
}

impl Roughness {
    /// The roughness at normal-map level `k` (of a `w` x `h` level 0), texel `(x, y)` of its
    /// `lw` x `lh`: the chain level of the nearest size, nearest texel.
    fn at(&self, nw: usize, k: usize, lw: usize, lh: usize, x: usize, y: usize) -> f32 {
        match self {
            Roughness::Factor(f) => *f,
            Roughness::Chain(levels) => {
                let (w0, _, _) = levels[0];
                let shift = (w0 as f64 / nw as f64).log2().round() as isize;
                let j = (k as isize + shift).clamp(0, levels.len() as isize - 1) as usize;
                let (w, h, v) = &levels[j];
                let sx = ((x as f64 + 0.5) * *w as f64 / lw as f64) as usize;
                let sy = ((y as f64 + 0.5) * *h as f64 / lh as f64) as usize;
                v[sy.min(h - 1) * w + sx.min(w - 1)]
            }
        }
    }

    fn min(&self) -> f32 {
        match self {
            Roughness::Factor(f) => *f,
            Roughness::Chain(l) => l.iter().flat_map(|(_, _, v)| v.iter().copied()).fold(1.0, f32::min),
        }
    }
}

/// The G channel of every level (scaled by `factor`); a texture without a chain gets the box
/// mips a renderer makes, which average roughness and add nothing for the normals.
fn chain_of(bytes: &[u8], factor: f32) -> Option<Vec<(usize, usize, Vec<f32>)>> {
    let imgs = if Kind::sniff(bytes) == Kind::Ktx2 {
        ktx2::decode_levels_within(bytes, &Limits::TEXTURE).ok()?
    } else {
        vec![img::decode(bytes).ok()?]
    };
    let g = |i: &image::DynamicImage| -> Vec<f32> { i.to_rgb32f().pixels().map(|p| p.0[1] * factor).collect() };
    let (w, h) = (imgs[0].width() as usize, imgs[0].height() as usize);
    if imgs.len() > 1 {
        return Some(imgs.iter().map(|i| (i.width() as usize, i.height() as usize, g(i))).collect());
    }
    let plane = g(&imgs[0]);
    Some(
        mips::scalar_levels(&plane, w, h)
            .into_iter()
            .enumerate()
            .map(|(k, v)| (mips::level_size(w, k), mips::level_size(h, k), v))
            .collect(),
    )
}

/// What material `m` gives as roughness, if it is a metal-roughness material whose roughness can
/// be read (`None`: not checked).
fn roughness_of(scene: &Scene, m: &MaterialInfo) -> Option<Roughness> {
    if scene.is_specular_glossiness(m.index) {
        return None;
    }
    let factor = m.roughness_factor.unwrap_or(1.0).clamp(0.0, 1.0);
    let Some(t) = m.texture(Slot::MetallicRoughness) else { return Some(Roughness::Factor(factor)) };
    // The image a client with KHR_texture_basisu shows first: that is where a chain can be.
    let bytes = scene
        .texture_images(t.texture)
        .into_iter()
        .filter_map(|ti| scene.image_bytes(ti.image).ok())
        .find(|b| img::not_decoded_why(b).is_none())?;
    chain_of(&bytes, factor).map(Roughness::Chain)
}

/// One material's levels: (level, texels under, texels), for levels 1 and below.
fn under_per_level(levels: &[Level], r: &Roughness) -> Vec<(usize, usize, usize)> {
    let base = &levels[0];
    let (w, h) = (base.width, base.height);
    let normals: Vec<[f32; 3]> = (0..h).flat_map(|y| (0..w).map(move |x| base.unit(x, y))).collect();
    let chain = mips::build(&normals, w, h);
    drop(normals);
    let r0: Vec<f32> = (0..h).flat_map(|y| (0..w).map(move |x| r.at(w, 0, w, h, x, y))).collect();
    let wanted = specular_aa::roughness_levels(&chain, &r0, specular_aa::DEFAULT_THRESHOLD);
    wanted
        .iter()
        .enumerate()
        .take(levels.len())
        .skip(1)
        .map(|(k, l)| {
            let mut under = 0;
            for y in 0..l.height {
                for x in 0..l.width {
                    let i = y * l.width + x;
                    let (want, own) = (l.roughness[i], l.base[i]);
                    let given = r.at(w, k, l.width, l.height, x, y);
                    if want - own > MARGIN && given < want - MARGIN {
                        under += 1;
                    }
                }
            }
            (k, under, l.width * l.height)
        })
        .collect()
}

/// The check for every material that shows this KTX2 chain as its normal texture.
pub fn check(scene: &Scene, materials: &[&MaterialInfo], levels: &[Level], s: &mut Subject) {
    if levels.len() < 2 {
        return;
    }
    // Where even the smoothest texel is rough enough (0.57 and up), the capped widening adds at
    // most MARGIN: nothing to find, and the level-0 chain need not be built.
    let most_added = |r: f32| (r.powi(4) + specular_aa::DEFAULT_THRESHOLD.powi(2)).sqrt().sqrt() - r;
    let mut checked = 0usize;
    // Per material: its label and its levels under (level, texels under, texels).
    type Under = (String, Vec<(usize, usize, usize)>);
    let mut flagged: Vec<Under> = Vec::new();
    for m in materials {
        let Some(r) = roughness_of(scene, m) else { continue };
        checked += levels.len() - 1;
        if most_added(r.min().clamp(0.0, 1.0)) <= MARGIN {
            continue;
        }
        let bad: Vec<_> =
            under_per_level(levels, &r).into_iter().filter(|&(_, u, n)| u as f64 > SHARE * n as f64).collect();
        if !bad.is_empty() {
            flagged.push((m.label(), bad));
        }
    }
    if checked == 0 {
        return;
    }
    let finding = (!flagged.is_empty()).then(|| {
        let count: usize = flagged.iter().map(|(_, b)| b.len()).sum();
        let words: Vec<String> = flagged
            .iter()
            .map(|(m, b)| {
                let ks: Vec<String> = b.iter().map(|(k, _, _)| k.to_string()).collect();
                format!("{m} at levels {}", ks.join(", "))
            })
            .collect();
        let mut examples = Vec::new();
        for (m, b) in &flagged {
            for &(k, u, n) in b {
                if examples.len() < super::MAX_EXAMPLES {
                    examples.push(Example {
                        kind: "level",
                        index: k as u64,
                        at: None,
                        detail: format!(
                            "{m}, level {k}: {u} of {n} texels more than {MARGIN} rougher to be right than the material makes them"
                        ),
                    });
                }
            }
        }
        Finding::new(
            Code::ROUGHNESS_MIPS_NOT_WIDENED,
            count,
            checked,
            "levels",
            format!(
                "the roughness of {} does not account for the bumps this normal map's mips average away: over most of those levels the material is more than {MARGIN} smoother than the roughness widened by the level's normal variance (Toksvig, threshold {}), so the far surface shines too much",
                words.join("; "),
                specular_aa::DEFAULT_THRESHOLD
            ),
        )
        .examples(examples)
        .metric("margin", MARGIN as f64)
        .metric("share", SHARE)
    });
    s.check(Code::ROUGHNESS_MIPS_NOT_WIDENED, finding);
}
