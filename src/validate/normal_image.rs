//! Normal-map images: texels that cannot be tangent-space normals, flat maps, and which way the
//! green channel runs.
//!
//! # The green-channel detector
//! A normal map made from a height field `h` (conventions: `n = normalize(-S dh/dx, -S dh/dy_up, 1)`)
//! has `g = (-nx/nz, -ny/nz) = S * grad h`: a gradient field, whose curl
//! `dg_y/dx - dg_x/dy_up` vanishes. With the green channel flipped (DirectX, `-Y`) the field is
//! `(S h_x, -S h_y)`, whose curl is `-2 S h_xy`: zero only where the surface has no twist.
//!
//! Central differences of central (or Sobel, or any separable) differences commute exactly, so the
//! residual of a map baked from a height field is quantisation noise alone. The detector sums the
//! squared curl of the map as it is (`E_as`) and with green negated (`E_flip`): with
//! `a = dg_y/dx` and `b = dg_x/dy_up` these are `sum (a - b)^2` and `sum (a + b)^2`, so noise adds
//! equally to both and only the structure tells them apart. The confidence is
//! `|E_flip - E_as| / (E_flip + E_as)`: 0 when the map cannot tell (flat, separable `f(x) + g(y)`
//! relief, pure noise, hand-painted detail), near 1 for any height-field bake with twist.

use super::lossy;
pub use super::lossy::Codec;
use super::{Code, Example, Finding, Subject, Worst};
use crate::normalmap::{Convention, Flatness, Verdict};
use image::{DynamicImage, Rgb32FImage, RgbImage};

/// Words for a detected convention, "undetermined" when the map does not say.
pub fn describe_convention(c: Option<Convention>) -> &'static str {
    c.map_or("undetermined", Convention::describe)
}

/// `None` (the map does not say: flat, separable relief, not from a height field) as `"unknown"`.
fn convention_or_unknown<S: serde::Serializer>(c: &Option<Convention>, s: S) -> Result<S::Ok, S::Error> {
    match c {
        Some(c) => serde::Serialize::serialize(c, s),
        None => s.serialize_str("unknown"),
    }
}

/// The detector's full answer.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Detection {
    /// `None` when the map does not say.
    #[serde(serialize_with = "convention_or_unknown")]
    pub convention: Option<Convention>,
    /// 0 (no evidence) to 1 (certain).
    pub confidence: f64,
    /// Mean squared curl of the map as it is.
    pub curl_as_is: f64,
    /// Mean squared curl with the green channel negated.
    pub curl_flipped: f64,
    /// Texels the curl was measured at.
    pub samples: usize,
}

/// Confidence from which a map in the other convention is reported.
pub const REPORT_CONFIDENCE: f64 = 0.5;
/// Texels whose z is below this cannot give a slope (and are reported as z < 0 or not unit).
const MIN_Z: f32 = 0.05;

/// Decoded texels of an image, whatever its bit depth.
pub enum Texels<'a> {
    Rgb8(&'a RgbImage),
    RgbF(&'a Rgb32FImage),
}

impl Texels<'_> {
    pub fn dimensions(&self) -> (u32, u32) {
        match self {
            Texels::Rgb8(i) => i.dimensions(),
            Texels::RgbF(i) => i.dimensions(),
        }
    }
    /// The texel decoded as the conventions say: `n = 2 * texel - 1`.
    #[inline]
    pub fn normal(&self, x: u32, y: u32) -> [f32; 3] {
        match self {
            Texels::Rgb8(i) => {
                let p = i.get_pixel(x, y).0;
                [p[0] as f32 / 127.5 - 1.0, p[1] as f32 / 127.5 - 1.0, p[2] as f32 / 127.5 - 1.0]
            }
            Texels::RgbF(i) => {
                let p = i.get_pixel(x, y).0;
                [p[0] * 2.0 - 1.0, p[1] * 2.0 - 1.0, p[2] * 2.0 - 1.0]
            }
        }
    }
    /// The slope field `(-nx/nz, -ny/nz)`, if the texel has one.
    #[inline]
    fn slope(&self, x: u32, y: u32) -> Option<(f64, f64)> {
        let n = self.normal(x, y);
        (n[2] > MIN_Z && n.iter().all(|v| v.is_finite())).then(|| ((-n[0] / n[2]) as f64, (-n[1] / n[2]) as f64))
    }
}

/// Which convention an 8-bit normal map follows, and how sure the detector is (0..1).
pub fn detect_convention(img: &RgbImage) -> (Option<Convention>, f64) {
    let d = detect(&Texels::Rgb8(img));
    (d.convention, d.confidence)
}

/// The detector on any decoded image (see the module documentation).
pub fn detect(t: &Texels) -> Detection {
    let (w, h) = t.dimensions();
    let (mut e_as, mut e_flip, mut samples) = (0.0f64, 0.0f64, 0usize);
    if w >= 3 && h >= 3 {
        for y in 1..h - 1 {
            for x in 1..w - 1 {
                let (Some(l), Some(r), Some(up), Some(down)) =
                    (t.slope(x - 1, y), t.slope(x + 1, y), t.slope(x, y - 1), t.slope(x, y + 1))
                else {
                    continue;
                };
                // Row index decreases upwards: y - 1 is up.
                let a = (r.1 - l.1) * 0.5;
                let b = (up.0 - down.0) * 0.5;
                e_as += (a - b) * (a - b);
                e_flip += (a + b) * (a + b);
                samples += 1;
            }
        }
    }
    let total = e_as + e_flip;
    let (convention, confidence) =
        if samples == 0 || total.is_nan() || total <= 1e-12 * samples as f64 || !total.is_finite() {
            (None, 0.0)
        } else {
            let conf = (e_flip - e_as).abs() / total;
            (Some(if e_as <= e_flip { Convention::Opengl } else { Convention::Directx }), conf)
        };
    let per = |e: f64| if samples > 0 { e / samples as f64 } else { 0.0 };
    Detection { convention, confidence, curl_as_is: per(e_as), curl_flipped: per(e_flip), samples }
}

/// All checks on one normal-map image; `codec` is how its bytes were coded
/// ([`Codec::sniff`]), `wanted_by` says who expects `expected`.
pub fn check(img: &DynamicImage, codec: Codec, expected: Convention, wanted_by: &str, s: &mut Subject) {
    let rgb8;
    let rgbf;
    let texels = match img {
        DynamicImage::ImageLuma8(_)
        | DynamicImage::ImageLumaA8(_)
        | DynamicImage::ImageRgb8(_)
        | DynamicImage::ImageRgba8(_) => {
            rgb8 = img.to_rgb8();
            Texels::Rgb8(&rgb8)
        }
        _ => {
            rgbf = img.to_rgb32f();
            Texels::RgbF(&rgbf)
        }
    };
    let (w, h) = texels.dimensions();
    let total = w as usize * h as usize;
    let (mut neg, mut nonunit) = (0usize, 0usize);
    let (mut w_neg, mut w_nu) = (Worst::default(), Worst::default());
    let mut flat = Flatness::default();
    // |n| - 1 of every finite texel: the map's own statistics for the lossy rule.
    let mut devs: Vec<f32> = Vec::with_capacity(if codec.is_lossy() { total } else { 0 });
    for y in 0..h {
        for x in 0..w {
            let n = texels.normal(x, y);
            flat.push(n);
            let texel = |detail: String| Example {
                kind: "texel",
                index: y as u64 * w as u64 + x as u64,
                at: Some([x, y]),
                detail,
            };
            if !n.iter().all(|v| v.is_finite()) {
                nonunit += 1;
                w_nu.push(f64::INFINITY, || {
                    texel("decodes to a vector that is not finite (NaN or infinity)".to_string())
                });
                continue;
            }
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if codec.is_lossy() {
                devs.push(len - 1.0);
            }
            // Half an 8-bit step below zero: 127 is negative, 128 (z = 0 rounded) is not.
            if n[2] < -0.002 {
                neg += 1;
                w_neg.push(-n[2] as f64, || texel(format!("decodes to ({:.3}, {:.3}, {:.3})", n[0], n[1], n[2])));
                continue;
            }
            if (len - 1.0).abs() as f64 > lossy::UNIT_TOLERANCE {
                nonunit += 1;
                w_nu.push((len - 1.0).abs() as f64, || {
                    texel(format!("decodes to ({:.3}, {:.3}, {:.3}), length {len:.3}", n[0], n[1], n[2]))
                });
            }
        }
    }
    let median = lossy::median_abs(&mut devs);
    drop(devs);
    let off = neg + nonunit;
    let explained = codec.is_lossy()
        && off > 0
        && median <= lossy::median_bound(codec)
        && off as f64 <= lossy::allowance(codec) * total as f64;
    if explained {
        s.check(Code::NORMALMAP_Z_NEGATIVE, None);
        s.check(Code::NORMALMAP_NOT_UNIT, None);
        s.check(Code::NORMALMAP_CODEC_NOISE, Some(codec_noise(codec, neg, nonunit, total, median, w_nu, w_neg)));
    } else {
        let systematic = if codec.is_lossy() {
            format!(
                "; more than {} coding explains (median |length - 1| {median:.3}, at most {:.3} and {:.1}% of texels allowed)",
                codec.name(),
                lossy::median_bound(codec),
                100.0 * lossy::allowance(codec)
            )
        } else {
            String::new()
        };
        s.check(
            Code::NORMALMAP_Z_NEGATIVE,
            (neg > 0).then(|| {
                Finding::new(
                    Code::NORMALMAP_Z_NEGATIVE,
                    neg,
                    total,
                    "texels",
                    format!("{neg} of {total} texels decode to z < 0 (pointing into the surface){systematic}"),
                )
                .examples(w_neg.into_examples())
            }),
        );
        s.check(
            Code::NORMALMAP_NOT_UNIT,
            (nonunit > 0).then(|| {
                let f = Finding::new(
                    Code::NORMALMAP_NOT_UNIT,
                    nonunit,
                    total,
                    "texels",
                    format!("{nonunit} of {total} texels decode to vectors more than 10% off unit length{systematic}"),
                )
                .examples(w_nu.into_examples());
                if codec.is_lossy() {
                    f.metric("median_length_error", median).metric("allowed_fraction", lossy::allowance(codec))
                } else {
                    f
                }
            }),
        );
        if codec.is_lossy() {
            s.check(Code::NORMALMAP_CODEC_NOISE, None);
        }
    }
    let tilt = flat.max_tilt_deg();
    s.check(
        Code::NORMALMAP_FLAT,
        (flat.verdict() == Verdict::Flat).then(|| {
            Finding::new(
                Code::NORMALMAP_FLAT,
                total,
                total,
                "texels",
                format!("every texel of this {w}x{h} map is the flat normal (0, 0, 1) to within 8-bit rounding (largest tilt {tilt:.2}°)"),
            )
            .metric("max_tilt_deg", tilt)
        }),
    );
    if flat.verdict() == Verdict::Flat {
        return;
    }
    s.check(
        Code::NORMALMAP_NEARLY_FLAT,
        (flat.verdict() == Verdict::NearlyFlat).then(|| {
            Finding::new(
                Code::NORMALMAP_NEARLY_FLAT,
                total,
                total,
                "texels",
                format!(
                    "the largest tilt of any texel of this {w}x{h} map is {tilt:.2}° (nearly flat: below {:.0}°), so it barely changes the shading",
                    crate::normalmap::NEARLY_FLAT_DEG
                ),
            )
            .metric("max_tilt_deg", tilt)
        }),
    );
    let d = detect(&texels);
    s.convention = Some(d);
    s.check(Code::NORMALMAP_GREEN_FLIPPED, green_finding(&d, expected, wanted_by));
}

/// The one info finding for texels a lossy coding explains.
fn codec_noise(
    codec: Codec,
    neg: usize,
    nonunit: usize,
    total: usize,
    median: f64,
    w_nu: Worst,
    w_neg: Worst,
) -> Finding {
    let off = neg + nonunit;
    let what = match (nonunit, neg) {
        (n, 0) => format!("{n} texels decode more than 10% off unit length"),
        (0, z) => format!("{z} texels decode to z slightly below 0"),
        (n, z) => format!("{n} texels decode more than 10% off unit length and {z} to z slightly below 0"),
    };
    let mut examples = w_nu.into_examples();
    examples.extend(w_neg.into_examples());
    examples.truncate(super::MAX_EXAMPLES);
    Finding::new(
        Code::NORMALMAP_CODEC_NOISE,
        off,
        total,
        "texels",
        format!(
            "{what} ({:.3}% of {total}), scattered: within what {} coding explains (up to {:.1}%; the median texel is {median:.4} off unit length)",
            100.0 * off as f64 / total.max(1) as f64,
            codec.name(),
            100.0 * lossy::allowance(codec)
        ),
    )
    .examples(examples)
    .metric("median_length_error", median)
    .metric("allowed_fraction", lossy::allowance(codec))
}

fn green_finding(d: &Detection, expected: Convention, wanted_by: &str) -> Option<Finding> {
    if d.convention.is_none_or(|c| c == expected) || d.confidence < REPORT_CONFIDENCE {
        return None;
    }
    let hint = match expected {
        Convention::Opengl => Code::NORMALMAP_GREEN_FLIPPED.hint().to_string(),
        Convention::Directx => {
            "invert the green channel: this map is OpenGL (+Y up) and DirectX (-Y) is expected".to_string()
        }
    };
    Some(
        Finding::new(
            Code::NORMALMAP_GREEN_FLIPPED,
            d.samples,
            d.samples,
            "texels",
            format!(
                "looks like {} (confidence {:.2}); {wanted_by} expects {}",
                describe_convention(d.convention),
                d.confidence,
                expected.describe()
            ),
        )
        .hint(hint)
        .metric("confidence", d.confidence)
        .metric("curl_as_is", d.curl_as_is)
        .metric("curl_flipped", d.curl_flipped),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A saddle `h = x * y_up / k` baked with central differences, as 8-bit or float texels.
    fn saddle(directx: bool) -> Rgb32FImage {
        Rgb32FImage::from_fn(16, 16, |x, row| {
            let y = 15.0 - row as f32;
            let (hx, hy) = (y / 8.0, x as f32 / 8.0);
            let l = (hx * hx + hy * hy + 1.0).sqrt();
            let ny = if directx { hy / l } else { -hy / l };
            image::Rgb([(-hx / l) * 0.5 + 0.5, ny * 0.5 + 0.5, (1.0 / l) * 0.5 + 0.5])
        })
    }

    #[test]
    fn float_texels_of_a_saddle() {
        let gl = detect(&Texels::RgbF(&saddle(false)));
        assert_eq!(gl.convention, Some(Convention::Opengl));
        assert!(gl.confidence > 0.99, "{gl:?}");
        let dx = detect(&Texels::RgbF(&saddle(true)));
        assert_eq!(dx.convention, Some(Convention::Directx));
        assert!(dx.confidence > 0.99, "{dx:?}");
    }

    #[test]
    fn flat_tiny_and_vertical_maps_are_unknown() {
        let flat = RgbImage::from_pixel(8, 8, image::Rgb([128, 128, 255]));
        assert_eq!(detect_convention(&flat), (None, 0.0));
        let tiny = RgbImage::from_pixel(2, 2, image::Rgb([200, 10, 255]));
        assert_eq!(detect_convention(&tiny), (None, 0.0));
        // z <= 0 everywhere: no slopes to measure.
        let down = RgbImage::from_pixel(8, 8, image::Rgb([128, 128, 0]));
        assert_eq!(detect_convention(&down), (None, 0.0));
    }
}
