use super::*;

/// A quad (two triangles after fanning) and a lone triangle, with normals, UVs and an extra
/// property and element to skip, in the given encoding.
fn sample(enc: &str) -> Vec<u8> {
    sample_in_order(enc, false)
}

/// [`sample`], with its face element before its vertex element when `faces_first`.
fn sample_in_order(enc: &str, faces_first: bool) -> Vec<u8> {
    let verts: [[f32; 8]; 5] = [
        [0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
        [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0],
        [1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        [0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0],
        [0.1, -0.5, 3.25, 0.0, 1.0, 0.0, 0.5, 0.25],
    ];
    let faces: [&[i32]; 2] = [&[0, 1, 2, 3], &[4, 1, 0]];
    let vertex = "element vertex 5\nproperty float x\nproperty float y\nproperty double z\nproperty float nx\n\
                  property float ny\nproperty float nz\nproperty uchar flags\nproperty float s\nproperty float t\n";
    let face = "element face 2\nproperty uint8 flags\nproperty list uchar int vertex_indices\n";
    let (first, second) = if faces_first { (face, vertex) } else { (vertex, face) };
    let mut out = format!(
        "ply\nformat {enc} 1.0\ncomment made by a test\n{first}{second}element edge 1\nproperty int a\nproperty int b\nend_header\n"
    )
    .into_bytes();
    let mut face_bytes = Vec::new();
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
        let out = &mut face_bytes;
        if enc == "ascii" {
            let idx: Vec<String> = f.iter().map(|i| i.to_string()).collect();
            out.extend(format!("0 {} {}\n", f.len(), idx.join(" ")).bytes());
            continue;
        }
        out.push(0);
        out.push(f.len() as u8);
        for i in f {
            put(out, &i.to_le_bytes());
        }
    }
    if faces_first {
        let header_end = out.windows(11).position(|w| w == b"end_header\n").expect("a header") + 11;
        out.splice(header_end..header_end, face_bytes);
    } else {
        out.extend(face_bytes);
    }
    if enc == "ascii" {
        out.extend(b"0 1\n");
    } else {
        put(&mut out, &0i32.to_le_bytes());
        put(&mut out, &1i32.to_le_bytes());
    }
    out
}

fn read(bytes: &[u8]) -> std::result::Result<StoredMesh, String> {
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
    // Elements may come in any order: faces before their vertices read the same.
    for enc in ["ascii", "binary_little_endian", "binary_big_endian"] {
        assert_eq!(read(&sample_in_order(enc, true)).unwrap(), m, "{enc}, faces first");
    }
    // Checked against the vertex count the header declares.
    let bad = String::from_utf8_lossy(&sample_in_order("ascii", true)).replace("0 3 4 1 0\n", "0 3 5 1 0\n");
    assert!(read(bad.as_bytes()).unwrap_err().contains("face 2 names vertex 5, but there are 5 vertices"));
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
        (
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n\
             element face 0\nproperty list uchar float vertex_indices\nend_header\n0 0 0\n",
            "vertex indices are floats",
        ),
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

/// A mesh of `faces` polygons of 3 to 6 corners (several of the binary reader's blocks), with a
/// list and a scalar around the index list, in the given encoding.
fn polygons(enc: &str, faces: usize) -> Vec<u8> {
    let nv = 5000;
    let mut out = format!(
        "ply\nformat {enc} 1.0\nelement vertex {nv}\nproperty double x\nproperty float y\nproperty float z\n\
         property short extra\nelement face {faces}\nproperty list uchar float texcoord\n\
         property list uchar uint vertex_indices\nproperty ushort flags\nend_header\n"
    )
    .into_bytes();
    let be = enc == "binary_big_endian";
    let put = |out: &mut Vec<u8>, b: &[u8]| out.extend(b.iter().rev().filter(|_| be).chain(b.iter().filter(|_| !be)));
    let mut seed = 7u64;
    let mut next = move || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 33) as u32
    };
    for k in 0..nv {
        let p = [k as f64 * 0.001, (k % 7) as f64, -(k as f64) / 3.0];
        if enc == "ascii" {
            out.extend(format!("{} {} {} 3\n", p[0], p[1] as f32, p[2] as f32).bytes());
        } else {
            put(&mut out, &p[0].to_le_bytes());
            put(&mut out, &(p[1] as f32).to_le_bytes());
            put(&mut out, &(p[2] as f32).to_le_bytes());
            put(&mut out, &3i16.to_le_bytes());
        }
    }
    for _ in 0..faces {
        let n = 3 + next() % 4;
        let idx: Vec<u32> = (0..n).map(|_| next() % nv).collect();
        if enc == "ascii" {
            let s: Vec<String> = idx.iter().map(|i| i.to_string()).collect();
            out.extend(format!("1 0.5 {n} {} 9\n", s.join(" ")).bytes());
            continue;
        }
        out.push(1);
        put(&mut out, &0.5f32.to_le_bytes());
        out.push(n as u8);
        idx.iter().for_each(|i| put(&mut out, &i.to_le_bytes()));
        put(&mut out, &9u16.to_le_bytes());
    }
    out
}

/// The binary reader reads faces block by block on every core and the ASCII one line by line:
/// they must agree, and name the same first damaged record.
#[test]
fn parallel_binary_reads_as_ascii_does() {
    let faces = 150_000;
    let m = read(&polygons("ascii", faces)).unwrap();
    assert!(m.triangles.len() > 2 * faces);
    assert_eq!(m.positions[4999], [4.999, 1.0, -4999.0 / 3.0]);
    for enc in ["binary_little_endian", "binary_big_endian"] {
        let good = polygons(enc, faces);
        assert_eq!(read(&good).unwrap(), m, "{enc}");
        // Cut inside a late face: the error names it, as the sequential reader would.
        let e = read(&good[..good.len() - 9]).unwrap_err();
        assert!(e.contains(&format!("record {faces} of {faces}")) && e.contains("truncated"), "{enc}: {e}");
        // A bad index in the second block comes before a cut in the third.
        let mut bad = good[..good.len() - 9].to_vec();
        let (mut at, mut k) = (good.windows(10).position(|w| w == b"end_header").unwrap() + 11 + 5000 * 18, 0);
        while k < 100_000 {
            at += 5;
            let n = bad[at] as usize;
            at += 1 + 4 * n + 2;
            k += 1;
        }
        let first = at + 6;
        bad[first..first + 4].copy_from_slice(&if enc == "binary_big_endian" {
            9999u32.to_be_bytes()
        } else {
            9999u32.to_le_bytes()
        });
        let e = read(&bad).unwrap_err();
        assert!(e.contains("face 100001 names vertex 9999, but there are 5000 vertices"), "{enc}: {e}");
    }
}

/// One record a line is read on every core; a record over two lines is not, and the sequential
/// reader reads it to the same mesh.
#[test]
fn ascii_lines_are_read_in_parallel_and_other_layouts_sequentially() {
    let b = polygons("ascii", 150_000);
    let (_, els, body) = header(&b).unwrap();
    let cols = ascii::Columns { xyz: [0, 1, 2], nrm: None, uv: None };
    let ((p, n, uv), used) = ascii::vertices(&els[0], &b[body..], &cols).expect("one vertex a line");
    assert_eq!((p.len(), n.len(), uv.len()), (5000, 0, 0));
    let (tris, end) = ascii::faces(&els[1], 1, &b[body + used..], 5000).expect("one face a line");
    assert_eq!(body + used + end, b.len());
    let whole = read(&b).unwrap();
    assert_eq!((&whole.positions, &whole.triangles), (&p, &tris));
    // The first face's texture list ends its line: that face is now two lines.
    let mut split = b.clone();
    let at = body + used + "1 0.5".len();
    assert_eq!(split[at], b' ');
    split[at] = b'\n';
    assert!(ascii::faces(&els[1], 1, &split[body + used..], 5000).is_none());
    assert_eq!(read(&split).unwrap(), whole);
}

/// Blender's ASCII export of the scene fixture's HIGH (`fixtures/blender_scene/make.py`) is read
/// on every core, to the faces of its binary export and the same vertices within the text's
/// rounding (Blender writes about eight significant digits).
#[test]
fn blenders_ascii_ply_reads_in_parallel_as_its_binary_ply() {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/blender_scene/moved");
    let text = std::fs::read(d.join("torus_high_ascii.ply")).unwrap();
    let (_, els, body) = header(&text).unwrap();
    let cols = ascii::Columns { xyz: [0, 1, 2], nrm: Some([3, 4, 5]), uv: None };
    let (_, used) = ascii::vertices(&els[0], &text[body..], &cols).expect("a vertex a line");
    ascii::faces(&els[1], 0, &text[body + used..], els[0].count).expect("a face a line");
    let a = read(&text).unwrap();
    let b = read(&std::fs::read(d.join("torus_high.ply")).unwrap()).unwrap();
    assert_eq!((a.triangles.len(), &a.triangles), (9216, &b.triangles));
    let near =
        |x: &[[f32; 3]], y: &[[f32; 3]]| x.iter().flatten().zip(y.iter().flatten()).all(|(p, q)| (p - q).abs() < 1e-5);
    assert!(near(&a.positions, &b.positions) && near(&a.normals, &b.normals));
    assert_eq!(a.positions.len(), b.positions.len());
}
