//! LOW's UV layout rasterised in texel space, a band of rows at a time.
//!
//! Each texel holds `n x n` samples on a regular grid. A sample belongs to the first triangle (by
//! index) whose UV triangle holds it, edges included; so overlapping UVs resolve the same way on
//! every run, and a sample on an edge two triangles share is not lost. Samples just outside every
//! triangle, within [`EXTEND`] texels of one, take the nearest such triangle with extrapolated
//! barycentrics: texels cut by an island's border then hold the surface continued a little past
//! it, which is what bilinear filtering reads there.

/// How far past a triangle's UV edges samples are still given to it, in texels.
pub const EXTEND: f32 = 1.0;

/// One LOW triangle in texel coordinates (x right, y down: glTF's UV times the image size).
#[derive(Debug, Clone, Copy)]
pub struct UvTri {
    pub p: [[f32; 2]; 3],
}

/// A triangle prepared for the band loop: edge equations scaled to signed texel distances.
#[derive(Debug, Clone, Copy)]
pub struct Edges {
    /// `(a, b, c)` per edge: distance of `(x, y)` inside the edge is `a*x + b*y + c`.
    e: [[f32; 3]; 3],
    /// Edge functions unscaled, and twice the signed area, for barycentrics.
    raw: [[f32; 3]; 3],
    area2: f32,
    pub min: [f32; 2],
    pub max: [f32; 2],
}

impl Edges {
    /// `None` for a triangle without UV area (or with non-finite UVs).
    pub fn new(t: &UvTri) -> Option<Edges> {
        let [p0, p1, p2] = t.p;
        let area2 = (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0]);
        if !area2.is_finite() || area2.abs() < 1e-12 {
            return None;
        }
        let s = area2.signum();
        // Edge k is opposite corner k, so its function is corner k's barycentric weight (times area2).
        let edge = |a: [f32; 2], b: [f32; 2]| {
            let (ea, eb) = (a[1] - b[1], b[0] - a[0]);
            [ea, eb, a[0] * b[1] - a[1] * b[0]]
        };
        let raw = [edge(p1, p2), edge(p2, p0), edge(p0, p1)];
        let mut e = raw;
        for k in 0..3 {
            let len = (raw[k][0] * raw[k][0] + raw[k][1] * raw[k][1]).sqrt();
            if len == 0.0 {
                return None;
            }
            let f = s / len;
            e[k] = [raw[k][0] * f, raw[k][1] * f, raw[k][2] * f];
        }
        let min = [p0[0].min(p1[0]).min(p2[0]) - EXTEND, p0[1].min(p1[1]).min(p2[1]) - EXTEND];
        let max = [p0[0].max(p1[0]).max(p2[0]) + EXTEND, p0[1].max(p1[1]).max(p2[1]) + EXTEND];
        Some(Edges { e, raw, area2, min, max })
    }

    /// Signed distance (texels) of the point outside the triangle: <= 0 inside.
    #[inline]
    fn outside(&self, x: f32, y: f32) -> f32 {
        let d = |k: usize| self.e[k][0] * x + self.e[k][1] * y + self.e[k][2];
        -(d(0).min(d(1)).min(d(2)))
    }

    /// Barycentric weights of the point (extrapolated outside the triangle).
    #[inline]
    pub fn bary(&self, x: f32, y: f32) -> [f32; 3] {
        let f = |k: usize| (self.raw[k][0] * x + self.raw[k][1] * y + self.raw[k][2]) / self.area2;
        let (b1, b2) = (f(1), f(2));
        [1.0 - b1 - b2, b1, b2]
    }
}

/// Which triangle each sample of a band belongs to.
pub struct BandSamples {
    /// Per sample, row-major over the band's `rows * n` sample rows: the triangle or `u32::MAX`.
    pub owner: Vec<u32>,
    /// Per sample, how far outside its triangle it lies (0 inside).
    key: Vec<f32>,
    /// Samples strictly inside two or more triangles.
    pub overlapping: usize,
}

impl BandSamples {
    pub fn inside(&self, s: usize) -> bool {
        self.owner[s] != u32::MAX && self.key[s] == 0.0
    }
}

/// Position of sample `(sx, sy)` (sample indices within the band) in texel coordinates.
#[inline]
pub fn sample_pos(sx: usize, sy: usize, y0: usize, n: usize) -> (f32, f32) {
    let f = 1.0 / n as f32;
    ((sx as f32 + 0.5) * f, y0 as f32 + (sy as f32 + 0.5) * f)
}

/// Assigns the samples of texel rows `y0..y1` (width `w`, `n x n` samples per texel) among the
/// triangles `candidates` (indices into `edges`, ascending).
pub fn band(edges: &[Option<Edges>], candidates: &[u32], y0: usize, y1: usize, w: usize, n: usize) -> BandSamples {
    let (sw, sh) = (w * n, (y1 - y0) * n);
    let mut owner = vec![u32::MAX; sw * sh];
    let mut key = vec![f32::INFINITY; sw * sh];
    let mut overlapping = 0;
    let f = n as f32;
    for &t in candidates {
        let Some(e) = &edges[t as usize] else { continue };
        // Sample (sx, sy) sits at ((sx + 0.5) / n, y0 + (sy + 0.5) / n).
        let sx0 = ((e.min[0] * f - 0.5).ceil().max(0.0) as usize).min(sw);
        let sx1 = (((e.max[0] * f - 0.5).floor() + 1.0).max(0.0) as usize).min(sw);
        let sy0 = (((e.min[1] - y0 as f32) * f - 0.5).ceil().max(0.0) as usize).min(sh);
        let sy1 = ((((e.max[1] - y0 as f32) * f - 0.5).floor() + 1.0).max(0.0) as usize).min(sh);
        for sy in sy0..sy1 {
            for sx in sx0..sx1 {
                let (x, y) = sample_pos(sx, sy, y0, n);
                let d = e.outside(x, y);
                if d > EXTEND {
                    continue;
                }
                let k = d.max(0.0);
                let s = sy * sw + sx;
                if d < 0.0 && key[s] == 0.0 && owner[s] != t {
                    overlapping += 1;
                }
                if k < key[s] {
                    key[s] = k;
                    owner[s] = t;
                }
            }
        }
    }
    BandSamples { owner, key, overlapping }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn edges(t: [[f32; 2]; 3]) -> Option<Edges> {
        Edges::new(&UvTri { p: t })
    }

    #[test]
    fn barycentrics_reproduce_the_point() {
        let e = edges([[1.0, 1.0], [5.0, 2.0], [2.0, 6.0]]).unwrap();
        let b = e.bary(2.5, 3.0);
        let x = b[0] * 1.0 + b[1] * 5.0 + b[2] * 2.0;
        let y = b[0] * 1.0 + b[1] * 2.0 + b[2] * 6.0;
        assert!((x - 2.5).abs() < 1e-5 && (y - 3.0).abs() < 1e-5);
        assert!((b.iter().sum::<f32>() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn zero_area_triangles_are_refused() {
        assert!(edges([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]).is_none());
        assert!(edges([[0.0, 0.0], [0.0, 0.0], [0.0, 0.0]]).is_none());
    }

    /// Two triangles splitting a square cover every sample in it once; the first wins where
    /// they overlap, and overlaps are counted.
    #[test]
    fn square_is_covered_and_overlaps_counted() {
        let tris = [
            edges([[0.0, 0.0], [4.0, 0.0], [4.0, 4.0]]),
            edges([[0.0, 0.0], [4.0, 4.0], [0.0, 4.0]]),
            edges([[0.0, 0.0], [4.1, 0.0], [0.0, 4.1]]),
        ];
        let b = band(&tris[..2], &[0, 1], 0, 4, 8, 2);
        for sy in 0..8 {
            for sx in 0..16 {
                let s = sy * 16 + sx;
                let (x, _) = sample_pos(sx, sy, 0, 2);
                if x < 4.0 {
                    assert!(b.inside(s), "sample {sx},{sy} not covered");
                } else if x < 5.0 {
                    assert!(!b.inside(s) && b.owner[s] != u32::MAX, "sample {sx},{sy} should extend the square");
                } else {
                    assert_eq!(b.owner[s], u32::MAX);
                }
            }
        }
        assert_eq!(b.overlapping, 0);
        let o = band(&tris, &[0, 1, 2], 0, 4, 8, 2);
        // Triangle 2 holds the samples with x + y < 4.1 (none on its edge): 36 of the 8x8.
        assert_eq!(o.overlapping, 36);
        // Inside the square the first two triangles keep every sample.
        assert!((0..8 * 16).filter(|s| s % 16 < 8).all(|s| o.owner[s] != 2));
    }
}
