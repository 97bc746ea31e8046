//! `bench transfer`'s production-scale rows, at a size a test can afford: the same HIGH from
//! memory, OBJ and binary PLY bakes the same map, and a Python without `bpy` for `--blender` is a
//! clear error.

mod common;
use common::run;
use serde_json::Value;

#[test]
fn obj_and_ply_rows_bake_the_same_out() {
    let out = common::run_ok(&[
        "bench",
        "transfer",
        "--runs",
        "0",
        "--large",
        "0.02",
        "--large-from",
        "memory,obj,ply",
        "--large-size",
        "64",
        "--json",
    ]);
    let r: Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = r["large"].as_array().unwrap();
    assert_eq!(rows.len(), 3);
    let print = |k: usize| rows[k]["out_fingerprint"].as_str().unwrap().to_string();
    assert_eq!(print(1).len(), 16);
    assert_eq!(print(1), print(2), "OBJ and PLY of one mesh bake different OUTs");
    for row in rows {
        let tris = row["high_triangles"].as_f64().unwrap();
        assert!(tris > 19_000.0 && tris < 21_000.0, "{row}");
        // The file rows' peak is the whole bake process: more than HIGH alone, finite.
        let per_tri = row["bytes_per_triangle"].as_f64().unwrap();
        assert!(per_tri > row["high_bytes_per_triangle"].as_f64().unwrap() && per_tri.is_finite(), "{row}");
        assert!(row["error"]["synced"]["mean"].as_f64().unwrap() < 0.6, "{row}");
    }
    assert!(rows[1]["file_mb"].as_f64().unwrap() > rows[2]["file_mb"].as_f64().unwrap(), "OBJ text outweighs PLY");
}

#[test]
fn blender_without_bpy_is_one_clear_line() {
    let out = run(&[
        "bench",
        "transfer",
        "--runs",
        "0",
        "--large",
        "0.01",
        "--large-from",
        "obj",
        "--large-size",
        "16",
        "--blender",
        "/bin/false",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("/bin/false") && err.contains("pip install bpy"), "{err}");
}
