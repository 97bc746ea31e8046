//! Reading PLY (Stanford polygon files: ASCII, binary little and big endian), the format scans
//! and sculpting tools export high-poly meshes in.
//!
//! Only what a mesh needs is kept: `vertex` x/y/z (any numeric type), nx/ny/nz and texture
//! coordinates (s/t, u/v or texture_u/texture_v) when all of a pair or triple are there, and the
//! `face` index list (`vertex_indices` or `vertex_index`, any count and index type), polygons
//! fanned from their first corner as OBJ faces are. Other elements and properties are skipped.
//! Every count is checked against the bytes that remain before anything is allocated, so a
//! header that claims billions of vertices is an error, not an allocation.
//! Texture v is kept as stored (up, as in OBJ); `scene.rs` and `raw.rs` convert it to glTF's
//! convention. The `vertex` and `face` elements are read on every core: binary ones always
//! (`binary.rs`), ASCII ones when each record is one line (`ascii.rs`; anything else is read
//! here, record by record).

mod ascii;
mod binary;
mod scene;

pub use scene::scene;

use super::mesh::text_number::parse_f32;
use super::mesh::{check_finite, StoredMesh};
use crate::error::{Error, Result};
use std::path::Path;

/// The name of the one mesh a PLY file holds: its file name without the extension.
pub fn mesh_name(path: &Path) -> String {
    path.file_stem().map_or("mesh".into(), |s| s.to_string_lossy().into_owned())
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

#[derive(Clone, Copy, PartialEq, Debug)]
pub(super) enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Ty {
    fn parse(s: &str) -> Option<Ty> {
        Some(match s {
            "char" | "int8" => Ty::I8,
            "uchar" | "uint8" => Ty::U8,
            "short" | "int16" => Ty::I16,
            "ushort" | "uint16" => Ty::U16,
            "int" | "int32" => Ty::I32,
            "uint" | "uint32" => Ty::U32,
            "float" | "float32" => Ty::F32,
            "double" | "float64" => Ty::F64,
            _ => return None,
        })
    }

    pub(super) fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::F64 => 8,
        }
    }
}

pub(super) struct Property {
    name: String,
    pub(super) ty: Ty,
    /// The count type of a list property.
    pub(super) list: Option<Ty>,
}

pub(super) struct Element {
    name: String,
    pub(super) count: u64,
    pub(super) props: Vec<Property>,
}

/// Reads the PLY file at `path`, through a memory map when it is a file (a scan's PLY is not
/// copied whole into memory beside what is read from it).
pub fn read_file(path: &Path) -> Result<StoredMesh> {
    let cannot = |e: std::io::Error| Error::input(path, format!("cannot read: {e}"));
    let file = std::fs::File::open(path).map_err(cannot)?;
    let meta = file.metadata().map_err(cannot)?;
    if meta.is_file() && meta.len() > 0 {
        // SAFETY: the map is only read. Like every reader that maps a file (the OBJ reader
        // too), this trusts nothing to truncate the file while it is read.
        if let Ok(map) = unsafe { memmap2::Mmap::map(&file) } {
            return parse(path, &map);
        }
    }
    let bytes = std::fs::read(path).map_err(cannot)?;
    parse(path, &bytes)
}

/// Whether `bytes` start like a PLY file.
pub fn is_ply(bytes: &[u8]) -> bool {
    bytes.starts_with(b"ply\n") || bytes.starts_with(b"ply\r\n")
}

/// Parses PLY bytes; `path` names the file in messages.
pub fn parse(path: &Path, bytes: &[u8]) -> Result<StoredMesh> {
    let err = |m: String| Error::input(path, m);
    let (enc, elements, body) = header(bytes).map_err(|m| err(format!("bad PLY header: {m}")))?;
    let mut cur = Cursor { b: &bytes[body..], i: 0, enc };
    let mut mesh = StoredMesh::default();
    let mut have_vertices = false;
    // Elements may come in any order: faces before their vertices are checked against the
    // vertex count the header declares, which the vertex element must then hold.
    let declared = elements.iter().find(|e| e.name == "vertex").map(|e| e.count);
    for el in &elements {
        // Each record takes at least this many bytes, so a count the file cannot hold is caught
        // before anything is allocated.
        let least = match enc {
            Encoding::Ascii => 2 * el.props.len().max(1) as u64,
            _ => el.props.iter().map(|p| p.list.unwrap_or(p.ty).size() as u64).sum::<u64>().max(1),
        };
        let left = (cur.b.len() - cur.i) as u64 + 1;
        if el.count > left / least || el.count > u32::MAX as u64 {
            return Err(err(format!(
                "the header declares {} '{}' records but only {} bytes follow: the file is truncated or its header is wrong",
                el.count,
                el.name,
                left - 1
            )));
        }
        let truncated = |k: u64| {
            err(format!(
                "ends inside '{}' record {} of {}: the file is truncated (export it again)",
                el.name,
                k + 1,
                el.count
            ))
        };
        let out_of_range = |k: u64, v: i64, nv: u64| {
            err(format!(
                "face {} names vertex {v}, but there are {nv} vertices (indices start at 0): the file is damaged",
                k + 1
            ))
        };
        let bad_value = |k: u64, p: &Property| {
            err(format!("'{}' record {}: property '{}' is not a number", el.name, k + 1, p.name))
        };
        match el.name.as_str() {
            "vertex" if !have_vertices => {
                have_vertices = true;
                let find = |names: &[&str]| -> Option<usize> {
                    names.iter().find_map(|n| el.props.iter().position(|p| p.name == *n && p.list.is_none()))
                };
                let xyz = [find(&["x"]), find(&["y"]), find(&["z"])];
                let [Some(x), Some(y), Some(z)] = xyz else {
                    return Err(err("the 'vertex' element has no x, y and z properties".to_string()));
                };
                let nrm = match [find(&["nx"]), find(&["ny"]), find(&["nz"])] {
                    [Some(a), Some(b), Some(c)] => Some([a, b, c]),
                    _ => None,
                };
                let uv =
                    match [find(&["u", "s", "texture_u", "texture_s"]), find(&["v", "t", "texture_v", "texture_t"])] {
                        [Some(a), Some(b)] => Some([a, b]),
                        _ => None,
                    };
                let n = el.count as usize;
                if enc == Encoding::Ascii && el.props.iter().all(|p| p.list.is_none()) {
                    let cols = ascii::Columns { xyz: [x, y, z], nrm, uv };
                    if let Some(((p, nr, t), used)) = ascii::vertices(el, &cur.b[cur.i..], &cols) {
                        (mesh.positions, mesh.normals, mesh.uvs) = (p, nr, t);
                        cur.i += used;
                        continue;
                    }
                }
                if let (true, Some((cols, stride))) = (enc != Encoding::Ascii, binary::fixed_layout(el)) {
                    let (b, big) = (&cur.b[cur.i..], enc == Encoding::Big);
                    if n * stride > b.len() {
                        return Err(truncated((b.len() / stride) as u64));
                    }
                    mesh.positions = binary::columns(b, n, stride, [cols[x], cols[y], cols[z]], big);
                    check_finite(path, &mesh.positions)?;
                    if let Some(c) = nrm {
                        mesh.normals = binary::columns(b, n, stride, c.map(|j| cols[j]), big);
                    }
                    if let Some(c) = uv {
                        mesh.uvs = binary::columns(b, n, stride, c.map(|j| cols[j]), big);
                    }
                    cur.i += n * stride;
                    continue;
                }
                mesh.positions.reserve_exact(n);
                if nrm.is_some() {
                    mesh.normals.reserve_exact(n);
                }
                if uv.is_some() {
                    mesh.uvs.reserve_exact(n);
                }
                let mut vals = vec![0f32; el.props.len()];
                for k in 0..el.count {
                    for (j, p) in el.props.iter().enumerate() {
                        if p.list.is_some() {
                            cur.skip_list(p).ok_or_else(|| truncated(k))?;
                        } else {
                            vals[j] = cur.float(p.ty).map_err(|e| if e { bad_value(k, p) } else { truncated(k) })?;
                        }
                    }
                    let q = [vals[x], vals[y], vals[z]];
                    if !q.iter().all(|c| c.is_finite()) {
                        return Err(err(format!("vertex {} has a non-finite coordinate", k + 1)));
                    }
                    mesh.positions.push(q);
                    if let Some([a, b, c]) = nrm {
                        mesh.normals.push([vals[a], vals[b], vals[c]]);
                    }
                    if let Some([a, b]) = uv {
                        mesh.uvs.push([vals[a], vals[b]]);
                    }
                }
            }
            "face" => {
                let list = el
                    .props
                    .iter()
                    .position(|p| p.list.is_some() && (p.name == "vertex_indices" || p.name == "vertex_index"))
                    .ok_or_else(|| err("the 'face' element has no vertex_indices list".to_string()))?;
                let Some(declared) = declared else { return Err(err("has no 'vertex' element".to_string())) };
                if matches!(el.props[list].ty, Ty::F32 | Ty::F64) {
                    return Err(err(
                        "the 'face' element's vertex indices are floats: they must be integers".to_string()
                    ));
                }
                let nv = if have_vertices { mesh.positions.len() as u64 } else { declared };
                if enc == Encoding::Ascii {
                    if let Some((tris, used)) = ascii::faces(el, list, &cur.b[cur.i..], nv) {
                        mesh.triangles = tris;
                        cur.i += used;
                        continue;
                    }
                } else {
                    let (tris, used) =
                        binary::faces(el, list, &cur.b[cur.i..], nv, enc == Encoding::Big).map_err(|f| match f {
                            binary::Fault::Truncated(k) => truncated(k),
                            binary::Fault::Index { face, v } => out_of_range(face, v, nv),
                        })?;
                    mesh.triangles = tris;
                    cur.i += used;
                    continue;
                }
                mesh.triangles.reserve(el.count as usize);
                let mut idx: Vec<u32> = Vec::new();
                for k in 0..el.count {
                    for (j, p) in el.props.iter().enumerate() {
                        if j != list {
                            match p.list {
                                Some(_) => cur.skip_list(p).ok_or_else(|| truncated(k))?,
                                None => cur.skip(p.ty).ok_or_else(|| truncated(k))?,
                            }
                            continue;
                        }
                        let count = cur.int(p.list.unwrap_or(Ty::U8)).map_err(|e| {
                            if e {
                                bad_value(k, p)
                            } else {
                                truncated(k)
                            }
                        })?;
                        if count < 0 || count as u64 > (cur.b.len() - cur.i) as u64 {
                            return Err(truncated(k));
                        }
                        idx.clear();
                        for _ in 0..count {
                            let v = cur.int(p.ty).map_err(|e| if e { bad_value(k, p) } else { truncated(k) })?;
                            if v < 0 || v as u64 >= nv {
                                return Err(out_of_range(k, v, nv));
                            }
                            idx.push(v as u32);
                        }
                        mesh.triangles.extend(fan(&idx));
                    }
                }
            }
            _ => {
                for k in 0..el.count {
                    for p in &el.props {
                        match p.list {
                            Some(_) => cur.skip_list(p).ok_or_else(|| truncated(k))?,
                            None => cur.skip(p.ty).ok_or_else(|| truncated(k))?,
                        }
                    }
                }
            }
        }
    }
    if !have_vertices {
        return Err(err("has no 'vertex' element".to_string()));
    }
    Ok(mesh)
}

/// A polygon's triangles, fanned from its first corner as OBJ faces are (none under three).
pub(super) fn fan<T: Copy>(idx: &[T]) -> impl Iterator<Item = [T; 3]> + '_ {
    idx.get(1..).unwrap_or(&[]).windows(2).map(|w| [idx[0], w[0], w[1]])
}

/// The encoding, the elements and where the body starts.
fn header(b: &[u8]) -> crate::error::Faulty<(Encoding, Vec<Element>, usize)> {
    if !is_ply(b) {
        return Err("the file does not start with the line 'ply'".to_string().into());
    }
    let mut i = 0;
    let mut enc = None;
    let mut elements: Vec<Element> = Vec::new();
    for n in 1.. {
        let end = b[i..].iter().position(|&c| c == b'\n').map(|k| i + k).ok_or("no end_header line")?;
        let line = std::str::from_utf8(&b[i..end]).map_err(|_| format!("line {n} is not text"))?.trim();
        i = end + 1;
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.as_slice() {
            ["ply"] if n == 1 => {}
            [] | ["comment", ..] | ["obj_info", ..] => {}
            ["format", f, "1.0"] if enc.is_none() => {
                enc = Some(match *f {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::Little,
                    "binary_big_endian" => Encoding::Big,
                    _ => return Err(format!("line {n}: unknown format '{f}'").into()),
                })
            }
            ["element", name, count] => {
                let count = count.parse().map_err(|_| format!("line {n}: element count '{count}' is not a number"))?;
                elements.push(Element { name: name.to_string(), count, props: Vec::new() });
            }
            ["property", "list", ct, it, name] => {
                let el = elements.last_mut().ok_or(format!("line {n}: property before any element"))?;
                let (Some(ct), Some(it)) = (Ty::parse(ct), Ty::parse(it)) else {
                    return Err(format!("line {n}: unknown property type in '{line}'").into());
                };
                // Items may be floats (MeshLab's per-corner `texcoord`); face indices are checked
                // where the face list is chosen.
                if matches!(ct, Ty::F32 | Ty::F64) {
                    return Err(format!("line {n}: a list's count must be an integer in '{line}'").into());
                }
                el.props.push(Property { name: name.to_string(), ty: it, list: Some(ct) });
            }
            ["property", ty, name] => {
                let el = elements.last_mut().ok_or(format!("line {n}: property before any element"))?;
                let ty = Ty::parse(ty).ok_or(format!("line {n}: unknown property type '{ty}'"))?;
                el.props.push(Property { name: name.to_string(), ty, list: None });
            }
            ["end_header"] => break,
            _ => return Err(format!("line {n}: '{line}' is not a header line").into()),
        }
    }
    let enc = enc.ok_or("no 'format' line")?;
    Ok((enc, elements, i))
}

struct Cursor<'a> {
    b: &'a [u8],
    i: usize,
    enc: Encoding,
}

impl Cursor<'_> {
    /// The next ASCII token; `None` at the end.
    fn token(&mut self) -> Option<&[u8]> {
        ascii::next_token(self.b, &mut self.i)
    }

    /// The next binary value's bytes; `None` at the end.
    fn value(&mut self, ty: Ty) -> Option<&[u8]> {
        let s = self.b.get(self.i..self.i + ty.size())?;
        self.i += ty.size();
        Some(s)
    }

    /// A value as f32 (a double rounded once). Err(true): not a number, Err(false): the end.
    fn float(&mut self, ty: Ty) -> std::result::Result<f32, bool> {
        if self.enc == Encoding::Ascii {
            let t = self.token().ok_or(false)?;
            return parse_f32(t).ok_or(true);
        }
        let big = self.enc == Encoding::Big;
        Ok(binary::float(self.value(ty).ok_or(false)?, ty, big))
    }

    /// An integer value (floats are refused where integers are needed).
    fn int(&mut self, ty: Ty) -> std::result::Result<i64, bool> {
        if self.enc == Encoding::Ascii {
            let t = self.token().ok_or(false)?;
            return ascii::int(t).ok_or(true);
        }
        if matches!(ty, Ty::F32 | Ty::F64) {
            return Err(true);
        }
        let big = self.enc == Encoding::Big;
        Ok(binary::int(self.value(ty).ok_or(false)?, ty, big))
    }

    fn skip(&mut self, ty: Ty) -> Option<()> {
        if self.enc == Encoding::Ascii {
            return self.token().map(|_| ());
        }
        let n = ty.size();
        (self.i + n <= self.b.len()).then(|| self.i += n)
    }

    fn skip_list(&mut self, p: &Property) -> Option<()> {
        let n = self.int(p.list?).ok()?;
        if n < 0 {
            return None;
        }
        for _ in 0..n {
            self.skip(p.ty)?;
        }
        Some(())
    }
}

#[cfg(test)]
#[path = "tests.rs"]
mod tests;
