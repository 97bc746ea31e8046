//! Analytic height fields whose exact normals are known, for measuring filter error.
//!
//! Every field is periodic over the `n x n` image (integer wave vectors; the Gaussian is ~1e-50
//! at the border), so the benchmark runs with `repeat` and measures the filter, not the edges.

use bumpbake::normalmap::HeightPlane;
use std::f64::consts::TAU;

/// `amp · sin(2π(p·x + q·y_up)/n + phase)`.
#[derive(Clone, Copy, Debug)]
struct Wave {
    amp: f64,
    p: f64,
    q: f64,
    phase: f64,
}

/// A named height field `h(x, y_up)` with its gradient and the strength used for it.
#[derive(Clone, Debug)]
pub struct Surface {
    pub name: &'static str,
    pub what: String,
    pub n: usize,
    /// Chosen so that the steepest texel is tilted by about 45 degrees.
    pub strength: f64,
    base: f64,
    waves: Vec<Wave>,
    /// Gaussian bump of this sigma (texels) at the centre, height 1.
    bump: Option<f64>,
    /// Heights rounded to this many steps (255: an 8-bit file), as a real map would be.
    levels: Option<f64>,
}

impl Surface {
    fn height_grad(&self, x: f64, yu: f64) -> (f64, f64, f64) {
        let n = self.n as f64;
        let (mut h, mut gx, mut gy) = (self.base, 0.0, 0.0);
        for w in &self.waves {
            let a = TAU * (w.p * x + w.q * yu) / n + w.phase;
            let (s, c) = a.sin_cos();
            h += w.amp * s;
            gx += w.amp * c * TAU * w.p / n;
            gy += w.amp * c * TAU * w.q / n;
        }
        if let Some(sigma) = self.bump {
            let (dx, dy) = (x - n / 2.0, yu - n / 2.0);
            let e = (-(dx * dx + dy * dy) / (2.0 * sigma * sigma)).exp();
            h += e;
            gx += -dx / (sigma * sigma) * e;
            gy += -dy / (sigma * sigma) * e;
        }
        (h, gx, gy)
    }

    /// The sampled heights as f32 (no quantisation: the filters' own error is measured).
    pub fn plane(&self) -> HeightPlane {
        let n = self.n;
        HeightPlane::from_fn(n, n, |x, row| {
            let h = self.height_grad(x as f64, (n - 1 - row) as f64).0;
            match self.levels {
                Some(l) => ((h * l).round() / l) as f32,
                None => h as f32,
            }
        })
    }

    /// Exact unit normals, row-major from the top row, OpenGL convention.
    pub fn exact_normals(&self) -> Vec<[f64; 3]> {
        let n = self.n;
        (0..n * n)
            .map(|i| {
                let (_, gx, gy) = self.height_grad((i % n) as f64, (n - 1 - i / n) as f64);
                let v = [-self.strength * gx, -self.strength * gy, 1.0];
                let l = (v[0] * v[0] + v[1] * v[1] + 1.0).sqrt();
                [v[0] / l, v[1] / l, v[2] / l]
            })
            .collect()
    }

    fn max_slope(&self) -> f64 {
        let n = self.n;
        (0..n * n)
            .map(|i| {
                let (_, gx, gy) = self.height_grad((i % n) as f64, (i / n) as f64);
                gx.hypot(gy)
            })
            .fold(0.0, f64::max)
    }

    fn tuned(mut self) -> Surface {
        self.strength = 1.0 / self.max_slope();
        self
    }
}

/// A plane wave of `cycles` periods across the image along a direction chosen so that both
/// derivatives are non-zero (3:4, a 36.9 degree heading).
fn sine(name: &'static str, n: usize, cycles: f64) -> Surface {
    let (p, q) = ((cycles * 0.6).round().max(1.0), (cycles * 0.8).round().max(1.0));
    let wavelength = n as f64 / p.hypot(q);
    Surface {
        name,
        what: format!("sine, wavelength {wavelength:.1} texels"),
        n,
        strength: 1.0,
        base: 0.5,
        waves: vec![Wave { amp: 0.5, p, q, phase: 0.3 }],
        bump: None,
        levels: None,
    }
    .tuned()
}

/// SplitMix64: a tiny deterministic generator so the surfaces are the same on every machine.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Sum of random plane waves, three per octave, from 2 cycles per image up to a wavelength of
/// about 4 texels, amplitude falling as f^-1.5 (slope per octave as f^-0.5): a band-limited
/// stand-in for real relief, with detail at every scale.
pub fn fractal(n: usize) -> Surface {
    let mut rng = Rng(0x5EED_0003);
    let mut waves = Vec::new();
    let mut f = 2.0;
    while n as f64 / f >= 4.0 {
        for _ in 0..3 {
            let theta = rng.next() * TAU;
            let (p, q) = ((f * theta.cos()).round(), (f * theta.sin()).round());
            waves.push(Wave { amp: f.powf(-1.5), p, q, phase: rng.next() * TAU });
        }
        f *= 2.0;
    }
    let total: f64 = waves.iter().map(|w| w.amp).sum();
    for w in &mut waves {
        w.amp *= 0.5 / total;
    }
    Surface {
        name: "fractal",
        what: format!("{} waves, f^-1.5, wavelengths {}..4 texels", waves.len(), n / 2),
        n,
        strength: 1.0,
        base: 0.5,
        waves,
        bump: None,
        levels: None,
    }
    .tuned()
}

/// The benchmark's surfaces on an `n x n` image.
pub fn all(n: usize) -> Vec<Surface> {
    let sigma = 6.0;
    vec![
        sine("sine-low", n, n as f64 / 128.0),
        sine("sine-mid", n, n as f64 / 12.8),
        sine("sine-high", n, n as f64 / 3.2),
        Surface {
            name: "gaussian",
            what: format!("Gaussian bump, sigma {sigma} texels"),
            n,
            strength: 1.0,
            base: 0.0,
            waves: vec![],
            bump: Some(sigma),
            levels: None,
        }
        .tuned(),
        fractal(n),
        Surface {
            name: "fractal-16bit",
            what: "the fractal stored in 16 bits".into(),
            levels: Some(65535.0),
            ..fractal(n)
        },
        Surface {
            name: "fractal-8bit",
            what: "the fractal stored in 8 bits (terracing)".into(),
            levels: Some(255.0),
            ..fractal(n)
        },
    ]
}
