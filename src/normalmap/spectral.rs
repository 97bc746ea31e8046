//! The spectral derivative: multiply the Fourier transform by `i·ω` and transform back.
//!
//! Exact (to float rounding) for band-limited periodic heights, where every finite difference
//! under-estimates the slope of the higher frequencies. The 2-D derivative along x equals the
//! 1-D derivative of each row (the transform along y commutes with a multiplier that depends on
//! x-frequency only), so the filter is separable: rows for `dh/dx`, columns for `dh/dy_up`, and
//! it needs one extra float plane (the column derivatives), never a complex 2-D spectrum.
//!
//! `repeat` uses the image's own period. `clamp` and `mirror` (treated alike) first remove the
//! line through each line's end samples, then mirror-extend the rest to twice its length
//! (`r0..r(n-1), r(n-1)..r0`), which is periodic and continuous, so there is no jump at the
//! seam to ring, and a ramp is differentiated exactly. What remains at the edges is the corner
//! where the residual's slope changes sign; its ringing falls off within a few texels.

// Lines are indexed from both ends (mirror extension, bottom-up columns): index loops read best.
#![allow(clippy::needless_range_loop)]

use super::Wrap;
use rayon::prelude::*;
use rustfft::num_complex::Complex32;
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// Columns per block in the column pass: 16 floats = one 64-byte cache line per row.
const BLOCK: usize = 16;

/// A planned derivative along lines of one length.
struct Line {
    n: usize,
    len: usize,
    fwd: Arc<dyn Fft<f32>>,
    inv: Arc<dyn Fft<f32>>,
    /// `ω_k / len` per bin: derivative and inverse-transform normalisation in one multiply.
    mult: Vec<f32>,
    scratch_len: usize,
}

impl Line {
    fn new(n: usize, wrap: Wrap, planner: &mut FftPlanner<f32>) -> Line {
        let len = if wrap == Wrap::Repeat || n == 1 { n } else { 2 * n };
        let fwd = planner.plan_fft_forward(len);
        let inv = planner.plan_fft_inverse(len);
        let mult = (0..len)
            .map(|k| {
                // The Nyquist bin of an even length has no sign: its derivative is not real,
                // so it is dropped (this keeps real input real, which the pairing relies on).
                if 2 * k == len {
                    return 0.0;
                }
                let f = if 2 * k < len { k as f64 } else { k as f64 - len as f64 };
                (std::f64::consts::TAU * f / len as f64 / len as f64) as f32
            })
            .collect();
        let scratch_len = fwd.get_inplace_scratch_len().max(inv.get_inplace_scratch_len());
        Line { n, len, fwd, inv, mult, scratch_len }
    }

    /// Writes the line `a` (real part) and `b` (imaginary part) into `buf`, extended as planned,
    /// less a trend whose slope it returns (to be added back to the derivative).
    ///
    /// `repeat` removes the mean: it has no slope, and without it a constant line would come
    /// back as the transform's rounding noise instead of exactly zero (a flat map must encode to
    /// exactly 128,128,255). The mirrored modes remove the line through the two end samples,
    /// so the extension has no corner for a ramp (exact on ramps, and far less ringing at the
    /// edges of sloped maps), and a constant line is exactly zero here too.
    #[inline]
    fn fill(&self, buf: &mut [Complex32], a: impl Fn(usize) -> f32, b: impl Fn(usize) -> f32) -> Complex32 {
        let n = self.n;
        let mut sum = [0.0f64; 2];
        for i in 0..n {
            let v = Complex32::new(a(i), b(i));
            sum[0] += v.re as f64;
            sum[1] += v.im as f64;
            buf[i] = v;
        }
        let (first, last) = (buf[0], buf[n - 1]);
        let trend = |i: usize| -> (Complex32, Complex32) {
            if self.len == self.n {
                let mean = Complex32::new((sum[0] / n as f64) as f32, (sum[1] / n as f64) as f32);
                (mean, Complex32::default())
            } else {
                let slope = (last - first) / (n - 1).max(1) as f32;
                (first + slope * i as f32, slope)
            }
        };
        for i in 0..n {
            let v = buf[i] - trend(i).0;
            buf[i] = v;
            if self.len > n {
                buf[self.len - 1 - i] = v;
            }
        }
        trend(0).1
    }

    /// Differentiates in place. The operator is real, so the derivatives of two real lines
    /// packed as real and imaginary parts come back packed the same way: half the transforms.
    #[inline]
    fn differentiate(&self, buf: &mut [Complex32], scratch: &mut [Complex32]) {
        self.fwd.process_with_scratch(buf, scratch);
        for (c, &m) in buf.iter_mut().zip(&self.mult) {
            *c = Complex32::new(-c.im * m, c.re * m);
        }
        self.inv.process_with_scratch(buf, scratch);
    }

    fn buffers(&self) -> (Vec<Complex32>, Vec<Complex32>) {
        (vec![Complex32::default(); self.len], vec![Complex32::default(); self.scratch_len])
    }
}

/// The spectral filter over one height plane: column derivatives precomputed, rows on demand.
pub(crate) struct Spectral<'a> {
    plane: &'a [f32],
    width: usize,
    rows: Line,
    /// `dh/dy_up` in blocks of [`BLOCK`] columns, each block row-major: `[block][y][BLOCK]`.
    gy_blocks: Vec<f32>,
    height: usize,
}

/// Per-worker buffers for the row pass.
pub(crate) struct SpectralScratch {
    buf: Vec<Complex32>,
    scratch: Vec<Complex32>,
}

impl<'a> Spectral<'a> {
    pub fn new(plane: &'a [f32], width: usize, height: usize, wrap: Wrap) -> Spectral<'a> {
        let mut planner = FftPlanner::new();
        let rows = Line::new(width, wrap, &mut planner);
        let cols = Line::new(height, wrap, &mut planner);
        let nblocks = width.div_ceil(BLOCK);
        let mut gy_blocks = vec![0.0f32; nblocks * height * BLOCK];
        gy_blocks.par_chunks_mut(height * BLOCK).enumerate().for_each(|(b, out)| {
            let (mut buf, mut scratch) = cols.buffers();
            let x0 = b * BLOCK;
            let ncols = BLOCK.min(width - x0);
            for pair in (0..ncols).step_by(2) {
                let (xa, xb) = (x0 + pair, x0 + pair + 1);
                let has_b = pair + 1 < ncols;
                // Row index y is y_up = height-1-y, so feed the column bottom-up.
                let slope = cols.fill(
                    &mut buf,
                    |i| plane[(height - 1 - i) * width + xa],
                    |i| {
                        if has_b {
                            plane[(height - 1 - i) * width + xb]
                        } else {
                            0.0
                        }
                    },
                );
                cols.differentiate(&mut buf, &mut scratch);
                for i in 0..height {
                    let y = height - 1 - i;
                    out[y * BLOCK + pair] = buf[i].re + slope.re;
                    if has_b {
                        out[y * BLOCK + pair + 1] = buf[i].im + slope.im;
                    }
                }
            }
        });
        Spectral { plane, width, rows, gy_blocks, height }
    }

    pub fn scratch(&self) -> SpectralScratch {
        let (buf, scratch) = self.rows.buffers();
        SpectralScratch { buf, scratch }
    }

    pub fn row(&self, y: usize, s: &mut SpectralScratch, gx: &mut [f32], gy: &mut [f32]) {
        let w = self.width;
        let row = &self.plane[y * w..(y + 1) * w];
        let slope = self.rows.fill(&mut s.buf, |i| row[i], |_| 0.0);
        self.rows.differentiate(&mut s.buf, &mut s.scratch);
        for x in 0..w {
            gx[x] = s.buf[x].re + slope.re;
        }
        for (b, chunk) in gy[..w].chunks_mut(BLOCK).enumerate() {
            let src = &self.gy_blocks[(b * self.height + y) * BLOCK..][..chunk.len()];
            chunk.copy_from_slice(src);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    fn all_grads(s: &Spectral, w: usize, h: usize) -> (Vec<f32>, Vec<f32>) {
        let mut sc = s.scratch();
        let (mut gx, mut gy) = (vec![0.0; w * h], vec![0.0; w * h]);
        for y in 0..h {
            s.row(y, &mut sc, &mut gx[y * w..(y + 1) * w], &mut gy[y * w..(y + 1) * w]);
        }
        (gx, gy)
    }

    #[test]
    fn exact_on_periodic_sines_of_any_size() {
        // Odd and prime sizes go through rustfft's mixed-radix and Bluestein paths.
        for (w, h) in [(16, 8), (13, 7), (17, 31), (1, 9)] {
            let (fx, fy) = (3.0 / w as f64, 2.0 / h as f64);
            let hgt = |x: f64, yu: f64| 0.5 + 0.2 * (TAU * (fx * x + fy * yu)).sin();
            let plane: Vec<f32> = (0..w * h).map(|i| hgt((i % w) as f64, (h - 1 - i / w) as f64) as f32).collect();
            let s = Spectral::new(&plane, w, h, Wrap::Repeat);
            let (gx, gy) = all_grads(&s, w, h);
            for i in 0..w * h {
                let (x, yu) = ((i % w) as f64, (h - 1 - i / w) as f64);
                let c = 0.2 * TAU * (TAU * (fx * x + fy * yu)).cos();
                // A 1-wide image has only the zero frequency along x, like any sampled signal.
                let ex = if w == 1 { 0.0 } else { c * fx };
                let fy_eff = if 2 * 2 >= h { 0.0 } else { fy };
                assert!((gx[i] as f64 - ex).abs() < 1e-4, "{w}x{h} gx {} vs {ex}", gx[i]);
                assert!((gy[i] as f64 - c * fy_eff).abs() < 1e-4, "{w}x{h} gy {} vs {}", gy[i], c * fy);
            }
        }
    }

    #[test]
    fn mirrored_modes_are_exact_on_a_ramp() {
        let (w, h) = (37, 5);
        let plane: Vec<f32> = (0..w * h).map(|i| 0.01 * (i % w) as f32 - 0.03 * (i / w) as f32).collect();
        for wrap in [Wrap::Mirror, Wrap::Clamp] {
            let s = Spectral::new(&plane, w, h, wrap);
            let (gx, gy) = all_grads(&s, w, h);
            for i in 0..w * h {
                assert!((gx[i] - 0.01).abs() < 1e-5, "gx {} at {i}", gx[i]);
                assert!((gy[i] - 0.03).abs() < 1e-5, "gy {} at {i}", gy[i]);
            }
        }
    }

    #[test]
    fn constant_lines_are_exactly_flat() {
        let plane = vec![0.7f32; 12 * 9];
        for wrap in [Wrap::Repeat, Wrap::Mirror] {
            let (gx, gy) = all_grads(&Spectral::new(&plane, 12, 9, wrap), 12, 9);
            assert!(gx.iter().chain(&gy).all(|g| *g == 0.0));
        }
    }
}
