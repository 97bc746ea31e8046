//! A renderer's view of a primitive (`scene::view`) is the only place the stages learn what a
//! renderer makes of a primitive: its mode, its values as floats, the node tree that places it.

mod common;

/// No stage outside `src/scene/` (the model) and `src/format/` (the readers that build it) reads
/// a primitive's `mode`, dequantizes, or walks the node tree itself: they ask `PrimView`,
/// `Geometry` and `nodes::instances`.
#[test]
fn only_the_scene_model_reads_mode_dequantizes_or_walks_nodes() {
    let lookups = ["\"mode\"", "dequant::", "\"children\"", "local_matrix("];
    let bad = common::stage_lines_where(|line| lookups.iter().any(|l| line.contains(l)));
    assert!(
        bad.is_empty(),
        "outside src/scene/ and src/format/ (use scene::view and scene::nodes):\n{}",
        bad.join("\n")
    );
}

/// Every `.rs` file below `src/{dir}`, with its text.
fn rust_files(dir: &str) -> Vec<(std::path::PathBuf, String)> {
    let mut stack = vec![std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src").join(dir)];
    let mut out = Vec::new();
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                let text = std::fs::read_to_string(&p).unwrap();
                out.push((p, text));
            }
        }
    }
    out
}

/// Dequantization is the model's (`scene::dequant`, called by `scene::view`): the readers below it
/// in `src/format/` hand over streams as stored and never name it.
#[test]
fn the_readers_do_not_dequantize() {
    for (p, text) in rust_files("format") {
        assert!(!text.contains("dequant"), "{} names dequant (it belongs to scene::view)", p.display());
    }
}

/// OBJ and PLY UVs are turned to glTF's orientation once, at load: no flag travels with a
/// primitive for stages to branch on, in any module.
#[test]
fn no_stage_branches_on_the_source_uv_orientation() {
    for (p, text) in rust_files("") {
        assert!(!text.contains("uv_v_up"), "{} names uv_v_up", p.display());
    }
}

/// Untrusted JSON is read through typed access that can fail (`get`, `pointer`, `as_*`) and
/// written through `scene::set_key`: `value["key"]` indexing, which panics when `value` is not an
/// object, appears nowhere in the library or the binary outside tests. The shapes themselves are
/// held once, on reading, by `scene::shape`.
#[test]
fn no_json_indexing_outside_tests() {
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut stack = vec![src];
    let mut bad = Vec::new();
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
                continue;
            }
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            if !name.ends_with(".rs") || name.ends_with("_tests.rs") {
                continue;
            }
            let text = std::fs::read_to_string(&p).unwrap();
            let code = text.split("#[cfg(test)]").next().unwrap_or("");
            for (i, line) in code.lines().enumerate() {
                let b = line.as_bytes();
                let indexed = (1..b.len()).any(|k| {
                    b[k] == b'['
                        && b.get(k + 1) == Some(&b'"')
                        && (b[k - 1].is_ascii_alphanumeric() || matches!(b[k - 1], b'_' | b')' | b']'))
                });
                if indexed && !line.trim_start().starts_with("//") {
                    bad.push(format!("{}:{}: {}", p.display(), i + 1, line.trim()));
                }
            }
        }
    }
    assert!(bad.is_empty(), "JSON indexing (use get/pointer and scene::set_key):\n{}", bad.join("\n"));
}
