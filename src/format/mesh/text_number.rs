//! The numbers of OBJ and ASCII PLY text, read straight from the bytes: decimals exactly as
//! `str::parse::<f32>` gives them and short integers, with no UTF-8 check and no token scanned
//! twice.

/// A blank inside a line, as OBJ and PLY text separate their tokens.
pub(in crate::format) fn is_space(c: u8) -> bool {
    matches!(c, b' ' | b'\t' | b'\r' | 0x0b | 0x0c)
}

/// A sign, then 1 to 18 decimal digits (so it never overflows), as `str::parse::<i64>` reads it
/// without its UTF-8 check; `None` for anything else, a longer number included.
#[inline]
pub(in crate::format) fn short_int(t: &[u8]) -> Option<i64> {
    let (neg, digits) = match t.first()? {
        b'-' => (true, &t[1..]),
        b'+' => (false, &t[1..]),
        _ => (false, t),
    };
    if digits.is_empty() || digits.len() > 18 {
        return None;
    }
    let mut v = 0i64;
    for &c in digits {
        let d = c.wrapping_sub(b'0');
        if d > 9 {
            return None;
        }
        v = v * 10 + d as i64;
    }
    Some(if neg { -v } else { v })
}

/// The leading decimal digits of `b[i..]`, up to eight, read at once when eight bytes are there:
/// how many there are (8 when there may be more) and their value.
#[inline]
pub(in crate::format) fn digits8(b: &[u8], i: usize) -> Option<(usize, u64)> {
    let chunk = u64::from_le_bytes(b.get(i..i + 8)?.try_into().ok()?);
    let sub = chunk.wrapping_sub(0x3030_3030_3030_3030);
    // A byte's top bit is set in one of these if it is below '0', above '9' or not ASCII; bytes
    // after the first such one may be garbled by carries, and are not looked at.
    let flags = (sub | chunk.wrapping_add(0x4646_4646_4646_4646) | chunk) & 0x8080_8080_8080_8080;
    let n = (flags.trailing_zeros() / 8) as usize;
    if n == 0 {
        return Some((0, 0));
    }
    // The digits moved to the high bytes, zeros (as digits) before them: eight digits, parsed
    // as in simdjson's parse_eight_digits_unrolled.
    let mut v = sub << (8 * (8 - n));
    v = v.wrapping_mul(10).wrapping_add(v >> 8);
    let mask = 0x0000_00FF_0000_00FF;
    v = (v & mask)
        .wrapping_mul(100 + (1_000_000 << 32))
        .wrapping_add(((v >> 16) & mask).wrapping_mul(1 + (10_000 << 32)))
        >> 32;
    Some((n, v & 0xFFFF_FFFF))
}

const POW10_INT: [u64; 9] = [1, 10, 100, 1_000, 10_000, 100_000, 1_000_000, 10_000_000, 100_000_000];

const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20,
    1e21, 1e22,
];

/// A decimal as the nearest f32, exactly as `str::parse::<f32>` gives it.
///
/// Fast path: a mantissa of at most 2^53 and a power of ten of at most 22 are both exact in f64,
/// so one multiplication or division gives the correctly rounded f64. Rounding that to f32 is
/// correct unless the f64 landed exactly on the midpoint between two f32s (rounding is monotonic
/// and every f32 midpoint is an f64, so x and its f64 fall between the same two midpoints
/// otherwise); that case, and everything else, goes to the standard library.
pub fn parse_f32(t: &[u8]) -> Option<f32> {
    match lead_f32(t)? {
        (v, n) if n == t.len() => Some(v),
        _ => None,
    }
}

/// The number that `t` starts with, as [`parse_f32`] reads it, and its length: the token runs to
/// the first blank or newline (`None` when that token is not a number).
#[inline]
pub fn lead_f32(t: &[u8]) -> Option<(f32, usize)> {
    #[cfg(target_arch = "x86_64")]
    if super::decimal16::available() {
        // SAFETY: the CPU has what `read` uses, just checked.
        if let Some(r) = unsafe { super::decimal16::read(t) } {
            return Some(r);
        }
    }
    scalar_f32(t)
}

/// [`lead_f32`] byte by byte: every token the vector reader declines. Out of line, so that the
/// vector reader's callers stay small enough to inline it and keep its result in registers.
#[inline(never)]
pub(in crate::format) fn scalar_f32(t: &[u8]) -> Option<(f32, usize)> {
    let ends = |c: u8| is_space(c) || c == b'\n';
    let slow = || {
        let e = t.iter().position(|&c| ends(c)).unwrap_or(t.len());
        Some((std::str::from_utf8(&t[..e]).ok()?.parse::<f32>().ok()?, e))
    };
    let (neg, mut p) = match t.first() {
        Some(b'-') => (true, 1),
        Some(b'+') => (false, 1),
        _ => (false, 0),
    };
    let (mut w, mut e, mut digits) = (0u64, 0i32, 0);
    // Eight digits at a time while the mantissa stays far below the per-digit limit (1e17).
    let run = |w: &mut u64, p: &mut usize, digits: &mut i32| -> i32 {
        let mut taken = 0;
        while *w < 1_000_000_000 {
            let Some((n, v)) = digits8(t, *p) else { break };
            *w = *w * POW10_INT[n] + v;
            *p += n;
            taken += n as i32;
            if n < 8 {
                break;
            }
        }
        *digits += taken;
        taken
    };
    run(&mut w, &mut p, &mut digits);
    while p < t.len() && t[p].is_ascii_digit() {
        if w >= 100_000_000_000_000_000 {
            return slow();
        }
        w = w * 10 + (t[p] - b'0') as u64;
        digits += 1;
        p += 1;
    }
    if p < t.len() && t[p] == b'.' {
        p += 1;
        e -= run(&mut w, &mut p, &mut digits);
        while p < t.len() && t[p].is_ascii_digit() {
            if w >= 100_000_000_000_000_000 {
                return slow();
            }
            w = w * 10 + (t[p] - b'0') as u64;
            e -= 1;
            digits += 1;
            p += 1;
        }
    }
    if digits == 0 {
        return slow();
    }
    if p < t.len() && (t[p] | 0x20) == b'e' {
        p += 1;
        let eneg = match t.get(p) {
            Some(b'-') => {
                p += 1;
                true
            }
            Some(b'+') => {
                p += 1;
                false
            }
            _ => false,
        };
        let (mut x, s) = (0i32, p);
        while p < t.len() && t[p].is_ascii_digit() && p - s < 6 {
            x = x * 10 + (t[p] - b'0') as i32;
            p += 1;
        }
        if p == s {
            return slow();
        }
        e += if eneg { -x } else { x };
    }
    if p < t.len() && !ends(t[p]) {
        return slow();
    }
    let v = if w == 0 {
        0.0
    } else {
        if w > 1 << 53 || !(-22..=22).contains(&e) {
            return slow();
        }
        let r = if e >= 0 { w as f64 * POW10[e as usize] } else { w as f64 / POW10[(-e) as usize] };
        if r.to_bits() & ((1 << 29) - 1) == 1 << 28 {
            return slow();
        }
        r as f32
    };
    Some((if neg { -v } else { v }, p))
}
