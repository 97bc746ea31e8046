//! Fixture builders for tests/validate.rs: small glTF primitives to break one way at a time, and
//! normal maps made from analytic height fields (the conventions' encoding, central differences).
#![allow(dead_code)]

use crate::common::*;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// Runs `validate --format json` and returns the exit code and the parsed report. The same
/// command with `--format sarif` runs too: its log must pass the SARIF 2.1.0 schema and carry the
/// same findings ([`assert_sarif_matches`]), so every file these tests validate checks both.
pub fn validate(args: &[&str]) -> (i32, Value) {
    let (code, v) = validate_as("json", args);
    let (sarif_code, log) = validate_as("sarif", args);
    assert_eq!(sarif_code, code, "same exit code with --format sarif: {args:?}");
    assert_sarif_matches(&log, &v);
    (code, v)
}

/// Runs `validate --format FORMAT -q ARGS` and parses stdout as JSON.
pub fn validate_as(format: &str, args: &[&str]) -> (i32, Value) {
    let mut a = vec!["validate", "--format", format, "-q"];
    a.extend_from_slice(args);
    let out = run(&a);
    let code = out.status.code().expect("exit code");
    let v: Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!("{format} ({e}): {}\n{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr))
    });
    (code, v)
}

/// The SARIF 2.1.0 schema (OASIS errata 01, vendored in fixtures/sarif), compiled once.
pub fn sarif_schema() -> &'static jsonschema::Validator {
    static V: std::sync::OnceLock<jsonschema::Validator> = std::sync::OnceLock::new();
    V.get_or_init(|| {
        let text = std::fs::read_to_string(fixture("sarif/sarif-schema-2.1.0.json")).unwrap();
        let schema: Value = serde_json::from_str(&text).unwrap();
        jsonschema::validator_for(&schema).expect("the SARIF schema compiles")
    })
}

/// Asserts that a SARIF log passes the schema, listing every violation.
pub fn assert_sarif_valid(log: &Value) {
    let errors: Vec<String> =
        sarif_schema().iter_errors(log).map(|e| format!("{} at {}", e, e.instance_path())).collect();
    assert!(errors.is_empty(), "SARIF schema violations:\n{}\n{log:#}", errors.join("\n"));
}

/// Undoes the percent-escapes of a URI.
pub fn unescape_uri(u: &str) -> String {
    let b = u.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            out.push(u8::from_str_radix(&u[i + 1..i + 3], 16).expect("hex escape"));
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).unwrap()
}

/// The SARIF level a JSON severity maps to.
pub fn sarif_level(severity: &str) -> &'static str {
    match severity {
        "error" => "error",
        "warning" => "warning",
        "info" => "note",
        other => panic!("unknown severity {other}"),
    }
}

/// Asserts that a SARIF log is valid and carries exactly the JSON report's findings, in order:
/// rule, level, message, the file, and the glTF element as a logical location.
pub fn assert_sarif_matches(log: &Value, report: &Value) {
    assert_sarif_valid(log);
    assert_eq!(log["version"], "2.1.0");
    let run = &log["runs"][0];
    let rules = run["tool"]["driver"]["rules"].as_array().unwrap();
    let artifacts = run["artifacts"].as_array().unwrap();
    let files = report["files"].as_array().unwrap();
    assert_eq!(artifacts.len(), files.len(), "one artifact per file: {log:#}");
    for (a, f) in artifacts.iter().zip(files) {
        let path = f["path"].as_str().unwrap();
        let uri = unescape_uri(a["location"]["uri"].as_str().unwrap());
        let expected = if path.starts_with('/') { format!("file://{path}") } else { path.to_string() };
        assert_eq!(uri, expected);
    }
    let mut expected = Vec::new();
    for (fi, f) in files.iter().enumerate() {
        for s in f["subjects"].as_array().unwrap() {
            for x in s["findings"].as_array().unwrap() {
                expected.push((fi, s, x));
            }
        }
    }
    let results = run["results"].as_array().unwrap();
    assert_eq!(results.len(), expected.len(), "one result per finding: {log:#}\n{report:#}");
    for (res, (fi, sub, x)) in results.iter().zip(expected) {
        let code = x["code"].as_str().unwrap();
        assert_eq!(res["ruleId"], code);
        assert_eq!(rules[res["ruleIndex"].as_u64().unwrap() as usize]["id"], code, "ruleIndex points at the rule");
        assert_eq!(res["level"], sarif_level(x["severity"].as_str().unwrap()), "{res:#}");
        let text = res["message"]["text"].as_str().unwrap();
        assert!(text.contains(x["message"].as_str().unwrap()) && text.contains(x["hint"].as_str().unwrap()), "{text}");
        assert_eq!((&res["properties"]["count"], &res["properties"]["total"]), (&x["count"], &x["total"]));
        let loc = &res["locations"][0];
        assert_eq!(loc["physicalLocation"]["artifactLocation"]["index"], fi);
        assert_eq!(loc["physicalLocation"]["artifactLocation"]["uri"], artifacts[fi]["location"]["uri"]);
        let logical: Vec<&str> = loc["logicalLocations"]
            .as_array()
            .map(|l| l.iter().map(|l| l["fullyQualifiedName"].as_str().unwrap()).collect())
            .unwrap_or_default();
        let want: Vec<String> = match (sub["mesh"].as_u64(), sub["primitive"].as_u64(), sub["image"].as_u64()) {
            (Some(m), Some(p), _) => vec![format!("meshes/{m}/primitives/{p}")],
            (_, _, Some(i)) => vec![format!("images/{i}")],
            _ => x["examples"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|e| e["kind"] == "node")
                .map(|e| format!("nodes/{}", e["index"]))
                .collect(),
        };
        assert_eq!(logical, want, "{res:#}");
    }
}

/// Every finding as (code, severity).
pub fn findings(report: &Value) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for f in report["files"].as_array().unwrap() {
        for s in f["subjects"].as_array().unwrap() {
            for x in s["findings"].as_array().unwrap() {
                out.push((x["code"].as_str().unwrap().to_string(), x["severity"].as_str().unwrap().to_string()));
            }
        }
    }
    out
}

pub fn finding<'a>(report: &'a Value, code: &str) -> &'a Value {
    report["files"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|f| f["subjects"].as_array().unwrap())
        .flat_map(|s| s["findings"].as_array().unwrap())
        .find(|x| x["code"] == code)
        .unwrap_or_else(|| panic!("no {code} in {report:#}"))
}

/// Asserts that the report holds exactly one finding, `code` at `severity`.
pub fn assert_only(report: &Value, code: &str, severity: &str) {
    let f = findings(report);
    assert_eq!(f, vec![(code.to_string(), severity.to_string())], "expected only {code}: {report:#}");
}

/// Encodes a normal as the conventions say: round to nearest, 8 bits.
pub fn encode(n: [f64; 3]) -> [u8; 3] {
    n.map(|c| ((c * 0.5 + 0.5) * 255.0).round().clamp(0.0, 255.0) as u8)
}

/// A tangent-space normal map from an analytic height field `h(x, y_up)` (texel units),
/// central differences, clamped edges; `directx` negates n.y before encoding.
pub fn normal_map(w: u32, h: u32, strength: f64, directx: bool, height: impl Fn(f64, f64) -> f64) -> image::RgbImage {
    let hv = |x: i64, row: i64| {
        let x = x.clamp(0, w as i64 - 1) as f64;
        let row = row.clamp(0, h as i64 - 1);
        height(x, (h as i64 - 1 - row) as f64)
    };
    image::RgbImage::from_fn(w, h, |x, row| {
        let (x, row) = (x as i64, row as i64);
        let dx = (hv(x + 1, row) - hv(x - 1, row)) * 0.5;
        let dy_up = (hv(x, row - 1) - hv(x, row + 1)) * 0.5;
        let v = [-strength * dx, -strength * dy_up, 1.0];
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let mut n = [v[0] / l, v[1] / l, v[2] / l];
        if directx {
            n[1] = -n[1];
        }
        image::Rgb(encode(n))
    })
}

pub fn png_bytes(img: &image::RgbImage) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// A bumpy OpenGL normal map, so that clean fixtures have nothing to report about their image.
pub fn bumpy(directx: bool) -> image::RgbImage {
    normal_map(32, 32, 1.0, directx, |x, y| 4.0 * (x / 5.0).sin() * (y / 4.0).cos())
}

/// Adds a texture whose image is `img` (as a data URI); returns the texture index.
pub fn texture_of(g: &mut Gltf, img: &image::RgbImage) -> usize {
    use base64::Engine as _;
    let t = g.texture();
    let src = g.json["textures"][t]["source"].as_u64().unwrap() as usize;
    g.json["images"][src]["uri"] =
        json!(format!("data:image/png;base64,{}", base64::engine::general_purpose::STANDARD.encode(png_bytes(img))));
    t
}

/// Geometry of one primitive, all attributes optional but POSITION.
#[derive(Clone)]
pub struct Prim {
    pub pos: Vec<[f32; 3]>,
    pub nrm: Option<Vec<[f32; 3]>>,
    pub uv: Option<Vec<[f32; 2]>>,
    pub tan: Option<Vec<[f32; 4]>>,
    pub idx: Vec<u16>,
}

/// The 2x2 grid of tests/common facing +Z with glTF UVs; its MikkTSpace tangent is (1, 0, 0, +1).
pub fn grid_prim() -> Prim {
    let (pos, nrm, uv, idx) = grid(2);
    let tan = vec![[1.0, 0.0, 0.0, 1.0]; pos.len()];
    Prim { pos, nrm: Some(nrm), uv: Some(uv), tan: Some(tan), idx }
}

/// Writes one primitive (with a bumpy normal texture when `map`) to `dir/name.glb`.
pub fn write_prim(dir: &Path, name: &str, p: &Prim, map: bool) -> PathBuf {
    let mut g = Gltf::new();
    let attrs = attrs_of(&mut g, p);
    let i = g.indices(&p.idx);
    let mut prim = json!({ "attributes": attrs, "indices": i });
    if map {
        let tex = texture_of(&mut g, &bumpy(false));
        prim["material"] = json!(g.material(json!({ "normalTexture": { "index": tex } })));
    }
    g.mesh(prim);
    let path = dir.join(format!("{name}.glb"));
    g.write_glb(&path);
    path
}

/// Builds a broken variant of the grid in a scratch folder and validates it.
pub fn broken(name: &str, p: &Prim, map: bool, extra: &[&str]) -> (i32, Value) {
    let d = scratch_dir(&format!("validate_{name}"));
    let path = write_prim(&d, name, p, map);
    let mut args = vec![s(&path)];
    args.extend_from_slice(extra);
    validate(&args)
}

/// The attributes of `p` as accessors of `g`, for tests that build their own primitive JSON.
pub fn attrs_of(g: &mut Gltf, p: &Prim) -> Value {
    let mut attrs = json!({ "POSITION": g.floats(&p.pos, Some(34962)) });
    if let Some(n) = &p.nrm {
        attrs["NORMAL"] = json!(g.floats(n, Some(34962)));
    }
    if let Some(t) = &p.uv {
        attrs["TEXCOORD_0"] = json!(g.floats(t, Some(34962)));
    }
    if let Some(t) = &p.tan {
        attrs["TANGENT"] = json!(g.floats(t, Some(34962)));
    }
    attrs
}

/// A wavy `n x n` grid (2n² triangles, 32-bit indices, smooth normals, a normal texture, no
/// tangents), for timing `validate` against `tangents`.
pub fn write_big_grid(path: &Path, n: usize) {
    let mut pos = Vec::new();
    let mut uv = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
            pos.push([x, y, 0.05 * (x * 40.0).sin() * (y * 30.0).cos()]);
            uv.push([x, 1.0 - y]);
        }
    }
    let w = (n + 1) as u32;
    let mut idx: Vec<u32> = Vec::new();
    for j in 0..n as u32 {
        for i in 0..n as u32 {
            let a = j * w + i;
            idx.extend([a, a + 1, a + w + 1, a, a + w + 1, a + w]);
        }
    }
    // The analytic normals of the wave.
    let nrm: Vec<[f32; 3]> = pos
        .iter()
        .map(|p| {
            let (dx, dy) =
                (2.0 * (p[0] * 40.0).cos() * (p[1] * 30.0).cos(), -1.5 * (p[0] * 40.0).sin() * (p[1] * 30.0).sin());
            let l = (dx * dx + dy * dy + 1.0f32).sqrt();
            [-dx / l, -dy / l, 1.0 / l]
        })
        .collect();
    let mut g = Gltf::new();
    let p = g.floats(&pos, Some(34962));
    let nn = g.floats(&nrm, Some(34962));
    let t = g.floats(&uv, Some(34962));
    let bytes: Vec<u8> = idx.iter().flat_map(|i| i.to_le_bytes()).collect();
    let i = g.bytes(&bytes, 5125, "SCALAR", idx.len());
    let view = g.json["accessors"][i]["bufferView"].as_u64().unwrap() as usize;
    g.json["bufferViews"][view]["target"] = json!(34963);
    let tex = texture_of(&mut g, &bumpy(false));
    let m = g.material(json!({ "normalTexture": { "index": tex } }));
    g.mesh(json!({ "attributes": { "POSITION": p, "NORMAL": nn, "TEXCOORD_0": t }, "indices": i, "material": m }));
    g.write_glb(path);
}
