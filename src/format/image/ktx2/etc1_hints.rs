//! The ETC1 hints of a UASTC block: the choice the Basis Universal encoder makes, found with a
//! fraction of its work.
//!
//! A UASTC block carries hints (flip, differential mode, an intensity table per subblock, a
//! colour bias) that let a transcoder write an ETC1 block without searching. The encoder's search
//! (`compute_etc1_hints`, basisu_uastc_enc.cpp, Apache-2.0) tries up to 2 flips x 2 colour modes
//! x 32 biases, and for each trial and subblock up to 8 intensity tables against 8 decoded
//! pixels: at pack level 2 it is the largest part of the encoder's time on a normal map
//! (`docs/textures.md`). Two facts make most of that work repeat, and this search skips it:
//! - the best table of a subblock and its error against the source depend only on the
//!   subblock's base colour, and most biases move one subblock's base or neither; each distinct
//!   base colour of a subblock is evaluated once ([`Subblock::eval`]);
//! - the encoder's metric (4 luma² + blue-difference² + red-difference²) does not see a grey
//!   offset in its chroma terms, so while no channel clamps, a table's nearest modifier is a
//!   one-dimensional search in luma and the chroma error is the same for every table.
//!
//! Every comparison is the encoder's (strict, first in its order wins; with columns it stops at
//! the first table that is no better, with rows it tries them all), on the same integers, so the
//! hints are the encoder's bit for bit; `uastc.rs` asks the encoder for its cheapest hints and
//! writes these over them (tested against the encoder's own at every pack level).

/// The ETC1 intensity modifier tables.
const INTEN: [[i32; 4]; 8] = [
    [-8, -2, 2, 8],
    [-17, -5, 5, 17],
    [-29, -9, 9, 29],
    [-42, -13, 13, 42],
    [-60, -18, 18, 60],
    [-80, -24, 24, 80],
    [-106, -33, 33, 106],
    [-183, -47, 47, 183],
];

/// The order the encoder tries biases in below its slowest level; 13 is no bias.
const SORTED_BIASES: [u8; 32] = [
    13, 0, 22, 29, 27, 12, 26, 9, 30, 31, 8, 10, 25, 2, 23, 5, 15, 7, 3, 11, 6, 17, 28, 18, 1, 19, 20, 21, 24, 4, 14,
    16,
];

/// The hints as they go into the block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Hints {
    pub flip: bool,
    pub diff: bool,
    pub inten: [u8; 2],
    pub bias: u8,
}

/// Luma and the two colour differences, the encoder's integer scale.
#[derive(Clone, Copy, Default)]
struct Ycc {
    y: i32,
    cb: i32,
    cr: i32,
}

impl Ycc {
    fn of(r: i32, g: i32, b: i32) -> Ycc {
        let y = r * 54 + g * 183 + b * 19;
        Ycc { y, cb: (b << 8) - y, cr: (r << 8) - y }
    }
}

fn clamp255(v: i32) -> i32 {
    v.clamp(0, 255)
}

/// The pack levels whose hints this search finds. Below level 2 the encoder guesses the flip and
/// tries at most 5 biases, little enough that its own search is as fast as this one.
pub(super) const LEVELS: std::ops::RangeInclusive<u32> = 2..=4;

/// The hints of a block that is not a solid colour: `source` the pixels given to the encoder,
/// `decoded` the UASTC block's own pixels (both RGBA, row by row), `has_bias` whether the block's
/// mode stores a bias, `level` the pack level (in [`LEVELS`]).
pub(super) fn hints(source: &[[u8; 4]; 16], decoded: &[[u8; 4]; 16], has_bias: bool, level: u32) -> Hints {
    search(source, decoded, has_bias, level, true)
}

/// Whether this CPU runs AVX2.
fn avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    return std::arch::is_x86_feature_detected!("avx2");
    #[cfg(not(target_arch = "x86_64"))]
    return false;
}

/// [`hints`], with the AVX2 build of the inner loop where `wide` and the CPU allows it.
fn search(source: &[[u8; 4]; 16], decoded: &[[u8; 4]; 16], has_bias: bool, level: u32, wide: bool) -> Hints {
    debug_assert!(LEVELS.contains(&level));
    let biases: &[u8] = match (has_bias, level) {
        (false, _) => &[0],
        (true, 2) => &SORTED_BIASES[..20],
        (true, 3) => &SORTED_BIASES,
        (true, _) => &ALL_BIASES,
    };
    let all_tables = level >= 4;
    let mut best = Hints { flip: false, diff: false, inten: [0, 0], bias: 0 };
    let mut best_err = u64::MAX;
    for flip in [0, 1] {
        let mut subs = [0, 1].map(|s| Subblock::new(source, decoded, flip, s, all_tables, wide));
        for individual in [false, true] {
            let mul = if individual { 15 } else { 31 };
            let unbiased = [0, 1].map(|s| subs[s].mean(mul));
            for &bias in biases {
                let c = [0, 1].map(|s| if has_bias { apply_bias(unbiased[s], bias, mul, s) } else { unbiased[s] });
                let bases = base_colors(c, individual);
                let (t0, e0) = subs[0].eval(bases[0]);
                let (t1, e1) = subs[1].eval(bases[1]);
                let err = e0 + e1;
                if err < best_err {
                    best_err = err;
                    best = Hints {
                        flip: flip == 1,
                        diff: !individual,
                        inten: [t0, t1],
                        bias: if has_bias { bias } else { 0 },
                    };
                }
            }
        }
    }
    best
}

/// Every bias in numeric order: the slowest level's search.
const ALL_BIASES: [u8; 32] = {
    let mut a = [0u8; 32];
    let mut i = 0;
    while i < 32 {
        a[i] = i as u8;
        i += 1;
    }
    a
};

/// The 8-bit base colours of the two subblocks for the two subblocks' colours in ETC1 units
/// (4-bit in individual mode; 5-bit in differential mode, the second as a delta from the first,
/// clamped to what 3 bits hold).
fn base_colors(c: [[i32; 3]; 2], individual: bool) -> [[i32; 3]; 2] {
    if individual {
        c.map(|c| c.map(|v| v.min(15) * 17))
    } else {
        let c0 = c[0].map(|v| v.min(31));
        let c1: [i32; 3] = std::array::from_fn(|k| (c0[k] + (c[1][k] - c0[k]).clamp(-4, 3)).clamp(0, 31));
        [c0, c1].map(|c| c.map(|v| (v << 3) | (v >> 2)))
    }
}

/// The bias modes that move one channel of one subblock by one step:
/// (mode, subblock, channel, step).
const ONE_CHANNEL_BIASES: [(u8, usize, usize, i32); 12] = [
    (2, 0, 0, -1),
    (5, 0, 1, -1),
    (6, 0, 2, -1),
    (7, 0, 0, 1),
    (11, 0, 1, 1),
    (15, 0, 2, 1),
    (18, 1, 0, -1),
    (19, 1, 1, -1),
    (20, 1, 2, -1),
    (21, 1, 0, 1),
    (24, 1, 1, 1),
    (8, 1, 2, 1),
];

/// The step bias mode `bias` gives channel `ch` of subblock `sub`: one channel of one subblock
/// (above), every channel of one or both subblocks (10, 27-31), or, for the other modes, each
/// channel its own base-3 digit of the mode, less one.
fn bias_step(bias: u8, sub: usize, ch: usize) -> i32 {
    if let Some(&(_, s, c, d)) = ONE_CHANNEL_BIASES.iter().find(|e| e.0 == bias) {
        return if (s, c) == (sub, ch) { d } else { 0 };
    }
    // (subblock 0, subblock 1)
    let both = match bias {
        10 => (-2, -2),
        27 => (-1, 0),
        28 => (1, -1),
        29 => (0, 1),
        30 => (0, -1),
        31 => (1, 0),
        _ => return (bias as i32 / [1, 3, 9][ch]) % 3 - 1,
    };
    if sub == 0 {
        both.0
    } else {
        both.1
    }
}

/// A colour in ETC1 units moved by bias mode `bias` (the transcoder's rule: each channel by -2
/// to +1, reflected where the move would leave 0..=`limit`), for subblock `sub`.
fn apply_bias(c: [i32; 3], bias: u8, limit: i32, sub: usize) -> [i32; 3] {
    std::array::from_fn(|ch| {
        let delta = bias_step(bias, sub, ch);
        let v = c[ch];
        if v == 0 {
            if delta == -2 {
                3
            } else {
                delta + 1
            }
        } else if v == limit {
            v + delta - 1
        } else {
            let m = v + delta;
            if m < 0 || m > limit {
                v - delta
            } else {
                m
            }
        }
    })
}

/// Eight values, one per pixel of a subblock, in `f64`: every distance here is an integer below
/// 2^38 and every sum of eight below 2^41, so `f64` holds them exactly (the encoder's `uint64_t`
/// comparisons give the same answers) and the compiler keeps them in vector registers.
type Lanes = [f64; 8];

/// A subblock's pixels in the encoder's metric, one array per component.
struct Pixels {
    y: Lanes,
    cb: Lanes,
    cr: Lanes,
}

impl Pixels {
    fn new(p: [Ycc; 8]) -> Pixels {
        Pixels { y: p.map(|c| c.y as f64), cb: p.map(|c| c.cb as f64), cr: p.map(|c| c.cr as f64) }
    }

    /// Each pixel's distance to colour `e`.
    fn dist(&self, e: Ycc) -> Lanes {
        let (y, cb, cr) = (e.y as f64, e.cb as f64, e.cr as f64);
        std::array::from_fn(|j| {
            let (dy, dcb, dcr) = (y - self.y[j], cb - self.cb[j], cr - self.cr[j]);
            4.0 * dy * dy + dcr * dcr + dcb * dcb
        })
    }
}

fn min_lanes(a: Lanes, b: Lanes) -> Lanes {
    std::array::from_fn(|j| if b[j] < a[j] { b[j] } else { a[j] })
}

/// One subblock of one flip: its 8 pixels and every base colour tried on it so far.
struct Subblock {
    decoded: Pixels,
    source: Pixels,
    sum: [i32; 3],
    min: [i32; 3],
    max: [i32; 3],
    all_tables: bool,
    /// Whether to run the AVX2 build of [`Self::eval`].
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    wide: bool,
    /// The encoder stops trying tables at the first that is no better when the subblocks are
    /// columns (flip 0), and tries them all when they are rows.
    greedy: bool,
    /// (base colour, best table, error against the source), in the order first tried: at most
    /// one per colour mode and bias.
    seen: [(u32, u8, u64); 64],
    tried: usize,
}

impl Subblock {
    fn new(
        source: &[[u8; 4]; 16],
        decoded: &[[u8; 4]; 16],
        flip: usize,
        s: usize,
        all_tables: bool,
        wide: bool,
    ) -> Subblock {
        // Flip 0 splits into left and right columns, flip 1 into top and bottom rows.
        let index = |j: usize| if flip == 0 { (j % 4) * 4 + 2 * s + j / 4 } else { (2 * s + j / 4) * 4 + j % 4 };
        let ycc = |p: [u8; 4]| Ycc::of(p[0] as i32, p[1] as i32, p[2] as i32);
        let (mut sum, mut min, mut max) = ([0; 3], [255; 3], [0; 3]);
        for j in 0..8 {
            let d = decoded[index(j)];
            for c in 0..3 {
                let v = d[c] as i32;
                sum[c] += v;
                min[c] = min[c].min(v);
                max[c] = max[c].max(v);
            }
        }
        Subblock {
            decoded: Pixels::new(std::array::from_fn(|j| ycc(decoded[index(j)]))),
            source: Pixels::new(std::array::from_fn(|j| ycc(source[index(j)]))),
            sum,
            min,
            max,
            all_tables,
            wide: wide && avx2(),
            greedy: flip == 0,
            seen: [(0, 0, 0); 64],
            tried: 0,
        }
    }

    /// The decoded pixels' mean in ETC1 units of `mul` + 1 steps, rounded as the encoder rounds.
    fn mean(&self, mul: i32) -> [i32; 3] {
        self.sum.map(|s| (s * mul + 1020) / (8 * 255))
    }

    /// The best intensity table for base colour `base` (fit to the decoded pixels) and the
    /// error of that table against the source pixels.
    fn eval(&mut self, base: [i32; 3]) -> (u8, u64) {
        #[cfg(target_arch = "x86_64")]
        if self.wide {
            // SAFETY: `wide` is set only where the CPU has AVX2 (`Subblock::new`).
            return unsafe { self.eval_avx2(base) };
        }
        self.eval_here(base)
    }

    /// [`Self::eval`] compiled for 4-wide vectors; the arithmetic is exact either way, so the
    /// answers are the same.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn eval_avx2(&mut self, base: [i32; 3]) -> (u8, u64) {
        self.eval_here(base)
    }

    #[inline(always)]
    fn eval_here(&mut self, base: [i32; 3]) -> (u8, u64) {
        let key = ((base[0] as u32) << 16) | ((base[1] as u32) << 8) | base[2] as u32;
        if let Some(&(_, t, e)) = self.seen[..self.tried].iter().find(|e| e.0 == key) {
            return (t, e);
        }
        let range = (0..3).map(|c| (self.max[c] - base[c]).abs().max((base[c] - self.min[c]).abs())).max().unwrap_or(0);
        let tables = if self.all_tables || range > 51 {
            8
        } else if range >= 7 {
            4
        } else {
            2
        };
        let b = Ycc::of(base[0], base[1], base[2]);
        let lo = base[0].min(base[1]).min(base[2]);
        let hi = base[0].max(base[1]).max(base[2]);
        let mut chroma: Option<f64> = None;
        let (mut best_t, mut best) = (0u8, f64::INFINITY);
        for (t, m) in INTEN.iter().enumerate().take(tables) {
            let total = if lo - m[3] >= 0 && hi + m[3] <= 255 {
                // No channel clamps: every entry is the base plus grey, which moves luma alone.
                let c = *chroma.get_or_insert_with(|| {
                    self.decoded.dist(Ycc { y: 0, ..b }).iter().zip(self.decoded.y).map(|(d, y)| d - 4.0 * y * y).sum()
                });
                let e: Lanes = std::array::from_fn(|j| self.decoded.y[j] - b.y as f64);
                let near: Lanes = std::array::from_fn(|j| {
                    let d = m.map(|mk| (e[j] - 256.0 * mk as f64).abs());
                    d[0].min(d[1]).min(d[2]).min(d[3])
                });
                c + near.iter().map(|d| 4.0 * d * d).sum::<f64>()
            } else {
                let table = entries(base, m);
                let mut near = self.decoded.dist(table[0]);
                for e in &table[1..] {
                    near = min_lanes(near, self.decoded.dist(*e));
                }
                near.iter().sum()
            };
            if total < best {
                best = total;
                best_t = t as u8;
            } else if self.greedy {
                break;
            }
        }
        // Each pixel takes its nearest entry (the first of equals) and is measured against its
        // source.
        let table = entries(base, &INTEN[best_t as usize]);
        let mut near = self.decoded.dist(table[0]);
        let mut err = self.source.dist(table[0]);
        for e in &table[1..] {
            let (d, o) = (self.decoded.dist(*e), self.source.dist(*e));
            for j in 0..8 {
                if d[j] < near[j] {
                    near[j] = d[j];
                    err[j] = o[j];
                }
            }
        }
        let err = err.iter().sum::<f64>() as u64;
        self.seen[self.tried] = (key, best_t, err);
        self.tried += 1;
        (best_t, err)
    }
}

/// The four colours of a table on a base colour, each channel clamped.
fn entries(base: [i32; 3], m: &[i32; 4]) -> [Ycc; 4] {
    m.map(|mk| Ycc::of(clamp255(base[0] + mk), clamp255(base[1] + mk), clamp255(base[2] + mk)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The AVX2 and the plain build give the same hints (the encoder's: `uastc.rs`'s tests), on
    /// the blocks of `uastc.rs`'s tests, each against a decoding of it two bits short.
    #[test]
    fn both_builds_agree() {
        for (i, px) in super::super::tests::blocks().iter().enumerate() {
            let source: [[u8; 4]; 16] = std::array::from_fn(|p| [px[4 * p], px[4 * p + 1], px[4 * p + 2], 255]);
            let decoded = source.map(|p| p.map(|v| v & 0xfc));
            for level in LEVELS {
                let plain = search(&source, &decoded, i % 5 != 0, level, false);
                assert_eq!(search(&source, &decoded, i % 5 != 0, level, true), plain, "block {i}, level {level}");
            }
        }
    }
}
