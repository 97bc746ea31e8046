//! The library is free of the command line, and its modules form layers (docs/architecture.md,
//! "Module map"): these tests read the sources and fail on a clap type or a printout in the
//! library, an import from a higher layer, or a circle of file imports.
//!
//! Items under `#[cfg(test)]` (test modules, inline or in files of their own) are left out: a
//! test may reach anything it checks against. The rest of each file is checked, also after an
//! inner test module.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn src() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// Every `.rs` file under `src/`, as paths relative to it (`scene/view.rs`).
fn files() -> Vec<String> {
    fn walk(dir: &Path, root: &Path, out: &mut Vec<String>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, root, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p.strip_prefix(root).unwrap().to_string_lossy().replace('\\', "/"));
            }
        }
    }
    let mut out = Vec::new();
    walk(&src(), &src(), &mut out);
    out.sort();
    out
}

/// The file's code: comments dropped, and every item under `#[cfg(test)]` (a test module, inline
/// or in a file of its own, a test helper) cut out, by matching its braces: production code after
/// an inner test module is still checked.
fn code(file: &str) -> String {
    let text = std::fs::read_to_string(src().join(file)).unwrap();
    let text = text.lines().map(|l| l.split("//").next().unwrap()).collect::<Vec<_>>().join("\n");
    without_test_items(&text).0
}

/// `text` without its `#[cfg(test)]` items, and the `#[path]` (or, else, the name) of each test
/// module declared in a file of its own (`#[cfg(test)] mod tests;`).
fn without_test_items(text: &str) -> (String, Vec<String>) {
    const MARK: &str = "#[cfg(test)]";
    let (mut out, mut test_files, mut rest) = (String::new(), Vec::new(), text);
    while let Some(i) = rest.find(MARK) {
        out.push_str(&rest[..i]);
        let item = &rest[i + MARK.len()..];
        let end = item_end(item);
        let decl = &item[..end];
        if decl.trim_end().ends_with(';') {
            if let Some(p) = decl.split("#[path = \"").nth(1).and_then(|p| p.split('"').next()) {
                test_files.push(p.to_string());
            } else if let Some(name) = decl.split("mod ").nth(1) {
                test_files.push(format!("{}.rs", name.trim_end().trim_end_matches(';').trim()));
            }
        }
        rest = &item[end..];
    }
    out.push_str(rest);
    (out, test_files)
}

/// Where the item at the start of `s` ends: after its `;` (or `,`, for a field) or, when a `{`
/// comes first, after the matching `}` (strings and character literals skipped, so their braces do not count).
fn item_end(s: &str) -> usize {
    let b = s.as_bytes();
    let (mut i, mut depth) = (0, 0usize);
    // The item's own attributes (`#[path = "..."]`) come first.
    loop {
        while i < b.len() && b[i].is_ascii_whitespace() {
            i += 1;
        }
        if b.get(i) == Some(&b'#') {
            i += s[i..].find(']').map_or(s.len() - i, |j| j + 1);
        } else {
            break;
        }
    }
    while i < b.len() {
        match b[i] {
            b'"' => {
                i += 1;
                while i < b.len() && b[i] != b'"' {
                    i += if b[i] == b'\\' { 2 } else { 1 };
                }
            }
            b'\'' if b.get(i + 2) == Some(&b'\'') => i += 2,
            b'\'' if b.get(i + 1) == Some(&b'\\') => i += s[i + 3..].find('\'').map_or(s.len() - i, |j| j + 3),
            b';' | b',' if depth == 0 => return i + 1,
            // The end of the enclosing block: the item was a field or an expression.
            b'}' if depth == 0 => return i,
            b'{' => depth += 1,
            b'}' => {
                depth -= 1;
                if depth == 0 {
                    return i + 1;
                }
            }
            _ => {}
        }
        i += 1;
    }
    s.len()
}

/// Files that only tests compile: the test modules other files declare as files of their own.
fn test_only_files() -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for f in files() {
        let text = std::fs::read_to_string(src().join(&f)).unwrap();
        let dir = match f.rsplit_once('/') {
            Some((d, "mod.rs")) => d.to_string(),
            Some((d, name)) => format!("{d}/{}", name.trim_end_matches(".rs")),
            None if f == "lib.rs" || f == "main.rs" => String::new(),
            None => f.trim_end_matches(".rs").to_string(),
        };
        // `#[path]` is relative to the declaring file's folder; a plain `mod x;` of a non-mod
        // file lives in the folder named after it.
        let here = f.rsplit_once('/').map_or(String::new(), |(d, _)| d.to_string());
        let (_, declared) = without_test_items(&text);
        for d in declared {
            let base = if text.contains(&format!("#[path = \"{d}\"]")) { &here } else { &dir };
            out.insert(if base.is_empty() { d } else { format!("{base}/{d}") });
        }
    }
    out
}

/// The files whose code the rules read: all but those only tests compile.
fn checked_files() -> Vec<String> {
    let tests = test_only_files();
    files().into_iter().filter(|f| !tests.contains(f)).collect()
}

fn in_binary(file: &str) -> bool {
    file == "main.rs" || file.starts_with("cli/")
}

#[test]
fn clap_is_only_in_the_command_line() {
    let offenders: Vec<String> = checked_files()
        .into_iter()
        .filter(|f| !in_binary(f))
        .filter(|f| code(f).split(|c: char| !c.is_alphanumeric() && c != '_').any(|w| w == "clap"))
        .collect();
    assert!(offenders.is_empty(), "clap outside src/cli and src/main.rs: {offenders:?}");
}

/// Library files (outside the binary) whose code holds any of `words`, with the word.
fn library_files_using(words: &[&'static str]) -> Vec<(String, &'static str)> {
    checked_files()
        .into_iter()
        .filter(|f| !in_binary(f))
        .flat_map(|f| {
            let c = code(&f);
            words.iter().filter(|w| c.contains(*w)).map(|w| (f.clone(), *w)).collect::<Vec<_>>()
        })
        .collect()
}

/// What the library returns is printed by `cli/print` and `cli/bench`, never by the library.
#[test]
fn the_library_prints_no_text_tables_or_plots() {
    let offenders =
        library_files_using(&["println!", "print!", "eprintln!", "eprint!", "stdout()", "stderr()", "<svg"]);
    assert!(offenders.is_empty(), "printing in the library: {offenders:?}");
}

/// Settings reach the library as data (options, jobs), never from the process's environment: a
/// caller from Python or Blender sees every switch. The command line may read the environment.
#[test]
fn the_library_reads_no_environment() {
    let offenders =
        library_files_using(&["env::var", "env::vars", "env::args", "var_os(", "option_env!", "env::current_dir"]);
    assert!(offenders.is_empty(), "environment reads in the library: {offenders:?}");
}

/// The layer of a top-level module of the library (the first part of its path).
fn layer(module: &str) -> Option<u8> {
    Some(match module {
        "error" | "progress" | "output" | "timings" | "batch" | "pages" | "scan" => 0,
        "scene" => 1,
        "format" => 2,
        "tangent" | "normalmap" => 3,
        "bake" | "transfer" | "validate" | "preview" | "inspect" | "analytic" | "textures" => 4,
        // `crate::{Error, Result}`: the crate root's re-exports of `error`.
        "Error" | "Result" => 0,
        _ => return None,
    })
}

/// Every path a file names after `prefix::` (`crate`, `super`, `bumpbake`), brace groups
/// expanded: `use crate::{scene::Scene, Error}` gives `scene::Scene` and `Error`.
fn paths_after(code: &str, prefix: &str) -> Vec<Vec<String>> {
    fn expand(s: &str, base: &[String], out: &mut Vec<Vec<String>>) {
        // `s` starts right after `::`.
        if let Some(inner) = s.strip_prefix('{') {
            let mut depth = 0;
            let mut start = 0;
            for (i, c) in inner.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => {
                        expand(inner[start..i].trim(), base, out);
                        return;
                    }
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        expand(inner[start..i].trim(), base, out);
                        start = i + 1;
                    }
                    _ => {}
                }
            }
            return;
        }
        let mut segs = base.to_vec();
        let mut rest = s;
        loop {
            let end = rest.find(|c: char| !c.is_alphanumeric() && c != '_').unwrap_or(rest.len());
            if end == 0 {
                break;
            }
            segs.push(rest[..end].to_string());
            rest = &rest[end..];
            match rest.strip_prefix("::") {
                Some(r) if r.starts_with('{') => return expand(r, &segs, out),
                Some(r) => rest = r,
                None => break,
            }
        }
        if segs.len() > base.len() && segs.last().is_some_and(|s| s != "self") {
            out.push(segs);
        } else if segs.len() > base.len() {
            segs.pop();
            out.push(segs);
        }
    }
    let mut out = Vec::new();
    let pat = format!("{prefix}::");
    for (i, _) in code.match_indices(&pat) {
        let before = code[..i].chars().next_back();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
            continue;
        }
        expand(&code[i + pat.len()..], &[], &mut out);
    }
    out
}

/// No file of the library names a module of a higher layer.
#[test]
fn imports_flow_downward() {
    const EXCEPTIONS: [(&str, &str); 0] = [];
    let mut offenders = Vec::new();
    for f in checked_files().into_iter().filter(|f| !in_binary(f) && f != "lib.rs") {
        let own = f.split(['/', '.']).next().unwrap();
        let own_layer = layer(own).unwrap_or_else(|| panic!("{f}: module {own} has no layer in this test"));
        for p in paths_after(&code(&f), "crate") {
            let to = p[0].as_str();
            if to == own || EXCEPTIONS.contains(&(f.as_str(), to)) {
                continue;
            }
            match layer(to) {
                Some(l) if l > own_layer => offenders.push(format!("{f} -> crate::{}", p.join("::"))),
                Some(_) => {}
                None => offenders.push(format!("{f} -> crate::{}: a module with no layer in this test", p.join("::"))),
            }
        }
    }
    assert!(offenders.is_empty(), "imports from a higher layer: {offenders:#?}");
}

/// The file a module path names: the longest prefix of `segs` that is a file under `root`.
fn file_of(root: &str, segs: &[String]) -> Option<String> {
    let all = files();
    for n in (0..=segs.len()).rev() {
        let base = if root.is_empty() {
            segs[..n].join("/")
        } else {
            std::iter::once(root.to_string()).chain(segs[..n].iter().cloned()).collect::<Vec<_>>().join("/")
        };
        let candidates = if base.is_empty() {
            vec!["lib.rs".to_string()]
        } else {
            vec![format!("{base}.rs"), format!("{base}/mod.rs")]
        };
        if let Some(c) = candidates.into_iter().find(|c| all.contains(c)) {
            return Some(c);
        }
    }
    None
}

/// A file's module path inside its crate (`cli/bench/tangents/plot.rs`: cli, bench, tangents,
/// plot; `scene/mod.rs`: scene).
fn module_of(file: &str) -> Vec<String> {
    let p = file.trim_end_matches(".rs");
    let p = p.strip_suffix("/mod").unwrap_or(p);
    if p == "lib" || p == "main" {
        return Vec::new();
    }
    p.split('/').map(String::from).collect()
}

/// The files each file imports from, by `crate::`, `super::` and (in the binary) `bumpbake::`.
fn import_graph() -> BTreeMap<String, BTreeSet<String>> {
    let mut g = BTreeMap::new();
    for f in checked_files() {
        let c = code(&f);
        let here = module_of(&f);
        let mut to = BTreeSet::new();
        // The binary's crate root is main.rs, whose only module is `cli`.
        for p in paths_after(&c, "crate") {
            to.extend(file_of("", &p));
        }
        if in_binary(&f) {
            for p in paths_after(&c, "bumpbake") {
                to.extend(file_of("", &p));
            }
        }
        for p in paths_after(&c, "super") {
            let mut base: Vec<String> = here[..here.len().saturating_sub(1)].to_vec();
            let mut rest = &p[..];
            while rest.first().is_some_and(|s| s == "super") {
                base.pop();
                rest = &rest[1..];
            }
            base.extend(rest.iter().cloned());
            to.extend(file_of("", &base));
        }
        to.remove(&f);
        to.remove("lib.rs");
        to.remove("main.rs");
        g.insert(f, to);
    }
    g
}

/// Whether `a` is the parent module of `b` or the other way round.
fn parent_and_child(a: &str, b: &str) -> bool {
    let (ma, mb) = (module_of(a), module_of(b));
    let is_parent = |p: &[String], c: &[String]| c.len() == p.len() + 1 && c.starts_with(p);
    is_parent(&ma, &mb) || is_parent(&mb, &ma)
}

/// Circles between sibling files that split one reader or structure and still share helpers both
/// ways. Each lies inside one folder and one layer; they are named so that a new circle fails.
const KNOWN_CIRCLES: [&[&str]; 0] = [];

#[test]
fn no_import_circle_but_parent_and_child() {
    let g = import_graph();
    // Tarjan's strongly connected components, iteratively simple enough for a few hundred files.
    let names: Vec<&String> = g.keys().collect();
    let idx: BTreeMap<&String, usize> = names.iter().enumerate().map(|(i, n)| (*n, i)).collect();
    let adj: Vec<Vec<usize>> =
        names.iter().map(|n| g[*n].iter().filter_map(|t| idx.get(t).copied()).collect()).collect();
    let n = names.len();
    let (mut index, mut low, mut on, mut stack, mut next) =
        (vec![usize::MAX; n], vec![0; n], vec![false; n], vec![], 0);
    let mut sccs: Vec<Vec<usize>> = Vec::new();
    fn strong(
        v: usize,
        adj: &[Vec<usize>],
        st: (&mut Vec<usize>, &mut Vec<usize>, &mut Vec<bool>, &mut Vec<usize>, &mut usize),
        sccs: &mut Vec<Vec<usize>>,
    ) {
        let (index, low, on, stack, next) = st;
        index[v] = *next;
        low[v] = *next;
        *next += 1;
        stack.push(v);
        on[v] = true;
        for &w in &adj[v] {
            if index[w] == usize::MAX {
                strong(w, adj, (index, low, on, stack, next), sccs);
                low[v] = low[v].min(low[w]);
            } else if on[w] {
                low[v] = low[v].min(index[w]);
            }
        }
        if low[v] == index[v] {
            let mut c = Vec::new();
            while let Some(w) = stack.pop() {
                on[w] = false;
                c.push(w);
                if w == v {
                    break;
                }
            }
            sccs.push(c);
        }
    }
    for v in 0..n {
        if index[v] == usize::MAX {
            strong(v, &adj, (&mut index, &mut low, &mut on, &mut stack, &mut next), &mut sccs);
        }
    }
    let circles: Vec<Vec<&String>> = sccs
        .into_iter()
        .filter(|c| c.len() > 1)
        .map(|c| c.into_iter().map(|i| names[i]).collect::<Vec<_>>())
        .filter(|c| !(c.len() == 2 && parent_and_child(c[0], c[1])))
        .filter(|c| {
            let mut files: Vec<&str> = c.iter().map(|f| f.as_str()).collect();
            files.sort();
            !KNOWN_CIRCLES.contains(&files.as_slice())
        })
        .collect();
    assert!(circles.is_empty(), "files that import from each other: {circles:#?}");
}

/// The checks themselves see what they look for.
#[test]
fn the_rules_see_their_targets() {
    let p = paths_after("use crate::{scene::{Scene, view::Geometry}, Error};\nlet x = super::super::a::b();", "crate");
    assert_eq!(p, vec![vec!["scene", "Scene"], vec!["scene", "view", "Geometry"], vec!["Error"]]);
    let s = paths_after("super::super::a::b()", "super");
    assert_eq!(s, vec![vec!["super", "a", "b"]]);
    assert_eq!(file_of("", &["scene".into(), "view".into(), "Geometry".into()]).as_deref(), Some("scene/view.rs"));
    assert!(parent_and_child("cli/bench/tangents.rs", "cli/bench/tangents/plot.rs"));
    assert!(!parent_and_child("cli/bench/tangents.rs", "cli/bench/normalmap.rs"));
    let inner = "fn a() {}\n#[cfg(test)]\nmod tests {\n    fn b() { let s = \"}\"; let c = '{'; }\n}\nfn after() { crate::x::y(); }\n#[cfg(test)]\n#[path = \"t.rs\"]\nmod more;\nfn last() {}";
    let (kept, declared) = without_test_items(inner);
    assert!(kept.contains("fn a()") && kept.contains("fn after()") && kept.contains("fn last()"), "{kept}");
    assert!(!kept.contains("fn b()") && !kept.contains("mod more"), "{kept}");
    assert_eq!(declared, vec!["t.rs"]);
    let tests = test_only_files();
    assert!(tests.contains("format/obj/parse_tests.rs") && tests.contains("format/ply/tests.rs"), "{tests:?}");
    // Production code after an inner test module, and a `#[cfg(test)]` method left out.
    assert!(code("scene/normals.rs").contains("fn repair_normals"), "code after an inner test module is read");
    let filter = code("normalmap/filter.rs");
    assert!(filter.contains("fn vertical") && !filter.contains("fn row("), "test-only items cut, the rest kept");
    let g = import_graph();
    assert!(g["cli/bench/tangents/plot.rs"].contains("cli/bench/tangents.rs"), "{:?}", g["cli/bench/tangents/plot.rs"]);
    assert!(g["bake/maps.rs"].contains("validate/mod.rs"), "{:?}", g["bake/maps.rs"]);
}

/// The string literals of Rust source, outside comments and outside the items under
/// `#[cfg(test)]` (a test may spell a flag to check the command line).
fn string_literals(text: &str) -> Vec<String> {
    let c: Vec<char> = text.chars().collect();
    let ident = |i: usize| i < c.len() && (c[i].is_alphanumeric() || c[i] == '_');
    // The code with each literal replaced by \u{1}, and the literals in order.
    let (mut code, mut lits) = (String::new(), Vec::new());
    let mut i = 0;
    while i < c.len() {
        let raw_start = c[i] == 'r' && (i == 0 || !ident(i - 1) || (c[i - 1] == 'b' && (i < 2 || !ident(i - 2))));
        if c[i] == '/' && c.get(i + 1) == Some(&'/') {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if c[i] == '/' && c.get(i + 1) == Some(&'*') {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && c.get(i + 1) == Some(&'*') {
                    (depth, i) = (depth + 1, i + 2);
                } else if c[i] == '*' && c.get(i + 1) == Some(&'/') {
                    (depth, i) = (depth - 1, i + 2);
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
        } else if raw_start && matches!(c.get(i + 1), Some('#') | Some('"')) {
            let hashes = c[i + 1..].iter().take_while(|&&h| h == '#').count();
            if c.get(i + 1 + hashes) != Some(&'"') {
                code.push(c[i]);
                i += 1;
                continue;
            }
            let close: String = std::iter::once('"').chain(std::iter::repeat_n('#', hashes)).collect();
            let body: String = c[i + 2 + hashes..].iter().collect();
            let end = body.find(&close).expect("a raw string ends");
            lits.push(body[..end].to_string());
            code.push('\u{1}');
            i += 2 + hashes + body[..end].chars().count() + close.len();
        } else if c[i] == '"' {
            let mut s = String::new();
            i += 1;
            while i < c.len() && c[i] != '"' {
                if c[i] == '\\' {
                    s.push(c[i]);
                    i += 1;
                }
                s.push(c[i]);
                i += 1;
            }
            lits.push(s);
            code.push('\u{1}');
            i += 1;
        } else if c[i] == '\'' && c.get(i + 1) == Some(&'\\') {
            i += 2;
            while i < c.len() && c[i] != '\'' {
                i += 1;
            }
            i += 1;
        } else if c[i] == '\'' && c.get(i + 2) == Some(&'\'') {
            i += 3;
        } else {
            code.push(c[i]);
            i += 1;
        }
    }
    // Drop the literals of each item under `#[cfg(test)]`: up to its `;`, or its braces' end.
    let mut tested = vec![false; lits.len()];
    let marks = |s: &str| s.matches('\u{1}').count();
    for (at, _) in code.match_indices("#[cfg(test)]") {
        let rest = &code[at..];
        let Some(open) = rest.find(['{', ';']) else { continue };
        let mut end = open + 1;
        if rest[open..].starts_with('{') {
            let mut depth = 0;
            for (k, ch) in rest[open..].char_indices() {
                depth += (ch == '{') as i32 - (ch == '}') as i32;
                if depth == 0 {
                    end = open + k + 1;
                    break;
                }
            }
        }
        let first = marks(&code[..at]);
        for t in &mut tested[first..first + marks(&rest[..end])] {
            *t = true;
        }
    }
    lits.into_iter().zip(tested).filter(|(_, t)| !t).map(|(l, _)| l).collect()
}

/// Whether a literal names a command-line flag: `--` and a letter.
fn names_a_flag(lit: &str) -> bool {
    let b = lit.as_bytes();
    (0..b.len().saturating_sub(2))
        .any(|i| &b[i..i + 2] == b"--" && b[i + 2].is_ascii_alphabetic() && (i == 0 || b[i - 1] != b'-'))
}

/// The library speaks of its settings as data (`error::Setting`); each front end names them (the
/// command line with its flags), so no string of the library names a flag.
#[test]
fn no_string_of_the_library_names_a_flag() {
    // Fix advice to a person, naming `bumpbake` commands (its header says so).
    const ADVICE: &str = "validate/codes.rs";
    let sample = "let a = \"pass --convention\"; // \"--no\"\n/* \"--no\" */ let c = '\"'; let r = r#\"x --raw\"#;\n\
                  #[cfg(test)]\nmod tests { fn t() { let b = \"--no\"; } }\nfn f() { \"--yes\" }";
    let seen: Vec<String> = string_literals(sample).into_iter().filter(|l| names_a_flag(l)).collect();
    assert_eq!(seen, ["pass --convention", "x --raw", "--yes"]);
    assert!(!names_a_flag("a -- b") && !names_a_flag("----") && names_a_flag("--max-pixels"));

    let offenders: Vec<(String, String)> = files()
        .into_iter()
        .filter(|f| !in_binary(f) && f != ADVICE && !f.ends_with("/tests.rs"))
        .flat_map(|f| {
            let text = std::fs::read_to_string(src().join(&f)).unwrap();
            string_literals(&text).into_iter().filter(|l| names_a_flag(l)).map(move |l| (f.clone(), l))
        })
        .collect();
    assert!(offenders.is_empty(), "flags named in the library's strings: {offenders:#?}");
}
