//! The parallel row driver shared by every output type.
//!
//! Rows are independent given the height plane, so bands of rows go to rayon workers, each with
//! its own scratch allocated once per band (never per pixel). A row's bytes depend only on the
//! row, never on the banding or the thread count, so the output is deterministic.

use super::filter::{self, Kernel, RowScratch};
use super::spectral::{Spectral, SpectralScratch};
use super::{Filter, HeightPlane, Options};
use crate::progress::Reporter;
use rayon::prelude::*;

/// `normalize(-S·gx, -S·gy, 1)`, finite and unit for any finite input and any strength: the
/// scaled slopes are clamped at 1e15, far beyond any representable tilt (the angle from the
/// horizon is then 1e-15 rad) but small enough that their squares cannot overflow an f32.
#[inline(always)]
pub fn unit_normal(gx: f32, gy: f32, strength: f32) -> [f32; 3] {
    let x = (-strength * gx).clamp(-LIM, LIM);
    let y = (-strength * gy).clamp(-LIM, LIM);
    let inv = 1.0 / (x * x + y * y + 1.0).sqrt();
    [x * inv, y * inv, inv]
}

const LIM: f32 = 1e15;

/// [`unit_normal`] over a row into three planes, `n.y` times `ysign`: a loop of independent
/// lanes that compiles to packed SSE (min/max, sqrt, div), unlike the interleaved form.
#[inline(always)]
#[allow(clippy::manual_clamp)]
pub(crate) fn unit_normals_planar(gx: &[f32], gy: &[f32], s: f32, ysign: f32, n: &mut [Vec<f32>; 3]) {
    let w = gx.len();
    let [nx, ny, nz] = n;
    let (nx, ny, nz, gy) = (&mut nx[..w], &mut ny[..w], &mut nz[..w], &gy[..w]);
    for i in 0..w {
        // max/min rather than clamp: clamp's NaN-propagating form does not vectorise as well.
        let x = (-s * gx[i]).max(-LIM).min(LIM);
        let y = (-s * gy[i]).max(-LIM).min(LIM);
        let inv = 1.0 / (x * x + y * y + 1.0).sqrt();
        nx[i] = x * inv;
        ny[i] = ysign * (y * inv);
        nz[i] = inv;
    }
}

enum Source<'a> {
    R1(Kernel<1>),
    R2(Kernel<2>),
    Spectral(Spectral<'a>),
}

enum Scratch {
    Row(RowScratch),
    Spectral(SpectralScratch),
}

impl<'a> Source<'a> {
    fn new(h: &'a HeightPlane, opts: &Options) -> Source<'a> {
        match opts.filter {
            Filter::Central => Source::R1(filter::CENTRAL),
            Filter::Sobel => Source::R1(filter::SOBEL),
            Filter::Scharr => Source::R1(filter::SCHARR),
            Filter::Prewitt => Source::R1(filter::PREWITT),
            Filter::Central4 => Source::R2(filter::CENTRAL4),
            Filter::Sobel5 => Source::R2(filter::SOBEL5),
            Filter::Spectral => Source::Spectral(Spectral::new(&h.data, h.width, h.height, opts.wrap)),
        }
    }
    fn scratch(&self, width: usize) -> Scratch {
        match self {
            Source::R1(_) => Scratch::Row(RowScratch::new(width, 1)),
            Source::R2(_) => Scratch::Row(RowScratch::new(width, 2)),
            Source::Spectral(s) => Scratch::Spectral(s.scratch()),
        }
    }
}

/// Texels per tile of the second pass: its float rows stay in L1.
const TILE: usize = 512;

/// Runs `sink(y, x0, dh/dx, dh/dy_up, out, state)` over every row `y` of `h` in tiles of up to
/// [`TILE`] texels from column `x0`, rows in parallel. `out` is the tile's part of
/// `out[y*stride..(y+1)*stride]` (`stride / width` elements a texel) and `state` is the sink's
/// own scratch, made by `state()` once per band.
pub(crate) fn for_each_row<T: Send, S>(
    h: &HeightPlane,
    opts: &Options,
    out: &mut [T],
    stride: usize,
    progress: &Reporter,
    state: impl Fn() -> S + Sync,
    sink: impl Fn(usize, usize, &[f32], &[f32], &mut [T], &mut S) + Sync,
) {
    if h.width == 0 || h.height == 0 {
        return;
    }
    Rows::new(h, opts).run(0, out, stride, progress, state, sink);
}

/// A filter set up over one plane (the spectral filter's column pass done), to be run over
/// strips of rows: the streaming PNG writer filters a strip, compresses it, and goes on.
pub(crate) struct Rows<'a> {
    h: &'a HeightPlane,
    opts: Options,
    src: Source<'a>,
}

impl<'a> Rows<'a> {
    pub fn new(h: &'a HeightPlane, opts: &Options) -> Rows<'a> {
        Rows { h, opts: *opts, src: Source::new(h, opts) }
    }

    /// [`for_each_row`] over rows `y0..y0 + out.len() / stride`.
    pub fn run<T: Send, S>(
        &self,
        y0: usize,
        out: &mut [T],
        stride: usize,
        progress: &Reporter,
        state: impl Fn() -> S + Sync,
        sink: impl Fn(usize, usize, &[f32], &[f32], &mut [T], &mut S) + Sync,
    ) {
        let (h, src, wrap) = (self.h, &self.src, self.opts.wrap);
        let (w, ht) = (h.width, h.height);
        let nrows = out.len() / stride.max(1);
        assert!(out.len() == stride * nrows && y0 + nrows <= ht, "output buffer does not match the plane");
        if w == 0 || nrows == 0 {
            return;
        }
        let per_texel = stride / w;
        // Enough bands to balance the workers, few enough that per-band scratch is noise.
        let band = (nrows / (rayon::current_num_threads() * 8)).clamp(1, 64);
        out.par_chunks_mut(stride * band).enumerate().for_each(|(b, chunk)| {
            let mut scratch = src.scratch(w);
            let mut st = state();
            let full = matches!(src, Source::Spectral(_));
            let tile_len = if full { w } else { TILE.min(w) };
            let (mut gx, mut gy) = (vec![0.0f32; tile_len], vec![0.0f32; tile_len]);
            for (i, row) in chunk.chunks_mut(stride).enumerate() {
                let y = y0 + b * band + i;
                match (src, &mut scratch) {
                    (Source::R1(k), Scratch::Row(s)) => k.vertical(&h.data, w, ht, wrap, y, s),
                    (Source::R2(k), Scratch::Row(s)) => k.vertical(&h.data, w, ht, wrap, y, s),
                    (Source::Spectral(k), Scratch::Spectral(s)) => k.row(y, s, &mut gx, &mut gy),
                    _ => unreachable!("scratch made by its own source"),
                }
                for x0 in (0..w).step_by(TILE) {
                    let n = TILE.min(w - x0);
                    let out = &mut row[x0 * per_texel..(x0 + n) * per_texel];
                    match (src, &scratch) {
                        (Source::R1(k), Scratch::Row(s)) => k.horizontal(s, x0, &mut gx[..n], &mut gy[..n]),
                        (Source::R2(k), Scratch::Row(s)) => k.horizontal(s, x0, &mut gx[..n], &mut gy[..n]),
                        _ => {
                            sink(y, x0, &gx[x0..x0 + n], &gy[x0..x0 + n], out, &mut st);
                            continue;
                        }
                    }
                    sink(y, x0, &gx[..n], &gy[..n], out, &mut st);
                }
            }
            progress.tick((chunk.len() / stride) as u64);
        });
    }
}
