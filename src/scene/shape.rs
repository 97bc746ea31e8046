//! The one reading rule for a glTF document's JSON: every value bumpbake reads, or renumbers on
//! writing, has the type the glTF 2.0 schema gives it, and every index names an entry that
//! exists.
//!
//! The readers run [`check_and_settle`] once, before anything else looks at the document, so
//! every command refuses the same files with the same message (a JSON pointer and what was found
//! there), and the code after it may take the shapes it reads for granted without ever
//! panicking. A whole number written with a fraction (`1.0`) where the schema wants an integer is
//! that integer: it is rewritten as one there, and only there. What the
//! rule does not cover (unknown extensions, `extras`, cameras' fields) is passed through as read.
//! Values the schema makes optional are only checked when present.

use serde_json::{Map, Value};
use std::cell::RefCell;
use std::collections::HashSet;

/// Where a document breaks the rule, as one line: `meshes/4/primitives/0: expected an object,
/// found an array`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ShapeError(pub String);

impl std::fmt::Display for ShapeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

type Checked = Result<(), ShapeError>;

/// The document's top-level lists, each an array of objects.
const LISTS: &[&str] = &[
    "accessors",
    "animations",
    "buffers",
    "bufferViews",
    "cameras",
    "images",
    "materials",
    "meshes",
    "nodes",
    "samplers",
    "scenes",
    "skins",
    "textures",
];

/// Highest primitive mode glTF defines (TRIANGLE_FAN).
const MAX_MODE: u64 = 6;

/// Checks the document against the reading rule.
pub fn check(json: &Value) -> Checked {
    written_as_fractions(json).map(|_| ())
}

/// Checks the document and rewrites every whole number it holds where the schema wants an
/// integer but the file wrote a fraction (`1.0`, `3e0`) as that integer, so that the code after
/// it reads integers one way. Numbers anywhere else are left as written.
pub fn check_and_settle(json: &mut Value) -> Checked {
    let settle = written_as_fractions(json)?;
    if !settle.is_empty() {
        settle_integers(json, &settle);
    }
    Ok(())
}

/// The identities (addresses) of the integer-typed values written with a fraction; `json` is
/// not changed between collecting and rewriting them, so the addresses stay those values'.
fn written_as_fractions(json: &Value) -> Result<HashSet<usize>, ShapeError> {
    let root = json.as_object().ok_or_else(|| ShapeError("the glTF JSON is not an object".into()))?;
    let c = Checker { root, fractions: RefCell::new(HashSet::new()) };
    for key in LISTS {
        if let Some(v) = root.get(*key) {
            for (i, item) in c.array(v, key)?.iter().enumerate() {
                c.object(item, &format!("{key}/{i}"))?;
            }
        }
    }
    for key in ["extensionsUsed", "extensionsRequired"] {
        if let Some(v) = root.get(key) {
            for (i, e) in c.array(v, key)?.iter().enumerate() {
                if !e.is_string() {
                    return Err(found(&format!("{key}/{i}"), "a string", e));
                }
            }
        }
    }
    if let Some(s) = root.get("scene") {
        c.index(s, "scene", "scenes")?;
    }
    c.each("accessors", Checker::accessor)?;
    c.each("bufferViews", Checker::buffer_view)?;
    c.each("buffers", Checker::buffer)?;
    c.each("images", Checker::image)?;
    c.each("textures", Checker::texture)?;
    c.each("samplers", Checker::sampler)?;
    c.each("materials", Checker::material)?;
    c.each("meshes", Checker::mesh)?;
    c.each("nodes", Checker::node)?;
    c.each("scenes", Checker::scene)?;
    c.each("skins", Checker::skin)?;
    c.each("animations", Checker::animation)?;
    Ok(c.fractions.into_inner())
}

fn settle_integers(v: &mut Value, settle: &HashSet<usize>) {
    if settle.contains(&(v as *const Value as usize)) {
        if let Some(n) = whole(v) {
            *v = Value::from(n);
        }
        return;
    }
    match v {
        Value::Array(a) => a.iter_mut().for_each(|x| settle_integers(x, settle)),
        Value::Object(o) => o.values_mut().for_each(|x| settle_integers(x, settle)),
        _ => {}
    }
}

/// Largest whole number a fraction may be written as and still be read exactly (2^53, the
/// limit JSON readers that hold numbers as doubles share).
const MAX_EXACT: f64 = 9_007_199_254_740_992.0;

/// `v` as a whole number 0 or more, however it is written: `1`, `1.0` and `1e0` are one value
/// (JSON has one number type; the glTF validator reads them alike). Fractions past 2^53 are
/// refused rather than rounded.
fn whole(v: &Value) -> Option<u64> {
    v.as_u64().or_else(|| {
        let f = v.as_f64().filter(|_| !v.is_i64())?;
        (f.fract() == 0.0 && (0.0..=MAX_EXACT).contains(&f)).then_some(f as u64)
    })
}

fn kind(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

fn found(at: &str, expected: &str, v: &Value) -> ShapeError {
    let what = match v {
        Value::Number(n) => format!("{n}"),
        Value::String(s) if s.len() <= 40 => format!("the string \"{s}\""),
        _ => kind(v).to_string(),
    };
    ShapeError(format!("{at}: expected {expected}, found {what}"))
}

struct Checker<'a> {
    root: &'a Map<String, Value>,
    /// Integer-typed values the file wrote with a fraction, by address.
    fractions: RefCell<HashSet<usize>>,
}

impl Checker<'_> {
    fn len(&self, list: &str) -> usize {
        self.root.get(list).and_then(Value::as_array).map_or(0, Vec::len)
    }

    fn each(&self, list: &str, f: fn(&Self, &Map<String, Value>, &str) -> Checked) -> Checked {
        for (i, item) in self.root.get(list).and_then(Value::as_array).into_iter().flatten().enumerate() {
            if let Some(o) = item.as_object() {
                f(self, o, &format!("{list}/{i}"))?;
            }
        }
        Ok(())
    }

    fn object<'v>(&self, v: &'v Value, at: &str) -> Result<&'v Map<String, Value>, ShapeError> {
        v.as_object().ok_or_else(|| found(at, "an object", v))
    }

    fn array<'v>(&self, v: &'v Value, at: &str) -> Result<&'v Vec<Value>, ShapeError> {
        v.as_array().ok_or_else(|| found(at, "an array", v))
    }

    fn uint(&self, v: &Value, at: &str) -> Result<u64, ShapeError> {
        self.whole(v).ok_or_else(|| found(at, "a whole number 0 or more", v))
    }

    /// An index into the top-level list `list`.
    fn index(&self, v: &Value, at: &str, list: &str) -> Checked {
        let i = self.whole(v).ok_or_else(|| found(at, "an index (a whole number 0 or more)", v))?;
        self.in_range(i, at, list)
    }

    fn whole(&self, v: &Value) -> Option<u64> {
        let n = whole(v)?;
        if !v.is_u64() {
            self.fractions.borrow_mut().insert(v as *const Value as usize);
        }
        Some(n)
    }

    fn in_range(&self, i: u64, at: &str, list: &str) -> Checked {
        let n = self.len(list);
        if i >= n as u64 {
            let has = match n {
                0 => format!("the file has no {list}"),
                _ => format!("the file has {n}"),
            };
            return Err(ShapeError(format!("{at}: {list} {i} does not exist ({has})")));
        }
        Ok(())
    }

    /// The optional members of `o` named in `fields`, each of its kind.
    fn fields(&self, o: &Map<String, Value>, at: &str, fields: &[(&str, Kind)]) -> Checked {
        for (key, k) in fields {
            if let Some(v) = o.get(*key) {
                self.value(v, &format!("{at}/{key}"), *k)?;
            }
        }
        Ok(())
    }

    fn value(&self, v: &Value, at: &str, k: Kind) -> Checked {
        match k {
            Kind::Uint => self.uint(v, at).map(|_| ()),
            Kind::Index(list) => self.index(v, at, list),
            Kind::Number => v.as_f64().map(|_| ()).ok_or_else(|| found(at, "a number", v)),
            Kind::Bool => v.as_bool().map(|_| ()).ok_or_else(|| found(at, "true or false", v)),
            Kind::Str => v.as_str().map(|_| ()).ok_or_else(|| found(at, "a string", v)),
            Kind::Object => self.object(v, at).map(|_| ()),
            Kind::Numbers => {
                for (i, x) in self.array(v, at)?.iter().enumerate() {
                    if !x.is_number() {
                        return Err(found(&format!("{at}/{i}"), "a number", x));
                    }
                }
                Ok(())
            }
            Kind::Indices(list) => {
                for (i, x) in self.array(v, at)?.iter().enumerate() {
                    self.index(x, &format!("{at}/{i}"), list)?;
                }
                Ok(())
            }
            Kind::IndexMap(list) => {
                for (key, x) in self.object(v, at)? {
                    self.index(x, &format!("{at}/{key}"), list)?;
                }
                Ok(())
            }
            Kind::Uints => {
                for (i, x) in self.array(v, at)?.iter().enumerate() {
                    self.uint(x, &format!("{at}/{i}"))?;
                }
                Ok(())
            }
        }
    }

    /// An extension object of `o`, if present: `o.extensions` and its member must be objects.
    fn extension<'v>(
        &self,
        o: &'v Map<String, Value>,
        at: &str,
        name: &str,
    ) -> Result<Option<&'v Map<String, Value>>, ShapeError> {
        let Some(exts) = o.get("extensions") else { return Ok(None) };
        let exts = self.object(exts, &format!("{at}/extensions"))?;
        match exts.get(name) {
            Some(e) => self.object(e, &format!("{at}/extensions/{name}")).map(Some),
            None => Ok(None),
        }
    }

    fn accessor(&self, o: &Map<String, Value>, at: &str) -> Checked {
        use Kind::*;
        self.fields(
            o,
            at,
            &[
                ("bufferView", Index("bufferViews")),
                ("byteOffset", Uint),
                ("componentType", Uint),
                ("normalized", Bool),
                ("count", Uint),
                ("type", Str),
                ("min", Numbers),
                ("max", Numbers),
                ("sparse", Object),
            ],
        )?;
        if let Some(sp) = o.get("sparse").and_then(Value::as_object) {
            let at = format!("{at}/sparse");
            self.fields(sp, &at, &[("count", Uint), ("indices", Object), ("values", Object)])?;
            let view = [("bufferView", Index("bufferViews")), ("byteOffset", Uint), ("componentType", Uint)];
            if let Some(i) = sp.get("indices").and_then(Value::as_object) {
                self.fields(i, &format!("{at}/indices"), &view)?;
            }
            if let Some(v) = sp.get("values").and_then(Value::as_object) {
                self.fields(v, &format!("{at}/values"), &view[..2])?;
            }
        }
        Ok(())
    }

    fn buffer_view(&self, o: &Map<String, Value>, at: &str) -> Checked {
        use Kind::*;
        self.fields(
            o,
            at,
            &[
                ("buffer", Index("buffers")),
                ("byteOffset", Uint),
                ("byteLength", Uint),
                ("byteStride", Uint),
                ("target", Uint),
            ],
        )?;
        if let Some(m) = self.extension(o, at, "EXT_meshopt_compression")? {
            let at = format!("{at}/extensions/EXT_meshopt_compression");
            self.fields(
                m,
                &at,
                &[
                    ("buffer", Index("buffers")),
                    ("byteOffset", Uint),
                    ("byteLength", Uint),
                    ("byteStride", Uint),
                    ("count", Uint),
                    ("mode", Str),
                    ("filter", Str),
                ],
            )?;
        }
        Ok(())
    }

    fn buffer(&self, o: &Map<String, Value>, at: &str) -> Checked {
        self.fields(o, at, &[("uri", Kind::Str), ("byteLength", Kind::Uint)])
    }

    fn image(&self, o: &Map<String, Value>, at: &str) -> Checked {
        self.fields(o, at, &[("uri", Kind::Str), ("mimeType", Kind::Str), ("bufferView", Kind::Index("bufferViews"))])
    }

    fn texture(&self, o: &Map<String, Value>, at: &str) -> Checked {
        self.fields(o, at, &[("sampler", Kind::Index("samplers")), ("source", Kind::Index("images"))])?;
        for ext in super::refs::IMAGE_SOURCE_EXTENSIONS {
            if let Some(e) = self.extension(o, at, ext)? {
                self.fields(e, &format!("{at}/extensions/{ext}"), &[("source", Kind::Index("images"))])?;
            }
        }
        Ok(())
    }

    fn sampler(&self, o: &Map<String, Value>, at: &str) -> Checked {
        let u = Kind::Uint;
        self.fields(o, at, &[("magFilter", u), ("minFilter", u), ("wrapS", u), ("wrapT", u)])
    }

    fn material(&self, o: &Map<String, Value>, at: &str) -> Checked {
        use Kind::*;
        self.fields(
            o,
            at,
            &[
                ("pbrMetallicRoughness", Object),
                ("emissiveFactor", Numbers),
                ("alphaMode", Str),
                ("alphaCutoff", Number),
                ("doubleSided", Bool),
                ("extensions", Object),
            ],
        )?;
        if let Some(pbr) = o.get("pbrMetallicRoughness").and_then(Value::as_object) {
            let at = format!("{at}/pbrMetallicRoughness");
            self.fields(
                pbr,
                &at,
                &[("baseColorFactor", Numbers), ("metallicFactor", Number), ("roughnessFactor", Number)],
            )?;
        }
        self.texture_infos(o, at)
    }

    /// Every texture-info object of a material, at any depth (extensions' too), found as
    /// [`super::refs::texture_info_pointers`] finds them: a key ending in `Texture`.
    fn texture_infos(&self, o: &Map<String, Value>, at: &str) -> Checked {
        for (key, v) in o {
            let here = format!("{at}/{key}");
            if key.ends_with("Texture") {
                let info = self.object(v, &here)?;
                self.fields(
                    info,
                    &here,
                    &[
                        ("index", Kind::Index("textures")),
                        ("texCoord", Kind::Uint),
                        ("scale", Kind::Number),
                        ("strength", Kind::Number),
                    ],
                )?;
                if let Some(t) = self.extension(info, &here, "KHR_texture_transform")? {
                    let at = format!("{here}/extensions/KHR_texture_transform");
                    let k = &[
                        ("offset", Kind::Numbers),
                        ("rotation", Kind::Number),
                        ("scale", Kind::Numbers),
                        ("texCoord", Kind::Uint),
                    ];
                    self.fields(t, &at, k)?;
                }
            }
            if let Some(child) = v.as_object() {
                self.texture_infos(child, &here)?;
            }
        }
        Ok(())
    }

    fn mesh(&self, o: &Map<String, Value>, at: &str) -> Checked {
        self.fields(o, at, &[("weights", Kind::Numbers)])?;
        let Some(prims) = o.get("primitives") else { return Ok(()) };
        for (i, p) in self.array(prims, &format!("{at}/primitives"))?.iter().enumerate() {
            let at = format!("{at}/primitives/{i}");
            let p = self.object(p, &at)?;
            self.primitive(p, &at)?;
        }
        Ok(())
    }

    fn primitive(&self, p: &Map<String, Value>, at: &str) -> Checked {
        use Kind::*;
        self.fields(
            p,
            at,
            &[
                ("attributes", IndexMap("accessors")),
                ("indices", Index("accessors")),
                ("material", Index("materials")),
                ("mode", Uint),
            ],
        )?;
        if let Some(m) = p.get("mode").and_then(whole).filter(|&m| m > MAX_MODE) {
            return Err(ShapeError(format!("{at}/mode: {m} is not a glTF primitive mode (0 to 6)")));
        }
        if let Some(ts) = p.get("targets") {
            for (i, t) in self.array(ts, &format!("{at}/targets"))?.iter().enumerate() {
                self.value(t, &format!("{at}/targets/{i}"), IndexMap("accessors"))?;
            }
        }
        if let Some(v) = self.extension(p, at, "KHR_materials_variants")? {
            let at = format!("{at}/extensions/KHR_materials_variants");
            if let Some(ms) = v.get("mappings") {
                for (i, m) in self.array(ms, &format!("{at}/mappings"))?.iter().enumerate() {
                    let at = format!("{at}/mappings/{i}");
                    let m = self.object(m, &at)?;
                    self.fields(m, &at, &[("material", Index("materials")), ("variants", Uints)])?;
                }
            }
        }
        if let Some(d) = self.extension(p, at, "KHR_draco_mesh_compression")? {
            let at = format!("{at}/extensions/KHR_draco_mesh_compression");
            self.fields(d, &at, &[("bufferView", Index("bufferViews")), ("attributes", Object)])?;
            for (k, v) in d.get("attributes").and_then(Value::as_object).into_iter().flatten() {
                self.uint(v, &format!("{at}/attributes/{k}"))?;
            }
        }
        Ok(())
    }

    fn node(&self, o: &Map<String, Value>, at: &str) -> Checked {
        use Kind::*;
        self.fields(
            o,
            at,
            &[
                ("children", Indices("nodes")),
                ("mesh", Index("meshes")),
                ("skin", Index("skins")),
                ("camera", Index("cameras")),
                ("matrix", Numbers),
                ("rotation", Numbers),
                ("scale", Numbers),
                ("translation", Numbers),
                ("weights", Numbers),
            ],
        )?;
        for (key, n) in [("matrix", 16), ("rotation", 4), ("scale", 3), ("translation", 3)] {
            if let Some(a) = o.get(key).and_then(Value::as_array).filter(|a| a.len() != n) {
                return Err(ShapeError(format!("{at}/{key}: expected {n} numbers, found {}", a.len())));
            }
        }
        if let Some(g) = self.extension(o, at, "EXT_mesh_gpu_instancing")? {
            let at = format!("{at}/extensions/EXT_mesh_gpu_instancing");
            self.fields(g, &at, &[("attributes", IndexMap("accessors"))])?;
        }
        Ok(())
    }

    fn scene(&self, o: &Map<String, Value>, at: &str) -> Checked {
        self.fields(o, at, &[("nodes", Kind::Indices("nodes"))])
    }

    fn skin(&self, o: &Map<String, Value>, at: &str) -> Checked {
        use Kind::*;
        self.fields(
            o,
            at,
            &[("inverseBindMatrices", Index("accessors")), ("joints", Indices("nodes")), ("skeleton", Index("nodes"))],
        )
    }

    fn animation(&self, o: &Map<String, Value>, at: &str) -> Checked {
        let samplers = match o.get("samplers") {
            Some(s) => self.array(s, &format!("{at}/samplers"))?.as_slice(),
            None => &[],
        };
        for (i, s) in samplers.iter().enumerate() {
            let at = format!("{at}/samplers/{i}");
            let s = self.object(s, &at)?;
            let acc = Kind::Index("accessors");
            self.fields(s, &at, &[("input", acc), ("output", acc), ("interpolation", Kind::Str)])?;
        }
        if let Some(cs) = o.get("channels") {
            for (i, ch) in self.array(cs, &format!("{at}/channels"))?.iter().enumerate() {
                let at = format!("{at}/channels/{i}");
                let ch = self.object(ch, &at)?;
                self.fields(ch, &at, &[("sampler", Kind::Uint), ("target", Kind::Object)])?;
                if let Some(s) = ch.get("sampler").and_then(whole).filter(|&s| s >= samplers.len() as u64) {
                    return Err(ShapeError(format!("{at}/sampler: the animation has no sampler {s}")));
                }
                if let Some(t) = ch.get("target").and_then(Value::as_object) {
                    self.fields(t, &format!("{at}/target"), &[("node", Kind::Index("nodes")), ("path", Kind::Str)])?;
                }
            }
        }
        Ok(())
    }
}

#[derive(Debug, Clone, Copy)]
enum Kind {
    Uint,
    Index(&'static str),
    Number,
    Bool,
    Str,
    Object,
    Numbers,
    Uints,
    Indices(&'static str),
    IndexMap(&'static str),
}

/// Unit tests build documents that name textures, images or samplers they leave out; this adds
/// empty ones until every such reference resolves.
#[cfg(test)]
pub(crate) fn pad_references(json: &mut Value) {
    while let Err(ShapeError(e)) = check(json) {
        let Some((list, rest)) = e.split_once(": ").and_then(|(_, r)| r.split_once(' ')) else { return };
        let Some(n) = rest.split(' ').next().and_then(|n| n.parse::<usize>().ok()) else { return };
        if !["textures", "images", "samplers"].contains(&list) {
            return;
        }
        let a = super::array_mut(json, list);
        a.resize(n + 1, serde_json::json!({}));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::set_key;
    use serde_json::json;

    fn base() -> Value {
        json!({
            "asset": { "version": "2.0" },
            "accessors": [{ "componentType": 5126, "count": 3, "type": "VEC3" }],
            "materials": [{ "normalTexture": { "index": 0 } }],
            "textures": [{ "source": 0 }],
            "images": [{ "uri": "a.png" }],
            "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 }, "material": 0 }] }],
            "nodes": [{ "mesh": 0, "children": [] }],
            "scenes": [{ "nodes": [0] }],
        })
    }

    fn err(mutate: impl FnOnce(&mut Value)) -> String {
        let mut j = base();
        mutate(&mut j);
        check(&j).expect_err("refused").0
    }

    #[test]
    fn a_well_formed_document_passes() {
        assert_eq!(check(&base()), Ok(()));
    }

    #[test]
    fn the_pointer_and_what_was_found_are_named() {
        let e = err(|j| *j.pointer_mut("/meshes/0/primitives/0").unwrap() = json!([]));
        assert_eq!(e, "meshes/0/primitives/0: expected an object, found an array");
        let e = err(|j| *j.pointer_mut("/meshes/0/primitives/0/material").unwrap() = json!(-1));
        assert_eq!(e, "meshes/0/primitives/0/material: expected an index (a whole number 0 or more), found -1");
        let e = err(|j| *j.pointer_mut("/materials/0/normalTexture/index").unwrap() = json!(4294967296u64));
        assert_eq!(e, "materials/0/normalTexture/index: textures 4294967296 does not exist (the file has 1)");
        let e = err(|j| *j.pointer_mut("/nodes/0/children").unwrap() = json!([1]));
        assert_eq!(e, "nodes/0/children/0: nodes 1 does not exist (the file has 1)");
        let e = err(|j| *j.pointer_mut("/materials/0/normalTexture").unwrap() = json!("x"));
        assert_eq!(e, "materials/0/normalTexture: expected an object, found the string \"x\"");
        let e = err(|j| set_key(j.pointer_mut("/meshes/0/primitives/0").unwrap(), "mode", json!(7)));
        assert_eq!(e, "meshes/0/primitives/0/mode: 7 is not a glTF primitive mode (0 to 6)");
        let e = err(|j| *j.pointer_mut("/accessors").unwrap() = json!(null));
        assert_eq!(e, "accessors: expected an array, found null");
        let e = err(|j| *j.pointer_mut("/meshes/0/primitives/0/material").unwrap() = json!(0.5));
        assert_eq!(e, "meshes/0/primitives/0/material: expected an index (a whole number 0 or more), found 0.5");
        let e = err(|j| set_key(j.pointer_mut("/meshes/0/primitives/0").unwrap(), "mode", json!(7.0)));
        assert_eq!(e, "meshes/0/primitives/0/mode: 7 is not a glTF primitive mode (0 to 6)");
        let e = err(|j| *j.pointer_mut("/accessors/0/count").unwrap() = json!(1e300));
        assert_eq!(e, "accessors/0/count: expected a whole number 0 or more, found 1e+300");
    }

    #[test]
    fn whole_numbers_written_as_fractions_become_integers_where_the_schema_wants_one() {
        let mut j = base();
        *j.pointer_mut("/accessors/0/count").unwrap() = json!(3.0);
        *j.pointer_mut("/meshes/0/primitives/0/material").unwrap() = json!(0.0);
        *j.pointer_mut("/nodes/0/children").unwrap() = json!([]);
        *j.pointer_mut("/scenes/0/nodes/0").unwrap() = json!(-0.0);
        set_key(j.pointer_mut("/meshes/0/primitives/0/attributes").unwrap(), "A/B~", json!(0.0));
        set_key(j.pointer_mut("/materials/0").unwrap(), "alphaCutoff", json!(1.0));
        assert_eq!(check_and_settle(&mut j), Ok(()));
        let ints = ["/accessors/0/count", "/meshes/0/primitives/0/material", "/scenes/0/nodes/0"];
        for p in ints.into_iter().chain(["/meshes/0/primitives/0/attributes/A~1B~0"]) {
            assert!(j.pointer(p).unwrap().is_u64(), "{p}: {}", j.pointer(p).unwrap());
        }
        assert_eq!(j["accessors"][0]["count"], json!(3));
        // A float the schema wants as a float keeps its spelling.
        assert_eq!(serde_json::to_string(&j["materials"][0]["alphaCutoff"]).unwrap(), "1.0");
    }
}
