//! The engines on arrays. The package's Python side hands over C-contiguous, aligned NumPy
//! arrays of the right dtype as (address, length), keeps them alive for the call, and allocates
//! the outputs; the work runs with the GIL released. Nothing here is public API: the checked
//! entry points are `bumpbake.tangents` and `bumpbake.normalmap`.

use crate::errors::{raise, Kind};
use crate::progress::Callback;
use bumpbake::normalmap::{
    self as nm, Convention, Depth, EncodeOptions, Filter, HeightPlane, NormalData, Options, Wrap,
};
use bumpbake::scene::{Geometry, Primitive, Stream, UvSource};
use bumpbake::tangent::fallback::any_orthogonal;
use bumpbake::tangent::{self, mikk};
use glam::Vec3;
use pyo3::prelude::*;

/// `len` values of `T` at `addr`.
///
/// # Safety
/// `addr` is the data of a live, C-contiguous, aligned array of at least `len` `T`s that nothing
/// writes while the slice lives (the Python side guarantees it for the call).
unsafe fn slice<'a, T>(addr: usize, len: usize) -> &'a [T] {
    if len == 0 {
        return &[];
    }
    std::slice::from_raw_parts(addr as *const T, len)
}

/// As [`slice`], writable: `addr` is an array the Python side made for this output.
unsafe fn slice_mut<'a, T>(addr: usize, len: usize) -> &'a mut [T] {
    if len == 0 {
        return &mut [];
    }
    std::slice::from_raw_parts_mut(addr as *mut T, len)
}

/// MikkTSpace frames of a triangle list, written to `out_tangents` (x 4 float32) and, when
/// `out_bitangents` is not 0, `out_bitangents` (x 3): one row per corner, or with `per_vertex`
/// one per vertex. Returns, as JSON, the fallback counts and `conflicts`: the vertices whose
/// corners got different frames (a per-vertex answer cannot hold them; the caller refuses it).
/// A vertex no triangle uses gets a unit tangent orthogonal to its normal, `w = 1`.
/// `indices` is `corners` uint32 (checked below `vertices`), or 0 for the vertices in order.
/// `flip_v`: the UVs are bottom-left (OpenGL, Blender) and are turned to glTF's as OBJ's are.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (vertices, positions, normals, uvs, indices, corners, flip_v, per_vertex, out_tangents, out_bitangents))]
pub fn tangents(
    py: Python<'_>,
    vertices: usize,
    positions: usize,
    normals: usize,
    uvs: usize,
    indices: usize,
    corners: usize,
    flip_v: bool,
    per_vertex: bool,
    out_tangents: usize,
    out_bitangents: usize,
) -> PyResult<String> {
    crate::errors::speak_keywords();
    // SAFETY: the addresses and lengths come from arrays the Python side checked and holds.
    let (positions, normals, uvs, index_list) = unsafe {
        (
            slice::<[f32; 3]>(positions, vertices),
            (normals != 0).then(|| slice::<[f32; 3]>(normals, vertices)),
            slice::<[f32; 2]>(uvs, vertices),
            (indices != 0).then(|| slice::<u32>(indices, corners)),
        )
    };
    if let Some(bad) = index_list.and_then(|ix| ix.iter().position(|&i| i as usize >= vertices)) {
        let i = index_list.map_or(0, |ix| ix[bad]);
        return Err(raise(py, Kind::Input, format!("indices[{bad}] is {i}, but there are {vertices} vertices")));
    }
    let rows = if per_vertex { vertices } else { corners };
    // SAFETY: outputs the Python side allocated for `rows` frames.
    let (out_t, out_b) = unsafe {
        (
            slice_mut::<[f32; 4]>(out_tangents, rows),
            (out_bitangents != 0).then(|| slice_mut::<[f32; 3]>(out_bitangents, rows)),
        )
    };
    let report = py.detach(|| {
        let mut uvs = uvs.to_vec();
        if flip_v {
            bumpbake::format::mesh::v_down(&mut uvs);
        }
        let mut attributes = vec![("POSITION".to_string(), Stream::from_f32("VEC3", positions))];
        if let Some(n) = normals {
            attributes.push(("NORMAL".to_string(), Stream::from_f32("VEC3", n)));
        }
        attributes.push(("TEXCOORD_0".to_string(), Stream::from_f32("VEC2", &uvs)));
        drop(uvs);
        let indices: Vec<u32> = index_list.map_or_else(|| (0..corners as u32).collect(), <[u32]>::to_vec);
        let p = Primitive { attributes, targets: Vec::new(), indices, mode: 4 };
        let opts = tangent::Options { bitangents: out_b.is_some(), engine: mikk::Engine::default() };
        let g = Geometry::new(p, UvSource { set: 0, transform: None });
        // The library's work alone, without the binding's checks and copies (for the bench).
        let start = std::time::Instant::now();
        let frames = tangent::corner_frames(&g, &opts);
        let engine_ms = start.elapsed().as_secs_f64() * 1e3;
        let conflicts = if per_vertex {
            per_vertex_frames(&frames, &g.primitive.indices, normals, out_t, out_b)
        } else {
            out_t.copy_from_slice(&frames.tangents);
            if let (Some(out), Some(b)) = (out_b, &frames.bitangents) {
                out.copy_from_slice(b);
            }
            0
        };
        serde_json::json!({
            "fallback": frames.fallback,
            "generated_normals": frames.generated_normals,
            "conflicts": conflicts,
            "engine_ms": engine_ms,
        })
    });
    Ok(report.to_string())
}

/// Corner frames gathered per vertex; returns how many vertices have corners that disagree.
fn per_vertex_frames(
    frames: &tangent::CornerFrames,
    indices: &[u32],
    normals: Option<&[[f32; 3]]>,
    out_t: &mut [[f32; 4]],
    mut out_b: Option<&mut [[f32; 3]]>,
) -> usize {
    const UNSET: u8 = 0;
    const SET: u8 = 1;
    const CONFLICT: u8 = 2;
    let mut state = vec![UNSET; out_t.len()];
    for (c, &v) in indices.iter().enumerate() {
        let (v, t) = (v as usize, frames.tangents[c]);
        match state[v] {
            UNSET => {
                state[v] = SET;
                out_t[v] = t;
                if let (Some(out), Some(b)) = (out_b.as_deref_mut(), &frames.bitangents) {
                    out[v] = b[c];
                }
            }
            SET if t.map(f32::to_bits) != out_t[v].map(f32::to_bits) => state[v] = CONFLICT,
            _ => {}
        }
    }
    for v in (0..state.len()).filter(|&v| state[v] == UNSET) {
        let n = normals.map_or(Vec3::Z, |n| Vec3::from(n[v]));
        let t = any_orthogonal(n);
        out_t[v] = [t.x, t.y, t.z, 1.0];
        if let Some(out) = out_b.as_deref_mut() {
            out[v] = n.normalize_or_zero().cross(t).to_array();
        }
    }
    state.iter().filter(|&&s| s == CONFLICT).count()
}

fn named<T: serde::Serialize + Copy>(all: &[T], name: &str) -> Option<T> {
    all.iter().copied().find(|v| serde_json::to_value(v).ok().and_then(|s| s.as_str().map(|s| s == name)) == Some(true))
}

/// A height plane from the Python side's array: `dtype` is `u8`, `u16` (read as the command line
/// reads 8- and 16-bit images: over 255 and 65535) or `f32` (as it is).
fn height_plane(addr: usize, dtype: &str, width: usize, rows: usize) -> Option<HeightPlane> {
    let n = width * rows;
    // SAFETY: as `slice`; the Python side passes an array of `n` values of `dtype`.
    let data: Vec<f32> = unsafe {
        match dtype {
            "u8" => slice::<u8>(addr, n).iter().map(|&v| v as f32 / 255.0).collect(),
            "u16" => slice::<u16>(addr, n).iter().map(|&v| v as f32 / 65535.0).collect(),
            "f32" => slice::<f32>(addr, n).to_vec(),
            _ => return None,
        }
    };
    Some(HeightPlane::new(width, rows, data))
}

/// What both height-map calls are given besides the map, checked: the names as the library's
/// values, and the samples finite.
struct HeightArgs {
    filter: Filter,
    wrap: Wrap,
    convention: Convention,
    depth: Depth,
    plane: HeightPlane,
}

impl HeightArgs {
    fn read(
        py: Python<'_>,
        (height, dtype, width, rows): (usize, &str, usize, usize),
        filter: &str,
        wrap: &str,
        convention: &str,
        bits: u32,
    ) -> PyResult<HeightArgs> {
        let usage = |what: &str, v: &str| raise(py, Kind::Usage, format!("{what}={v:?} is not one of bumpbake's"));
        let filter = named(&Filter::ALL, filter).ok_or_else(|| usage("filter", filter))?;
        let wrap = named(&[Wrap::Repeat, Wrap::Clamp, Wrap::Mirror], wrap).ok_or_else(|| usage("wrap", wrap))?;
        let convention = named(&[Convention::Opengl, Convention::Directx], convention)
            .ok_or_else(|| usage("convention", convention))?;
        let depth = match bits {
            8 => Depth::Bits8,
            16 => Depth::Bits16,
            32 => Depth::Float,
            _ => return Err(usage("bits", &bits.to_string())),
        };
        let plane = height_plane(height, dtype, width, rows).ok_or_else(|| usage("height.dtype", dtype))?;
        if let Some(i) = plane.data.iter().position(|v| !v.is_finite()) {
            let msg = format!(
                "height[{}, {}] is {}: a height map's samples must be finite",
                i / width,
                i % width,
                plane.data[i]
            );
            return Err(raise(py, Kind::Input, msg));
        }
        Ok(HeightArgs { filter, wrap, convention, depth, plane })
    }
}

/// A tangent-space normal map of a height array, encoded as the command line writes it, into
/// `out` (`rows` x `width` x channels of uint8, uint16 or float32 for `bits` 8, 16, 32).
/// Returns the report (the flatness warning; with `report`, the steepest slope) as JSON.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (height, dtype, width, rows, strength, filter, wrap, invert, convention, bits, alpha, out, report, progress=None))]
pub fn normalmap(
    py: Python<'_>,
    height: usize,
    dtype: &str,
    width: usize,
    rows: usize,
    strength: f32,
    filter: &str,
    wrap: &str,
    invert: bool,
    convention: &str,
    bits: u32,
    alpha: bool,
    out: usize,
    report: bool,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    crate::errors::speak_keywords();
    let HeightArgs { filter, wrap, convention, depth, plane } =
        HeightArgs::read(py, (height, dtype, width, rows), filter, wrap, convention, bits)?;
    let opts = Options { strength, filter, wrap, invert };
    let channels = if alpha { 4 } else { 3 };
    let n = width * rows * channels;
    let (reporter, callback) = Callback::reporter(progress);
    let (warning, slope, engine_ms) = py.detach(|| {
        let start = std::time::Instant::now();
        reporter.start("normalmap", rows as u64, "rows");
        let img = match depth {
            // Unit vectors, not the encoding's `n/2 + 1/2`: what array code computes with.
            Depth::Float => {
                let normals = nm::normals_from_height(&plane, &opts, &reporter);
                // SAFETY: `out` is the float32 array the Python side allocated: `n` samples.
                let out = unsafe { slice_mut::<f32>(out, n) };
                for ((o, v), h) in out.chunks_exact_mut(channels).zip(&normals.data).zip(&plane.data) {
                    o[..3].copy_from_slice(&[v[0], v[1] * convention.y_sign(), v[2]]);
                    if alpha {
                        o[3] = if invert { 1.0 - h } else { *h };
                    }
                }
                nm::encode_plane(
                    &normals,
                    &EncodeOptions { depth: Depth::Float, convention, alpha_height: false },
                    None,
                )
            }
            _ => {
                let img = nm::encode_normals(
                    &plane,
                    &opts,
                    &EncodeOptions { depth, convention, alpha_height: alpha },
                    &reporter,
                );
                // SAFETY: `out` is the array the Python side allocated: `n` samples of the depth's type.
                unsafe {
                    match &img.data {
                        NormalData::U8(v) => slice_mut::<u8>(out, n).copy_from_slice(v),
                        NormalData::U16(v) => slice_mut::<u16>(out, n).copy_from_slice(v),
                        NormalData::F32(v) => slice_mut::<f32>(out, n).copy_from_slice(v),
                    }
                }
                img
            }
        };
        reporter.finish();
        // Judged on the texels as an image would store them, as the command line judges them.
        // The flatness check is the command's too: part of the library's work.
        let warning = nm::Flatness::of_image(&img).warning(&plane, strength, 1.0);
        let engine_ms = start.elapsed().as_secs_f64() * 1e3;
        (warning, report.then(|| nm::steepest_slope(&plane)), engine_ms)
    });
    if let Some(e) = callback.and_then(|c| c.take_error()) {
        return Err(e);
    }
    let report = serde_json::json!({
        "width": width,
        "height": rows,
        "strength": strength,
        "filter": filter,
        "wrap": wrap,
        "convention": convention,
        "invert": invert,
        "steepest_slope": slope,
        "warnings": warning.into_iter().collect::<Vec<_>>(),
        // The library's filter and encoding alone, without the binding's checks and copies.
        "engine_ms": engine_ms,
    });
    Ok(report.to_string())
}

/// The normal map of a height array through a mesh, as Cycles' Bump node shades it
/// ([`bumpbake::bake::surface`]), into `out` (`rows` x `width` x 3 of uint8, uint16 or float32
/// for `bits` 8, 16, 32). The mesh is a triangle list of `corners` corners, one row per corner
/// in each array; `uvs` are glTF's (v down). Returns the coverage and `engine_ms` as JSON.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (height, dtype, width, rows, corners, positions, normals, tangents, uvs, distance, strength, invert, filter, wrap, padding, convention, bits, out))]
pub fn bump_to_normal(
    py: Python<'_>,
    height: usize,
    dtype: &str,
    width: usize,
    rows: usize,
    corners: usize,
    positions: usize,
    normals: usize,
    tangents: usize,
    uvs: usize,
    distance: f64,
    strength: f64,
    invert: bool,
    filter: &str,
    wrap: &str,
    padding: usize,
    convention: &str,
    bits: u32,
    out: usize,
) -> PyResult<String> {
    use bumpbake::bake::surface::{surface_normals, Bump, SurfaceMesh};
    crate::errors::speak_keywords();
    let HeightArgs { filter, wrap, convention, depth, plane } =
        HeightArgs::read(py, (height, dtype, width, rows), filter, wrap, convention, bits)?;
    // SAFETY: per-corner arrays the Python side checked and holds, `corners` rows each.
    let (positions, normals, tangents, uvs) = unsafe {
        (
            slice::<[f32; 3]>(positions, corners),
            slice::<[f32; 3]>(normals, corners),
            slice::<[f32; 4]>(tangents, corners),
            slice::<[f32; 2]>(uvs, corners),
        )
    };
    let bump = Bump { distance, strength, invert, filter, wrap, padding };
    let n = width * rows * 3;
    let (map, engine_ms) = py.detach(|| {
        let start = std::time::Instant::now();
        let triangles: Vec<[u32; 3]> = (0..corners as u32 / 3).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
        let mesh = SurfaceMesh { positions, normals, tangents, uvs, triangles: &triangles };
        let map = surface_normals(&mesh, &plane, &bump);
        let enc = EncodeOptions { depth, convention, alpha_height: false };
        // SAFETY: `out` is the array the Python side allocated: `n` samples of the depth's type.
        unsafe {
            match depth {
                Depth::Float => {
                    let out = slice_mut::<f32>(out, n);
                    for (o, v) in out.chunks_exact_mut(3).zip(&map.normals.data) {
                        o.copy_from_slice(&[v[0], v[1] * convention.y_sign(), v[2]]);
                    }
                }
                _ => match nm::encode_plane(&map.normals, &enc, None).data {
                    NormalData::U8(v) => slice_mut::<u8>(out, n).copy_from_slice(&v),
                    NormalData::U16(v) => slice_mut::<u16>(out, n).copy_from_slice(&v),
                    NormalData::F32(v) => slice_mut::<f32>(out, n).copy_from_slice(&v),
                },
            }
        }
        (map, start.elapsed().as_secs_f64() * 1e3)
    });
    let report = serde_json::json!({
        "width": width,
        "height": rows,
        "triangles": corners / 3,
        "distance": distance,
        "strength": strength,
        "invert": invert,
        "filter": filter,
        "wrap": wrap,
        "convention": convention,
        "covered": map.covered,
        "padded": map.padded,
        "uncovered": map.uncovered,
        "engine_ms": engine_ms,
    });
    Ok(report.to_string())
}

/// The strength `normalmap` converts with: the library's one rule for `strength` against
/// `height_range` and `texel_size` ([`Options::strength_from`]), its refusals as `UsageError`s.
#[pyfunction]
#[pyo3(signature = (strength, height_range, texel_size))]
pub fn strength(
    py: Python<'_>,
    strength: Option<f32>,
    height_range: Option<f64>,
    texel_size: Option<f64>,
) -> PyResult<f32> {
    crate::errors::speak_keywords();
    Options::strength_from(strength, height_range, texel_size)
        .map_err(|e| crate::errors::from_library(py, &e, str::to_string))
}
