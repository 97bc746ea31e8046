//! The parser and its glue against `tobj` (the reference reading of OBJ) on the same inputs: every
//! object, material, position, normal, UV and index list as tobj numbered them.

use super::*;
use std::io::BufReader;
use std::path::PathBuf;

fn tobj_models(path: &Path, bytes: &[u8]) -> Vec<tobj::Model> {
    let load = tobj::LoadOptions { triangulate: true, single_index: false, ignore_points: true, ignore_lines: true };
    let dir = path.parent().unwrap().to_path_buf();
    let (models, _) = tobj::load_obj_buf(&mut BufReader::new(bytes), &load, |m: &Path| tobj::load_mtl(dir.join(m)))
        .expect("tobj reads it");
    models.into_iter().filter(|m| !m.mesh.indices.is_empty()).collect()
}

fn ours(path: &Path, bytes: &[u8]) -> Vec<(String, Option<usize>, Model)> {
    let data = parse::parse_bytes(path, bytes, &Default::default()).unwrap();
    let (_, ids, _) = load_materials(path, path.parent().unwrap(), &data.mtllibs, &ReadOptions::default()).unwrap();
    let mut remap = Remaps::new(&data);
    runs(&data.statements, data.triangles.len(), "unnamed_object", |m| ids.get(m).copied())
        .into_iter()
        .map(|r| (r.name.clone(), r.material, remap.model(&data, r.tris)))
        .collect()
}

fn same(path: &Path, bytes: &[u8]) {
    let theirs = tobj_models(path, bytes);
    let ours = ours(path, bytes);
    assert_eq!(theirs.len(), ours.len(), "{}: object count", path.display());
    for (t, (name, material, m)) in theirs.iter().zip(&ours) {
        let what = format!("{} object {name}", path.display());
        assert_eq!((&t.name, t.mesh.material_id), (name, *material), "{what}");
        assert_eq!((&t.mesh.positions, &t.mesh.indices), (&m.positions, &m.indices), "{what}: positions");
        assert_eq!((&t.mesh.normals, &t.mesh.normal_indices), (&m.normals, &m.normal_indices), "{what}: normals");
        assert_eq!((&t.mesh.texcoords, &t.mesh.texcoord_indices), (&m.texcoords, &m.texcoord_indices), "{what}: UVs");
    }
}

#[test]
fn every_fixture_reads_as_tobj_read_it() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    let mut files: Vec<PathBuf> = Vec::new();
    let mut dirs = vec![root];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|x| x == "obj") {
                files.push(p);
            }
        }
    }
    assert!(files.len() >= 3);
    for f in files {
        same(&f, &std::fs::read(&f).unwrap());
    }
}

#[test]
fn the_syntax_tobj_read_reads_the_same() {
    let dir = std::env::temp_dir().join(format!("bumpbake-obj-tobj-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("m.mtl"), "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n").unwrap();
    let cases = [
        // Quads and polygons, relative indices, v/vt/vn in any order, w.
        "mtllib m.mtl\nv 0 0 0\nvt 0 0\nvn 0 0 1\nv 1 0 0 2\nv 1 1 0\nvt 1 1\nv 0 1 0\nv -1 .5 1e-1\n\
         f 1/1/1 2/2/1 3/1/1 4/2/1\nf -1/-1/-1 -2/-2/-1 -3/-1/-1 -4/-2/-1 -5/-1/-1\n",
        // Objects, groups and materials: splits where tobj split, names as tobj named them.
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\no first\nusemtl red\nf 1 2 3\nusemtl red\nf 2 4 3\n\
         usemtl blue\nf 1 2 4\ng\nf 1 3 4\ng  spaced name \r\nusemtl unknown\nf 1 2 3\no first\nf 3 2 1\n",
        // v//vn and v/vt with some corners missing one (tobj's fallback: the previous corner's).
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 1 0\nvt 0.5 0.5\nvt 1 0\nf 1//2 2//1 3//2\nf 1/2 2 3/1\nf 3 2/1 1\n",
        // CRLF, numbers Rust reads, a BOM-less file with blank lines and comments.
        "# c\r\n\r\nv -0 .5 5.\r\nv +1 1e-3 -1E+2\r\nv 3.4028235e38 1e-45 0.1\r\nf 1 2 3\r\n",
    ];
    for (k, c) in cases.iter().enumerate() {
        same(&dir.join(format!("case{k}.obj")), c.as_bytes());
    }
    let _ = std::fs::remove_dir_all(&dir);
}
