//! Every command on every document of `fixtures/edge/` (written from the glTF spec by
//! `fixtures/edge/make.py`): no panic, exit 2 only as one line naming the file with nothing
//! written, and no refusal of an input the Khronos validator finds no error in unless
//! `fixtures/edge/expect.json` says why that command may refuse it. Written glTF/GLB outputs go
//! under `validated/edge_corpus/` with their input recorded, so CI's `.ci/validate-gltf.js` holds
//! each to "no Khronos issue its input lacks".
//!
//! One test collects every failure before failing, so that one run lists all of them.

mod common;
use common::*;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// A command line of the corpus run: `key` is what expect.json's `may_refuse` names it by.
struct Cmd {
    name: &'static str,
    key: &'static str,
    /// Output file name, if the command writes one; "" for none.
    out: &'static str,
    args: &'static [&'static str],
}

const CMDS: &[Cmd] = &[
    Cmd { name: "inspect", key: "inspect", out: "", args: &["inspect"] },
    Cmd { name: "validate", key: "validate", out: "", args: &["validate"] },
    Cmd { name: "validate-json", key: "validate", out: "", args: &["validate", "--format", "json"] },
    Cmd { name: "tangents-glb", key: "tangents", out: "out.glb", args: &["tangents"] },
    Cmd { name: "tangents-gltf", key: "tangents", out: "out.gltf", args: &["tangents"] },
    Cmd { name: "tangents-all", key: "tangents", out: "out.glb", args: &["tangents", "--all"] },
    Cmd { name: "bake", key: "bake", out: "out.glb", args: &["bake"] },
    Cmd { name: "bake-normal", key: "bake --normal", out: "out.glb", args: &["bake", "--normal", "NORMAL"] },
    Cmd { name: "preview", key: "preview", out: "out.png", args: &["preview", "--size", "64x64"] },
];

fn expect() -> Value {
    serde_json::from_slice(&std::fs::read(fixture("edge/expect.json")).unwrap()).unwrap()
}

/// The documents of the corpus, which must be exactly those expect.json describes: a file
/// make.py adds without a Khronos verdict would otherwise be held to nothing.
fn documents(expect: &Value) -> Vec<String> {
    let mut on_disk: Vec<String> = std::fs::read_dir(fixture("edge"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".gltf") || n.ends_with(".glb"))
        .collect();
    on_disk.sort();
    let listed: Vec<String> = expect["files"].as_object().unwrap().keys().cloned().collect();
    assert_eq!(on_disk, listed, "fixtures/edge/ and expect.json disagree: run make.py, then khronos.js");
    assert!(on_disk.len() >= 60, "the corpus shrank to {} documents", on_disk.len());
    // A misspelt command or reason in may_refuse would silently allow nothing or anything.
    for (name, entry) in expect["files"].as_object().unwrap() {
        for (cmd, reason) in entry["may_refuse"].as_object().into_iter().flatten() {
            assert!(CMDS.iter().any(|c| c.key == cmd), "{name}: may_refuse names no command: {cmd}");
            assert!(expect["reasons"][reason.as_str().unwrap()].is_string(), "{name}: unknown reason {reason}");
        }
    }
    on_disk
}

fn khronos_errors(entry: &Value) -> Vec<String> {
    match &entry["khronos"] {
        Value::String(s) if s == "valid" => vec![],
        v => v["errors"].as_array().unwrap().iter().map(|c| c.as_str().unwrap().to_string()).collect(),
    }
}

struct Outcome {
    code: Option<i32>,
    stdout: String,
    stderr: String,
}

/// Runs `cmd` on `input` with outputs in `dir`; returns the outcome and what it wrote.
fn run_cmd(cmd: &Cmd, input: &Path, dir: &Path) -> (Outcome, Vec<PathBuf>) {
    std::fs::create_dir_all(dir).unwrap();
    let normal = fixture("edge/normal.png");
    let out = dir.join(cmd.out);
    let mut args: Vec<&str> = cmd.args.iter().map(|a| if *a == "NORMAL" { s(&normal) } else { a }).collect();
    args.insert(1, s(input));
    if !cmd.out.is_empty() {
        args.extend(["-o", s(&out)]);
    }
    let o = outcome(&args);
    let mut written: Vec<PathBuf> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
    written.sort();
    (o, written)
}

/// The failures of one command on one file, as report lines.
fn check(name: &str, entry: &Value, cmd: &Cmd, input: &Path, o: &Outcome, written: &[PathBuf]) -> Vec<String> {
    let mut whys = Vec::new();
    let mut fail = |why: String| whys.push(why);
    let allowed: &[i32] = if cmd.key == "validate" { &[0, 1, 2] } else { &[0, 2] };
    if !o.code.is_some_and(|c| allowed.contains(&c)) {
        fail("exit code outside the contract".into());
    }
    // A panic, a backtrace hint or a Debug-formatted error are bugs whatever the input.
    for tell in ["panicked", "RUST_BACKTRACE", "Error {", "Custom {", "Os {"] {
        if o.stderr.contains(tell) || o.stdout.contains(tell) {
            fail(format!("output shows `{tell}`"));
        }
    }
    if o.code == Some(2) {
        if o.stderr.trim_end().lines().count() != 1 {
            fail(format!("exit 2 must print one line, printed {}", o.stderr.trim_end().lines().count()));
        }
        if !o.stderr.contains(s(input)) && !o.stderr.contains(name) {
            fail("exit 2 message does not name the input".into());
        }
        if !written.is_empty() {
            fail(format!("exit 2 but wrote {:?}", written.iter().map(|p| p.file_name().unwrap()).collect::<Vec<_>>()));
        }
        let may = &entry["may_refuse"][cmd.key];
        if khronos_errors(entry).is_empty() && may.is_null() {
            fail(
                "refuses an input the Khronos validator finds no error in (expect.json allows no refusal here)".into(),
            );
        }
    }
    if o.code == Some(0) && !cmd.out.is_empty() && !written.iter().any(|p| p.file_name().unwrap() == cmd.out) {
        fail(format!("exit 0 but {} was not written", cmd.out));
    }
    if whys.is_empty() {
        return vec![];
    }
    // A panic's first line is only its location; the second says what happened.
    let lines = if o.code == Some(101) { 2 } else { 1 };
    let shown: Vec<&str> = o.stderr.lines().filter(|l| !l.trim().is_empty()).take(lines).collect();
    vec![format!("{name} [{}] exit {:?}: {} | stderr: {}", cmd.name, o.code, whys.join("; "), shown.join(" / "))]
}

/// `inspect` counts primitives by mode: a points primitive is not "4 triangles".
fn check_inspect_modes(name: &str, o: &Outcome) -> Vec<String> {
    let word = match name {
        "mode_points.glb" => "point",
        "mode_lines.gltf" | "mode_line_loop.glb" | "mode_line_strip.gltf" => "line",
        _ => return vec![],
    };
    // inspect prints the file name, which says "points" or "lines" by itself.
    let text = format!("{}{}", o.stdout, o.stderr).replace(name, "FILE").to_lowercase();
    let mut bad = Vec::new();
    if text
        .split_whitespace()
        .collect::<Vec<_>>()
        .windows(2)
        .any(|w| w[0].parse::<u64>().is_ok() && w[1].starts_with("triangle"))
    {
        bad.push(format!("{name} [inspect]: counts triangles in a primitive without any"));
    }
    if !text.contains(word) {
        bad.push(format!("{name} [inspect]: does not say the primitive is made of {word}s"));
    }
    bad
}

/// Codes an output may add to its input's, with why. A KTX2 image moved from a data URI into a
/// GLB's BIN chunk takes the `mimeType` KHR_texture_basisu prescribes, `image/ktx2`, which the
/// validator's core mimeType list does not hold.
fn explained(name: &str) -> &'static [(&'static str, &'static str)] {
    if name.contains("ktx2") {
        &[("VALUE_NOT_IN_LIST", "image/ktx2 is KHR_texture_basisu's mimeType; the core list has only PNG and JPEG")]
    } else {
        &[]
    }
}

/// Files every command reads the same broken part of, under one reading rule: the commands that
/// need the data refuse them with the same message; `inspect` lists the primitive with that
/// message, and `validate` reports it as a finding (exit 1).
const SAME_REFUSAL: &[&str] = &["index_past_vertex_count.glb", "attribute_counts_unequal.gltf"];

fn message_without_file(o: &Outcome, input: &Path, name: &str) -> String {
    o.stderr.trim().replace(s(input), "FILE").replace(name, "FILE")
}

#[test]
fn every_command_on_every_edge_file() {
    let expect = expect();
    let files = documents(&expect);
    let out_root = validated_dir("edge_corpus");
    let scratch = scratch_dir("edge_corpus");
    let failures = Mutex::new(Vec::<String>::new());
    let next = Mutex::new(0usize);
    // Each job is a process on its own; more threads than cores keeps both cores busy while
    // processes start and write.
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get()) * 2;
    std::thread::scope(|sc| {
        for _ in 0..threads {
            sc.spawn(|| loop {
                let i = {
                    let mut n = next.lock().unwrap();
                    *n += 1;
                    *n - 1
                };
                let Some(name) = files.get(i) else { break };
                let entry = &expect["files"][name];
                let input = fixture(&format!("edge/{name}"));
                let mut bad = Vec::new();
                let mut refusals = BTreeMap::new();
                // The validator throws on a few inputs (expect.json says which), and a throw
                // stops .ci/validate-gltf.js for every file after it: their outputs, which
                // cannot be compared with their input anyway, stay out of `validated/`.
                let comparable = !khronos_errors(entry).iter().any(|c| c.starts_with("VALIDATOR_THREW"));
                for cmd in CMDS {
                    let gltf_out = comparable && (cmd.out.ends_with(".gltf") || cmd.out.ends_with(".glb"));
                    let dir = if gltf_out { &out_root } else { &scratch }.join(name).join(cmd.name);
                    let (o, written) = run_cmd(cmd, &input, &dir);
                    bad.extend(check(name, entry, cmd, &input, &o, &written));
                    if cmd.name == "inspect" {
                        bad.extend(check_inspect_modes(name, &o));
                    }
                    if o.code == Some(0) && gltf_out {
                        record_input(&dir.join(cmd.out), &input, explained(name));
                    } else if gltf_out {
                        // Only real outputs are for the Khronos check; a folder without one is noise.
                        let _ = std::fs::remove_dir_all(&dir);
                    }
                    let text = if cmd.name.starts_with("inspect") || cmd.name.starts_with("validate") {
                        format!("{}{}", o.stdout, o.stderr)
                    } else {
                        message_without_file(&o, &input, name)
                    };
                    refusals.insert(cmd.name, (o.code, text));
                }
                if SAME_REFUSAL.contains(&name.as_str()) {
                    let (refusing, reporting): (Vec<_>, Vec<_>) =
                        refusals.iter().partition(|(c, _)| !c.starts_with("inspect") && !c.starts_with("validate"));
                    let msgs: std::collections::BTreeSet<_> = refusing.iter().map(|(_, v)| v).collect();
                    let why = msgs.iter().next().and_then(|(_, m)| m.split_once("FILE: ")).map(|(_, w)| w.to_string());
                    let agree = msgs.len() == 1
                        && refusing.iter().all(|(_, (c, _))| *c == Some(2))
                        && why.as_ref().is_some_and(|w| {
                            reporting.iter().all(|(cmd, (c, text))| {
                                *c == Some(if cmd.starts_with("validate") { 1 } else { 0 }) && text.contains(w.as_str())
                            })
                        });
                    if !agree {
                        bad.push(format!("{name}: commands disagree: {refusals:?}"));
                    }
                }
                failures.lock().unwrap().extend(bad);
            });
        }
    });
    let mut failures = failures.into_inner().unwrap();
    failures.sort();
    // Kept beside the outputs: the list is long when a regression hits a whole class of files.
    std::fs::write(scratch.join("failures.txt"), failures.join("\n")).unwrap();
    assert!(failures.is_empty(), "{} failure(s) on fixtures/edge:\n{}", failures.len(), failures.join("\n"));
}

fn outcome(args: &[&str]) -> Outcome {
    let o = run(args);
    Outcome {
        code: o.status.code(),
        stdout: String::from_utf8_lossy(&o.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&o.stderr).into_owned(),
    }
}

/// Every finding code of a `validate --format json` report (the `checks` lists name what ran,
/// not what was found, so only `code` fields count).
fn finding_codes(json: &str) -> std::collections::BTreeSet<String> {
    fn walk(v: &Value, out: &mut std::collections::BTreeSet<String>) {
        match v {
            Value::Object(m) => {
                for (k, x) in m {
                    match (k.as_str(), x) {
                        ("code", Value::String(c)) => {
                            out.insert(c.clone());
                        }
                        _ => walk(x, out),
                    }
                }
            }
            Value::Array(a) => a.iter().for_each(|x| walk(x, out)),
            _ => {}
        }
    }
    let mut out = Default::default();
    walk(&serde_json::from_str(json).unwrap_or_else(|e| panic!("validate --format json: {e}: {json}")), &mut out);
    out
}

/// A NORMAL accessor without a bufferView is zeros; zeros are no normals. `tangents` must
/// regenerate them (and so need no fallback frames on this flat quad) and say so, and `validate`
/// must report them: the same quad with real normals is the control.
#[test]
fn zero_normals_are_regenerated_and_reported() {
    let dir = scratch_dir("edge_corpus_zero_normals");
    let control = outcome(&["validate", "--format", "json", s(&fixture("edge/baseline_datauri.gltf"))]);
    let control = finding_codes(&control.stdout);
    let mut bad = Vec::new();
    for name in ["accessor_no_bufferview_normal.gltf", "sparse_no_bufferview_normal.gltf"] {
        let input = fixture(&format!("edge/{name}"));
        let out = dir.join(format!("{name}.glb"));
        let t = outcome(&["tangents", s(&input), "-o", s(&out)]);
        // The file names say "normal"; only the report's own words count.
        let report = t.stderr.replace(s(&out), "OUT").replace(s(&input), "IN").to_lowercase();
        if t.code != Some(0) {
            bad.push(format!("{name} [tangents] exit {:?}: {}", t.code, t.stderr.trim()));
        } else {
            if t.stderr.contains("fallback") {
                bad.push(format!(
                    "{name} [tangents]: fallback frames instead of regenerated normals: {}",
                    t.stderr.trim()
                ));
            }
            if !report.contains("normal") {
                bad.push(format!(
                    "{name} [tangents]: the report does not mention the zero normals: {}",
                    t.stderr.trim()
                ));
            }
        }
        let v = outcome(&["validate", "--format", "json", s(&input)]);
        let found = finding_codes(&v.stdout);
        if found.difference(&control).next().is_none() {
            bad.push(format!("{name} [validate]: finds nothing the control does not ({found:?})"));
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// Messages that must say what is wrong, not something else.
#[test]
fn refusals_and_reports_say_what_is_wrong() {
    let dir = scratch_dir("edge_corpus_messages");
    let out = dir.join("o.glb");
    let normal = fixture("edge/normal.png");
    let mut bad = Vec::new();

    // The primitive has TEXCOORD_0; the base colour texture reads TEXCOORD_1. The mesh is
    // unwrapped: the missing part is one UV set, and "unwrap the mesh" sends the user astray.
    let input = fixture("edge/basecolor_reads_texcoord1.gltf");
    for args in [vec!["bake", s(&input), "-o", s(&out)], vec!["bake", s(&input), "--normal", s(&normal), "-o", s(&out)]]
    {
        let o = outcome(&args);
        if o.stderr.to_lowercase().contains("unwrap") {
            bad.push(format!("basecolor_reads_texcoord1.gltf [{}]: {}", args.join(" "), o.stderr.trim()));
        }
        let _ = std::fs::remove_file(&out);
    }

    // Morph target 1 has 3 POSITIONs against the base's 4: the message names the target, or the
    // user looks for the fault in the base attributes.
    let input = fixture("edge/morph_target_count_mismatch.gltf");
    for cmd in ["inspect", "tangents", "bake", "preview"] {
        let target = dir.join(if cmd == "preview" { "o.png" } else { "o.glb" });
        let args: Vec<&str> =
            if cmd == "inspect" { vec![cmd, s(&input)] } else { vec![cmd, s(&input), "-o", s(&target)] };
        let o = outcome(&args);
        if o.code == Some(2) && !o.stderr.contains("target 1") {
            bad.push(format!("morph_target_count_mismatch.gltf [{cmd}]: does not name target 1: {}", o.stderr.trim()));
        }
        let _ = std::fs::remove_file(&target);
    }

    // No material at all: bake --normal has to make one, and its report must not present a
    // material name the file never had.
    let input = fixture("edge/no_materials.gltf");
    let o = outcome(&["bake", s(&input), "--normal", s(&normal), "-o", s(&out)]);
    if o.code != Some(0) {
        bad.push(format!("no_materials.gltf [bake --normal] exit {:?}: {}", o.code, o.stderr.trim()));
    }
    if let Some(l) = o.stderr.lines().skip(1).find(|l| l.contains("material") && l.contains("bumpbake")) {
        bad.push(format!("no_materials.gltf [bake --normal]: reports an invented material: {}", l.trim()));
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}
