//! The mip chain of a KTX2 normal map: missing levels, levels filtered without renormalising, and
//! levels whose directions are not those of the level above.
//!
//! Only KTX2 carries its own chain: renderers make the mips of a PNG or JPEG themselves (and
//! cannot for a Basis Universal texture once transcoded to a block format), so what is stored is
//! what a minified surface shows. The thresholds are derived or measured in `docs/validate.md`
//! ("Mip chains").

use super::{lossy, normal_image::Texels, Code, Example, Finding, Subject};
use crate::normalmap::mips::footprints;
use image::{DynamicImage, Rgb32FImage, RgbImage};

/// A map larger than this on a side and without levels below it aliases when minified: at 256 a
/// texel still covers a pixel of a 256-pixel-wide object on screen, past it sparkles start.
pub const MIPS_NEEDED_ABOVE: u32 = 256;
/// Levels with fewer texels are not judged for direction: a few texels carry no statistics
/// and a minified surface shows them as a handful of pixels.
pub const DIRECTION_MIN_TEXELS: usize = 16;
/// Levels whose predicted normals tilt less than this (RMS) are not judged for direction: 8-bit
/// rounding and codec noise are then as large as the relief (measured: correct ETC1S levels at
/// 1.3° to 2.2° RMS tilt correlate from -0.41 to 0.62 with the level above).
pub const DIRECTION_MIN_TILT_DEG: f64 = 3.0;
/// A judged level whose tilts correlate less than this with those predicted from the level above
/// departs from it. Correct chains measured 0.51 at worst (ETC1S), a level rotated by 90°, with
/// green flipped or its image turned 0.08 at most (`docs/validate.md`).
pub const DIRECTION_MIN_CORRELATION: f64 = 0.25;

/// One decoded level.
pub struct Level {
    pub width: usize,
    pub height: usize,
    plane: Plane,
}

enum Plane {
    Rgb8(RgbImage),
    RgbF(Rgb32FImage),
}

impl Level {
    /// The level's texels, 8-bit ones kept at 3 bytes each (a large map's level 0 is most of it).
    pub fn new(img: &DynamicImage) -> Level {
        let plane = match img {
            DynamicImage::ImageLuma8(_)
            | DynamicImage::ImageLumaA8(_)
            | DynamicImage::ImageRgb8(_)
            | DynamicImage::ImageRgba8(_) => Plane::Rgb8(img.to_rgb8()),
            _ => Plane::RgbF(img.to_rgb32f()),
        };
        Level { width: img.width() as usize, height: img.height() as usize, plane }
    }

    /// The texel as decoded, `n = 2 * texel - 1`, not renormalised.
    #[inline]
    pub fn normal(&self, x: usize, y: usize) -> [f32; 3] {
        match &self.plane {
            Plane::Rgb8(i) => Texels::Rgb8(i).normal(x as u32, y as u32),
            Plane::RgbF(i) => Texels::RgbF(i).normal(x as u32, y as u32),
        }
    }

    /// The texel made unit (`+Z` for a zero or non-finite vector).
    #[inline]
    pub fn unit(&self, x: usize, y: usize) -> [f32; 3] {
        unit(self.normal(x, y))
    }
}

fn unit(n: [f32; 3]) -> [f32; 3] {
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if l > 1e-12 && l.is_finite() {
        [n[0] / l, n[1] / l, n[2] / l]
    } else {
        [0.0, 0.0, 1.0]
    }
}

/// Every level of a decoded KTX2 image.
pub fn levels(imgs: &[DynamicImage]) -> Vec<Level> {
    imgs.iter().map(Level::new).collect()
}

/// How far the mean length of a correctly renormalised level may be from 1 after 8-bit rounding
/// and `codec`: each texel of a unit vector rounded to 8 bits is within `sqrt(3)/255` of unit
/// length. A lossy codec's length error has RMS at most `lossy::sigma` (0.0315), and a mean is
/// never further from 0 than the RMS; ETC1S came to 0.030 on a correct chain of a steep map, so
/// the bound the lossy rule already gives a median, `sqrt(2) * sigma` (0.0445), leaves headroom.
pub fn unit_tolerance(codec: lossy::Codec) -> f64 {
    (3f64.sqrt() / 255.0).max(if codec.is_lossy() { lossy::median_bound(codec) } else { 0.0 })
}

fn level_example(k: usize, l: &Level, detail: String) -> Example {
    Example {
        kind: "level",
        index: k as u64,
        at: None,
        detail: format!("level {k} ({}x{}): {detail}", l.width, l.height),
    }
}

/// The three chain checks on one KTX2 normal map's levels (level 0 first); `codec` is how the
/// file codes them.
pub fn check(levels: &[Level], codec: lossy::Codec, s: &mut Subject) {
    let Some(base) = levels.first() else { return };
    check_missing(levels, base, s);
    if levels.len() < 2 {
        return;
    }
    check_unit(levels, codec, s);
    check_direction(levels, s);
}

fn check_missing(levels: &[Level], base: &Level, s: &mut Subject) {
    let last = &levels[levels.len() - 1];
    let side = last.width.max(last.height);
    let full = crate::normalmap::mips::level_count(base.width, base.height);
    let finding = (side > MIPS_NEEDED_ABOVE as usize).then(|| {
        let what = if levels.len() == 1 {
            "no mip levels".to_string()
        } else {
            format!("{} of the {full} levels of a full chain, the smallest {}x{}", levels.len(), last.width, last.height)
        };
        Finding::new(
            Code::NORMALMAP_MIPS_MISSING,
            full - levels.len(),
            full,
            "levels",
            format!(
                "this {}x{} KTX2 normal map has {what}: wherever it is drawn smaller than {side} pixels across, texels are skipped and the bumps sparkle and shimmer (and a Basis Universal texture cannot have mips made by the renderer)",
                base.width, base.height
            ),
        )
        .metric("levels", levels.len() as f64)
        .metric("full_chain_levels", full as f64)
    });
    s.check(Code::NORMALMAP_MIPS_MISSING, finding);
}

/// Levels below the first whose texels' mean length is off 1 by more than the rounding explains.
fn check_unit(levels: &[Level], codec: lossy::Codec, s: &mut Subject) {
    let tol = unit_tolerance(codec);
    let mut off = Vec::new();
    for (k, l) in levels.iter().enumerate().skip(1) {
        let mut sum = 0.0f64;
        for y in 0..l.height {
            for x in 0..l.width {
                let n = l.normal(x, y);
                let len = ((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) as f64).sqrt();
                sum += if len.is_finite() { len } else { 0.0 };
            }
        }
        let mean = sum / (l.width * l.height) as f64;
        if (mean - 1.0).abs() > tol {
            off.push((k, mean));
        }
    }
    let checked = levels.len() - 1;
    let finding = (!off.is_empty()).then(|| {
        let worst = off.iter().map(|&(_, m)| m).fold(1.0f64, |a, m| if (m - 1.0).abs() > (a - 1.0).abs() { m } else { a });
        let mut sorted = off.clone();
        sorted.sort_by(|a, b| (b.1 - 1.0).abs().total_cmp(&(a.1 - 1.0).abs()).then(a.0.cmp(&b.0)));
        let examples = sorted
            .iter()
            .take(super::MAX_EXAMPLES)
            .map(|&(k, m)| level_example(k, &levels[k], format!("mean texel length {m:.3}")))
            .collect();
        let list: Vec<String> = off.iter().map(|(k, _)| k.to_string()).collect();
        Finding::new(
            Code::NORMALMAP_MIPS_NOT_UNIT,
            off.len(),
            checked,
            "levels",
            format!(
                "levels {} store texels of mean length down to {worst:.3} (a renormalised level is within {tol:.4} of 1 after 8-bit{} rounding): the chain was filtered without renormalising, so renderers that do not normalise the sampled normal shade minified bumps darker and flatter",
                list.join(", "),
                if codec.is_lossy() { format!(" and {}", codec.name()) } else { String::new() }
            ),
        )
        .examples(examples)
        .metric("worst_mean_length", worst)
        .metric("tolerance", tol)
    });
    s.check(Code::NORMALMAP_MIPS_NOT_UNIT, finding);
}

/// What one level's directions say against the prediction from a level above.
struct Agreement {
    /// Correlation of the tilts `(x, y)` of the unit texels with the predicted ones.
    correlation: f64,
    /// RMS tilt of the prediction, degrees.
    tilt_deg: f64,
    /// Median angle between texel and prediction, degrees.
    median_deg: f64,
}

/// Level `dst` against the renormalised footprint means of level `src`'s unit texels.
fn agreement(src: &Level, dst: &Level) -> Agreement {
    let fx = footprints(src.width, dst.width);
    let fy = footprints(src.height, dst.height);
    let (mut ab, mut aa, mut bb) = (0.0f64, 0.0f64, 0.0f64);
    let mut angles = Vec::with_capacity(dst.width * dst.height);
    for (y, fy) in fy.iter().enumerate() {
        for (x, fx) in fx.iter().enumerate() {
            let mut m = [0.0f64; 3];
            for &(sy, wy) in fy {
                for &(sx, wx) in fx {
                    let u = src.unit(sx, sy);
                    for i in 0..3 {
                        m[i] += wx * wy * u[i] as f64;
                    }
                }
            }
            let b = unit([m[0] as f32, m[1] as f32, m[2] as f32]);
            let a = dst.unit(x, y);
            ab += (a[0] * b[0] + a[1] * b[1]) as f64;
            aa += (a[0] * a[0] + a[1] * a[1]) as f64;
            bb += (b[0] * b[0] + b[1] * b[1]) as f64;
            let dot = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) as f64;
            angles.push(dot.clamp(-1.0, 1.0).acos().to_degrees());
        }
    }
    let n = angles.len().max(1) as f64;
    let correlation = if aa > 0.0 && bb > 0.0 { ab / (aa * bb).sqrt() } else { 1.0 };
    let mid = angles.len() / 2;
    let median_deg = if angles.is_empty() { 0.0 } else { *angles.select_nth_unstable_by(mid, f64::total_cmp).1 };
    Agreement { correlation, tilt_deg: (bb / n).sqrt().min(1.0).asin().to_degrees(), median_deg }
}

/// Each level against the last level above it that agreed with its own predecessor, so that one
/// bad level is reported once and does not make the next one look bad too.
fn check_direction(levels: &[Level], s: &mut Subject) {
    let mut good = 0usize;
    let mut judged = 0usize;
    let mut off: Vec<(usize, usize, Agreement)> = Vec::new();
    for k in 1..levels.len() {
        let dst = &levels[k];
        if dst.width * dst.height < DIRECTION_MIN_TEXELS {
            break;
        }
        let a = agreement(&levels[good], dst);
        if a.tilt_deg < DIRECTION_MIN_TILT_DEG {
            good = k;
            continue;
        }
        judged += 1;
        if a.correlation < DIRECTION_MIN_CORRELATION {
            off.push((k, good, a));
        } else {
            good = k;
        }
    }
    if judged == 0 {
        return;
    }
    let finding = (!off.is_empty()).then(|| {
        let examples = off
            .iter()
            .take(super::MAX_EXAMPLES)
            .map(|(k, src, a)| {
                level_example(
                    *k,
                    &levels[*k],
                    format!(
                        "tilts correlate {:.2} with the mean of level {src} (median angle {:.1}°, predicted RMS tilt {:.1}°)",
                        a.correlation, a.median_deg, a.tilt_deg
                    ),
                )
            })
            .collect();
        let list: Vec<String> = off.iter().map(|(k, _, _)| k.to_string()).collect();
        let worst = off.iter().map(|(_, _, a)| a.correlation).fold(f64::INFINITY, f64::min);
        Finding::new(
            Code::NORMALMAP_MIPS_DIRECTION,
            off.len(),
            judged,
            "levels",
            format!(
                "levels {} do not point where the level above them does (tilt correlation {worst:.2}, correct chains keep it above {DIRECTION_MIN_CORRELATION} whatever the codec): the bumps turn or flip as the surface recedes",
                list.join(", ")
            ),
        )
        .examples(examples)
        .metric("worst_correlation", worst)
        .metric("threshold", DIRECTION_MIN_CORRELATION)
    });
    s.check(Code::NORMALMAP_MIPS_DIRECTION, finding);
}
