//! Is a map about to come out (nearly) flat? A gentle height map at a low strength gives slopes
//! that round to the flat texel, and a map that changes nothing is worse than none: it costs a
//! texture and tangents, and looks like a successful bake.

use super::HeightPlane;
use rayon::prelude::*;

/// Below this tilt of the steepest slope the map is reported as nearly flat: an 8-bit texel
/// step is about 0.45°, so at most a couple of steps anywhere.
const NEARLY_FLAT_DEG: f64 = 1.0;
/// The tilt a suggested strength gives the steepest slope: clearly visible, not extreme.
const SUGGESTED_DEG: f64 = 30.0;

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

/// A warning when `strength` (the strength the filter uses) leaves the map nearly flat, naming a
/// strength that would show the relief; `scale` turns that into the number the user gives
/// (`bake` multiplies `--strength` by an MTL `-bm`).
pub fn flat_warning(h: &HeightPlane, strength: f32, scale: f32) -> Option<String> {
    let slope = steepest_slope(h);
    if slope == 0.0 {
        return Some("the height map is constant, so the normal map is flat: it changes nothing".into());
    }
    let tilt = (strength.abs() as f64 * slope).atan().to_degrees();
    if tilt >= NEARLY_FLAT_DEG {
        return None;
    }
    let wanted = SUGGESTED_DEG.to_radians().tan() / slope / (scale.abs().max(f32::MIN_POSITIVE) as f64);
    Some(format!(
        "the normal map is nearly flat: at strength {strength} the steepest slope tilts the normal only {tilt:.2}°; \
         --strength {} would tilt it {SUGGESTED_DEG:.0}°",
        round2(wanted)
    ))
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

    #[test]
    fn a_ramp_has_its_slope_and_a_strength_that_tilts_it_thirty_degrees() {
        assert!((steepest_slope(&ramp(0.001)) - 0.001).abs() < 1e-7);
        let w = flat_warning(&ramp(0.001), 1.0, 1.0).expect("0.06° is flat");
        assert!(w.contains("--strength 580 "), "{w}");
        assert!(flat_warning(&ramp(0.001), 580.0, 1.0).is_none());
        assert!(flat_warning(&ramp(0.0), 1.0, 1.0).unwrap().contains("constant"));
    }
}
