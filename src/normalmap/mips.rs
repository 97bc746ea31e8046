//! Mip chains built from the full-resolution normals.
//!
//! Averaging encoded texels level by level compounds the 8-bit rounding at every step and loses
//! how much the normals under a texel disagree. Here every level-k texel is the area-weighted
//! mean of the level-0 unit normals its footprint covers, so its direction is the ideal one and
//! its length `L` (below 1 where the normals spread) is kept for specular antialiasing
//! (`variance = (1 - L) / L`, Toksvig).
//!
//! Level sizes follow KTX2: `max(1, floor(w / 2^k))`. When that does not divide the source size
//! evenly, a texel's footprint covers the source proportionally: `w / w_k` source texels, the
//! edge ones by the fraction that lies inside.

use super::encode::{decode8, quantize8};
use rayon::prelude::*;

/// One level: the stored texels and what they were made from.
#[derive(Clone, Debug, PartialEq)]
pub struct MipLevel {
    pub width: usize,
    pub height: usize,
    /// RGB8, row-major from the top row, in the convention of the level-0 bytes.
    pub rgb: Vec<u8>,
    /// The renormalised average of each texel (what `rgb` rounds).
    pub ideal: Vec<[f32; 3]>,
    /// The length of each texel's average before renormalising: 1 where its footprint is flat.
    pub mean_length: Vec<f32>,
}

/// How many levels a full chain of a `w` x `h` map has: `floor(log2(max(w, h))) + 1`.
pub fn level_count(w: usize, h: usize) -> usize {
    let m = w.max(h).max(1);
    (usize::BITS - m.leading_zeros()) as usize
}

/// `max(1, floor(n / 2^k))`.
pub fn level_size(n: usize, k: usize) -> usize {
    (n >> k.min(usize::BITS as usize - 1)).max(1)
}

/// The source texels (index, weight) each destination texel covers along one axis. Weights sum
/// to `n / m` for every destination texel; integer arithmetic in units of `1/m` keeps the
/// footprints exact, so the result does not depend on rounding of the boundaries.
pub fn footprints(n: usize, m: usize) -> Vec<Vec<(usize, f64)>> {
    (0..m)
        .map(|d| {
            // The footprint is [d·n/m, (d+1)·n/m); in units of 1/m: [d·n, (d+1)·n).
            let (lo, hi) = (d * n, (d + 1) * n);
            let first = lo / m;
            let last = (hi - 1) / m;
            (first..=last)
                .map(|i| {
                    let a = lo.max(i * m);
                    let b = hi.min((i + 1) * m);
                    (i, (b - a) as f64 / m as f64)
                })
                .collect()
        })
        .collect()
}

/// One texel as built: its bytes, its ideal direction, its mean length.
type Texel = ([u8; 3], [f32; 3], f32);

/// The 8-bit texel of a unit vector: rounding, `+Z` for a zero average.
fn encode(v: [f64; 3]) -> ([u8; 3], [f32; 3], f64) {
    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let n = if len > 1e-12 { [v[0] / len, v[1] / len, v[2] / len] } else { [0.0, 0.0, 1.0] };
    let n32 = [n[0] as f32, n[1] as f32, n[2] as f32];
    ([quantize8(n32[0]), quantize8(n32[1]), quantize8(n32[2])], n32, len)
}

/// Unit normals of RGB8 texels (`2c/255 - 1`, renormalised; `+Z` for a zero vector).
pub fn unit_normals(rgb: &[u8]) -> Vec<[f32; 3]> {
    rgb.par_chunks_exact(3)
        .with_min_len(4096)
        .map(|t| {
            let v = [decode8(t[0]), decode8(t[1]), decode8(t[2])];
            let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if len > 1e-12 {
                [v[0] / len, v[1] / len, v[2] / len]
            } else {
                [0.0, 0.0, 1.0]
            }
        })
        .collect()
}

/// The chain of an RGB8 normal map (`w` x `h`): [`build`] on its unit normals, with level 0 the
/// map's own bytes. Re-rounding the renormalised texels would move some by a code: the encoder
/// is given the map as it was made, as the Basis Universal command line is.
pub fn build_rgb(rgb: &[u8], w: usize, h: usize) -> Vec<MipLevel> {
    build_with(unit_normals(rgb), rgb.to_vec(), w, h)
}

/// Every level of the chain of a `w` x `h` map of unit normals (level 0 first; renormalised
/// first, so an ulp off unit does not matter). Level 0 is the input itself, encoded. Each texel
/// is computed on its own in a fixed order, so the bytes do not depend on the number of threads.
///
/// A level is kept as the weighted sums of the level-0 normals under each texel. Where a level's
/// side divides the one above it (every level of a power-of-two map), each footprint is exactly
/// the union of whole texels of the level above, so its sum is theirs: the chain costs about
/// 4/3 of one pass over level 0 instead of one pass per level. Other levels are summed from
/// level 0 with proportional footprints.
pub fn build(normals: &[[f32; 3]], w: usize, h: usize) -> Vec<MipLevel> {
    let (rgb, unit): (Vec<[u8; 3]>, Vec<[f32; 3]>) =
        normals.par_iter().with_min_len(4096).map(|n| encode(n.map(f64::from))).map(|(c, u, _)| (c, u)).unzip();
    build_with(unit, rgb.concat(), w, h)
}

/// The chain of `w` x `h` unit normals whose level 0 is stored as `rgb`.
fn build_with(normals: Vec<[f32; 3]>, rgb: Vec<u8>, w: usize, h: usize) -> Vec<MipLevel> {
    assert_eq!(normals.len(), w * h, "a plane of w x h normals");
    // Level 0: each texel's footprint is itself, so its mean normal has length 1 exactly (a unit
    // normal's length in floating point can fall an ulp short, which specular antialiasing would
    // read as variance and turn roughness 0 into 0.02).
    let base = MipLevel { width: w, height: h, rgb, ideal: normals, mean_length: vec![1.0; w * h] };
    let normals = &base.ideal;
    let mut out = Vec::with_capacity(level_count(w, h));
    // The level above as sums; level 0's sums are its normals (footprints of one texel, weight 1).
    let mut above: Option<(Vec<[f64; 3]>, usize, usize)> = None;
    for k in 1..level_count(w, h) {
        let (lw, lh) = (level_size(w, k), level_size(h, k));
        let area = (w as f64 / lw as f64) * (h as f64 / lh as f64);
        let sums = match &above {
            Some((s, pw, ph)) if pw % lw == 0 && ph % lh == 0 => sum_blocks(s, *pw, lw, lh, pw / lw, ph / lh),
            None if w.is_multiple_of(lw) && h.is_multiple_of(lh) => sum_blocks(normals, w, lw, lh, w / lw, h / lh),
            _ => sum_footprints(normals, w, h, lw, lh),
        };
        let texels: Vec<Texel> = sums
            .par_iter()
            .with_min_len(4096)
            .map(|s| {
                let (rgb, ideal, len) = encode([s[0] / area, s[1] / area, s[2] / area]);
                (rgb, ideal, len.min(1.0) as f32)
            })
            .collect();
        let mut level = MipLevel {
            width: lw,
            height: lh,
            rgb: Vec::with_capacity(lw * lh * 3),
            ideal: Vec::with_capacity(lw * lh),
            mean_length: Vec::with_capacity(lw * lh),
        };
        for (rgb, ideal, len) in texels {
            level.rgb.extend_from_slice(&rgb);
            level.ideal.push(ideal);
            level.mean_length.push(len);
        }
        out.push(level);
        above = Some((sums, lw, lh));
    }
    out.insert(0, base);
    out
}

/// Sums of `rx` x `ry` blocks of a `pw`-wide plane of sums (or of level 0's normals), into an
/// `lw` x `lh` plane.
fn sum_blocks<T: Copy + Into<f64> + Sync>(
    s: &[[T; 3]],
    pw: usize,
    lw: usize,
    lh: usize,
    rx: usize,
    ry: usize,
) -> Vec<[f64; 3]> {
    (0..lw * lh)
        .into_par_iter()
        .with_min_len(1024)
        .map(|i| {
            let (x, y) = (i % lw, i / lw);
            let mut t = [0.0f64; 3];
            for row in s[y * ry * pw..].chunks(pw).take(ry) {
                for v in &row[x * rx..x * rx + rx] {
                    t[0] += v[0].into();
                    t[1] += v[1].into();
                    t[2] += v[2].into();
                }
            }
            t
        })
        .collect()
}

/// Weighted sums of the level-0 normals under each texel of an `lw` x `lh` level.
fn sum_footprints(normals: &[[f32; 3]], w: usize, h: usize, lw: usize, lh: usize) -> Vec<[f64; 3]> {
    let fx = footprints(w, lw);
    let fy = footprints(h, lh);
    (0..lw * lh)
        .into_par_iter()
        .with_min_len(1024)
        .map(|i| {
            let (x, y) = (i % lw, i / lw);
            let mut s = [0.0f64; 3];
            for &(sy, wy) in &fy[y] {
                let row = &normals[sy * w..(sy + 1) * w];
                for &(sx, wx) in &fx[x] {
                    let n = row[sx];
                    let wt = wx * wy;
                    s[0] += wt * n[0] as f64;
                    s[1] += wt * n[1] as f64;
                    s[2] += wt * n[2] as f64;
                }
            }
            s
        })
        .collect()
}

/// Every level of a scalar plane averaged over the same footprints as [`build`]'s texels (level 0
/// is the plane itself).
pub fn scalar_levels(plane: &[f32], w: usize, h: usize) -> Vec<Vec<f32>> {
    assert_eq!(plane.len(), w * h, "a plane of w x h values");
    (0..level_count(w, h))
        .map(|k| {
            let (lw, lh) = (level_size(w, k), level_size(h, k));
            let fx = footprints(w, lw);
            let fy = footprints(h, lh);
            let area = (w as f64 / lw as f64) * (h as f64 / lh as f64);
            (0..lh)
                .into_par_iter()
                .flat_map_iter(|y| {
                    let (fx, fy, plane) = (&fx, &fy, plane);
                    (0..lw).map(move |x| {
                        let mut s = 0.0f64;
                        for &(sy, wy) in &fy[y] {
                            for &(sx, wx) in &fx[x] {
                                s += wx * wy * plane[sy * w + sx] as f64;
                            }
                        }
                        (s / area) as f32
                    })
                })
                .collect()
        })
        .collect()
}

/// Angles (degrees) between stored RGB8 texels and the ideal normals: mean and 99th percentile.
///
/// The angle is `atan2(|a x b|, a . b)`: it needs neither vector at unit length and keeps its
/// precision at the small angles a codec makes, where `acos` of a dot product near 1 would not,
/// so f32 (the precision of the inputs) is enough.
pub fn angular_error(rgb: &[u8], ideal: &[[f32; 3]]) -> (f64, f64) {
    let mut deg: Vec<f32> = rgb
        .par_chunks_exact(3)
        .with_min_len(4096)
        .zip(ideal)
        .map(|(t, b)| {
            let a = [decode8(t[0]), decode8(t[1]), decode8(t[2])];
            let c = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
            let sin = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
            let cos = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            sin.atan2(cos).to_degrees()
        })
        .collect();
    if deg.is_empty() {
        return (0.0, 0.0);
    }
    // In order, so the figure does not depend on the thread count.
    let mean = deg.iter().map(|&d| d as f64).sum::<f64>() / deg.len() as f64;
    let at = ((deg.len() as f64 * 0.99).ceil() as usize).clamp(1, deg.len()) - 1;
    let (_, p99, _) = deg.select_nth_unstable_by(at, f32::total_cmp);
    (mean, *p99 as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn level_sizes_follow_ktx2() {
        assert_eq!(level_count(256, 256), 9);
        assert_eq!(level_count(300, 17), 9);
        assert_eq!(level_count(1, 1), 1);
        assert_eq!((level_size(300, 3), level_size(17, 3)), (37, 2));
        assert_eq!(level_size(17, 8), 1);
    }

    #[test]
    fn footprints_cover_the_source_proportionally() {
        for (n, m) in [(8, 4), (5, 2), (17, 8), (3, 1), (7, 3)] {
            let f = footprints(n, m);
            let mut covered = vec![0.0; n];
            for d in &f {
                let sum: f64 = d.iter().map(|&(_, w)| w).sum();
                assert!((sum - n as f64 / m as f64).abs() < 1e-12);
                for &(i, w) in d {
                    covered[i] += w;
                }
            }
            assert!(covered.iter().all(|&c| (c - 1.0).abs() < 1e-12), "{n}->{m}: {covered:?}");
        }
    }

    /// A checkerboard of two normals tilted by ±t about y averages to +Z with length cos(t).
    #[test]
    fn checkerboard_of_tilts_averages_to_z_with_length_cos() {
        let t = 30f32.to_radians();
        let (a, b) = ([t.sin(), 0.0, t.cos()], [-t.sin(), 0.0, t.cos()]);
        let (w, h) = (16, 16);
        let n: Vec<[f32; 3]> = (0..w * h).map(|i| if (i % w + i / w) % 2 == 0 { a } else { b }).collect();
        let levels = build(&n, w, h);
        assert_eq!(levels.len(), 5);
        for l in &levels[1..] {
            for (&len, ideal) in l.mean_length.iter().zip(&l.ideal) {
                assert!((len - t.cos()).abs() < 1e-6, "{len}");
                assert!(ideal[0].abs() < 1e-6 && ideal[1].abs() < 1e-6 && (ideal[2] - 1.0).abs() < 1e-6);
            }
            assert!(l.rgb.chunks_exact(3).all(|c| c == [128, 128, 255]));
        }
        assert!(levels[0].mean_length.iter().all(|&l| (l - 1.0).abs() < 1e-6));
    }

    /// Opposite normals cancel: the texel is +Z by rule, with length 0.
    #[test]
    fn a_zero_average_is_plus_z() {
        let n = vec![[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]];
        let levels = build(&n, 2, 1);
        assert_eq!(levels[1].rgb, vec![128, 128, 255]);
        assert_eq!(levels[1].mean_length, vec![0.0]);
    }

    #[test]
    fn odd_sizes_cover_every_source_texel() {
        // Level 1 of a 3-wide map is floor(3/2) = 1 texel covering all three.
        let t = [[0.6f32, 0.0, 0.8], [0.0, 0.0, 1.0], [0.0, 0.6, 0.8]];
        let levels = build(&t, 3, 1);
        assert_eq!(levels.len(), 2);
        let m: [f64; 3] = [0.6 / 3.0, 0.6 / 3.0, 2.6 / 3.0];
        let len: f64 = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
        assert!((levels[1].mean_length[0] as f64 - len).abs() < 1e-6);
    }

    fn wavy(w: usize, h: usize) -> Vec<[f32; 3]> {
        (0..w * h)
            .map(|i| {
                let a = i as f32 * 0.37;
                let v = [a.sin() * 0.5, (a * 1.3).cos() * 0.4, 1.0f32];
                let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                [v[0] / l, v[1] / l, v[2] / l]
            })
            .collect()
    }

    /// Levels summed from the level above are the levels summed from level 0.
    #[test]
    fn levels_from_the_level_above_equal_levels_from_level_0() {
        for (w, h) in [(32, 8), (24, 12), (37, 23), (300, 17), (16, 1)] {
            let n = wavy(w, h);
            for (k, l) in build(&n, w, h).iter().enumerate() {
                let direct = sum_footprints(&n, w, h, l.width, l.height);
                let area = (w as f64 / l.width as f64) * (h as f64 / l.height as f64);
                for (i, s) in direct.iter().enumerate() {
                    let m = [s[0] / area, s[1] / area, s[2] / area];
                    let len = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
                    assert!((l.mean_length[i] as f64 - len.min(1.0)).abs() < 1e-6, "{w}x{h} level {k} texel {i}");
                    for (got, want) in l.ideal[i].iter().zip(m) {
                        assert!((*got as f64 - want / len).abs() < 1e-6, "{w}x{h} level {k} texel {i}");
                    }
                }
            }
        }
    }

    #[test]
    fn same_bytes_on_one_thread() {
        // Large enough that the parallel loops split (their chunks are at least 1024 texels).
        let (w, h) = (150, 70);
        let n = wavy(w, h);
        let pool = |t| rayon::ThreadPoolBuilder::new().num_threads(t).build().unwrap();
        let many = pool(4).install(|| build(&n, w, h));
        let one = pool(1).install(|| build(&n, w, h));
        assert_eq!(many, one);
    }

    /// Level 0 is the map's own bytes, though re-rounding its renormalised texels would move
    /// them; the levels below are built from its unit normals all the same.
    #[test]
    fn a_map_keeps_its_own_level_0() {
        // (200, 90, 230) decodes to length 1.07; renormalised it rounds to (196, 92, 224).
        let rgb: Vec<u8> = [[200u8, 90, 230], [128, 128, 255], [30, 140, 200], [128, 60, 240]].concat();
        let chain = build_rgb(&rgb, 2, 2);
        assert_eq!(chain[0].rgb, rgb);
        let rebuilt = build(&unit_normals(&rgb), 2, 2);
        assert_ne!(rebuilt[0].rgb, rgb, "the sample does not re-round");
        assert_eq!((&chain[0].ideal, &chain[1]), (&rebuilt[0].ideal, &rebuilt[1]));
    }
}
