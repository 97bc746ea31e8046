//! A plain decimal (`[-]digits[.digits]`, at most 15 bytes after its sign, no exponent) read in one 16-byte
//! SSE vector, with no branch on its digits: the common number of OBJ and ASCII PLY text. Every
//! other token, and the rare value this cannot round with certainty, is left to the scalar
//! reader in `text_number.rs`, which then gives exactly what `str::parse::<f32>` gives.
//!
//! Why: the scalar reader's branches on each number's shape (how many digits before and after
//! the dot) took about 22 ns a number; this takes about 13, and the numbers were a third of
//! reading a 10M-triangle OBJ (`docs/transfer-history.md`).
//!
//! Rounding: the digits (fewer than 2^53) are exact in f64, and are multiplied by the f64
//! nearest 10^-f. Two roundings leave the product within about 2 f64 ulps of the exact value,
//! so it rounds to the same f32 unless it lies within that of an f32 midpoint (an f64 whose
//! low 29 bits are 2^28): those, within 4 ulps, go to the scalar reader.

use std::arch::x86_64::*;

/// Whether this CPU has the instructions [`read`] uses (every x86-64 CPU since about 2008).
#[inline]
pub(in crate::format) fn available() -> bool {
    std::arch::is_x86_feature_detected!("sse4.1")
}

/// 10^-f, for f fraction digits.
const INV_POW10: [f64; 17] =
    [1e0, 1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 1e-14, 1e-15, 1e-16];

/// For a number of `end` bytes whose dot is at `k` (`k == end`: it has none), row `end * 17 + k`
/// moves its digits, the dot left out, to the high end of 16 bytes, with zeros (0x80 picks a
/// zero) before them.
static PACK: [[u8; 16]; 17 * 17] = pack_table();

const fn pack_table() -> [[u8; 16]; 17 * 17] {
    let mut t = [[0x80u8; 16]; 17 * 17];
    let mut end = 0;
    while end <= 16 {
        let mut k = 0;
        while k <= end {
            let digits = if k < end { end - 1 } else { end };
            let (mut i, mut j) = (0, 0);
            while i < end {
                if i != k {
                    t[end * 17 + k][16 - digits + j] = i as u8;
                    j += 1;
                }
                i += 1;
            }
            k += 1;
        }
        end += 1;
    }
    t
}

/// The plain decimal `t` starts with, followed by a blank or a newline, and its length; `None`
/// for anything else (fewer than 16 bytes from its first digit, an exponent, more than 15
/// bytes of digits and dot, a value too near an f32 midpoint), which the scalar reader then reads.
///
/// # Safety
/// The CPU must have SSE4.1 ([`available`]).
#[inline]
#[target_feature(enable = "sse4.1")]
pub(super) unsafe fn read(t: &[u8]) -> Option<(f32, usize)> {
    let neg = *t.first()? == b'-';
    let p = neg as usize;
    let bytes: &[u8; 16] = t.get(p..p + 16)?.try_into().ok()?;
    // SAFETY: `bytes` is 16 readable bytes; an unaligned load.
    let x = unsafe { _mm_loadu_si128(bytes.as_ptr().cast()) };
    let splat = |c: u8| _mm_set1_epi8(c as i8);
    // A byte is in 0..=n (unsigned) if its minimum with n is itself.
    let at_most = |v: __m128i, n: u8| _mm_cmpeq_epi8(_mm_min_epu8(v, splat(n)), v);
    let d = _mm_sub_epi8(x, splat(b'0'));
    let digit = _mm_movemask_epi8(at_most(d, 9)) as u32;
    let dot = _mm_movemask_epi8(_mm_cmpeq_epi8(x, splat(b'.'))) as u32;
    // `is_space` or a newline: a space, or 9..=13.
    let blank = _mm_or_si128(_mm_cmpeq_epi8(x, splat(b' ')), at_most(_mm_sub_epi8(x, splat(9)), 4));
    let end = (!(digit | dot) | 1 << 16).trailing_zeros() as usize;
    let before = (1u32 << end) - 1;
    let dots = dot & before;
    let digits = (digit & before).count_ones();
    let ends_well = (_mm_movemask_epi8(blank) as u32 >> end) & 1 == 1;
    // Fifteen bytes at most, so that the byte after it is in the vector and the digits (at most
    // 15) are exact in f64.
    if end == 16 || !ends_well || dots.count_ones() > 1 || digits == 0 {
        return None;
    }
    let k = (dots | 1 << end).trailing_zeros() as usize;
    let fraction = end - k - (k < end) as usize;
    // SAFETY: a 16-byte row of a static table; an unaligned load.
    let pack = unsafe { _mm_loadu_si128(PACK[end * 17 + k].as_ptr().cast()) };
    let packed = _mm_shuffle_epi8(d, pack);
    // Sixteen digits to eight of two, four of four, two of eight (simdjson's method).
    let two = _mm_maddubs_epi16(packed, _mm_setr_epi8(10, 1, 10, 1, 10, 1, 10, 1, 10, 1, 10, 1, 10, 1, 10, 1));
    let four = _mm_madd_epi16(two, _mm_setr_epi16(100, 1, 100, 1, 100, 1, 100, 1));
    let four = _mm_packus_epi32(four, four);
    let eight = _mm_madd_epi16(four, _mm_setr_epi16(10_000, 1, 10_000, 1, 10_000, 1, 10_000, 1));
    let high = _mm_cvtsi128_si32(eight) as u32 as u64;
    let low = _mm_extract_epi32::<1>(eight) as u32 as u64;
    let w = high * 100_000_000 + low;
    let r = w as i64 as f64 * INV_POW10[fraction];
    let bits = r.to_bits() & ((1 << 29) - 1);
    if bits.wrapping_sub((1 << 28) - 4) <= 8 {
        return None;
    }
    let v = r as f32;
    Some((if neg { -v } else { v }, p + end))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn simd(t: &str) -> Option<(u32, usize)> {
        assert!(available(), "the tests run on a CPU with SSE4.1");
        // SAFETY: checked just above.
        unsafe { read(t.as_bytes()) }.map(|(v, n)| (v.to_bits(), n))
    }

    /// Whatever it reads is what `str::parse` gives, with its length. Random decimals of up
    /// to 15 digits are read; decimals next to f32 midpoints (the band it declines) are read
    /// right or declined, and some of each happen.
    #[test]
    fn reads_what_str_parse_gives_or_declines() {
        let mut rng = crate::test_rng::XorShift64(0x2545_F491_4F6C_DD1D);
        let check = |t: &str| -> Option<()> {
            let want = t.parse::<f32>().ok().map(|w| (w.to_bits(), t.len()));
            let mut got = None;
            for end in [" 1.5 2\n", "\r\n", "\t0000000000000000"] {
                got = simd(&format!("{t}{end}"));
                assert!(got.is_none() || got == want, "{t}{end:?}: {got:?} against {want:?}");
            }
            got.map(|_| ())
        };
        let (mut random, mut midpoints) = ([0, 0], [0, 0]);
        for _ in 0..100_000 {
            let x = rng.next();
            let whole = (x % 8) as usize;
            let fraction = ((x >> 3) % 15) as usize;
            let n = (whole + fraction).clamp(1, 14);
            let digits: String = (0..n).map(|i| char::from(b'0' + ((x >> (8 + 3 * i)) % 10) as u8)).collect();
            let (a, b) = digits.split_at(whole.min(n));
            let sign = if x >> 63 == 1 { "-" } else { "" };
            let t = if b.is_empty() { format!("{sign}{a}") } else { format!("{sign}{a}.{b}") };
            random[check(&t).is_some() as usize] += 1;
            // An f32 midpoint between 1 and 2^20, to 14 significant digits: within about
            // 45 f64 ulps of it, inside the band or near it.
            let f = f32::from_bits(0x3F80_0000 + (x >> 20) as u32 % (0x4980_0000 - 0x3F80_0000));
            let mid = (f as f64 + f32::from_bits(f.to_bits() + 1) as f64) / 2.0;
            let places = (13 - mid.log10().floor() as i32).max(0) as usize;
            midpoints[check(&format!("{:.*}", places, mid)).is_some() as usize] += 1;
        }
        // Declined only at a midpoint (as 9630815.5, where f32s are 1 apart).
        assert!(random[0] * 1000 < random[1], "random decimals declined and read: {random:?}");
        assert!(midpoints[0] > 1000 && midpoints[1] > 1000, "midpoints declined and read: {midpoints:?}");
    }

    #[test]
    fn every_shape_of_a_short_decimal() {
        for t in [
            "0",
            "-0",
            "7",
            "5.",
            ".5",
            "-.5",
            "0.0026703516",
            "-0.0025087663",
            "1.36",
            "123456789012345",
            "1.2345678901234",
        ] {
            let want = t.parse::<f32>().unwrap();
            assert_eq!(simd(&format!("{t}\n                ")), Some((want.to_bits(), t.len())), "{t}");
        }
        for t in [
            "",
            ".",
            "-",
            "+1",
            "1e5",
            "1.2.3",
            "1x",
            "1234567890123456",
            "1.23456789012345",
            "0.00000000000001",
            "1_0",
        ] {
            assert_eq!(simd(&format!("{t} 0000000000000000")), None, "{t}");
        }
        // Fewer than 16 bytes from its first digit: the scalar reader's.
        assert_eq!(simd("1.5 2"), None);
    }
}
