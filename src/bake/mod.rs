//! `bake`: a mesh and a height or normal map to a render-ready glTF in one step. The map is made
//! (or converted) and attached, tangents are generated where a normal texture now needs them, and
//! whatever the scene does not need is left out ([`Scene::leave_out`]).

pub mod maps;
pub mod surface;

use crate::error::{Error, Result, Setting, Words};
use crate::format::{self, WriteOptions, WriteStats};
use crate::normalmap::Convention;
use crate::scene::leave_out::Removal;
use crate::scene::{ReadOptions, Scene};
use crate::tangent::apply::{apply, ApplyOptions, PrimTangents};
use crate::timings::Timings;
use maps::{ConventionCheck, HeightSettings};
use std::path::PathBuf;

/// Where the normal map comes from.
#[derive(Debug, Clone, Default)]
pub enum MapSource {
    /// The scene's own: MTL height maps are converted, normal textures used as they are.
    #[default]
    Scene,
    Height(PathBuf),
    Normal(PathBuf),
    /// Baked from high-poly meshes onto the scene's UV layout ([`crate::transfer`]).
    Transfer(Box<crate::transfer::Settings>),
}

#[derive(Debug, Clone, Default)]
pub struct BakeJob {
    pub mesh: PathBuf,
    pub output: PathBuf,
    pub map: MapSource,
    /// Only this material gets the map.
    pub material: Option<String>,
    pub height: HeightSettings,
    /// What a `--normal` map's green channel is, if the user says.
    pub normal_convention: Option<Convention>,
    pub keep_all: bool,
    pub bitangents: bool,
    pub read: ReadOptions,
    pub write: WriteOptions,
    pub depfile: Option<PathBuf>,
    /// Re-encode the normal textures as KTX2 ([`crate::textures::encode_ktx2`]); `None`: as made (PNG).
    pub textures: Option<crate::textures::EncodeOptions>,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct MaterialMap {
    pub material: usize,
    pub name: Option<String>,
    /// The material is new: the file had none, and the map needed one.
    pub created: bool,
    /// `height`, `normal` or `existing`.
    pub source: &'static str,
    pub file: Option<PathBuf>,
    pub convention: Option<ConventionCheck>,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct BakeReport {
    pub input: PathBuf,
    pub output: PathBuf,
    pub maps: Vec<MaterialMap>,
    pub primitives: Vec<PrimTangents>,
    pub removed: Vec<Removal>,
    pub removed_bytes: usize,
    pub written: WriteStats,
    pub notes: Vec<String>,
    /// Maps that came out (nearly) flat, with a strength that would show their relief.
    pub warnings: Vec<String>,
    pub timings_ms: Timings,
    /// What `--from` baking did, when it ran.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub transfer: Option<crate::transfer::TransferReport>,
    /// What `--textures ktx2` encoded, when it ran.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub textures: Option<crate::textures::TexturesReport>,
}

pub fn run(job: &BakeJob) -> Result<BakeReport> {
    run_from(job, Vec::new())
}

/// [`run`] with HIGH meshes already in memory for a [`MapSource::Transfer`] job
/// ([`crate::transfer::bake_from`]).
pub fn run_from(job: &BakeJob, high: Vec<crate::transfer::high::HighMesh>) -> Result<BakeReport> {
    // Settings refused before any work, not after the bake.
    job.textures.as_ref().map(|o| o.check()).transpose()?;
    let mut t = Timings::default();
    let mut scene = t.time("read", || crate::format::read(&job.mesh, &job.read))?;
    let mut deps = scene.dependencies();
    let created = scene.ensure_material();
    let mut warnings = Vec::new();
    let (mut targets, through) = t.time("maps", || attach_maps(&mut scene, job, &mut deps, &mut warnings))?;
    for target in targets.iter_mut() {
        target.created = created == Some(target.material);
    }
    check_uv_sets(&scene, job, &mut warnings)?;
    let prims = t.time("tangents", || {
        apply(
            &mut scene,
            &ApplyOptions {
                frames: crate::tangent::Options { bitangents: job.bitangents, ..Default::default() },
                ..Default::default()
            },
        )
    })?;
    if let Some(range) = job.height.height_range {
        for h in &through {
            let (png, warning) = t.time("maps through mesh", || {
                maps::through_mesh(&scene, h.material, &h.path, h.multiplier, range, &job.height)
            })?;
            warnings.extend(warning);
            maps::replace_normal_image(&mut scene, h.material, &png);
        }
    }
    let transfer = match &job.map {
        MapSource::Transfer(ts) => {
            deps.extend(ts.highs.iter().chain(ts.cage.iter()).cloned());
            let mats: Vec<usize> = targets.iter().map(|m| m.material).collect();
            let baked = t.time("transfer", || crate::transfer::bake_from(&scene, &mats, ts, high))?;
            baked.maps.iter().for_each(|(m, png)| maps::replace_normal_image(&mut scene, *m, png));
            Some((baked.report, baked.files))
        }
        _ => None,
    };
    let removed = if job.keep_all { Vec::new() } else { t.time("leave-out", || scene.leave_out(job.bitangents))? };
    let textures = match &job.textures {
        Some(o) => Some(t.time("textures", || crate::textures::encode_ktx2(&mut scene, o))?),
        None => None,
    };
    let (mut files, written) = t.time("encode", || format::write(&scene, &job.output, &job.write))?;
    if let Some(d) = &job.depfile {
        files.add(d, crate::output::depfile(&[&job.output], &deps));
    }
    if let Some((_, extra)) = &transfer {
        extra.iter().for_each(|(p, b)| files.add(p, b.clone()));
    }
    t.time("write", || files.commit())?;
    Ok(BakeReport {
        input: job.mesh.clone(),
        output: job.output.clone(),
        maps: targets,
        primitives: prims,
        removed_bytes: removed.iter().map(|r| r.bytes).sum(),
        removed,
        written,
        notes: scene.notes.clone(),
        warnings,
        timings_ms: t,
        transfer: transfer.map(|(r, _)| r),
        textures,
    })
}

/// A normal map needs UV coordinates to be placed: a primitive without the set its normal
/// texture reads is refused, not written as a file renderers cannot draw. Other textures that
/// read a set the primitive lacks are bake's concern only as far as saying so: they pass through
/// as the input had them, with validate's fix.
fn check_uv_sets(scene: &Scene, job: &BakeJob, warnings: &mut Vec<String>) -> Result<()> {
    let mats = scene.materials();
    for r in scene.primitives() {
        let attrs = scene.prim_json(r).get("attributes").and_then(|a| a.as_object());
        let sets: Vec<&str> =
            attrs.into_iter().flatten().map(|(k, _)| k.as_str()).filter(|k| k.starts_with("TEXCOORD_")).collect();
        for (m, t) in mats.missing_uv_sets(scene, r) {
            let set = t.tex_coord;
            let at = format!("mesh {} primitive {}", r.mesh, r.primitive);
            if t.slot != crate::scene::Slot::Normal {
                let msg = format!(
                    "{} {} reads TEXCOORD_{set}, which {at} does not have: point the texture's texCoord at a set it has",
                    m.label(),
                    t.name()
                );
                if !warnings.contains(&msg) {
                    warnings.push(msg);
                }
                continue;
            }
            let what = if set == 0 {
                "no UV coordinates (TEXCOORD_0)".to_string()
            } else {
                format!("no UV set {set} (TEXCOORD_{set})")
            };
            let fix = if !sets.is_empty() {
                format!("point the normal texture's texCoord at a set the primitive has ({})", sets.join(", "))
            } else if job.mesh.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj")) {
                "give the mesh UVs (vt lines in the OBJ) and bake again".to_string()
            } else {
                "unwrap the mesh (give it UVs) and bake again".to_string()
            };
            return Err(Error::input(
                &job.mesh,
                format!("{at} has {what}, so {} cannot place its {} on it; {fix}", m.label(), t.name()),
            ));
        }
    }
    Ok(())
}

fn material_names(scene: &Scene) -> Vec<Option<String>> {
    scene.materials().list.iter().map(|m| m.name.clone()).collect()
}

/// A height map to make through the mesh once it has tangents ([`maps::through_mesh`]).
struct ThroughMesh {
    material: usize,
    path: PathBuf,
    multiplier: f32,
}

/// Decides which materials get which map, and attaches them; height maps made through the mesh
/// hold a flat map's place until tangents exist, and are returned.
fn attach_maps(
    scene: &mut Scene,
    job: &BakeJob,
    deps: &mut Vec<PathBuf>,
    warnings: &mut Vec<String>,
) -> Result<(Vec<MaterialMap>, Vec<ThroughMesh>)> {
    let mesh_aware = job.height.height_range.is_some();
    let mut through = Vec::new();
    let names = material_names(scene);
    let chosen: Option<usize> = match &job.material {
        Some(want) => Some(names.iter().position(|n| n.as_deref() == Some(want.as_str())).ok_or_else(|| {
            let have: Vec<String> = names.iter().map(|n| n.clone().unwrap_or_else(|| "(unnamed)".into())).collect();
            let msg = format!("{}: no material named '{want}' (have: {})", job.mesh.display(), have.join(", "));
            Error::setting(Setting::Material, Some(want.clone()), msg)
        })?),
        None => None,
    };
    // As read, before any map is attached below.
    let has_normal_texture: Vec<bool> =
        scene.materials().list.iter().map(|i| i.texture(crate::scene::Slot::Normal).is_some()).collect();
    let wants_bump = |m: usize| scene.height_maps.iter().any(|h| h.material == m) || has_normal_texture[m];
    let targets: Vec<usize> = match (chosen, &job.map) {
        (Some(m), _) => vec![m],
        (None, MapSource::Scene) => (0..names.len()).collect(),
        (None, _) if names.len() == 1 => vec![0],
        (None, MapSource::Transfer(_)) => transfer_targets(scene, job)?,
        (None, _) => {
            let t: Vec<usize> = (0..names.len()).filter(|&m| wants_bump(m)).collect();
            if t.is_empty() {
                let msg = format!(
                    "{}: {} materials and none has a bump map; choose one with ",
                    job.mesh.display(),
                    names.len()
                );
                return Err(Error::setting(Setting::Material, None, Words::from(msg).name(Setting::Material)));
            }
            t
        }
    };
    let mut out = Vec::new();
    let mut made: Option<(Vec<u8>, Option<ConventionCheck>)> = None;
    for m in targets {
        let name = names[m].clone();
        let label = format!("{}_normal", name.clone().unwrap_or_else(|| format!("material{m}")));
        match &job.map {
            MapSource::Transfer(ts) => {
                // The map is baked once tangents exist; a flat texel holds its place until then.
                maps::attach(scene, m, &maps::flat_png(), &label);
                let file = ts.highs.first().cloned();
                out.push(MaterialMap { material: m, name, created: false, source: "high", file, convention: None });
            }
            MapSource::Height(p) if mesh_aware => {
                maps::attach(scene, m, &maps::flat_png(), &label);
                through.push(ThroughMesh { material: m, path: p.clone(), multiplier: 1.0 });
                if !deps.contains(p) {
                    deps.push(p.clone());
                }
                out.push(MaterialMap {
                    material: m,
                    name,
                    created: false,
                    source: "height",
                    file: Some(p.clone()),
                    convention: None,
                });
            }
            MapSource::Height(p) | MapSource::Normal(p) => {
                if made.is_none() {
                    made = Some(match &job.map {
                        MapSource::Height(_) => {
                            let (png, warning) = maps::from_height(p, 1.0, maps::material_wrap(scene, m), &job.height)?;
                            warnings.extend(warning);
                            (png, None)
                        }
                        _ => {
                            let (b, c) = maps::from_normal(p, job.normal_convention, job.height.max_pixels)?;
                            (b, Some(c))
                        }
                    });
                    deps.push(p.clone());
                }
                let (png, conv) = made.clone().expect("made above");
                maps::attach(scene, m, &png, &label);
                let source = if matches!(job.map, MapSource::Height(_)) { "height" } else { "normal" };
                out.push(MaterialMap {
                    material: m,
                    name,
                    created: false,
                    source,
                    file: Some(p.clone()),
                    convention: conv,
                });
            }
            MapSource::Scene => {
                if let Some(h) = scene.height_maps.iter().find(|h| h.material == m).cloned() {
                    if mesh_aware {
                        maps::attach(scene, m, &maps::flat_png(), &label);
                        through.push(ThroughMesh { material: m, path: h.path.clone(), multiplier: h.multiplier });
                    } else {
                        let (png, warning) =
                            maps::from_height(&h.path, h.multiplier, maps::material_wrap(scene, m), &job.height)?;
                        warnings.extend(warning);
                        maps::attach(scene, m, &png, &label);
                    }
                    out.push(MaterialMap {
                        material: m,
                        name,
                        created: false,
                        source: "height",
                        file: Some(h.path.clone()),
                        convention: None,
                    });
                } else if has_normal_texture[m] {
                    out.push(MaterialMap {
                        material: m,
                        name,
                        created: false,
                        source: "existing",
                        file: None,
                        convention: None,
                    });
                }
            }
        }
    }
    if out.is_empty() {
        let why = Words::from("no material has a height or normal map: nothing to bake (give ");
        scene.notes.push(why.name(Setting::Height).text(" or ").name(Setting::Normal).text(")").to_string());
    }
    Ok((out, through))
}

/// Without `--material`, `--from` bakes every material LOW's triangle primitives use, each into
/// its own map, as a baker with several texture sets does. A material whose primitives have no
/// UVs has nowhere to put a map: it is left as it is, with a note.
fn transfer_targets(scene: &mut Scene, job: &BakeJob) -> Result<Vec<usize>> {
    let names = material_names(scene);
    let mut out = Vec::new();
    for (m, name) in names.iter().enumerate() {
        let prims = crate::transfer::material_prims(scene, m);
        if prims.is_empty() {
            continue;
        }
        if prims.iter().all(|&r| scene.prim_json(r).pointer("/attributes/TEXCOORD_0").is_some()) {
            out.push(m);
        } else {
            let label = name.clone().unwrap_or_else(|| format!("material {m}"));
            scene.notes.push(format!("{label}: its primitives have no UVs (TEXCOORD_0), so no map is baked for it"));
        }
    }
    if out.is_empty() {
        return Err(Error::input(
            &job.mesh,
            "no triangle primitive has UVs (TEXCOORD_0) to bake a map into; unwrap LOW (give it UVs) and bake again",
        ));
    }
    Ok(out)
}
