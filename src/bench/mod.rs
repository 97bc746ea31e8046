//! Benchmarks that measure error against run time (`bumpbake bench ...`): library code so that
//! tests and the binary share it.

pub mod batch;
pub mod blender;
pub mod command;
pub mod normalmap;
pub mod plot;
pub mod surfaces;
pub mod tangents;
pub mod tangents_plot;
pub mod transfer;
pub mod transfer_large;

/// FNV-1a 64 of `bytes` as hex: tells two runs' outputs apart in a report (not a checksum).
pub(crate) fn fingerprint(bytes: &[u8]) -> String {
    let h = bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3));
    format!("{h:016x}")
}

/// The smallest and largest of `v` ((inf, 0) when empty: times are never negative).
pub(crate) fn spread(v: &[f64]) -> (f64, f64) {
    (v.iter().copied().fold(f64::INFINITY, f64::min), v.iter().copied().fold(0.0, f64::max))
}

/// The median of `v` (sorted in place), the mean of the middle two for an even count; 0 when empty.
pub(crate) fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        0.0
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}
