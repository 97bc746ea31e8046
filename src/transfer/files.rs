//! The files a bake writes besides OUT: the map itself (PNG, TIFF or EXR), the height map and the
//! miss mask, one set per material, named after it when there are several.

use super::tracer::Texel;
use super::{dither, Settings};
use crate::error::{Error, Result};
use crate::normalmap::{self, Convention, Depth, NormalData, NormalImage, PngSettings};
use crate::scene::Scene;
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// A material's name as it can stand in a file name: letters, digits, `-` and `_`.
pub fn file_label(name: Option<&str>, m: usize) -> String {
    let clean: String =
        name.unwrap_or("").chars().map(|c| if c.is_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect();
    if clean.trim_matches('_').is_empty() {
        format!("material{m}")
    } else {
        clean
    }
}

/// `dir/stem.ext` as `dir/stem_label.ext`.
pub(super) fn labelled(p: &Path, label: &str) -> PathBuf {
    let stem = p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let name = match p.extension() {
        Some(e) => format!("{stem}_{label}.{}", e.to_string_lossy()),
        None => format!("{stem}_{label}"),
    };
    p.with_file_name(name)
}

/// Each material's file label, made unique by its index where two would be the same.
pub(super) fn unique_labels(scene: &Scene, materials: &[usize]) -> Vec<String> {
    let names = scene.materials();
    let labels: Vec<String> =
        materials.iter().map(|&m| file_label(names.get(m).and_then(|x| x.name.as_deref()), m)).collect();
    labels
        .iter()
        .zip(materials)
        .map(|(l, m)| if labels.iter().filter(|x| *x == l).count() > 1 { format!("{l}_{m}") } else { l.clone() })
        .collect()
}

/// The map as PNG (glTF convention), and the extra files asked for.
#[allow(clippy::type_complexity)]
pub(super) fn encode(
    s: &Settings,
    texels: &[Texel],
    n: &[[f32; 3]],
) -> Result<(Vec<u8>, Vec<(PathBuf, Vec<u8>)>, Option<[f32; 2]>)> {
    let (w, h) = (s.width, s.height);
    let img = |depth: Depth, dx: bool| {
        let ny = |v: f32| if dx { -v } else { v };
        let data = match depth {
            // On every core: a 2048² map is 4M texels.
            Depth::Bits8 if s.dither => NormalData::U8(
                n.par_iter()
                    .enumerate()
                    .map(|(i, v)| {
                        let (x, y) = ((i % w) as u32, (i / w) as u32);
                        let c = [v[0], ny(v[1]), v[2]];
                        [0, 1, 2].map(|k| dither::quantize8(c[k], dither::noise(x, y, k as u32)))
                    })
                    .collect::<Vec<_>>()
                    .into_flattened(),
            ),
            Depth::Bits8 => NormalData::U8(
                n.par_iter()
                    .map(|v| [v[0], ny(v[1]), v[2]].map(normalmap::quantize8))
                    .collect::<Vec<_>>()
                    .into_flattened(),
            ),
            Depth::Bits16 => NormalData::U16(
                n.par_iter()
                    .map(|v| [v[0], ny(v[1]), v[2]].map(normalmap::quantize16))
                    .collect::<Vec<_>>()
                    .into_flattened(),
            ),
            Depth::Float => NormalData::F32(n.iter().flat_map(|v| [v[0], ny(v[1]), v[2]]).collect()),
        };
        NormalImage { width: w, height: h, channels: 3, data }
    };
    let depth = if s.sixteen_bit { Depth::Bits16 } else { Depth::Bits8 };
    let png =
        normalmap::png_bytes(&img(depth, false), PngSettings::default()).map_err(|e| Error::usage(e.to_string()))?;
    let mut files = Vec::new();
    if let Some(p) = &s.map_out {
        let format = normalmap::OutputFormat::from_path(p)?;
        let d = if format == normalmap::OutputFormat::Exr { Depth::Float } else { depth };
        let bytes =
            normalmap::image_bytes(&img(d, s.convention == Convention::Directx), format, PngSettings::default())
                .map_err(|e| Error::output(p, e))?;
        files.push((p.clone(), bytes));
    }
    // On every core, without a copy of the heights: blocks of a fixed size, joined in order, so
    // the range is the same on any thread count.
    let join = |r: Option<[f32; 2]>, x: Option<[f32; 2]>| match (r, x) {
        (Some([a, b]), Some([c, d])) => Some([a.min(c), b.max(d)]),
        (r, x) => r.or(x),
    };
    let range = texels
        .par_chunks(1 << 16)
        .map(|c| c.iter().filter(|x| x.hits > 0).map(|x| Some([x.height; 2])).fold(None, join))
        .collect::<Vec<_>>()
        .into_iter()
        .fold(None, join);
    if let Some(p) = &s.height_out {
        let [lo, hi] = range.unwrap_or([0.0, 0.0]);
        let span = if hi > lo { hi - lo } else { 1.0 };
        let v: Vec<u16> = texels
            .iter()
            .map(|x| {
                let d = if x.hits > 0 { x.height } else { 0.0 };
                (((d - lo) / span).clamp(0.0, 1.0) * 65535.0).round() as u16
            })
            .collect();
        let img = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_raw(w as u32, h as u32, v).expect("sized");
        files.push((p.clone(), png_of(image::DynamicImage::ImageLuma16(img), p)?));
    }
    if let Some(p) = &s.miss_mask {
        let v: Vec<u8> = texels
            .iter()
            .map(|x| if x.samples == 0 { 0 } else { ((x.missed as f32 / x.samples as f32) * 255.0).round() as u8 })
            .collect();
        let img = image::GrayImage::from_raw(w as u32, h as u32, v).expect("sized");
        files.push((p.clone(), png_of(image::DynamicImage::ImageLuma8(img), p)?));
    }
    Ok((png, files, range))
}

fn png_of(img: image::DynamicImage, path: &std::path::Path) -> Result<Vec<u8>> {
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).map_err(|e| Error::output(path, e))?;
    Ok(out.into_inner())
}
