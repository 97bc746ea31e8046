use super::*;

/// A quad (two triangles after fanning) and a lone triangle, with normals, UVs and an extra
/// property and element to skip, in the given encoding.
fn sample(enc: &str) -> Vec<u8> {
    let verts: [[f32; 8]; 5] = [
        [0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
        [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0],
        [1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        [0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0],
        [0.1, -0.5, 3.25, 0.0, 1.0, 0.0, 0.5, 0.25],
    ];
    let faces: [&[i32]; 2] = [&[0, 1, 2, 3], &[4, 1, 0]];
    let mut out = format!(
        "ply\nformat {enc} 1.0\ncomment made by a test\nelement vertex 5\nproperty float x\nproperty float y\n\
         property double z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty uchar flags\n\
         property float s\nproperty float t\nelement face 2\nproperty uint8 flags\nproperty list uchar int vertex_indices\n\
         element edge 1\nproperty int a\nproperty int b\nend_header\n"
    )
    .into_bytes();
    let be = enc == "binary_big_endian";
    let put = |out: &mut Vec<u8>, b: &[u8]| {
        let mut b = b.to_vec();
        if be {
            b.reverse();
        }
        out.extend(b);
    };
    for v in verts {
        if enc == "ascii" {
            out.extend(format!("{} {} {} {} {} {} 7 {} {}\n", v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]).bytes());
            continue;
        }
        for (k, x) in v.iter().enumerate() {
            if k == 2 {
                put(&mut out, &(*x as f64).to_le_bytes());
            } else {
                put(&mut out, &x.to_le_bytes());
            }
            if k == 5 {
                out.push(7);
            }
        }
    }
    for f in faces {
        if enc == "ascii" {
            let idx: Vec<String> = f.iter().map(|i| i.to_string()).collect();
            out.extend(format!("0 {} {}\n", f.len(), idx.join(" ")).bytes());
            continue;
        }
        out.push(0);
        out.push(f.len() as u8);
        for i in f {
            put(&mut out, &i.to_le_bytes());
        }
    }
    if enc == "ascii" {
        out.extend(b"0 1\n");
    } else {
        put(&mut out, &0i32.to_le_bytes());
        put(&mut out, &1i32.to_le_bytes());
    }
    out
}

fn read(bytes: &[u8]) -> std::result::Result<PlyMesh, String> {
    parse(Path::new("scan.ply"), bytes).map_err(|e| e.to_string())
}

#[test]
fn ascii_and_both_binaries_read_the_same_mesh() {
    let m = read(&sample("ascii")).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [4, 1, 0]]);
    assert_eq!(m.positions[4], [0.1, -0.5, 3.25]);
    assert_eq!(m.normals[4], [0.0, 1.0, 0.0]);
    assert_eq!(m.uvs[2], [1.0, 1.0]);
    assert_eq!(read(&sample("binary_little_endian")).unwrap(), m);
    assert_eq!(read(&sample("binary_big_endian")).unwrap(), m);
}

#[test]
fn damage_is_a_clear_error() {
    for enc in ["ascii", "binary_little_endian", "binary_big_endian"] {
        let good = sample(enc);
        let cut = read(&good[..good.len() - 5]).unwrap_err();
        assert!(cut.contains("scan.ply") && cut.contains("truncated"), "{enc}: {cut}");
        // Face 2 names vertex 9 of 5.
        let mut bad = good.clone();
        let at = good.len() - if enc == "ascii" { 4 + 6 } else { 8 + 12 };
        if enc == "ascii" {
            bad[at] = b'9';
        } else if enc == "binary_big_endian" {
            bad[at + 3] = 9;
        } else {
            bad[at] = 9;
        }
        let e = read(&bad).unwrap_err();
        assert!(e.contains("face 2 names vertex 9, but there are 5 vertices"), "{enc}: {e}");
    }
    let absurd = String::from_utf8_lossy(&sample("binary_little_endian")).replace("vertex 5", "vertex 4000000000");
    assert!(read(absurd.as_bytes()).unwrap_err().contains("declares 4000000000 'vertex' records"));
    for (header, want) in [
        ("plx\n", "does not start with the line 'ply'"),
        ("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", "no end_header"),
        ("ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\nend_header\n", "unknown property type 'half'"),
        ("ply\nformat xml 1.0\nend_header\n", "unknown format 'xml'"),
        ("ply\nelement vertex 0\nend_header\n", "no 'format' line"),
        ("ply\nformat ascii 1.0\nproperty float x\nend_header\n", "property before any element"),
        ("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n", "no x, y and z"),
        ("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 a 2\n", "not a number"),
    ] {
        let e = read(header.as_bytes()).unwrap_err();
        assert!(e.contains(want), "{header:?}: {e}");
    }
}

#[test]
fn the_fuzz_seeds_read_as_one_quad() {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds/ply_read");
    for enc in ["ascii", "binary_little_endian", "binary_big_endian"] {
        let f = d.join(format!("quad_{enc}.ply"));
        let m = parse(&f, &std::fs::read(&f).unwrap()).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [2, 1, 0]], "{enc}");
        assert_eq!((m.positions[2], m.normals[2], m.uvs[3]), ([1.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0]), "{enc}");
    }
}
