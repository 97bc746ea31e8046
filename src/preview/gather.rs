//! Turns a [`Scene`] into what the rasteriser draws: world-space triangle lists with complete
//! vertex frames, and materials with decoded textures.
//!
//! Everything a renderer would otherwise have to guess is settled here, the way the conventions
//! say a client should: missing normals become flat normals, missing tangents become MikkTSpace
//! tangents (the same code and the same UVs `bumpbake tangents` uses), and a node transform that
//! mirrors flips both the winding and `w`, so that `B = cross(N, T) * w` still points where the
//! texture's +v-up axis lies on the surface. What the values are, which UVs the frames follow and
//! where each primitive is shown come from the scene's view ([`crate::scene::view`]).

use super::texture::{Footprint, Mips, Sampler, Texture};
use crate::error::Result;
use crate::scene::material::{MaterialInfo, TextureUse};
use crate::scene::nodes::{instances, Instance};
use crate::scene::view::views;
use crate::scene::{flat_normals, Geometry, Materials, PrimRef, PrimView, Scene, Slot, UvSource, UvTransform};
use glam::{Vec2, Vec3, Vec4};
use std::collections::HashMap;
use std::sync::Arc;

/// A texture as a material uses it.
#[derive(Debug, Clone)]
pub struct TexRef {
    pub texture: Arc<Texture>,
    pub sampler: Sampler,
    /// Which UV set: 0 for `TEXCOORD_0`, 1 for `TEXCOORD_1`.
    pub texcoord: u32,
    /// `KHR_texture_transform`, applied to the interpolated UV (it is affine, so that is the same
    /// as interpolating transformed UVs).
    pub transform: Option<UvTransform>,
}

impl TexRef {
    /// The UV this texture is sampled at, from the interpolated UV sets.
    pub fn uv(&self, sets: &[Vec2; 2]) -> Vec2 {
        let uv = sets[self.texcoord as usize];
        match &self.transform {
            Some(t) => Vec2::from(t.apply(uv.to_array())),
            None => uv,
        }
    }

    /// Samples the texture at a fragment: `sets` the interpolated UV sets, `duv` their
    /// derivatives per screen sample.
    pub fn sample(&self, sets: &[Vec2; 2], duv: &[Footprint; 2], mips: Mips) -> Vec4 {
        let uv = self.uv(sets);
        let d = duv[self.texcoord as usize];
        // The transform is affine: its linear part carries the derivatives.
        let f = match &self.transform {
            Some(t) => {
                let at = |x: Vec2| Vec2::from(t.apply(x.to_array()));
                let o = at(Vec2::ZERO);
                Footprint { dx: at(d.dx) - o, dy: at(d.dy) - o }
            }
            None => d,
        };
        self.texture.sample_lod(&self.sampler, uv, &f, mips)
    }
}

/// The parts of a glTF material the seeds' shading model uses.
#[derive(Debug, Clone)]
pub struct Material {
    pub base_color: Vec4,
    pub base_texture: Option<TexRef>,
    pub normal_texture: Option<TexRef>,
    /// `normalTexture.scale`: multiplies the decoded x and y.
    pub normal_scale: f32,
    /// `metallicRoughnessTexture`: roughness in G, metalness in B.
    pub metal_rough_texture: Option<TexRef>,
    pub metallic: f32,
    pub roughness: f32,
    pub double_sided: bool,
}

impl Default for Material {
    fn default() -> Self {
        Material {
            base_color: Vec4::ONE,
            base_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            metal_rough_texture: None,
            // glTF's defaults for both factors.
            metallic: 1.0,
            roughness: 1.0,
            double_sided: false,
        }
    }
}

/// One primitive placed in the world: the rasteriser's unit of work.
#[derive(Debug, Clone)]
pub struct Draw {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    /// World-space unit tangent and handedness `w` (±1).
    pub tangents: Vec<Vec4>,
    /// UV sets 0 and 1 in glTF's convention (v down); set 1 is empty when absent.
    pub uvs: [Vec<Vec2>; 2],
    pub triangles: Vec<[u32; 3]>,
    pub material: usize,
    /// Where the primitive came from, for messages.
    pub source: PrimRef,
}

/// A scene made ready to draw any number of times from any camera.
#[derive(Debug, Clone)]
pub struct Prepared {
    pub draws: Vec<Draw>,
    pub materials: Vec<Material>,
    /// World-space bounds of everything drawn.
    pub bounds: (Vec3, Vec3),
    /// What was substituted or skipped, for the report.
    pub notes: Vec<String>,
}

impl Prepared {
    /// Reads every triangle primitive the scene shows (its default scene's node trees, or every
    /// mesh when there are no nodes). Fails on a scene with nothing to draw.
    ///
    /// Primitives without TANGENT get MikkTSpace tangents only where a normal map needs them:
    /// without a map any frame lights the same, and generating frames costs more than drawing.
    pub fn new(scene: &Scene) -> Result<Prepared> {
        Prepared::with_frames(scene, false)
    }

    /// [`Prepared::new`], and `all_frames` also generates MikkTSpace tangents for primitives
    /// whose material has no normal map (for the tangent, bitangent and handedness views).
    pub fn with_frames(scene: &Scene, all_frames: bool) -> Result<Prepared> {
        let mut gatherer = Gatherer {
            scene,
            mats: scene.materials().clone(),
            all_frames,
            textures: HashMap::new(),
            materials: Vec::new(),
            material_index: HashMap::new(),
            notes: Vec::new(),
        };
        let views = views(scene, &gatherer.mats);
        let mut of_mesh: HashMap<usize, Vec<&PrimView>> = HashMap::new();
        views.iter().for_each(|v| of_mesh.entry(v.at.mesh).or_default().push(v));
        let mut draws = Vec::new();
        let mut prim_cache: HashMap<PrimRef, Option<Local>> = HashMap::new();
        for inst in instances(scene) {
            for &view in of_mesh.get(&inst.mesh).into_iter().flatten() {
                let r = view.at;
                if let std::collections::hash_map::Entry::Vacant(e) = prim_cache.entry(r) {
                    let local = gatherer.local(view)?;
                    e.insert(local);
                }
                if let Some(Some(local)) = prim_cache.get(&r) {
                    let material = gatherer.material(r)?;
                    draws.push(place(local, &inst, material, r));
                }
            }
        }
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for d in &draws {
            for t in &d.triangles {
                for &i in t {
                    let p = d.positions[i as usize];
                    if p.is_finite() {
                        lo = lo.min(p);
                        hi = hi.max(p);
                    }
                }
            }
        }
        if !(lo.is_finite() && hi.is_finite()) {
            return Err(scene.err("nothing to draw: the scene shows no triangles"));
        }
        Ok(Prepared { draws, materials: gatherer.materials, bounds: (lo, hi), notes: gatherer.notes })
    }

    /// The sum of every drawn triangle's normal by winding, weighted by area: which way the
    /// faces look, on the whole.
    pub fn face_normal(&self) -> Vec3 {
        let mut sum = Vec3::ZERO;
        for d in &self.draws {
            for t in &d.triangles {
                let [a, b, c] = t.map(|i| d.positions[i as usize]);
                let n = (b - a).cross(c - a);
                if n.is_finite() {
                    sum += n;
                }
            }
        }
        sum
    }

    pub fn triangle_count(&self) -> usize {
        self.draws.iter().map(|d| d.triangles.len()).sum()
    }
}

/// A primitive in its mesh's own space, with every attribute the renderer needs.
#[derive(Debug, Clone)]
struct Local {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    tangents: Vec<Vec4>,
    uvs: [Vec<Vec2>; 2],
    triangles: Vec<[u32; 3]>,
}

/// What gathering a scene keeps as it goes: each texture and material decoded once, and the notes
/// on what was not drawn.
struct Gatherer<'a> {
    scene: &'a Scene,
    mats: Materials,
    all_frames: bool,
    textures: HashMap<(usize, bool), Arc<Texture>>,
    materials: Vec<Material>,
    material_index: HashMap<Option<usize>, usize>,
    notes: Vec<String>,
}

impl Gatherer<'_> {
    fn local(&mut self, view: &PrimView) -> Result<Option<Local>> {
        let s = self.scene;
        let r = view.at;
        let where_ = format!("mesh {} primitive {}", r.mesh, r.primitive);
        // Strips and fans are drawn as the triangles they make, as `tangents` processes them.
        if !view.mode.has_triangles() {
            self.notes.push(format!("{where_}: mode {} draws no triangles; not drawn", view.mode));
            return Ok(None);
        }
        let mut g = view.read(s)?;
        if g.primitive.attr("POSITION").is_none() {
            self.notes.push(format!("{where_}: no POSITION; not drawn"));
            return Ok(None);
        }
        // Frames are made where the material drawn (the primitive's own) needs them, from the UVs
        // `bumpbake tangents` would use.
        let uvs = view.tangent_uvs();
        let has_map = view.own_material_needs_tangents();
        let tangents_ok = g.primitive.attr("TANGENT").map(|t| t.format.components() == 4).unwrap_or(false);
        if !tangents_ok
            && (has_map || self.all_frames)
            && g.primitive.attr(&uvs.attribute()).is_some()
            && g.primitive.indices.len() >= 3
        {
            // Exactly what `bumpbake tangents` would store, so the preview shows the tool's frames.
            g = Geometry::new(crate::tangent::with_frames(g, &Default::default()).0, uvs);
            if has_map {
                self.notes
                    .push(format!("{where_}: no TANGENT; drew it with MikkTSpace tangents from TEXCOORD_{}", uvs.set));
            }
        }
        let mut positions: Vec<Vec3> = g.positions().iter().map(|&p| Vec3::from(p)).collect();
        let mut normals: Option<Vec<Vec3>> = g.normals().map(|n| n.iter().map(|&v| Vec3::from(v)).collect());
        let vec4 = g.primitive.attr("TANGENT").is_some_and(|t| t.format.components() == 4);
        let mut tangents: Option<Vec<Vec4>> =
            g.tangents().filter(|_| vec4).map(|t| t.into_iter().map(Vec4::from).collect());
        let uv = |k: u32| -> Vec<Vec2> {
            g.uvs(UvSource { set: k, transform: None })
                .map(|t| t.iter().map(|&v| Vec2::from(v)).collect())
                .unwrap_or_default()
        };
        let mut uvs = [uv(0), uv(1)];
        let mut indices = g.primitive.indices.clone();
        indices.truncate(indices.len() / 3 * 3);

        if normals.is_none() {
            // glTF: a client must use flat normals, so every corner becomes its own vertex.
            let corner_pos: Vec<[f32; 3]> = indices.iter().map(|&i| positions[i as usize].to_array()).collect();
            let (n, _) = flat_normals(&corner_pos);
            let gather3 = |v: &Vec<Vec2>| {
                if v.is_empty() {
                    Vec::new()
                } else {
                    indices.iter().map(|&i| v[i as usize]).collect()
                }
            };
            uvs = [gather3(&uvs[0]), gather3(&uvs[1])];
            tangents = tangents.map(|t| indices.iter().map(|&i| t[i as usize]).collect());
            positions = corner_pos.into_iter().map(Vec3::from).collect();
            normals = Some(n.into_iter().map(Vec3::from).collect());
            indices = (0..positions.len() as u32).collect();
        }
        let normals: Vec<Vec3> = normals.unwrap_or_default().into_iter().map(|n| unit_or(n, Vec3::Z)).collect();
        let tangents: Vec<Vec4> = match tangents {
            Some(t) => t.into_iter().zip(&normals).map(|(t, &n)| sane_tangent(t, n)).collect(),
            None => normals.iter().map(|&n| sane_tangent(Vec4::ZERO, n)).collect(),
        };
        for u in uvs.iter_mut() {
            if u.len() != positions.len() {
                u.clear();
            }
        }
        let triangles = indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
        Ok(Some(Local { positions, normals, tangents, uvs, triangles }))
    }

    fn material(&mut self, r: PrimRef) -> Result<usize> {
        let idx = self.mats.default_of(self.scene, r).map(|m| m.index);
        if let Some(&i) = self.material_index.get(&idx) {
            return Ok(i);
        }
        let m = match idx.and_then(|i| self.mats.get(i)).cloned() {
            Some(info) => self.read_material(&info)?,
            None => Material::default(),
        };
        self.materials.push(m);
        let i = self.materials.len() - 1;
        self.material_index.insert(idx, i);
        Ok(i)
    }

    fn read_material(&mut self, info: &MaterialInfo) -> Result<Material> {
        let mut m = Material::default();
        if let Some(c) = info.base_color_factor.filter(|c| c.iter().all(|x| x.is_finite())) {
            m.base_color = Vec4::from_array(c);
        }
        if let Some(t) = info.texture(Slot::BaseColor) {
            m.base_texture = self.tex_ref(t, true)?;
        }
        if let Some(t) = info.texture(Slot::Normal) {
            m.normal_texture = self.tex_ref(t, false)?;
            m.normal_scale = t.scale.unwrap_or(1.0) as f32;
        }
        if let Some(t) = info.texture(Slot::MetallicRoughness) {
            // Only PBR shading reads it: an image it cannot use must not stop the other views.
            m.metal_rough_texture = self.tex_ref(t, false).unwrap_or_else(|e| {
                self.notes.push(format!("{}: metallicRoughnessTexture not used: {e}", info.label()));
                None
            });
        }
        m.metallic = info.metallic_factor.filter(|f| f.is_finite()).unwrap_or(1.0).clamp(0.0, 1.0);
        m.roughness = info.roughness_factor.filter(|f| f.is_finite()).unwrap_or(1.0).clamp(0.0, 1.0);
        m.double_sided = info.double_sided;
        Ok(m)
    }

    fn tex_ref(&mut self, t: &TextureUse, srgb: bool) -> Result<Option<TexRef>> {
        let s = self.scene;
        let ti = t.texture;
        if !s.has_texture(ti) {
            return Err(s.err(format!("texture {ti} does not exist")));
        }
        let choice = crate::format::image::texture_image_to_decode(s, ti)?;
        self.notes.extend(choice.note(ti));
        let Some((chosen, bytes)) = choice.chosen else {
            if choice.passed_over.is_empty() {
                self.notes.push(format!("texture {ti} has no image; drawn without it"));
            }
            return Ok(None);
        };
        let img = chosen.image;
        let sampler = Sampler::from_json(s.sampler_json(t.sampler));
        let texcoord = t.tex_coord;
        if texcoord > 1 {
            self.notes.push(format!("texture {ti} reads TEXCOORD_{texcoord}; only sets 0 and 1 are drawn"));
            return Ok(None);
        }
        let texture = match self.textures.get(&(img, srgb)) {
            Some(t) => t.clone(),
            None => {
                let t = Arc::new(Texture::decode(&bytes, srgb).map_err(|e| s.err(format!("image {img}: {e}")))?);
                self.textures.insert((img, srgb), t.clone());
                t
            }
        };
        Ok(Some(TexRef { texture, sampler, texcoord, transform: t.transform }))
    }
}

fn place(l: &Local, inst: &Instance, material: usize, source: PrimRef) -> Draw {
    let place = inst.placement();
    let positions = l.positions.iter().map(|&p| place.point(p)).collect();
    let normals: Vec<Vec3> = l.normals.iter().map(|&n| unit_or(place.normal(n), Vec3::Z)).collect();
    let tangents = l
        .tangents
        .iter()
        .zip(&normals)
        .map(|(&t, &n)| {
            let (v, w) = place.tangent(t.to_array());
            sane_tangent(v.extend(w), n)
        })
        .collect();
    let triangles = l.triangles.iter().map(|&t| place.triangle(t)).collect();
    Draw { positions, normals, tangents, uvs: l.uvs.clone(), triangles, material, source }
}

fn unit_or(v: Vec3, fallback: Vec3) -> Vec3 {
    let n = v.normalize_or_zero();
    if n == Vec3::ZERO || !n.is_finite() {
        fallback
    } else {
        n
    }
}

/// A usable frame from whatever the file holds: unit, finite, not parallel to `n`, `w` = ±1.
/// Where there is no tangent the frame is arbitrary; without a normal map it only orients the
/// tangent space the lighting runs in, which does not change the lit result.
fn sane_tangent(t: Vec4, n: Vec3) -> Vec4 {
    let w = if t.w < 0.0 { -1.0 } else { 1.0 };
    let v = t.truncate();
    let ortho = (v - n * v.dot(n)).normalize_or_zero();
    if v.is_finite() && ortho != Vec3::ZERO && ortho.is_finite() {
        return v.normalize().extend(w);
    }
    n.any_orthonormal_vector().extend(w)
}
