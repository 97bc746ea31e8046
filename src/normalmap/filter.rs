//! Separable derivative kernels and edge handling.
//!
//! Every kernel is `D ⊗ S`: an antisymmetric derivative `D` along the axis being differentiated
//! and a symmetric smoothing `S` across it. `D` is scaled so that `Σ k·D[k] = 1` (a linear ramp
//! of slope 1 gives exactly 1) and `S` so that `Σ S[k] = 1` (smoothing keeps a ramp's slope), so
//! every filter estimates the true derivative per texel and one strength means the same on all.
//!
//! Each output row is made from `2R+1` input rows in two 1-D passes through two padded row
//! buffers, so the inner loops are branch-free, contiguous and auto-vectorise; the edges are
//! handled once per row by the padding, not per pixel.

use super::Wrap;

/// A separable derivative filter of radius `R` (taps `-R..=R`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Kernel<const R: usize> {
    /// Derivative taps, index `k + R` for offset `k`; antisymmetric.
    pub d: [f32; 5],
    /// Smoothing taps, index `k + R`; symmetric, summing to 1.
    pub s: [f32; 5],
}

/// Maps an index that may lie outside `0..n` onto the image according to the wrap mode.
/// `mirror` repeats the edge texel (half-sample symmetric, like GL_MIRRORED_REPEAT), which is
/// also the extension that makes a 2n-periodic signal for the spectral filter.
#[inline]
pub fn wrap_index(i: isize, n: usize, wrap: Wrap) -> usize {
    let n_i = n as isize;
    match wrap {
        Wrap::Repeat => i.rem_euclid(n_i) as usize,
        Wrap::Clamp => i.clamp(0, n_i - 1) as usize,
        Wrap::Mirror => {
            let m = i.rem_euclid(2 * n_i);
            (if m >= n_i { 2 * n_i - 1 - m } else { m }) as usize
        }
    }
}

/// Scratch for one worker: the two padded intermediate rows.
pub(crate) struct RowScratch {
    smooth: Vec<f32>,
    deriv: Vec<f32>,
}

impl RowScratch {
    pub fn new(width: usize, radius: usize) -> Self {
        RowScratch { smooth: vec![0.0; width + 2 * radius], deriv: vec![0.0; width + 2 * radius] }
    }
}

impl<const R: usize> Kernel<R> {
    /// Computes `dh/dx` and `dh/dy_up` for image row `y` of a `width`-wide plane.
    #[cfg(test)]
    #[allow(clippy::too_many_arguments)]
    pub fn row(
        &self,
        plane: &[f32],
        width: usize,
        height: usize,
        wrap: Wrap,
        y: usize,
        scratch: &mut RowScratch,
        gx: &mut [f32],
        gy: &mut [f32],
    ) {
        self.vertical(plane, width, height, wrap, y, scratch);
        self.horizontal(scratch, 0, &mut gx[..width], &mut gy[..width]);
    }

    /// First pass for row `y`: the smoothed and the differentiated column sums, padded at both
    /// ends following the wrap mode, into `scratch`.
    ///
    /// `y_up` points to the top of the image, so the derivative across rows takes the row
    /// above (index `y - 1`) as the positive side: row offset k (downwards) is y_up offset -k,
    /// so row k is weighted by -D[k] = D[-k].
    #[inline]
    pub fn vertical(&self, plane: &[f32], width: usize, height: usize, wrap: Wrap, y: usize, scratch: &mut RowScratch) {
        let rows: [&[f32]; 5] = std::array::from_fn(|j| {
            if j > 2 * R {
                return &plane[..0];
            }
            let r = wrap_index(y as isize + j as isize - R as isize, height, wrap);
            &plane[r * width..(r + 1) * width]
        });
        let smooth = &mut scratch.smooth[..width + 2 * R];
        let deriv = &mut scratch.deriv[..width + 2 * R];
        {
            let (s_out, d_out) = (&mut smooth[R..R + width], &mut deriv[R..R + width]);
            let mid = rows[R];
            for x in 0..width {
                s_out[x] = self.s[R] * mid[x];
                d_out[x] = 0.0;
            }
            for k in 1..=R {
                let (up, down) = (&rows[R - k][..width], &rows[R + k][..width]);
                let (sk, dk) = (self.s[R + k], self.d[R + k]);
                for x in 0..width {
                    s_out[x] += sk * (up[x] + down[x]);
                    d_out[x] += dk * (up[x] - down[x]);
                }
            }
        }
        pad(smooth, width, R, wrap);
        pad(deriv, width, R, wrap);
    }

    /// Second pass: `gx.len()` texels of both derivatives from column `x0` on, from the
    /// buffers [`Kernel::vertical`] filled. Done in tiles so its outputs stay in L1.
    #[inline]
    pub fn horizontal(&self, scratch: &RowScratch, x0: usize, gx: &mut [f32], gy: &mut [f32]) {
        let n = gx.len();
        let gy = &mut gy[..n];
        let (smooth, deriv) = (&scratch.smooth[x0..x0 + n + 2 * R], &scratch.deriv[x0..x0 + n + 2 * R]);
        let dm = &deriv[R..R + n];
        for x in 0..n {
            gx[x] = 0.0;
            gy[x] = self.s[R] * dm[x];
        }
        for k in 1..=R {
            let (sk, dk) = (self.s[R + k], self.d[R + k]);
            let (sl, sr) = (&smooth[R - k..R - k + n], &smooth[R + k..R + k + n]);
            let (dl, dr) = (&deriv[R - k..R - k + n], &deriv[R + k..R + k + n]);
            for x in 0..n {
                gx[x] += dk * (sr[x] - sl[x]);
                gy[x] += sk * (dl[x] + dr[x]);
            }
        }
    }
}

/// Fills the `r` padding texels on each side of `buf[r..r + width]` following the wrap mode.
fn pad(buf: &mut [f32], width: usize, r: usize, wrap: Wrap) {
    for i in 1..=r {
        let left = wrap_index(-(i as isize), width, wrap);
        let right = wrap_index((width + i - 1) as isize, width, wrap);
        buf[r - i] = buf[r + left];
        buf[r + width + i - 1] = buf[r + right];
    }
}

/// Central difference `[-1, 0, 1] / 2`: the narrowest estimate, no smoothing.
pub(crate) const CENTRAL: Kernel<1> = Kernel { d: [-0.5, 0.0, 0.5, 0.0, 0.0], s: [0.0, 1.0, 0.0, 0.0, 0.0] };
/// Fourth-order central difference `[1, -8, 0, 8, -1] / 12`: exact on cubics, so its error on
/// smooth data falls as h^4 instead of h^2, for two more taps and no smoothing.
pub(crate) const CENTRAL4: Kernel<2> =
    Kernel { d: [1.0 / 12.0, -8.0 / 12.0, 0.0, 8.0 / 12.0, -1.0 / 12.0], s: [0.0, 0.0, 1.0, 0.0, 0.0] };
/// Sobel: central difference smoothed across by `[1, 2, 1] / 4`.
pub(crate) const SOBEL: Kernel<1> = Kernel { d: [-0.5, 0.0, 0.5, 0.0, 0.0], s: [0.25, 0.5, 0.25, 0.0, 0.0] };
/// Scharr: central difference smoothed by `[3, 10, 3] / 16`, tuned for rotational symmetry.
pub(crate) const SCHARR: Kernel<1> =
    Kernel { d: [-0.5, 0.0, 0.5, 0.0, 0.0], s: [3.0 / 16.0, 10.0 / 16.0, 3.0 / 16.0, 0.0, 0.0] };
/// Prewitt: central difference averaged across by `[1, 1, 1] / 3`.
pub(crate) const PREWITT: Kernel<1> =
    Kernel { d: [-0.5, 0.0, 0.5, 0.0, 0.0], s: [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 0.0, 0.0] };
/// 5x5 Sobel: derivative `[-1, -2, 0, 2, 1] / 8` (Σ k·D = 1) and smoothing `[1, 4, 6, 4, 1] / 16`.
pub(crate) const SOBEL5: Kernel<2> = Kernel {
    d: [-1.0 / 8.0, -2.0 / 8.0, 0.0, 2.0 / 8.0, 1.0 / 8.0],
    s: [1.0 / 16.0, 4.0 / 16.0, 6.0 / 16.0, 4.0 / 16.0, 1.0 / 16.0],
};

#[cfg(test)]
mod tests {
    use super::*;

    fn grads<const R: usize>(k: &Kernel<R>, plane: &[f32], w: usize, h: usize, wrap: Wrap) -> (Vec<f32>, Vec<f32>) {
        let mut s = RowScratch::new(w, R);
        let (mut gx, mut gy) = (vec![0.0; w * h], vec![0.0; w * h]);
        for y in 0..h {
            k.row(plane, w, h, wrap, y, &mut s, &mut gx[y * w..(y + 1) * w], &mut gy[y * w..(y + 1) * w]);
        }
        (gx, gy)
    }

    /// h = a·x + b·y_up, with y_up = h - 1 - row.
    fn ramp(w: usize, h: usize, a: f32, b: f32) -> Vec<f32> {
        (0..w * h).map(|i| a * (i % w) as f32 + b * (h - 1 - i / w) as f32).collect()
    }

    fn check_ramp<const R: usize>(k: &Kernel<R>) {
        let (w, h) = (11, 9);
        let plane = ramp(w, h, 0.03, -0.02);
        let (gx, gy) = grads(k, &plane, w, h, Wrap::Clamp);
        // Interior texels (at least R from every edge) see the ramp's exact slope.
        for y in R..h - R {
            for x in R..w - R {
                assert!((gx[y * w + x] - 0.03).abs() < 1e-6, "gx {} at {x},{y}", gx[y * w + x]);
                assert!((gy[y * w + x] + 0.02).abs() < 1e-6, "gy {} at {x},{y}", gy[y * w + x]);
            }
        }
    }

    #[test]
    fn every_kernel_is_exact_on_a_ramp() {
        check_ramp(&CENTRAL);
        check_ramp(&CENTRAL4);
        check_ramp(&SOBEL);
        check_ramp(&SCHARR);
        check_ramp(&PREWITT);
        check_ramp(&SOBEL5);
    }

    #[test]
    fn taps_are_normalised() {
        fn sums<const R: usize>(k: &Kernel<R>) -> (f32, f32) {
            let mut m = 0.0;
            let mut s = 0.0;
            for j in 0..=2 * R {
                m += (j as f32 - R as f32) * k.d[j];
                s += k.s[j];
            }
            (m, s)
        }
        for (m, s) in [sums(&CENTRAL), sums(&SOBEL), sums(&SCHARR), sums(&PREWITT)] {
            assert!((m - 1.0).abs() < 1e-6 && (s - 1.0).abs() < 1e-6);
        }
        for (m, s) in [sums(&CENTRAL4), sums(&SOBEL5)] {
            assert!((m - 1.0).abs() < 1e-6 && (s - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn wrap_modes_map_indices() {
        assert_eq!(wrap_index(-1, 5, Wrap::Repeat), 4);
        assert_eq!(wrap_index(5, 5, Wrap::Repeat), 0);
        assert_eq!(wrap_index(-1, 5, Wrap::Clamp), 0);
        assert_eq!(wrap_index(7, 5, Wrap::Clamp), 4);
        assert_eq!(wrap_index(-1, 5, Wrap::Mirror), 0);
        assert_eq!(wrap_index(-2, 5, Wrap::Mirror), 1);
        assert_eq!(wrap_index(5, 5, Wrap::Mirror), 4);
        assert_eq!(wrap_index(6, 5, Wrap::Mirror), 3);
        for wrap in [Wrap::Repeat, Wrap::Clamp, Wrap::Mirror] {
            for i in -3..4 {
                assert_eq!(wrap_index(i, 1, wrap), 0);
            }
        }
    }

    #[test]
    fn repeat_differentiates_across_the_seam() {
        // A periodic sawtooth-free signal: repeat sees the wrap neighbour, clamp does not.
        let (w, h) = (8, 1);
        let plane: Vec<f32> = (0..w).map(|x| (x as f32 * std::f32::consts::TAU / 8.0).sin()).collect();
        let (gr, _) = grads(&CENTRAL, &plane, w, h, Wrap::Repeat);
        let (gc, _) = grads(&CENTRAL, &plane, w, h, Wrap::Clamp);
        let expect0 = (plane[1] - plane[7]) / 2.0;
        assert!((gr[0] - expect0).abs() < 1e-6);
        assert!((gc[0] - (plane[1] - plane[0]) / 2.0).abs() < 1e-6);
        for x in 1..w - 1 {
            assert_eq!(gr[x], gc[x]);
        }
    }

    #[test]
    fn tiny_images_are_flat_and_finite() {
        for (w, h) in [(1, 1), (1, 7), (7, 1), (2, 3)] {
            let plane = vec![0.5; w * h];
            let (gx, gy) = grads(&SOBEL5, &plane, w, h, Wrap::Mirror);
            assert!(gx.iter().chain(&gy).all(|g| *g == 0.0));
        }
    }
}
