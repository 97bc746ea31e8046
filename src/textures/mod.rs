//! Textures that ship: every material's normal texture re-encoded as KTX2 (`KHR_texture_basisu`)
//! with a mip chain averaged from the full-resolution normals, and, with specular antialiasing,
//! a metallic-roughness texture whose roughness levels carry what the normal levels lost
//! ([`crate::normalmap::specular_aa`]). Every other texture is left as it was.
//!
//! `bake --textures ktx2` runs [`encode_ktx2`] on its scene before writing; `bumpbake textures` runs
//! [`run`] on files other tools wrote.

pub mod roughness;

use crate::error::{Error, Result, Setting, Words};
use crate::format::image::ktx2::{self, Codec, Level};
use crate::format::image::{self as img, Kind};
use crate::format::{self, WriteOptions, WriteStats};
use crate::normalmap::mips::{self, MipLevel};
use crate::normalmap::specular_aa::{RoughnessAdded, DEFAULT_THRESHOLD};
use crate::normalmap::{measure, LevelError, DEFAULT_UASTC_LEVEL};
use crate::scene::leave_out::Removal;
use crate::scene::material::TextureUse;
use crate::scene::{ReadOptions, Scene, Slot};
use crate::timings::Timings;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// How [`encode_ktx2`] encodes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EncodeOptions {
    /// The normal maps' codec.
    pub codec: Codec,
    /// Keep the PNG/JPEG as each texture's core `source`, for clients without KTX2: the
    /// extension is then used but not required.
    pub fallback: bool,
    /// Widen each roughness level by the variance its normal level lost.
    pub specular_aa: bool,
    /// The widening's cap (`min(2 * variance, threshold^2)`).
    pub threshold: f32,
}

impl Default for EncodeOptions {
    fn default() -> Self {
        EncodeOptions {
            codec: Codec::Uastc { level: DEFAULT_UASTC_LEVEL, rdo: None },
            fallback: false,
            specular_aa: true,
            threshold: DEFAULT_THRESHOLD,
        }
    }
}

impl EncodeOptions {
    /// Refuses a codec setting the encoder does not have, or a threshold outside 0 to 1.
    pub fn check(&self) -> Result<()> {
        self.codec.check()?;
        if !(0.0..=1.0).contains(&self.threshold) {
            let s = Setting::SpecularAaThreshold;
            let msg = Words::new().given(s, self.threshold).text(": give a number from 0 to 1");
            return Err(Error::setting(s, Some(self.threshold.to_string()), msg));
        }
        Ok(())
    }
}

/// The roughness texture one material got.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RoughnessReport {
    /// The roughness factor moved into the texture (the material's is 1 now).
    pub roughness_factor: f32,
    /// Whether the material had a metallic-roughness texture (else: factors only).
    pub from_texture: bool,
    pub added: Vec<RoughnessAdded>,
    pub bytes: usize,
}

/// What one material's textures became.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MaterialTextures {
    pub material: usize,
    pub name: Option<String>,
    pub width: usize,
    pub height: usize,
    /// The normal map's levels against the averaged full-resolution normals.
    pub levels: Vec<LevelError>,
    /// The normal map's KTX2 bytes (shared with other materials showing the same image).
    pub bytes: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub roughness: Option<RoughnessReport>,
}

/// What [`encode_ktx2`] did.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct TexturesReport {
    /// `uastc level N` or `etc1s quality N`.
    pub codec: String,
    pub fallback: bool,
    pub specular_aa: bool,
    pub threshold: f32,
    pub materials: Vec<MaterialTextures>,
    /// Normal images encoded (each once, however many materials show it).
    pub normal_maps: usize,
    pub ktx2_bytes: usize,
    /// Textures and images nothing shows any more.
    pub removed: Vec<Removal>,
    pub notes: Vec<String>,
}

fn codec_words(c: Codec) -> String {
    match c {
        Codec::Uastc { level, .. } => format!("uastc level {level}"),
        Codec::Etc1s { quality } => format!("etc1s quality {quality}"),
    }
}

/// A normal image encoded once.
struct Encoded {
    image: usize,
    mips: Vec<MipLevel>,
    levels: Vec<LevelError>,
    bytes: usize,
}

/// The KTX2 of RGB8 `levels` (width, height, texels).
fn ktx2_of(levels: &[(usize, usize, &[u8])], codec: Codec) -> crate::error::Faulty<Vec<u8>> {
    let input: Vec<Level> =
        levels.iter().map(|&(w, h, rgb)| Level { width: w as u32, height: h as u32, rgb }).collect();
    ktx2::encode(&input, codec, rayon::current_num_threads() as u32)
}

/// [`ktx2_of`], its failure named by the scene's file.
fn encode_levels(scene: &Scene, levels: &[(usize, usize, &[u8])], codec: Codec) -> Result<Vec<u8>> {
    ktx2_of(levels, codec).map_err(|e| Error::in_file(&scene.source, e))
}

/// The first of the texture's images bumpbake decodes, its plain `source` first: a PNG holds
/// the map as drawn, a KTX2 already shipped only its lossy copy.
fn decodable(scene: &Scene, t: &TextureUse) -> Result<Option<(usize, Vec<u8>)>> {
    for i in &t.images {
        let bytes = scene.image_bytes(i.image)?;
        if img::not_decoded_why(&bytes).is_none() {
            return Ok(Some((i.image, bytes)));
        }
    }
    Ok(None)
}

fn decode(scene: &Scene, image: usize, bytes: &[u8]) -> Result<image::DynamicImage> {
    img::decode(bytes).map_err(|e| Error::in_file(&scene.source, e.at(format!("image {image}"))))
}

fn encode_normal(scene: &mut Scene, image: usize, bytes: &[u8], codec: Codec) -> Result<Encoded> {
    let rgb = decode(scene, image, bytes)?.to_rgb8();
    let (w, h) = (rgb.width() as usize, rgb.height() as usize);
    let chain = mips::build_rgb(rgb.as_raw(), w, h);
    let levels: Vec<(usize, usize, &[u8])> = chain.iter().map(|l| (l.width, l.height, l.rgb.as_slice())).collect();
    let ktx = encode_levels(scene, &levels, codec)?;
    let errors = measure(&ktx, &chain).map_err(|e| Error::in_file(&scene.source, e))?;
    let name = scene.image_label(image);
    let bytes = ktx.len();
    let image = scene.push_image(&ktx, "image/ktx2", name.as_deref());
    Ok(Encoded { image, mips: chain, levels: errors, bytes })
}

/// Re-encodes every material's normal texture as KTX2 and, with `opts.specular_aa`, gives it a
/// widened metallic-roughness texture. Textures and images only these used are dropped.
pub fn encode_ktx2(scene: &mut Scene, opts: &EncodeOptions) -> Result<TexturesReport> {
    opts.check()?;
    let mut report = TexturesReport {
        codec: codec_words(opts.codec),
        fallback: opts.fallback,
        specular_aa: opts.specular_aa,
        threshold: opts.threshold,
        ..Default::default()
    };
    let normals: Vec<(usize, Option<String>, TextureUse)> = scene
        .materials()
        .list
        .iter()
        .filter_map(|m| m.texture(Slot::Normal).map(|t| (m.index, m.name.clone(), t.clone())))
        .collect();
    let mut encoded: BTreeMap<usize, Encoded> = BTreeMap::new();
    // Old texture -> the texture that shows the KTX2 in its place.
    let mut shipped: BTreeMap<usize, usize> = BTreeMap::new();
    let (mut replaced_textures, mut replaced_images) = (Vec::new(), Vec::new());
    let mut required = false;
    for (m, name, n) in &normals {
        let Some((image, bytes)) = decodable(scene, n)? else {
            report
                .notes
                .push(format!("material {m}: its normal texture has no image bumpbake decodes; left as it was"));
            continue;
        };
        if let std::collections::btree_map::Entry::Vacant(slot) = encoded.entry(image) {
            let e = encode_normal(scene, image, &bytes, opts.codec)?;
            report.ktx2_bytes += e.bytes;
            slot.insert(e);
        }
        let e = &encoded[&image];
        let t = match shipped.get(&n.texture) {
            Some(&t) => t,
            None => {
                let readers: Vec<(usize, String)> = normals
                    .iter()
                    .filter(|(_, _, u)| u.texture == n.texture)
                    .map(|(m, _, u)| (*m, u.pointer.clone()))
                    .collect();
                // A texture another slot reads too stays as it is for that slot.
                let t = if scene.texture_read_elsewhere(n.texture, &readers) {
                    scene.copy_texture(n.texture)
                } else {
                    n.texture
                };
                let keep = opts.fallback && core_fallback(scene, n);
                required |= !keep;
                scene.set_basisu_source(t, e.image, keep);
                replaced_images.extend(n.images.iter().map(|i| i.image));
                shipped.insert(n.texture, t);
                t
            }
        };
        if t != n.texture {
            scene.set_texture_index(*m, &n.pointer, t);
        }
        let (width, height) = (e.mips[0].width, e.mips[0].height);
        let mut mt = MaterialTextures {
            material: *m,
            name: name.clone(),
            width,
            height,
            levels: e.levels.clone(),
            bytes: e.bytes,
            roughness: None,
        };
        if opts.specular_aa {
            let mips = &encoded[&image].mips;
            match roughness::widen_material(scene, *m, n, mips, opts)? {
                Ok(r) => {
                    report.ktx2_bytes += r.report.bytes;
                    required |= !opts.fallback;
                    replaced_textures.extend(r.old_texture);
                    replaced_images.extend(r.old_images);
                    mt.roughness = Some(r.report);
                }
                Err(why) => report.notes.push(format!("material {m}: no specular antialiasing: {why}")),
            }
        }
        report.materials.push(mt);
    }
    report.normal_maps = encoded.len();
    if !encoded.is_empty() {
        scene.use_basisu(required);
        scene.forget_unused_image_extensions();
    }
    replaced_images.sort_unstable();
    replaced_images.dedup();
    report.removed = scene.drop_replaced(&replaced_textures, &replaced_images);
    Ok(report)
}

/// Whether the texture's core `source` is a PNG or JPEG a client without KTX2 can show.
fn core_fallback(scene: &Scene, n: &TextureUse) -> bool {
    n.images
        .iter()
        .filter(|i| i.via == "source")
        .any(|i| scene.image_bytes(i.image).is_ok_and(|b| matches!(Kind::sniff(&b), Kind::Png | Kind::Jpeg)))
}

/// `bumpbake textures`: one file read, shipped, written.
#[derive(Debug, Clone, Default)]
pub struct TexturesJob {
    pub input: PathBuf,
    pub output: PathBuf,
    pub options: EncodeOptions,
    pub read: ReadOptions,
    pub write: WriteOptions,
    pub depfile: Option<PathBuf>,
}

/// What `bumpbake textures` did to one file.
#[derive(Debug, Clone, Serialize)]
pub struct TexturesRun {
    pub input: PathBuf,
    pub output: PathBuf,
    #[serde(flatten)]
    pub textures: TexturesReport,
    pub written: WriteStats,
    pub timings_ms: Timings,
}

pub fn run(job: &TexturesJob) -> Result<TexturesRun> {
    job.options.check()?;
    let mut t = Timings::default();
    let mut scene = t.time("read", || crate::format::read(&job.input, &job.read))?;
    let deps = scene.dependencies();
    let textures = t.time("textures", || encode_ktx2(&mut scene, &job.options))?;
    let (mut files, written) = t.time("encode", || format::write(&scene, &job.output, &job.write))?;
    if let Some(d) = &job.depfile {
        files.add(d, crate::output::depfile(&[&job.output], &deps));
    }
    t.time("write", || files.commit())?;
    Ok(TexturesRun { input: job.input.clone(), output: job.output.clone(), textures, written, timings_ms: t })
}
