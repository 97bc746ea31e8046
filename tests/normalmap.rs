//! `bumpbake normalmap` end to end: inputs are made here, the binary is run, and the written
//! files are checked against answers worked out independently (in f64, from the conventions).
#![allow(clippy::needless_range_loop)]

use image::{DynamicImage, ImageBuffer, Luma, Rgb, Rgb32FImage};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const FILTERS: [&str; 7] = ["central", "central4", "sobel", "scharr", "prewitt", "sobel5", "spectral"];
const LOCAL_FILTERS: [(&str, usize); 6] =
    [("central", 1), ("central4", 2), ("sobel", 1), ("scharr", 1), ("prewitt", 1), ("sobel5", 2)];

fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_bumpbake"));
    c.env_remove("RAYON_NUM_THREADS");
    c
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("the binary runs")
}

fn ok(args: &[&str]) {
    let out = run(args);
    assert!(out.status.success(), "{args:?} failed: {}", String::from_utf8_lossy(&out.stderr));
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

struct Dir(tempfile::TempDir);
impl Dir {
    fn new() -> Dir {
        Dir(tempfile::tempdir().unwrap())
    }
    fn path(&self, name: &str) -> PathBuf {
        self.0.path().join(name)
    }
}

fn gray8(path: &Path, w: u32, h: u32, f: impl Fn(u32, u32) -> u8) {
    ImageBuffer::from_fn(w, h, |x, y| Luma([f(x, y)])).save(path).unwrap();
}

fn gray16(path: &Path, w: u32, h: u32, f: impl Fn(u32, u32) -> u16) {
    let img: ImageBuffer<Luma<u16>, Vec<u16>> = ImageBuffer::from_fn(w, h, |x, y| Luma([f(x, y)]));
    img.save(path).unwrap();
}

fn read_rgb8(path: &Path) -> image::RgbImage {
    match image::open(path).unwrap() {
        DynamicImage::ImageRgb8(i) => i,
        other => panic!("expected 8-bit RGB, got {:?}", other.color()),
    }
}

fn read_rgb16(path: &Path) -> ImageBuffer<Rgb<u16>, Vec<u16>> {
    match image::open(path).unwrap() {
        DynamicImage::ImageRgb16(i) => i,
        other => panic!("expected 16-bit RGB, got {:?}", other.color()),
    }
}

/// The conventions' normal for slopes (per texel) `gx`, `gy` at strength `s`, in f64.
fn exact_normal(gx: f64, gy: f64, s: f64) -> [f64; 3] {
    let v = [-s * gx, -s * gy, 1.0];
    let l = (v[0] * v[0] + v[1] * v[1] + 1.0).sqrt();
    [v[0] / l, v[1] / l, v[2] / l]
}

/// `(n*0.5+0.5)*max` before rounding, asserting that it is not so close to a rounding
/// boundary that f32 arithmetic in the tool could honestly land on either side.
fn code(n: f64, max: f64) -> u32 {
    let t = (n * 0.5 + 0.5) * max;
    assert!((t.fract() - 0.5).abs() > 1e-3, "test value {t} is too close to a tie");
    t.round() as u32
}

#[test]
fn flat_input_gives_exactly_128_128_255() {
    let d = Dir::new();
    let input = d.path("flat.png");
    gray8(&input, 13, 7, |_, _| 77);
    let input16 = d.path("flat16.png");
    gray16(&input16, 5, 4, |_, _| 40000);
    for f in FILTERS {
        for wrap in ["repeat", "clamp", "mirror"] {
            for (inp, name) in [(&input, "a.png"), (&input16, "b.png")] {
                let out = d.path(name);
                ok(&["normalmap", p(inp), "-o", p(&out), "--filter", f, "--wrap", wrap, "--strength", "50"]);
                let img = read_rgb8(&out);
                assert!(img.pixels().all(|px| px.0 == [128, 128, 255]), "{f} {wrap}");
            }
        }
    }
}

#[test]
fn linear_ramp_gives_the_analytic_normal_for_every_filter() {
    // h = (1000 + 300·x + 200·y_up) / 65535: exact in 16 bits, so the slopes are exact too.
    let d = Dir::new();
    let (w, h) = (24u32, 11u32);
    let input = d.path("ramp16.png");
    gray16(&input, w, h, |x, y| (1000 + 300 * x + 200 * (h - 1 - y)) as u16);
    let s = 60.0;
    let n = exact_normal(300.0 / 65535.0, 200.0 / 65535.0, s);
    let want8 = [code(n[0], 255.0), code(n[1], 255.0), code(n[2], 255.0)];
    // 16 bits resolve the f32 rounding of the slope (about 1e-6 relative here): allow the
    // rounding to land within 0.05 of a step beyond the half step.
    let want16 = n.map(|c| (c * 0.5 + 0.5) * 65535.0);
    for f in FILTERS {
        // Clamp flattens the slope at the edge for the local filters (nothing is invented
        // beyond it); the spectral filter removes the end-to-end line and is exact everywhere.
        let margin = LOCAL_FILTERS.iter().find(|l| l.0 == f).map(|l| l.1).unwrap_or(0) as u32;
        let out = d.path("n8.png");
        ok(&["normalmap", p(&input), "-o", p(&out), "--filter", f, "--strength", "60"]);
        let img = read_rgb8(&out);
        let out16 = d.path("n16.png");
        ok(&["normalmap", p(&input), "-o", p(&out16), "--filter", f, "--strength", "60", "--bits", "16"]);
        let img16 = read_rgb16(&out16);
        for y in margin..h - margin {
            for x in margin..w - margin {
                let got = img.get_pixel(x, y).0.map(u32::from);
                assert_eq!(got, want8, "{f} 8-bit at {x},{y}");
                let got = img16.get_pixel(x, y).0;
                for k in 0..3 {
                    let e = (got[k] as f64 - want16[k]).abs();
                    assert!(e <= 0.55, "{f} 16-bit at {x},{y}: {got:?} vs {want16:?}");
                }
            }
        }
    }
}

#[test]
fn sixteen_bit_ramp_too_subtle_for_8_bits_still_tilts() {
    // 3 counts in 65535 a texel: as 8 bits this would be one step every 85 texels.
    let d = Dir::new();
    let input = d.path("subtle.png");
    gray16(&input, 32, 8, |x, _| (20000 + 3 * x) as u16);
    let out = d.path("n.png");
    ok(&["normalmap", p(&input), "-o", p(&out), "--strength", "1000"]);
    let n = exact_normal(3.0 / 65535.0, 0.0, 1000.0);
    let want = [code(n[0], 255.0), 128, code(n[2], 255.0)];
    assert!(want[0] < 124, "the ramp must tilt visibly: {want:?}");
    let img = read_rgb8(&out);
    for y in 0..8 {
        for x in 1..31 {
            assert_eq!(img.get_pixel(x, y).0.map(u32::from), want, "at {x},{y}");
        }
    }
}

#[test]
fn spectral_matches_a_sine_within_the_output_quantisation() {
    let d = Dir::new();
    let (w, h) = (48u32, 30u32); // not powers of two: mixed-radix transforms
    let (fx, fy) = (5.0 / w as f64, 3.0 / h as f64);
    let tau = std::f64::consts::TAU;
    let hgt = |x: f64, yu: f64| 0.5 + 0.3 * (tau * (fx * x + fy * yu) + 0.4).sin();
    let img = Rgb32FImage::from_fn(w, h, |x, y| {
        let v = hgt(x as f64, (h - 1 - y) as f64) as f32;
        Rgb([v, v, v])
    });
    let input = d.path("sine.exr");
    img.save(&input).unwrap();
    let out = d.path("n16.png");
    ok(&[
        "normalmap",
        p(&input),
        "-o",
        p(&out),
        "--filter",
        "spectral",
        "--wrap",
        "repeat",
        "--strength",
        "4",
        "--bits",
        "16",
    ]);
    let got = read_rgb16(&out);
    for y in 0..h {
        for x in 0..w {
            let yu = (h - 1 - y) as f64;
            let c = 0.3 * tau * (tau * (fx * x as f64 + fy * yu) + 0.4).cos();
            let n = exact_normal(c * fx, c * fy, 4.0);
            for k in 0..3 {
                let t = (n[k] * 0.5 + 0.5) * 65535.0;
                let g = got.get_pixel(x, y).0[k] as f64;
                assert!((g - t).abs() <= 0.5 + 0.05, "channel {k} at {x},{y}: {g} vs {t}");
            }
        }
    }
}

fn noise(x: u32, y: u32) -> u16 {
    let mut z = (x as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (y as u64).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z ^= z >> 29;
    z = z.wrapping_mul(0x94D0_49BB_1331_11EB);
    (z >> 48) as u16
}

#[test]
fn directx_negates_green_and_nothing_else() {
    let d = Dir::new();
    let input = d.path("noise.png");
    gray16(&input, 19, 13, noise);
    for f in ["sobel", "spectral"] {
        let (gl, dx) = (d.path("gl.png"), d.path("dx.png"));
        ok(&["normalmap", p(&input), "-o", p(&gl), "--filter", f, "--strength", "3"]);
        ok(&["normalmap", p(&input), "-o", p(&dx), "--filter", f, "--strength", "3", "--convention", "directx"]);
        let (gl, dx) = (read_rgb8(&gl), read_rgb8(&dx));
        let mut tilted = 0;
        for (a, b) in gl.pixels().zip(dx.pixels()) {
            assert_eq!((a[0], a[2]), (b[0], b[2]));
            // round(127.5 + 127.5·y) + round(127.5 - 127.5·y) = 255, except at y = 0 (128 both).
            assert!(a[1] as u32 + b[1] as u32 == 255 || (a[1] == 128 && b[1] == 128), "{a:?} {b:?}");
            tilted += (a[1] != 128) as usize;
        }
        assert!(tilted > 100);
    }
}

#[test]
fn repeat_and_clamp_differ_only_near_the_edges() {
    let d = Dir::new();
    let (w, h) = (21u32, 17u32);
    let input = d.path("noise.png");
    gray16(&input, w, h, noise);
    for (f, r) in LOCAL_FILTERS {
        let (a, b) = (d.path("r.png"), d.path("c.png"));
        ok(&["normalmap", p(&input), "-o", p(&a), "--filter", f, "--wrap", "repeat", "--strength", "2"]);
        ok(&["normalmap", p(&input), "-o", p(&b), "--filter", f, "--wrap", "clamp", "--strength", "2"]);
        let (a, b) = (read_rgb8(&a), read_rgb8(&b));
        let r = r as u32;
        let mut edge_diffs = 0;
        for y in 0..h {
            for x in 0..w {
                let interior = x >= r && y >= r && x < w - r && y < h - r;
                if interior {
                    assert_eq!(a.get_pixel(x, y), b.get_pixel(x, y), "{f} at {x},{y}");
                } else {
                    edge_diffs += (a.get_pixel(x, y) != b.get_pixel(x, y)) as usize;
                }
            }
        }
        assert!(edge_diffs > 0, "{f}: the wrap mode must matter at the edge");
    }
}

#[test]
fn tiny_and_odd_sizes_work() {
    let d = Dir::new();
    for (w, h) in [(1u32, 1u32), (1, 7), (7, 1), (13, 7), (2, 2)] {
        let input = d.path("in.png");
        gray8(&input, w, h, |x, y| (x * 40 + y * 25) as u8);
        for f in FILTERS {
            for wrap in ["repeat", "clamp", "mirror"] {
                let out = d.path("out.png");
                ok(&["normalmap", p(&input), "-o", p(&out), "--filter", f, "--wrap", wrap, "--strength", "2"]);
                let img = read_rgb8(&out);
                assert_eq!(img.dimensions(), (w, h));
                if w == 1 {
                    assert!(img.pixels().all(|px| px[0] == 128), "{w}x{h} {f}: no slope across one column");
                }
                if (w, h) == (1, 1) {
                    assert_eq!(img.get_pixel(0, 0).0, [128, 128, 255]);
                }
            }
        }
    }
    // A 1x7 vertical ramp (brighter downwards) tilts every clamp-interior normal towards +y.
    let input = d.path("col.png");
    gray8(&input, 1, 7, |_, y| (y * 30) as u8);
    let out = d.path("col_n.png");
    ok(&["normalmap", p(&input), "-o", p(&out), "--strength", "4"]);
    let n = exact_normal(0.0, -30.0 / 255.0, 4.0);
    let img = read_rgb8(&out);
    for y in 1..6 {
        assert_eq!(img.get_pixel(0, y).0.map(u32::from), [128, code(n[1], 255.0), code(n[2], 255.0)]);
    }
}

#[test]
fn every_pixel_decodes_to_a_unit_vector_with_z_up() {
    let d = Dir::new();
    let input = d.path("noise.png");
    gray16(&input, 23, 18, noise);
    for f in FILTERS {
        for s in ["0.5", "30"] {
            let out = d.path("n.png");
            ok(&["normalmap", p(&input), "-o", p(&out), "--filter", f, "--strength", s]);
            let img = read_rgb8(&out);
            for px in img.pixels() {
                let v: Vec<f64> = px.0.iter().map(|&c| c as f64 / 127.5 - 1.0).collect();
                let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                assert!(v[2] >= 0.0, "{f}: z < 0 in {px:?}");
                assert!((len - 1.0).abs() <= 3f64.sqrt() / 255.0 + 1e-9, "{f}: length {len} in {px:?}");
            }
        }
    }
}

#[test]
fn cliffs_and_extreme_strengths_stay_finite_and_unit() {
    let d = Dir::new();
    let input = d.path("cliff.png");
    gray16(&input, 16, 6, |x, _| if x < 8 { 0 } else { 65535 });
    for f in FILTERS {
        for s in ["1e6", "1e-6", "1"] {
            let out = d.path("n.exr");
            ok(&["normalmap", p(&input), "-o", p(&out), "--filter", f, "--strength", s]);
            let img = image::open(&out).unwrap().into_rgb32f();
            for px in img.pixels() {
                let v: Vec<f32> = px.0.iter().map(|&c| 2.0 * c - 1.0).collect();
                assert!(v.iter().all(|c| c.is_finite()), "{f} {s}: {v:?}");
                let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                assert!((len - 1.0).abs() < 1e-5 && v[2] >= 0.0, "{f} {s}: {v:?}");
            }
        }
    }
    // At 1e6 the texels at the cliff face point almost straight down the slope.
    let out = d.path("n.png");
    ok(&["normalmap", p(&input), "-o", p(&out), "--strength", "1e6", "--filter", "central"]);
    assert_eq!(read_rgb8(&out).get_pixel(7, 2).0, [0, 128, 128]);
}

#[test]
fn output_is_the_same_whatever_the_thread_count() {
    let d = Dir::new();
    let input = d.path("noise.png");
    gray16(&input, 301, 203, noise);
    for f in ["sobel", "central4", "spectral"] {
        let (a, b) = (d.path("a.png"), d.path("b.png"));
        let args = |o: &Path| {
            vec![
                "normalmap".to_string(),
                p(&input).into(),
                "-o".into(),
                p(o).into(),
                "--filter".into(),
                f.into(),
                "--alpha".into(),
                "height".into(),
            ]
        };
        let st = bin().args(args(&a)).env("RAYON_NUM_THREADS", "1").status().unwrap();
        assert!(st.success());
        let st = bin().args(args(&b)).env("RAYON_NUM_THREADS", "3").status().unwrap();
        assert!(st.success());
        assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap(), "{f}");
    }
}

#[test]
fn alpha_holds_the_height_and_invert_flips_the_relief() {
    let d = Dir::new();
    let input = d.path("in.png");
    gray8(&input, 9, 6, |x, y| (x * 20 + y * 7) as u8);
    let (a, b) = (d.path("a.png"), d.path("b.png"));
    ok(&["normalmap", p(&input), "-o", p(&a), "--alpha", "height", "--strength", "5"]);
    ok(&["normalmap", p(&input), "-o", p(&b), "--alpha", "height", "--strength", "5", "--invert"]);
    let (a, b) = (image::open(&a).unwrap().into_rgba8(), image::open(&b).unwrap().into_rgba8());
    for (x, y, px) in a.enumerate_pixels() {
        let h = (x * 20 + y * 7) as u8;
        assert_eq!(px[3], h);
        let q = b.get_pixel(x, y);
        assert_eq!(q[3], 255 - h);
        assert_eq!(q[2], px[2]);
        assert!(px[0] as u32 + q[0] as u32 == 255 || (px[0] == 128 && q[0] == 128));
    }
}

#[test]
fn physical_units_are_a_strength() {
    let d = Dir::new();
    let input = d.path("in.png");
    gray16(&input, 12, 9, noise);
    let (a, b) = (d.path("a.png"), d.path("b.png"));
    ok(&["normalmap", p(&input), "-o", p(&a), "--strength", "20"]);
    ok(&["normalmap", p(&input), "-o", p(&b), "--height-range", "0.02", "--texel-size", "0.001"]);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

#[test]
fn a_chosen_channel_carries_the_height() {
    let d = Dir::new();
    let input = d.path("rgb.png");
    ImageBuffer::from_fn(10, 5, |x, y| Rgb([noise(x, y) as u8, (x * 20) as u8, 200u8])).save(&input).unwrap();
    let out = d.path("n.png");
    ok(&["normalmap", p(&input), "-o", p(&out), "--channel", "g", "--strength", "3"]);
    let n = exact_normal(20.0 / 255.0, 0.0, 3.0);
    let img = read_rgb8(&out);
    for y in 0..5 {
        for x in 1..9 {
            assert_eq!(img.get_pixel(x, y).0.map(u32::from), [code(n[0], 255.0), 128, code(n[2], 255.0)]);
        }
    }
}

fn assert_refused(args: &[&str], file: &Path, needle: &str, not_written: &Path) {
    let out = run(args);
    assert_eq!(out.status.code(), Some(2), "{args:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "one line: {err}");
    assert!(err.starts_with(&format!("bumpbake: {}: ", file.display())), "{err}");
    assert!(err.contains(needle), "{err}");
    assert!(!not_written.exists(), "nothing may be written");
    let leftovers: Vec<_> = std::fs::read_dir(not_written.parent().unwrap())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty());
}

#[test]
fn unusable_input_exits_2_with_one_line_and_writes_nothing() {
    let d = Dir::new();
    let out = d.path("out.png");
    let garbage = d.path("garbage.png");
    std::fs::write(&garbage, b"\x89PNG\r\n\x1a\nthis is not a png").unwrap();
    assert_refused(&["normalmap", p(&garbage), "-o", p(&out)], &garbage, "cannot decode", &out);
    let text = d.path("notes.txt");
    std::fs::write(&text, "hello").unwrap();
    assert_refused(&["normalmap", p(&text), "-o", p(&out)], &text, "not an image in a format bumpbake reads", &out);
    let named = d.path("notes.png");
    std::fs::write(&named, "hello").unwrap();
    assert_refused(&["normalmap", p(&named), "-o", p(&out)], &named, "cannot decode as PNG", &out);
    let missing = d.path("missing.png");
    assert_refused(&["normalmap", p(&missing), "-o", p(&out)], &missing, "cannot open", &out);
    let big = d.path("big.png");
    gray8(&big, 20, 20, |_, _| 0);
    assert_refused(&["normalmap", p(&big), "-o", p(&out), "--max-pixels", "399"], &big, "more than the limit", &out);
    let gray = d.path("gray.png");
    gray8(&gray, 4, 4, |_, _| 9);
    assert_refused(&["normalmap", p(&gray), "-o", p(&out), "--channel", "a"], &gray, "no alpha", &out);
    let jpg = d.path("out.jpg");
    assert_refused(&["normalmap", p(&gray), "-o", p(&jpg)], &jpg, "unsupported output format", &jpg);
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in bytes {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 { 0xEDB8_8320 ^ (c >> 1) } else { c >> 1 };
        }
    }
    !c
}

fn chunk(out: &mut Vec<u8>, kind: &[u8], data: &[u8]) {
    out.extend((data.len() as u32).to_be_bytes());
    let start = out.len();
    out.extend(kind);
    out.extend(data);
    let crc = crc32(&out[start..]);
    out.extend(crc.to_be_bytes());
}

#[test]
fn a_header_claiming_huge_dimensions_is_refused_before_allocating() {
    // A valid PNG header for 100000 x 100000 16-bit gray (20 GB decoded), a token IDAT (a
    // stored deflate block of one zero byte) and IEND: only the header may be believed.
    let d = Dir::new();
    let path = d.path("huge.png");
    let mut f = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend(100_000u32.to_be_bytes());
    ihdr.extend(100_000u32.to_be_bytes());
    ihdr.extend([16, 0, 0, 0, 0]);
    chunk(&mut f, b"IHDR", &ihdr);
    chunk(&mut f, b"IDAT", &[0x78, 0x01, 0x01, 0x01, 0x00, 0xfe, 0xff, 0x00, 0x00, 0x01, 0x00, 0x01]);
    chunk(&mut f, b"IEND", &[]);
    std::fs::write(&path, &f).unwrap();
    let out = d.path("out.png");
    let started = std::time::Instant::now();
    assert_refused(&["normalmap", p(&path), "-o", p(&out)], &path, "100000x100000", &out);
    // Not a timing assertion on the filter: refusing must simply not mean decoding 20 GB.
    assert!(started.elapsed().as_secs() < 60);
}

#[test]
fn help_ends_with_examples() {
    let out = run(&["normalmap", "--help"]);
    let text = String::from_utf8_lossy(&out.stdout);
    let tail: Vec<&str> = text.trim_end().lines().rev().take(4).collect();
    assert!(tail.iter().filter(|l| l.trim_start().starts_with("bumpbake normalmap")).count() >= 3, "{text}");
}

#[test]
fn streamed_png_matches_the_in_memory_encoder_across_strips() {
    // 1500 rows of width 5 make two strips (strips hold at most 1024 rows).
    use bumpbake::normalmap as nm;
    let d = Dir::new();
    let (w, h) = (5u32, 1500u32);
    let input = d.path("tall.png");
    gray16(&input, w, h, noise);
    let plane = nm::load_height(&input, nm::Channel::Luma, nm::DEFAULT_MAX_PIXELS).unwrap();
    for (bits, depth) in [("8", nm::Depth::Bits8), ("16", nm::Depth::Bits16)] {
        for f in ["sobel", "spectral"] {
            let out = d.path("n.png");
            ok(&[
                "normalmap",
                p(&input),
                "-o",
                p(&out),
                "--bits",
                bits,
                "--filter",
                f,
                "--alpha",
                "height",
                "--strength",
                "3",
            ]);
            let filter = if f == "sobel" { nm::Filter::Sobel } else { nm::Filter::Spectral };
            let opts = nm::Options { strength: 3.0, filter, ..Default::default() };
            let enc = nm::EncodeOptions { depth, alpha_height: true, ..Default::default() };
            let want = nm::encode_normals(&plane, &opts, &enc, &bumpbake::progress::Reporter::none());
            let got = nm::load_normal_image(&out, nm::DEFAULT_MAX_PIXELS).unwrap();
            assert_eq!(got, want, "{bits}-bit {f}");
        }
    }
}

#[test]
fn tiff_and_png_inputs_and_outputs_agree() {
    let d = Dir::new();
    let (png_in, tif_in) = (d.path("h.png"), d.path("h.tif"));
    gray16(&png_in, 17, 9, noise);
    gray16(&tif_in, 17, 9, noise);
    let (a, b, c) = (d.path("a.png"), d.path("b.png"), d.path("c.tif"));
    ok(&["normalmap", p(&png_in), "-o", p(&a), "--bits", "16", "--strength", "2"]);
    ok(&["normalmap", p(&tif_in), "-o", p(&b), "--bits", "16", "--strength", "2"]);
    ok(&["normalmap", p(&png_in), "-o", p(&c), "--bits", "16", "--strength", "2"]);
    let (a, b, c) = (read_rgb16(&a), read_rgb16(&b), image::open(&c).unwrap().into_rgb16());
    assert_eq!(a, b);
    assert_eq!(a, c);
}

/// A gentle 16-bit Gaussian bump (sigma 30 texels, heights 0..0.25) at the default strength
/// rounds to the flat texel everywhere: the command warns and names a strength that shows it,
/// and `--help` explains the default in terms of the image.
#[test]
fn a_flat_result_is_warned_about_and_the_default_strength_explained() {
    let d = Dir::new();
    let bump = d.path("bump.png");
    gray16(&bump, 200, 200, |x, y| {
        let r2 = (x as f64 - 100.0).powi(2) + (y as f64 - 100.0).powi(2);
        (0.25 * (-r2 / (2.0 * 30.0 * 30.0)).exp() * 65535.0).round() as u16
    });
    let flat = d.path("flat.png");
    let o = run(&["normalmap", p(&bump), "-o", p(&flat)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let near_flat = |t: &image::Rgb<u8>| t.0[0].abs_diff(128) <= 1 && t.0[1].abs_diff(128) <= 1 && t.0[2] == 255;
    assert!(read_rgb8(&flat).pixels().all(near_flat), "the map is flat to within one step");
    assert!(err.contains("warning") && err.contains("is flat") && err.contains("--strength 110"), "{err}");
    let shown = d.path("shown.png");
    let o = run(&["normalmap", p(&bump), "-o", p(&shown), "--strength", "110"]);
    assert!(o.status.success() && !String::from_utf8_lossy(&o.stderr).contains("warning"));
    let tilted = read_rgb8(&shown).pixels().filter(|t| !near_flat(t)).count();
    assert!(tilted > 200 * 200 / 4, "{tilted} texels show the bump");
    let help = String::from_utf8_lossy(&run(&["normalmap", "--help"]).stdout).to_string();
    assert!(help.contains("black-to-white height range") && help.contains("tilts the normal by only 0.6°"), "{help}");
}
