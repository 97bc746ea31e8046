//! The reference's float operations, spelled out so that every rounding happens in the same
//! order as in `bevy_mikktspace` (and so in the C reference): no fused multiply-add, dot
//! products summed left to right, normalisation by multiplying with the reciprocal length.

pub(crate) type V3 = [f32; 3];

#[inline]
pub(crate) fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
pub(crate) fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `s * v`, component by component (`f32 * Vec3` in the reference).
#[inline]
pub(crate) fn scale(s: f32, v: V3) -> V3 {
    [s * v[0], s * v[1], s * v[2]]
}

#[inline]
pub(crate) fn dot(a: V3, b: V3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub(crate) fn length(v: V3) -> f32 {
    dot(v, v).sqrt()
}

/// `fabsf(x) > FLT_MIN`: false for zero, subnormals and NaN.
#[inline]
pub(crate) fn not_zero(x: f32) -> bool {
    x.abs() > f32::MIN_POSITIVE
}

/// The reference's `normalize_or_zero`: vectors whose components are all (sub)normal-zero or
/// NaN are returned unchanged.
#[inline]
pub(crate) fn normalized_or_zero(v: V3) -> V3 {
    if not_zero(v[0]) || not_zero(v[1]) || not_zero(v[2]) {
        let r = length(v).recip();
        [v[0] * r, v[1] * r, v[2] * r]
    } else {
        v
    }
}

/// `v - (n·v) n`, normalised: the projection of a tangent onto the plane of `n`.
#[inline]
pub(crate) fn project(v: V3, n: V3) -> V3 {
    normalized_or_zero(sub(v, scale(dot(n, v), n)))
}

/// The reference's `acos`: evaluated in double precision, rounded to single.
#[inline]
pub(crate) fn acos(x: f32) -> f32 {
    (x as f64).acos() as f32
}

/// f32 equality of whole vectors (NaN unequal, `-0 == +0`).
#[inline]
pub(crate) fn eq3(a: V3, b: V3) -> bool {
    a[0] == b[0] && a[1] == b[1] && a[2] == b[2]
}

/// Bits of `x` with `-0.0` folded onto `+0.0`, so that bit equality is f32 equality for
/// non-NaN values.
#[inline]
pub(crate) fn canon_bits(x: f32) -> u32 {
    if x == 0.0 {
        0
    } else {
        x.to_bits()
    }
}
