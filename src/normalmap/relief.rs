//! Is a map (nearly) flat? A gentle height map at a low strength gives slopes that round to the
//! flat texel, and a map that changes nothing is worse than none: it costs a texture and
//! tangents, and looks like a successful bake.
//!
//! One definition serves every command: [`Flatness`] is the largest tilt of a map's texels away
//! from `(0, 0, 1)`, measured on the texels as written (or read), so `bake` and `normalmap`
//! warn on exactly the maps `validate` reports as `NORMALMAP_FLAT` or `NORMALMAP_NEARLY_FLAT`.

use super::{HeightPlane, NormalData, NormalImage};
use crate::error::{Setting, Words};
use rayon::prelude::*;

/// Up to this largest tilt a map is exactly flat: every texel is `(0, 0, 1)` to within 8-bit
/// rounding (x and y half a step off, `atan(sqrt(2) * 0.5 / 127.5)` = 0.318°, 0.320° with z one
/// step short of 255), so the map changes nothing.
pub const EXACT_FLAT_DEG: f64 = 0.33;
/// Below this largest tilt a map is nearly flat: about four 8-bit steps in x and y together, a
/// shading change of a few percent at most that few viewers see.
pub const NEARLY_FLAT_DEG: f64 = 2.0;
/// The tilt a suggested strength gives the steepest slope: clearly visible, not extreme.
const SUGGESTED_DEG: f64 = 30.0;

/// What [`Flatness`] says about a map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Every texel is the flat normal (to within 8-bit rounding).
    Flat,
    /// The largest tilt is below [`NEARLY_FLAT_DEG`].
    NearlyFlat,
    /// The map shows relief.
    Relief,
}

/// The largest tilt of a map's texels, accumulated texel by texel (or strip by strip).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Flatness {
    /// Largest `(x^2 + y^2) / z^2` seen: the squared tangent of the tilt (infinite for z <= 0).
    max_tan2: f64,
    /// Texels seen.
    pub texels: usize,
}

impl Flatness {
    /// Adds one decoded normal `n = 2 * texel - 1`.
    #[inline]
    pub fn push(&mut self, n: [f32; 3]) {
        let (x, y, z) = (n[0] as f64, n[1] as f64, n[2] as f64);
        let t = if z > 0.0 { (x * x + y * y) / (z * z) } else { f64::INFINITY };
        // NaN texels count as tilted: they are not flat.
        let t = if t.is_nan() { f64::INFINITY } else { t };
        self.max_tan2 = self.max_tan2.max(t);
        self.texels += 1;
    }

    /// Adds interleaved 8-bit texels with `channels` samples each (RGB or RGBA).
    pub fn push_u8(&mut self, data: &[u8], channels: usize) {
        for t in data.chunks_exact(channels) {
            self.push([t[0] as f32 / 127.5 - 1.0, t[1] as f32 / 127.5 - 1.0, t[2] as f32 / 127.5 - 1.0]);
        }
    }

    /// Adds interleaved 16-bit texels.
    pub fn push_u16(&mut self, data: &[u16], channels: usize) {
        for t in data.chunks_exact(channels) {
            let d = |v: u16| v as f32 / 32767.5 - 1.0;
            self.push([d(t[0]), d(t[1]), d(t[2])]);
        }
    }

    /// The flatness of a whole encoded map (float maps hold the vectors themselves).
    pub fn of_image(img: &NormalImage) -> Flatness {
        let mut f = Flatness::default();
        match &img.data {
            NormalData::U8(d) => f.push_u8(d, img.channels),
            NormalData::U16(d) => f.push_u16(d, img.channels),
            NormalData::F32(d) => d.chunks_exact(img.channels).for_each(|t| f.push([t[0], t[1], t[2]])),
        }
        f
    }

    /// The largest tilt away from `(0, 0, 1)`, in degrees (90 or more for z <= 0).
    pub fn max_tilt_deg(&self) -> f64 {
        if self.max_tan2.is_infinite() {
            90.0
        } else {
            self.max_tan2.sqrt().atan().to_degrees()
        }
    }

    pub fn verdict(&self) -> Verdict {
        let tilt = self.max_tilt_deg();
        if self.texels == 0 || tilt >= NEARLY_FLAT_DEG {
            Verdict::Relief
        } else if tilt <= EXACT_FLAT_DEG {
            Verdict::Flat
        } else {
            Verdict::NearlyFlat
        }
    }

    /// A warning for a map made from `h` at `strength` when it came out (nearly) flat, naming a
    /// strength that would show the relief; `scale` turns that into the number the user gives
    /// (`bake` multiplies [`Setting::Strength`] by an MTL `-bm`).
    pub fn warning(&self, h: &HeightPlane, strength: f32, scale: f32) -> Option<String> {
        let verdict = self.verdict();
        if verdict == Verdict::Relief {
            return None;
        }
        let slope = steepest_slope(h);
        if slope == 0.0 {
            return Some("the height map is constant, so the normal map is flat: it changes nothing".into());
        }
        let tilt = self.max_tilt_deg();
        // The continuous slope, not the rounded texels, sets the strength: the texels of a
        // flat map no longer know how steep the heights were.
        let wanted = SUGGESTED_DEG.to_radians().tan() / slope / (scale.abs().max(f32::MIN_POSITIVE) as f64);
        let what = match verdict {
            Verdict::Flat => "flat: every texel rounds to (0, 0, 1)".to_string(),
            _ => format!("nearly flat: its largest tilt is {tilt:.2}° (below {NEARLY_FLAT_DEG:.0}°)"),
        };
        let w = Words::from(format!("the normal map is {what} at strength {strength}; "));
        let w = w.given(Setting::Strength, round2(wanted));
        Some(w.text(format!(" would tilt the steepest slope {SUGGESTED_DEG:.0}°")).to_string())
    }
}

/// The steepest slope of the heights, in units of `h` per texel (central differences; the
/// smoothing filters give a little less).
pub fn steepest_slope(h: &HeightPlane) -> f64 {
    let (w, ht) = (h.width, h.height);
    if w < 3 && ht < 3 {
        return 0.0;
    }
    (0..ht)
        .into_par_iter()
        .map(|y| {
            let row = &h.data[y * w..(y + 1) * w];
            let mut best = 0.0f64;
            for x in 0..w {
                let dx = if w >= 3 { (row[(x + 1).min(w - 1)] - row[x.saturating_sub(1)]) as f64 / 2.0 } else { 0.0 };
                let dy = if ht >= 3 {
                    (h.data[(y + 1).min(ht - 1) * w + x] - h.data[y.saturating_sub(1) * w + x]) as f64 / 2.0
                } else {
                    0.0
                };
                let s = dx.hypot(dy);
                if s.is_finite() && s > best {
                    best = s;
                }
            }
            best
        })
        .reduce(|| 0.0, f64::max)
}

/// Two significant digits: a strength to type, not a measurement.
fn round2(x: f64) -> f64 {
    if x <= 0.0 || !x.is_finite() {
        return x;
    }
    let p = 10f64.powi(x.log10().floor() as i32 - 1);
    (x / p).round() * p
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(step: f32) -> HeightPlane {
        let (w, h) = (16, 8);
        HeightPlane { width: w, height: h, data: (0..w * h).map(|i| (i % w) as f32 * step).collect() }
    }

    fn tilted(deg: f64) -> Flatness {
        let mut f = Flatness::default();
        let t = deg.to_radians();
        f.push([0.0, 0.0, 1.0]);
        f.push([t.sin() as f32, 0.0, t.cos() as f32]);
        f
    }

    #[test]
    fn a_ramp_has_its_slope_and_a_strength_that_tilts_it_thirty_degrees() {
        assert!((steepest_slope(&ramp(0.001)) - 0.001).abs() < 1e-7);
        let w = tilted(0.06).warning(&ramp(0.001), 1.0, 1.0).expect("0.06° is flat");
        assert!(w.contains("strength=580 "), "{w}");
        assert!(tilted(30.0).warning(&ramp(0.001), 580.0, 1.0).is_none());
        assert!(tilted(0.0).warning(&ramp(0.0), 1.0, 1.0).unwrap().contains("constant"));
    }

    #[test]
    fn the_eight_bit_flat_texels_are_flat_one_step_more_is_nearly_flat() {
        let mut f = Flatness::default();
        f.push_u8(&[128, 128, 255, 127, 127, 255, 127, 128, 254], 3);
        assert_eq!(f.verdict(), Verdict::Flat, "{}", f.max_tilt_deg());
        // 125..130: the gentle bump of issue 22, about 1.6° at the corner texel.
        f.push_u8(&[130, 125, 255], 3);
        assert_eq!(f.verdict(), Verdict::NearlyFlat);
        assert!((f.max_tilt_deg() - 1.55).abs() < 0.05, "{}", f.max_tilt_deg());
        f.push_u8(&[150, 128, 250], 3);
        assert_eq!(f.verdict(), Verdict::Relief);
        let mut down = Flatness::default();
        down.push([0.0, 0.0, -1.0]);
        assert_eq!(down.max_tilt_deg(), 90.0);
        assert_eq!(Flatness::default().verdict(), Verdict::Relief, "no texels: nothing to call flat");
    }
}
