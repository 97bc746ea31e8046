use super::*;
use crate::format::mesh::text_number::{lead_f32, parse_f32, scalar_f32};
use crate::format::mesh::{Statement, MISSING};

fn parse(s: &str) -> StoredMesh {
    parse_bytes(Path::new("t.obj"), s.as_bytes(), &Default::default()).unwrap()
}

fn error(s: &str) -> String {
    parse_bytes(Path::new("t.obj"), s.as_bytes(), &Default::default()).unwrap_err().to_string()
}

#[test]
fn every_listed_syntax() {
    let d = parse(concat!(
        "# comment\r\n",
        "mtllib my lib.mtl\r\n",
        "vn 0 0 1\n",
        "vt .5 -0\n",
        "v 1e-3 -0 +2.5E1\n",
        "v 2 0 0 2\n",           // w divides
        "v 0 1 0 0.5 0.5 0.5\n", // a colour, not kept
        "  o  first part  \n",
        "usemtl red\n",
        "f 1/1/1 2//1 3/1 # trailing comment\n",
        "vt 1 1 0\n", // a third vt number is ignored
        "v 0 0 1\n",
        "g\n",
        "f -4/-2/-1 -3/-1 -2 -1\n",   // relative, a quad
        "s off\nl 1 2\np 1\nf 1 2\n", // a smoothing group; no surface
        "s 12 # a group number\n",
        "usemtl  \tblue\n",
        "vt 0.75 # v left out: 0\n",
    ));
    assert_eq!(d.positions, vec![[1e-3, -0.0, 25.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    assert!(d.positions[0][1].is_sign_negative());
    assert_eq!(d.uvs, vec![[0.5, -0.0], [1.0, 1.0], [0.75, 0.0]]);
    assert_eq!(d.normals, vec![[0.0, 0.0, 1.0]]);
    assert_eq!(d.triangles, vec![[0, 1, 2], [0, 1, 2], [0, 2, 3]]);
    assert_eq!(d.uv_triangles, vec![[0, MISSING, 0], [0, 1, MISSING], [0, MISSING, MISSING]]);
    assert_eq!(d.normal_triangles, vec![[0, 0, MISSING], [0, MISSING, MISSING], [0, MISSING, MISSING]]);
    assert_eq!(
        d.statements,
        vec![
            (0, Statement::Name("first part".into())),
            (0, Statement::Material("red".into())),
            (1, Statement::Name("unnamed_object".into())),
            (3, Statement::Smooth(0)),
            (3, Statement::Smooth(12)),
            (3, Statement::Material("blue".into())),
        ]
    );
    assert_eq!(d.mtllibs, vec!["my lib.mtl".to_string()]);
}

#[test]
fn a_polygon_is_fanned_from_its_first_corner() {
    let d = parse("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv -1 1 0\nf 1 2 3 4 5\n");
    assert_eq!(d.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
    assert!(d.uv_triangles.is_empty() && d.normal_triangles.is_empty());
}

#[test]
fn faces_may_come_before_what_they_name() {
    let d = parse("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
    assert_eq!(d.triangles, vec![[0, 1, 2]]);
    // vt/vn indices into a kind the file never defines are ignored (as tobj did).
    let d = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1 2/2/2 3/3/3\n");
    assert!(d.uv_triangles.is_empty() && d.normal_triangles.is_empty());
}

#[test]
fn errors_name_the_line_and_the_way_out() {
    let past = error("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n");
    assert!(
        past.contains("t.obj") && past.contains("line 5") && past.contains("vertex index 4 is past the 3"),
        "{past}"
    );
    assert!(error("v 0 0 0\nf 1 -2 1\n").contains("line 2: relative vertex index -2"));
    assert!(error("v 0 0 0\nf 0 1 1\n").contains("index 0 (OBJ indices start at 1)"));
    assert!(error("v 0 0 0\nvt 0 0\nv 1 x 0\n").contains("line 3: v: 'x' is not a number"));
    assert!(error("v 0 0\n").contains("line 1: v has too few numbers"));
    assert!(error("v 0 0 0 1 1\n").contains("v has 5 numbers"));
    assert!(error("v 0 0 0 0\n").contains("w = 0"));
    assert!(error("v 0 0 0\nf 1/1/1/1 1 1\n").contains("more than v/vt/vn"));
    assert!(error("v 0 0 0\nf 1/a 1 1\n").contains("not v, v/vt"));
    assert!(error("usemtl\n").contains("line 1: usemtl names no material"));
    assert!(error("vt\n").contains("vt has too few numbers"));
    assert!(error("vt 1 x\n").contains("line 1: vt: 'x' is not a number"));
}

#[test]
fn floats_are_exactly_what_str_parse_gives() {
    let tricky = [
        "0",
        "-0",
        "+0.0",
        ".5",
        "5.",
        "1e-3",
        "1E+3",
        "-1.5e-7",
        "3.4028235e38",
        "3.4028236e38",
        "1e39",
        "1.17549435e-38",
        "1e-45",
        "1.4e-45",
        "7e-46",
        "0.1",
        "0.2",
        "0.3",
        "16777217",
        "16777216.5",
        "33554431",
        "0.000000059604645",
        "1.00000005960464477539",
        "1.0000000596046448",
        "1.000000059604644775390625",
        "0.100000001490116119384765625",
        "123456789012345678901234567890",
        "0.00000000000000000000000000000000000001",
        "9007199254740993",
        "9007199254740992e-22",
        "inf",
        "-NaN",
        "infinity",
        "1e",
        "e5",
        ".",
        "-",
        "1.2.3",
        "0x10",
        "1_0",
    ];
    for t in tricky {
        let want = t.parse::<f32>().ok();
        let got = parse_f32(t.as_bytes());
        assert_eq!(got.map(f32::to_bits), want.map(f32::to_bits), "{t}");
        for end in [" 0000000000\n", "\r\nv 1 2 3\n", "x1234567890"] {
            let line = format!("{t}{end}");
            let want = if end.starts_with('x') { None } else { want.map(|w| (w.to_bits(), t.len())) };
            for read in [lead_f32, scalar_f32] {
                assert_eq!(read(line.as_bytes()).map(|(v, n)| (v.to_bits(), n)), want, "{line}");
            }
        }
    }
    // Every f32 midpoint neighbourhood and random decimals of every length.
    let mut rng = crate::test_rng::XorShift64(0x9E37_79B9_7F4A_7C15);
    for _ in 0..40_000 {
        let x = rng.next();
        let f = f32::from_bits(x as u32 & 0x7F7F_FFFF);
        let mid = (f as f64 + f32::from_bits(f.to_bits() + 1) as f64) / 2.0;
        let digits = (x >> 40) as usize % 12 + 1;
        for t in [format!("{f}"), format!("{mid:e}"), format!("{:.*e}", digits, mid), format!("{:.*}", digits, f)] {
            let want = t.parse::<f32>().ok().map(f32::to_bits);
            assert_eq!(parse_f32(t.as_bytes()).map(f32::to_bits), want, "{t}");
            // Followed by more of the line, the digits are read eight at a time.
            let line = format!("{t} 12345678 9\n");
            // The scalar reader too: the one a CPU without SSE4.1 uses for every number.
            for read in [lead_f32, scalar_f32] {
                assert_eq!(read(line.as_bytes()).map(|(v, n)| (v.to_bits(), n)), want.map(|w| (w, t.len())), "{t}");
            }
        }
    }
}

#[test]
fn any_piece_size_gives_the_same_result() {
    let mut s = String::from("mtllib a.mtl\no a\nvt 0 0\nvn 0 0 1\n");
    for i in 0..40 {
        s += &format!("v {i} {}.25 -{i}e-2\r\n", i * 3);
        if i % 7 == 3 {
            s += &format!("g part{i}\nusemtl m{}\n", i % 2);
        }
        if i >= 3 {
            s += &format!("f -1/1/1 -2//1 -3/1 {}\n", i / 2 + 1);
        }
    }
    let whole = parse(&s);
    assert!(whole.triangles.len() > 60);
    for piece in [1, 2, 3, 5, 7, 16, 64, 1000] {
        assert_eq!(pieces(&s, piece).unwrap(), whole, "piece {piece}");
    }
    // Errors keep their line numbers too: one at the end, a relative index reaching before the
    // first in the middle, and one past the file's end in a face before the last `v`.
    let lines = s.lines().count();
    let bad = [
        (format!("{s}f 1 2 999\n"), lines + 1),
        (format!("v 0 0 0\n{s}f 1 -999 2\n{s}"), lines + 2),
        (format!("{s}f 1 2 999\n{s}"), lines + 1),
    ];
    for (bad, line) in &bad {
        for piece in [1, 3, 64, 1 << 12] {
            let e = pieces(bad, piece).unwrap_err();
            assert!(e.contains(&format!("line {line}:")), "{e}");
        }
    }
}

/// Lines continued by `\` (any line, comments too, as Blender reads them) read as the joined
/// text, for every piece size and through a reader, and an error after them names its line.
#[test]
fn continued_lines_read_as_joined() {
    let (mut cont, mut plain) = (String::new(), String::new());
    for i in 0..30 {
        cont += &format!("v {i} \\\n 0 \\ \r\n 0\nvt {i} 1\n");
        plain += &format!("v {i} 0 0\n\n\nvt {i} 1\n");
        if i >= 2 {
            cont += "f -1/-1 \\\n-2/-2 \\\t\n -3/-3\n# a comment \\\nv 9 9 9\n";
            plain += "f -1/-1 -2/-2 -3/-3\n\n\n# a comment\n\n";
        }
    }
    let whole = parse(&plain);
    assert_eq!((whole.positions.len(), whole.triangles.len()), (30, 28));
    for piece in [1, 2, 3, 5, 7, 16, 64, 1000] {
        assert_eq!(pieces(&cont, piece).unwrap(), whole, "piece {piece}");
    }
    let line = cont.lines().count() + 1;
    let bad = format!("{cont}f 1 2 \\\n 999\nv 0 0 0\n");
    for piece in [1, 3, 64, 1 << 12] {
        let e = pieces(&bad, piece).unwrap_err();
        assert!(e.contains(&format!("line {line}:")), "{e}");
    }
}

/// Random files strewn with backslashes, blanks and line ends read the same, data or error, with
/// pieces of every size, from memory and through a reader, as in one piece: no cut lands inside
/// a continued line, and errors keep their line numbers.
#[test]
fn continuations_anywhere_read_the_same_in_any_pieces() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let bits = ["v 1 2 3", "vt 0 1", "vn 0 0 1", "f 1 2 3", "f -1 -2 -3", "s 1", "# c", "\\", " ", "\t", "\r", "\n"];
    for _ in 0..300 {
        let mut s = String::new();
        for _ in 0..rng.below(40) {
            s += rng.pick(&bits);
            if rng.below(3) == 0 {
                s += "\n";
            }
        }
        // One piece (a reader's block is 64 pieces, zeroed once: kept small).
        let whole = pieces(&s, 1 << 12);
        for piece in [1, 2, 3, 5, 8, 13] {
            assert_eq!(pieces(&s, piece), whole, "piece {piece} of {s:?}");
        }
    }
}

/// `s` parsed with pieces of about `piece` bytes, both from memory and through a reader.
fn pieces(s: &str, piece: usize) -> std::result::Result<StoredMesh, String> {
    let path = Path::new("t.obj");
    let mapped = parse_pieces::<true>(path, s.as_bytes(), piece, &Reporter::none()).map_err(|e| e.to_string());
    let read = parse_reader(path, s.as_bytes(), piece).map_err(|e| e.to_string());
    assert_eq!(mapped, read, "piece {piece}");
    mapped
}

/// Pieces that need what comes before them (relative indices, faces naming vertices further
/// down) read as the whole file does, for every piece size.
#[test]
fn pieces_that_need_their_base_read_as_the_whole() {
    let mut s = String::from("f 3 2 1\n");
    for i in 0..30 {
        s += &format!("v {i} 0 0\nvn 0 0 1\nvt {i} 1\n");
        s += if i % 4 == 3 { "f 1/1/1 -1/-1/-1 -2/-2/-2\n" } else { "f 1 2 3 4 5 6 7\n" };
    }
    let whole = parse(&s);
    assert_eq!(whole.triangles[0], [2, 1, 0]);
    for piece in [1, 4, 9, 30, 200] {
        assert_eq!(pieces(&s, piece).unwrap(), whole, "piece {piece}");
    }
}

struct Rng(u64);

impl Rng {
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % n as u64) as usize
    }
    fn pick<'a>(&mut self, from: &[&'a str]) -> &'a str {
        from[self.below(from.len())]
    }
}

/// The common lines' own path reads every line as the general path does: random files mixing
/// plain lines with everything that must leave it (tabs, comments, w, colours, signs, exponents,
/// odd corners, negative and forward indices, junk), read both ways, give the same data or the
/// same error.
#[test]
fn fast_path_reads_as_the_general_path() {
    let mut r = Rng(0x2545_F491_4F6C_DD1D);
    let nums = ["1", "-0", "0.5", ".25", "1e-3", "-2.5E+1", "3.", "7", "inf", "1x", "1-2", "0.1000000015", "+4"];
    let sep = [" ", " ", " ", "  ", "\t", " \x0b"];
    let ends = ["\n", "\n", "\n", "\r\n", " \n", " # c\n", "\t\n", " x\n", "\r \n"];
    // Mostly small positive indices, which the fast path takes.
    let idx = ["1", "2", "3", "1", "2", "3", "1", "2", "-1", "-2", "9", "0", "12345678901", "+1", "1a", ""];
    let numbers =
        |r: &mut Rng, k: usize| (0..k).map(|_| format!("{}{}", r.pick(&sep), r.pick(&nums))).collect::<String>();
    for file in 0..300 {
        let mut s = String::new();
        for _ in 0..40 {
            let e = r.pick(&ends);
            match r.below(8) {
                0 | 1 => {
                    let k = [3, 3, 3, 3, 4, 6, 5][r.below(7)];
                    s += &format!("v{}{e}", numbers(&mut r, k));
                }
                2 | 3 => {
                    let k = r.below(8) / 7;
                    let (kw, k) = if r.below(2) == 0 { ("vn", 3 + k) } else { ("vt", 2 + k) };
                    s += &format!("{kw}{}{e}", numbers(&mut r, k));
                }
                4 | 5 => {
                    let shape = r.below(4);
                    let mut f = String::from("f");
                    for _ in 0..2 + r.below(4) {
                        f += r.pick(&sep);
                        f += &match shape {
                            0 => r.pick(&idx).to_string(),
                            1 => format!("{}/{}", r.pick(&idx), r.pick(&idx)),
                            2 => format!("{}//{}", r.pick(&idx), r.pick(&idx)),
                            _ => format!("{}/{}/{}", r.pick(&idx), r.pick(&idx), r.pick(&idx)),
                        };
                    }
                    s += &format!("{f}{e}");
                }
                6 => s += r.pick(&["g part\n", "usemtl m\n", "# note\n", "\n", "s 1\n", "o\n"]),
                _ => s += "v 0 0 0\nvt 0 0\nvn 0 0 1\n",
            }
        }
        // Pieces of 7 bytes cut lines everywhere; 4096 holds each file whole.
        for piece in [7, 1 << 12] {
            let none = Reporter::none();
            let fast = parse_pieces::<true>(Path::new("t.obj"), s.as_bytes(), piece, &none).map_err(|e| e.to_string());
            let slow = parse_pieces::<false>(Path::new("t.obj"), s.as_bytes(), piece, &none).map_err(|e| e.to_string());
            assert_eq!(fast, slow, "file {file}, piece {piece}:\n{s}");
        }
    }
}
