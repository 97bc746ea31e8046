//! The normal map a material gets: made from a height map with the normalmap command's code, or
//! taken from a given normal map (turned to glTF's +Y-up convention when it is DirectX).

use crate::error::{Error, Result, Setting, Words};
use crate::normalmap::{self, Channel, Convention, EncodeOptions, Filter, Options, PngSettings, Wrap};
use crate::scene::{Scene, Slot};
use std::path::Path;

/// How height maps become normal maps in `bake`.
#[derive(Debug, Clone, Copy)]
pub struct HeightSettings {
    pub strength: f32,
    /// The surface height of `h = 1`, in scene units: the map is made through the mesh
    /// ([`super::surface`]), each texel as large as the mesh lays it out (times `strength` and an
    /// MTL `-bm`). `None`: `strength` texels per unit of `h`, one size for every texel.
    pub height_range: Option<f64>,
    pub filter: Filter,
    pub invert: bool,
    pub channel: Channel,
    pub max_pixels: u64,
    pub sixteen_bit: bool,
}

impl Default for HeightSettings {
    fn default() -> Self {
        HeightSettings {
            strength: 1.0,
            height_range: None,
            filter: Filter::default(),
            invert: false,
            channel: Channel::Luma,
            max_pixels: normalmap::DEFAULT_MAX_PIXELS,
            sixteen_bit: false,
        }
    }
}

/// The wrap mode a material's textures sample with: the sampler of its normal texture, else of
/// its base colour texture, else glTF's default (repeat). A map's filter must wrap the same way.
pub fn material_wrap(scene: &Scene, material: usize) -> Wrap {
    let m = scene.materials().get(material);
    let tex = m.and_then(|m| m.texture(Slot::Normal).or_else(|| m.texture(Slot::BaseColor)));
    match scene.sampler_wrap_s(tex.and_then(|t| t.sampler)) {
        33071 => Wrap::Clamp,
        33648 => Wrap::Mirror,
        _ => Wrap::Repeat,
    }
}

/// A PNG normal map (glTF convention) from a height map file, and a warning when it comes out
/// (nearly) flat.
pub fn from_height(path: &Path, multiplier: f32, wrap: Wrap, s: &HeightSettings) -> Result<(Vec<u8>, Option<String>)> {
    let plane = normalmap::load_height(path, s.channel, s.max_pixels)?;
    let opts = Options { strength: s.strength * multiplier, filter: s.filter, wrap, invert: s.invert };
    let enc = EncodeOptions {
        depth: if s.sixteen_bit { normalmap::Depth::Bits16 } else { normalmap::Depth::Bits8 },
        convention: Convention::Opengl,
        alpha_height: false,
    };
    let img = normalmap::encode_normals(&plane, &opts, &enc, &crate::progress::Reporter::none());
    let warning = normalmap::Flatness::of_image(&img)
        .warning(&plane, opts.strength, multiplier)
        .map(|w| format!("{}: {w}", path.file_name().map(|f| f.to_string_lossy()).unwrap_or_default()));
    let png = normalmap::png_bytes(&img, PngSettings::default()).map_err(|e| Error::output(path, e))?;
    Ok((png, warning))
}

/// A PNG normal map (glTF convention) of a height map file made through the triangles of
/// material `m` where the scene places them ([`super::surface`]): what Cycles' Bump node with
/// Distance `range · strength · multiplier` shows on that mesh. The material's primitives carry
/// tangents already. Also a warning when it comes out (nearly) flat.
pub fn through_mesh(
    scene: &Scene,
    m: usize,
    path: &Path,
    multiplier: f32,
    range: f64,
    s: &HeightSettings,
) -> Result<(Vec<u8>, Option<String>)> {
    use crate::transfer::mesh;
    let plane = normalmap::load_height(path, s.channel, s.max_pixels)?;
    let prims = crate::transfer::material_prims(scene, m);
    // A mesh shown by several nodes has one map for all of them: made in its own units.
    let placed = mesh::place(scene, &prims, None).unwrap_or_else(|_| {
        prims.iter().map(|&prim| mesh::Placed { prim, placement: None, part: String::new() }).collect()
    });
    let part = vec![0; placed.len()];
    let (origin, diagonal) = mesh::frame(scene, &placed)?;
    let low = mesh::low(scene, &placed, &part, origin, diagonal)?;
    let v3 = |v: &[glam::Vec3A]| v.iter().map(|p| p.to_array()).collect::<Vec<[f32; 3]>>();
    let (positions, normals) = (v3(&low.positions), v3(&low.normals));
    let surface = super::surface::SurfaceMesh {
        positions: &positions,
        normals: &normals,
        tangents: &low.tangents,
        uvs: &low.uvs,
        triangles: &low.triangles,
    };
    let distance = range * s.strength as f64 * multiplier as f64;
    let bump = super::surface::Bump {
        distance,
        invert: s.invert,
        filter: s.filter,
        wrap: material_wrap(scene, m),
        ..Default::default()
    };
    let map = super::surface::surface_normals(&surface, &plane, &bump);
    let enc = EncodeOptions {
        depth: if s.sixteen_bit { normalmap::Depth::Bits16 } else { normalmap::Depth::Bits8 },
        convention: Convention::Opengl,
        alpha_height: false,
    };
    let img = normalmap::encode_plane(&map.normals, &enc, None);
    let mut tilt = normalmap::Flatness::default();
    map.normals.data.iter().for_each(|&n| tilt.push(n));
    let warning = (normalmap::Flatness::of_image(&img).verdict() != normalmap::Verdict::Relief).then(|| {
        let name = path.file_name().map(|f| f.to_string_lossy()).unwrap_or_default();
        let deg = tilt.max_tilt_deg();
        if deg == 0.0 {
            return format!("{name}: the height map is flat on the mesh, so the normal map changes nothing");
        }
        // Small tilts grow in proportion to the distance.
        let wanted = range * 30f64.to_radians().tan() / deg.to_radians().tan();
        let w = Words::from(format!("{name}: the normal map is (nearly) flat: its largest tilt is {deg:.2}°; "));
        w.given(Setting::HeightRange, format!("{wanted:.3e}")).text(" would tilt the steepest slope 30°").to_string()
    });
    let png = normalmap::png_bytes(&img, PngSettings::default()).map_err(|e| Error::output(path, e))?;
    Ok((png, warning))
}

/// What bake decided about a given normal map's green channel.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ConventionCheck {
    pub detected: String,
    pub confidence: f64,
    pub converted: bool,
}

/// A given normal map, in glTF's convention. `declared` is what the user said (`None`: trust the
/// detector). A declared convention the detector confidently contradicts is refused.
pub fn from_normal(path: &Path, declared: Option<Convention>, max_pixels: u64) -> Result<(Vec<u8>, ConventionCheck)> {
    let bytes = std::fs::read(path).map_err(|e| Error::input(path, format!("cannot read: {e}")))?;
    let img = normalmap::open_image(path, max_pixels)?;
    let (detected, confidence) = crate::validate::detect_convention(&img.to_rgb8());
    let detected_dx = detected == Some(Convention::Directx);
    let confident = confidence >= crate::validate::REPORT_CONFIDENCE && detected.is_some();
    let is_dx = match declared {
        Some(Convention::Directx) if confident && !detected_dx => {
            return Err(Error::input(
                path,
                format!("declared DirectX (-Y), but the map looks like OpenGL (+Y) (confidence {confidence:.2})"),
            ))
        }
        Some(Convention::Opengl) if confident && detected_dx => {
            let msg = format!(
                "declared OpenGL (+Y), but the map looks like DirectX (-Y) (confidence {confidence:.2}); pass "
            );
            return Err(Error::input(
                path,
                Words::from(msg).given(Setting::Convention, "directx").text(" to convert it"),
            ));
        }
        Some(c) => c == Convention::Directx,
        None => detected_dx && confident,
    };
    let check = ConventionCheck {
        detected: crate::validate::describe_convention(detected).into(),
        confidence,
        converted: is_dx,
    };
    let kind = crate::format::image::Kind::sniff(&bytes);
    let core = matches!(kind, crate::format::image::Kind::Png | crate::format::image::Kind::Jpeg);
    if !is_dx && core {
        // PNG and JPEG are glTF's own image formats: embedded as given, byte for byte.
        return Ok((bytes, check));
    }
    if !is_dx {
        // WebP, TIFF and OpenEXR are not core glTF images: stored as PNG, 16-bit for float maps.
        let img = match img {
            i @ (image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_)) => {
                image::DynamicImage::ImageRgb16(i.to_rgb16())
            }
            i => i,
        };
        return Ok((encode(img).map_err(|e| Error::output(path, e))?, check));
    }
    // Flip green: n.y -> -n.y is c -> max - c exactly, so nothing else moves.
    let out = match img {
        image::DynamicImage::ImageRgb16(mut b) => {
            b.pixels_mut().for_each(|p| p[1] = u16::MAX - p[1]);
            encode(image::DynamicImage::ImageRgb16(b))
        }
        image::DynamicImage::ImageRgba16(mut b) => {
            b.pixels_mut().for_each(|p| p[1] = u16::MAX - p[1]);
            encode(image::DynamicImage::ImageRgba16(b))
        }
        image::DynamicImage::ImageRgba8(mut b) => {
            b.pixels_mut().for_each(|p| p[1] = 255 - p[1]);
            encode(image::DynamicImage::ImageRgba8(b))
        }
        other => {
            let mut b = other.to_rgb8();
            b.pixels_mut().for_each(|p| p[1] = 255 - p[1]);
            encode(image::DynamicImage::ImageRgb8(b))
        }
    }
    .map_err(|e| Error::output(path, e))?;
    Ok((out, check))
}

fn encode(img: image::DynamicImage) -> crate::error::Faulty<Vec<u8>> {
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).map_err(|e| {
        let why = format!("cannot encode as PNG: {e}");
        crate::error::Fault::caused_by(why, e)
    })?;
    Ok(out.into_inner())
}

/// Gives material `m` the normal map in `png` (PNG or JPEG bytes, as a new image and texture)
/// from UV set 0, sampled like its base colour texture.
pub fn attach(scene: &mut Scene, m: usize, png: &[u8], name: &str) {
    let sampler = scene.materials().get(m).and_then(|m| m.texture(Slot::BaseColor)).and_then(|t| t.sampler);
    let jpeg = crate::format::image::Kind::sniff(png) == crate::format::image::Kind::Jpeg;
    let img = scene.push_image(png, if jpeg { "image/jpeg" } else { "image/png" }, Some(name));
    let t = scene.push_texture(img, sampler);
    scene.set_normal_texture(m, t);
}

/// A 1x1 flat normal map.
pub fn flat_png() -> Vec<u8> {
    let img = image::RgbImage::from_pixel(1, 1, image::Rgb([128, 128, 255]));
    encode(image::DynamicImage::ImageRgb8(img)).expect("a 1x1 PNG encodes")
}

/// Puts `png` in place of the image material `m`'s normal texture shows (its name kept).
pub fn replace_normal_image(scene: &mut Scene, m: usize, png: &[u8]) {
    let normal = scene.materials().get(m).and_then(|m| m.texture(Slot::Normal));
    if let Some(img) = normal.and_then(|t| t.image()) {
        scene.replace_image(img, png);
    }
}
