//! A CPU renderer of the reference bump-mapping model (`shaders/` in GLSL), so that "ready for any
//! bump-mapping renderer" can be shown, and measured, without a GPU.
//!
//! Use: [`Prepared::new`] once per scene (normals, tangents, textures settled), a [`Camera`]
//! ([`Camera::framed`] on [`Prepared::bounds`]), then [`render`] as many views as needed.
//! [`render_scene`] does all three for the common case; [`compare::compare`] measures one scene
//! against another from the same camera.
//!
//! - [`camera`]: perspective camera framed on the bounds.
//! - [`gather`]: scene to world-space draws and materials.
//! - [`raster`]: visibility (tiles, depth buffer, perspective-correct barycentrics).
//! - [`lod`]: UV derivatives per screen sample, for the mip level.
//! - [`texture`]: decoding, mip chains and sampling with glTF's sampler rules.
//! - [`shade`]: the seeds' model (tangent-space lighting, Blinn-Phong, lights).
//! - [`pbr`]: glTF's metallic-roughness BRDF (`Shading::Pbr`).
//! - [`views`]: the debug views.
//! - [`compare`]: pipeline error between two renders.
//! - [`file`](mod@file): the `preview` command file to file ([`render_file`], [`compare_files`]) and its
//!   reports.

pub mod camera;
pub mod compare;
pub mod file;
pub mod gather;
pub mod lod;
pub mod pbr;
pub mod raster;
pub mod shade;
pub mod texture;
pub mod views;

pub use camera::{Camera, CameraSpec, Facing};
pub use file::{compare_files, render_file, CameraReport, Compared, Comparing, Rendered, Stages};
pub use gather::Prepared;
pub use shade::{Light, Params, Shading};
pub use texture::Mips;
pub use views::View;

use crate::error::{Result, Setting, Words};
use crate::scene::Scene;
use glam::Vec3;
use rayon::prelude::*;

/// How to render.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel along each axis (box-filtered).
    pub ssaa: u32,
    /// Where textures' mip levels come from.
    pub mips: Mips,
    /// How a physically based pixel averages its samples.
    pub resolve: Resolve,
    pub camera: CameraSpec,
    /// Empty: the camera-relative default rig ([`shade::default_lights`]).
    pub lights: Vec<Light>,
    pub view: View,
    pub params: Params,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            width: 512,
            height: 512,
            ssaa: 1,
            mips: Mips::default(),
            resolve: Resolve::default(),
            camera: CameraSpec::default(),
            lights: Vec::new(),
            view: View::Shaded,
            params: Params::default(),
        }
    }
}

/// How `Shading::Pbr` averages a pixel's samples (the course model always averages display values).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Resolve {
    /// Each sample clamped to what an 8-bit sRGB target stores, then averaged in linear: a GPU's
    /// MSAA resolve of a plain canvas. A highlight brighter than white loses what the clamp cut.
    #[default]
    Clamped,
    /// The samples' linear radiance averaged before the clamp: an HDR target's resolve, and the
    /// mean a prefiltered texture can aim at (docs/preview.md, "The truth's resolve").
    Hdr,
}

/// Largest number of pixels, and of samples in one row of pixels (memory stays around 2 GB at
/// worst).
pub const MAX_SAMPLES: u64 = 1 << 26;
/// Most samples per pixel along each axis: a supersampled truth needs 16 or more.
pub const MAX_SSAA: u32 = 32;
/// Samples resolved at once: larger renders go in bands of rows, so supersampling costs time,
/// not memory.
const BAND_SAMPLES: u64 = 1 << 23;

impl Options {
    /// Checks sizes before any memory is committed to them.
    pub fn check(&self) -> Result<()> {
        if self.width == 0 || self.height == 0 || self.ssaa == 0 || self.ssaa > MAX_SSAA {
            let msg = Words::from("preview: size must be at least 1x1 and ").name(Setting::Ssaa);
            let setting = if self.width == 0 || self.height == 0 { Setting::Size } else { Setting::Ssaa };
            return Err(crate::Error::setting(setting, None, msg.text(format!(" between 1 and {MAX_SSAA}"))));
        }
        self.check_numbers()?;
        let n = self.width as u64 * self.height as u64;
        let row = self.width as u64 * (self.ssaa as u64).pow(2);
        if n > MAX_SAMPLES || row > MAX_SAMPLES {
            let msg =
                Words::from(format!("preview: {}x{} with ", self.width, self.height)).given(Setting::Ssaa, self.ssaa);
            let msg = msg.text(format!(" is {n} pixels and {row} samples a row; the limit is {MAX_SAMPLES}"));
            return Err(crate::Error::setting(Setting::Size, Some(format!("{}x{}", self.width, self.height)), msg));
        }
        Ok(())
    }

    /// The camera's and the shading's numbers: finite, and what each measures can be.
    fn check_numbers(&self) -> Result<()> {
        let (c, p) = (&self.camera, &self.params);
        let d = c.distance.unwrap_or(1.0);
        let numbers = [
            (
                Setting::Fov,
                c.fov,
                c.fov > 0.0 && c.fov < 180.0,
                "is not a usable value: give degrees between 0 and 180",
            ),
            (Setting::Yaw, c.yaw, true, "is not a usable value"),
            (Setting::Pitch, c.pitch, true, "is not a usable value"),
            (Setting::Distance, d, d > 0.0, "must be positive"),
            (Setting::Ambient, p.ambient, p.ambient >= 0.0, "is not a usable value"),
            (Setting::Specular, p.specular, p.specular >= 0.0, "is not a usable value"),
            (Setting::Shininess, p.shininess, p.shininess >= 0.0, "is not a usable value"),
        ];
        for (s, v, ok, why) in numbers {
            if !(v.is_finite() && ok) {
                let msg = Words::from("preview: ").given(s, v).text(format!(" {why}"));
                return Err(crate::Error::setting(s, Some(v.to_string()), msg));
            }
        }
        Ok(())
    }
}

/// A rendered image and what each pixel saw.
#[derive(Debug, Clone)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    /// Display values in `[0, 1]` (sRGB-encoded for the lit views), row-major from the top.
    pub rgb: Vec<[f32; 3]>,
    /// Mean world-space shading normal of the covered samples (zero where none).
    pub normal: Vec<Vec3>,
    /// Fraction of the pixel's samples that hit a surface.
    pub coverage: Vec<f32>,
    /// Mean view depth of the covered samples (infinite where none).
    pub depth: Vec<f32>,
}

impl Frame {
    /// 8-bit RGB, rounded.
    pub fn to_rgb8(&self) -> image::RgbImage {
        let mut img = image::RgbImage::new(self.width, self.height);
        for (p, c) in img.pixels_mut().zip(&self.rgb) {
            *p = image::Rgb(c.map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u8));
        }
        img
    }

    /// PNG bytes.
    pub fn to_png(&self) -> Vec<u8> {
        let mut out = std::io::Cursor::new(Vec::new());
        // Encoding an in-memory RGB8 image cannot fail short of running out of memory.
        let _ = self.to_rgb8().write_to(&mut out, image::ImageFormat::Png);
        out.into_inner()
    }
}

/// Frames the camera on the scene and renders it.
pub fn render_scene(scene: &Scene, opts: &Options) -> Result<Frame> {
    opts.check()?;
    let prep = Prepared::new(scene)?;
    let cam = Camera::framed(prep.bounds, &opts.camera, opts.width, opts.height);
    Ok(render(&prep, &cam, opts))
}

/// Renders a prepared scene from `cam` (its width and height are ignored in favour of `opts`').
pub fn render(prep: &Prepared, cam: &Camera, opts: &Options) -> Frame {
    let ss = opts.ssaa.clamp(1, MAX_SSAA);
    let (sw, sh) = (opts.width * ss, opts.height * ss);
    let lights = if opts.lights.is_empty() { shade::default_lights(cam.eye, cam.target) } else { opts.lights.clone() };
    let prims = raster::setup_all(&prep.draws, &prep.materials, cam, sw, sh);
    let default_material = gather::Material::default();
    // A physically based pixel is the mean radiance of its samples, clamped per sample or after
    // the mean as `opts.resolve` says. The course model keeps its display-value mean, so its
    // images stay as they were.
    let linear = opts.params.shading == Shading::Pbr && matches!(opts.view, View::Shaded | View::Nomap);
    let band = (BAND_SAMPLES / (sw as u64 * ss as u64)).clamp(1, opts.height as u64) as u32;

    let mut px = Vec::with_capacity((opts.width * opts.height) as usize);
    for y0 in (0..opts.height).step_by(band as usize) {
        let y1 = (y0 + band).min(opts.height);
        let samples = raster::resolve(&prims, sw, y0 * ss..y1 * ss);
        // Shade and resolve one output row at a time: its `ss` sample rows are independent of all
        // others, so rows run in parallel and the result does not depend on scheduling.
        let rows: Vec<Vec<(Vec3, Vec3, f32, f32)>> = (y0..y1)
            .into_par_iter()
            .map(|y| {
                let mut row = Vec::with_capacity(opts.width as usize);
                for x in 0..opts.width {
                    let (mut rgb, mut nrm, mut hit, mut depth) = (Vec3::ZERO, Vec3::ZERO, 0u32, 0.0f32);
                    for sy in 0..ss {
                        for sx in 0..ss {
                            let s = samples[(((y - y0) * ss + sy) * sw + x * ss + sx) as usize];
                            if s.prim == raster::EMPTY {
                                rgb += match linear {
                                    true => Vec3::from(views::BACKGROUND.map(texture::srgb_to_linear)),
                                    false => Vec3::from(views::BACKGROUND),
                                };
                                continue;
                            }
                            let p = &prims[s.prim as usize];
                            let d = &prep.draws[p.draw as usize];
                            let tri = d.triangles[p.tri as usize];
                            let f = shade::Fragment {
                                draw: d,
                                material: prep.materials.get(d.material).unwrap_or(&default_material),
                                tri,
                                bary: p.whole_bary(s.b),
                                back: p.back,
                                duv: lod::footprints(p, d, tri, &s),
                                mips: opts.mips,
                            };
                            let out = views::shade(opts.view, &f, cam.eye, &lights, &opts.params);
                            rgb += match (linear, out.radiance) {
                                (true, Some(r)) if opts.resolve == Resolve::Hdr => r,
                                (true, _) => Vec3::from(out.color.map(texture::srgb_to_linear)),
                                (false, _) => Vec3::from(out.color),
                            };
                            nrm += out.normal;
                            hit += 1;
                            depth += s.depth;
                        }
                    }
                    let n = (ss * ss) as f32;
                    let cov = hit as f32 / n;
                    let depth = if hit > 0 { depth / hit as f32 } else { f32::INFINITY };
                    let rgb = match linear {
                        true => (rgb / n).to_array().map(texture::linear_to_srgb).into(),
                        false => rgb / n,
                    };
                    row.push((rgb, nrm.normalize_or_zero(), cov, depth));
                }
                row
            })
            .collect();
        px.extend(rows.into_iter().flatten());
    }
    let mut frame = Frame {
        width: opts.width,
        height: opts.height,
        rgb: Vec::new(),
        normal: Vec::new(),
        coverage: Vec::new(),
        depth: Vec::new(),
    };
    for (c, n, cov, d) in px {
        frame.rgb.push(c.to_array());
        frame.normal.push(n);
        frame.coverage.push(cov);
        frame.depth.push(d);
    }
    frame
}
