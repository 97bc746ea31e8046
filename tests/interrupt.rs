//! A run cancelled while it writes leaves no temporary beside its output: SIGINT and SIGTERM
//! remove it before the process ends; after SIGKILL, the next run writing that output removes it.
#![cfg(unix)]

mod common;
use common::*;
use serde_json::json;
use std::path::{Path, PathBuf};
use std::process::{Child, Command};
use std::time::{Duration, Instant};

/// A grid big enough that writing its output takes a moment (about 130 000 triangles).
fn big_mesh(dir: &Path) -> PathBuf {
    let mut g = Gltf::new();
    let (pos, nrm, uv, idx) = grid(254);
    let p = g.floats(&pos, Some(34962));
    let n = g.floats(&nrm, Some(34962));
    let t = g.floats(&uv, Some(34962));
    let i = g.indices(&idx);
    let tex = g.texture();
    let m = g.material(json!({ "normalTexture": { "index": tex } }));
    g.mesh(json!({ "attributes": { "POSITION": p, "NORMAL": n, "TEXCOORD_0": t }, "indices": i, "material": m }));
    let path = dir.join("big.glb");
    g.write_glb(&path);
    path
}

fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".out.glb.") && n.ends_with(".tmp"))
        .collect()
}

/// Starts `tangents` and sends `signal` the moment its temporary appears. Returns the finished
/// child, or `None` when the run ended before a temporary was seen (then the caller tries again).
fn cancel_while_writing(input: &Path, dir: &Path, signal: &str) -> Option<Child> {
    let out = dir.join("out.glb");
    let mut child = bin().args(["tangents", s(input), "-o", s(&out), "--bitangents", "-q"]).spawn().unwrap();
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(120) {
        if !temporaries(dir).is_empty() {
            let k = Command::new("kill").args([signal, &child.id().to_string()]).status().unwrap();
            assert!(k.success());
            if child.wait().unwrap().success() {
                // The signal came after the rename: not a cancelled write.
                let _ = std::fs::remove_file(&out);
                return None;
            }
            return Some(child);
        }
        if child.try_wait().unwrap().is_some() {
            let _ = std::fs::remove_file(&out);
            return None;
        }
    }
    let _ = child.kill();
    let _ = child.wait();
    panic!("tangents on the big mesh did not finish in 2 minutes");
}

fn cancelled(test: &str, signal: &str) -> PathBuf {
    let d = scratch_dir(test);
    let input = big_mesh(&d);
    let out_dir = d.join("out");
    std::fs::create_dir_all(&out_dir).unwrap();
    for _ in 0..10 {
        if let Some(mut child) = cancel_while_writing(&input, &out_dir, signal) {
            let status = child.wait().unwrap();
            if signal != "-KILL" {
                let sig = if signal == "-TERM" { 15 } else { 2 };
                assert_eq!(status.code(), Some(128 + sig), "{signal}: exit code 128 + the signal");
            }
            if out_dir.join("out.glb").exists() {
                // The signal came between the rename and the exit: the write was complete.
                std::fs::remove_file(out_dir.join("out.glb")).unwrap();
                continue;
            }
            return out_dir;
        }
    }
    panic!("never caught the run while it wrote");
}

#[test]
fn sigterm_and_sigint_leave_no_temporary() {
    for (test, signal) in [("interrupt_term", "-TERM"), ("interrupt_int", "-INT")] {
        let dir = cancelled(test, signal);
        assert_eq!(temporaries(&dir), Vec::<String>::new(), "{signal}: the temporary was removed");
    }
}

#[test]
fn the_next_run_removes_what_sigkill_left() {
    let dir = cancelled("interrupt_kill", "-KILL");
    let left = temporaries(&dir);
    assert_eq!(left.len(), 1, "SIGKILL cannot be caught: its temporary stays until the next run");
    // A temporary of a live process (this test's) is someone's write in progress: it stays.
    let live = dir.join(format!(".out.glb.{}.tmp", std::process::id()));
    std::fs::write(&live, b"in progress").unwrap();
    let input = dir.parent().unwrap().join("big.glb");
    run_ok(&["tangents", s(&input), "-o", s(&dir.join("out.glb")), "-q"]);
    assert_eq!(temporaries(&dir), vec![live.file_name().unwrap().to_string_lossy().into_owned()]);
}
