//! The dither of 8-bit maps: before rounding, each channel of each texel gets noise of a
//! triangular distribution on `(-1, 1)` levels (the difference of two uniform variables), which
//! makes the rounding error independent of the value and spreads a gentle gradient's steps
//! into fine grain instead of bands, while keeping its mean.
//!
//! The noise is a hash of the texel's column, row and channel (Wellons' `lowbias32`, applied
//! three times), so a map is the same, byte for byte, on every run and whatever the thread count.

/// `lowbias32` (Chris Wellons, "Hash function prospector"): a 32-bit integer hash whose output
/// bits each flip with nearly half the input bits.
fn lowbias32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// Triangular noise on `(-1, 1)` for texel `(x, y)`, channel `c`: the difference of the hash's
/// upper and lower 16 bits, each read as a fraction of one.
pub fn noise(x: u32, y: u32, c: u32) -> f64 {
    let h = lowbias32(x ^ lowbias32(y ^ lowbias32(c ^ 0x5bd1_e995)));
    ((h >> 16) as f64 - (h & 0xffff) as f64) / 65536.0
}

/// A component in `[-1, 1]` as an 8-bit level with the dither `noise` (in levels) added before
/// rounding: `normalmap::quantize8`'s `v * 127.5 + 128`, floored, plus the noise, clamped.
#[inline]
pub fn quantize8(v: f32, noise: f64) -> u8 {
    ((v as f64) * 127.5 + 128.0 + noise).floor().clamp(0.0, 255.0) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The noise's mean is 0, its variance 1/6 (a triangle on `(-1, 1)`), and its histogram a
    /// triangle: a quarter of the values within 0.5 of either end would be a uniform's.
    #[test]
    fn noise_is_triangular_and_centred() {
        let v: Vec<f64> = (0..256u32).flat_map(|y| (0..256u32).map(move |x| noise(x, y, y % 3))).collect();
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
        assert!(mean.abs() < 0.01, "mean {mean}");
        assert!((var - 1.0 / 6.0).abs() < 0.005, "variance {var}");
        assert!(v.iter().all(|x| x.abs() < 1.0));
        let outer = v.iter().filter(|x| x.abs() > 0.5).count() as f64 / n;
        assert!((outer - 0.25).abs() < 0.01, "{outer} of the values beyond 0.5");
    }

    /// Without noise the levels are `normalmap::quantize8`'s; with it, the mean level over many
    /// texels is the exact value, which rounding alone misses by up to half a level.
    #[test]
    fn unbiased_and_rounding_without_noise() {
        for k in -100..=100 {
            let v = k as f32 / 100.0;
            assert_eq!(quantize8(v, 0.0), crate::normalmap::quantize8(v));
            let exact = v as f64 * 127.5 + 127.5;
            let mean = (0..4096u32).map(|i| quantize8(v, noise(i % 64, i / 64, 0)) as f64).sum::<f64>() / 4096.0;
            if exact > 1.0 && exact < 254.0 {
                assert!((mean - exact).abs() < 0.04, "{v}: mean {mean}, exact {exact}");
            }
        }
        assert_eq!(quantize8(1.0, 0.99), 255);
        assert_eq!(quantize8(-1.0, -0.99), 0);
    }
}
