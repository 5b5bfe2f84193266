//! The workspace's structural rules (DESIGN section 2, `docs/ARCHITECTURE.md`), each held by a
//! test here:
//! * which workspace crates each crate may depend on: a technique crate on `shadow-core`
//!   alone, nothing on the harness (`cargo metadata`);
//! * a renderer's crate that takes one technique and the loader builds and runs without the
//!   reference, the GPU stack or the harness (`tests/fixtures/one-technique`);
//! * no import circle between sibling modules of any crate.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

/// The workspace root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ sits in the workspace")
        .to_path_buf()
}

fn cargo() -> Command {
    Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
}

/// The harness: it may depend on everything, nothing may depend on it.
const HARNESS: [&str; 3] = ["shadow-conformance", "shadow-tests", "xtask"];

/// The workspace crates each library crate may take as ordinary (not dev) dependencies.
fn allowed() -> BTreeMap<&'static str, &'static [&'static str]> {
    const CORE: &[&str] = &["shadow-core"];
    BTreeMap::from([
        ("shadow-core", &[] as &[&str]),
        ("shadow-io", CORE),
        ("shadow-scenes", &["shadow-core", "shadow-io"]),
        ("shadow-metrics", CORE),
        // Technique crates: the vocabulary alone (a hybrid takes rays through
        // `shadow_core::rays`).
        ("shadow-ref", CORE),
        ("shadow-dcs", CORE),
        ("shadow-ssm", CORE),
        ("shadow-afsm", CORE),
        // The chooser composes techniques through the trait.
        ("shadow-auto", &["shadow-core", "shadow-ref", "shadow-dcs"]),
        (
            "shadow-presets",
            &[
                "shadow-core",
                "shadow-scenes",
                "shadow-ref",
                "shadow-dcs",
                "shadow-ssm",
                "shadow-afsm",
                "shadow-auto",
            ],
        ),
        // The Python package converts arrays and calls the crates (no technique of its own).
        (
            "shadow-python",
            &[
                "shadow-core",
                "shadow-io",
                "shadow-scenes",
                "shadow-presets",
            ],
        ),
    ])
}

/// `cargo metadata --no-deps`: the workspace's own manifests (no network, no resolution).
fn metadata() -> Value {
    let out = cargo()
        .args(["metadata", "--no-deps", "--format-version", "1"])
        .current_dir(root())
        .output()
        .expect("cargo runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("cargo metadata prints JSON")
}

#[test]
fn each_crate_depends_only_on_the_crates_its_rule_allows() {
    let meta = metadata();
    let packages = meta["packages"].as_array().expect("packages");
    let members: BTreeSet<&str> = packages
        .iter()
        .map(|p| p["name"].as_str().expect("name"))
        .collect();
    let allowed = allowed();
    let mut broken = Vec::new();
    for p in packages {
        let name = p["name"].as_str().expect("name");
        let deps: Vec<&str> = p["dependencies"]
            .as_array()
            .expect("dependencies")
            .iter()
            .filter(|d| d["kind"].is_null())
            .map(|d| d["name"].as_str().expect("dependency name"))
            .filter(|d| members.contains(d))
            .collect();
        if HARNESS.contains(&name) {
            continue;
        }
        let Some(ok) = allowed.get(name) else {
            broken.push(format!(
                "{name}: a workspace crate without a rule (add it to `allowed`)"
            ));
            continue;
        };
        for d in deps {
            if !ok.contains(&d) {
                broken.push(format!("{name} depends on {d}; it may take only {ok:?}"));
            }
        }
    }
    assert!(broken.is_empty(), "{}", broken.join("\n"));
}

#[test]
fn shadow_core_compiles_the_gpu_stack_only_behind_its_feature() {
    let meta = metadata();
    let core = meta["packages"]
        .as_array()
        .expect("packages")
        .iter()
        .find(|p| p["name"] == "shadow-core")
        .expect("shadow-core is a member");
    for d in core["dependencies"].as_array().expect("dependencies") {
        let name = d["name"].as_str().expect("name");
        if ["wgpu", "naga", "pollster", "bytemuck"].contains(&name) {
            assert_eq!(d["optional"], true, "shadow-core's {name} must be optional");
        }
        assert!(
            !["gltf", "tobj", "image", "obvhs"].contains(&name),
            "shadow-core depends on {name}, which belongs to another crate"
        );
    }
}

/// What a crate with one technique and the loader must not pull in.
const NOT_IN_ONE_TECHNIQUE: [&str; 11] = [
    "wgpu",
    "naga",
    "obvhs",
    "shadow-ref",
    "shadow-ssm",
    "shadow-afsm",
    "shadow-scenes",
    "shadow-metrics",
    "shadow-auto",
    "shadow-presets",
    "shadow-conformance",
];

#[test]
fn one_technique_crate_builds_without_the_rest() {
    let fixture = root().join("tests/fixtures/one-technique");
    // The workspace's lock pins the fixture's versions to the ones this workspace tests.
    std::fs::copy(root().join("Cargo.lock"), fixture.join("Cargo.lock")).expect("copy lock");
    let target = root().join("target/one-technique");
    let run = |args: &[&str]| {
        let out = cargo()
            .args(args)
            .current_dir(&fixture)
            .env("CARGO_TARGET_DIR", &target)
            .output()
            .expect("cargo runs");
        let text = String::from_utf8_lossy(&out.stdout).to_string();
        assert!(
            out.status.success(),
            "cargo {args:?} failed:\n{text}\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        text
    };
    let tree = run(&["tree", "-e", "normal", "--prefix", "none"]);
    let names: BTreeSet<&str> = tree
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    assert!(names.contains("shadow-dcs") && names.contains("shadow-io"));
    for n in NOT_IN_ONE_TECHNIQUE {
        assert!(!names.contains(n), "the one-technique crate pulls in {n}");
    }
    let out = run(&["run", "--quiet"]);
    assert!(out.starts_with("valid "), "{out}");
}

/// A crate's source modules: module path (`load::texture`) -> file.
fn modules(src: &Path) -> BTreeMap<Vec<String>, PathBuf> {
    let mut out = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).expect("read src") {
            let path = e.expect("entry").path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            if path.extension().is_none_or(|x| x != "rs") {
                continue;
            }
            let rel = path.strip_prefix(src).expect("under src");
            let mut parts: Vec<String> = rel
                .iter()
                .map(|c| c.to_string_lossy().trim_end_matches(".rs").to_string())
                .collect();
            let last = parts.last().cloned().unwrap_or_default();
            if ["mod", "lib", "main"].contains(&last.as_str()) {
                parts.pop();
            }
            // `src/bin/x.rs` and `src/main.rs` beside `lib.rs` are roots of their own.
            if parts.first().is_some_and(|p| p == "bin") {
                continue;
            }
            out.insert(parts, path);
        }
    }
    out
}

/// The module paths a file's code names (`crate::a::b`, `super::c`, and their `{...}` groups),
/// outside comments and test modules, resolved against `here` (the file's module).
fn references(text: &str, here: &[String]) -> Vec<Vec<String>> {
    let code: String = text
        .split("#[cfg(test)]\nmod tests")
        .next()
        .unwrap_or_default()
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n");
    let mut out = Vec::new();
    for (anchor, base) in [
        ("crate::", Vec::new()),
        ("super::", here[..here.len().saturating_sub(1)].to_vec()),
    ] {
        let mut rest = code.as_str();
        while let Some(i) = rest.find(anchor) {
            let preceded = rest[..i]
                .chars()
                .last()
                .is_some_and(|c| c.is_alphanumeric() || c == '_');
            rest = &rest[i + anchor.len()..];
            if preceded {
                continue;
            }
            for path in expand(rest) {
                let mut full = base.clone();
                full.extend(path);
                out.push(full);
            }
        }
    }
    out
}

/// The paths a `use` tail names: `a::b::C;` gives `[a, b, C]`, `a::{b, c::d}` gives
/// `[a, b]` and `[a, c, d]`.
fn expand(tail: &str) -> Vec<Vec<String>> {
    let mut prefix = Vec::new();
    let mut s = tail;
    loop {
        if let Some(group) = s.strip_prefix('{') {
            return group_items(group)
                .into_iter()
                .flat_map(expand)
                .map(|p| prefix.iter().cloned().chain(p).collect())
                .collect();
        }
        let end = s
            .find(|c: char| !(c.is_alphanumeric() || c == '_'))
            .unwrap_or(s.len());
        if end > 0 {
            prefix.push(s[..end].to_string());
        }
        match s[end..].strip_prefix("::") {
            Some(r) => s = r,
            None => return vec![prefix],
        }
    }
}

/// The top-level items of a `{...}` group whose opening brace is already consumed.
fn group_items(group: &str) -> Vec<&str> {
    let mut depth = 1;
    let (mut start, mut items) = (0, Vec::new());
    for (k, c) in group.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => {
                depth -= 1;
                if depth == 0 {
                    items.push(&group[start..k]);
                    break;
                }
            }
            ',' if depth == 1 => {
                items.push(&group[start..k]);
                start = k + 1;
            }
            _ => {}
        }
    }
    items
        .into_iter()
        .map(str::trim)
        .filter(|i| !i.is_empty())
        .collect()
}

/// The import graph between a crate's module files, without edges between a module and its
/// ancestors (a parent declares and re-exports its children; children use their parent's
/// items): only imports across the tree can make a circle.
fn import_graph(src: &Path) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let mods = modules(src);
    let mut graph: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    for (here, file) in &mods {
        let text = std::fs::read_to_string(file).expect("read module");
        let edges = graph.entry(here.clone()).or_default();
        for path in references(&text, here) {
            let target = (0..=path.len())
                .rev()
                .map(|n| path[..n].to_vec())
                .find(|p| mods.contains_key(p));
            let Some(target) = target else { continue };
            let related = target.starts_with(here) || here.starts_with(&target);
            if !related {
                edges.insert(target);
            }
        }
    }
    graph
}

/// One circle of `graph`, if any (depth-first search with colours).
fn find_circle(graph: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> Option<Vec<String>> {
    fn visit(
        n: &Vec<String>,
        graph: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
        state: &mut BTreeMap<Vec<String>, u8>,
        path: &mut Vec<Vec<String>>,
    ) -> Option<Vec<String>> {
        state.insert(n.clone(), 1);
        path.push(n.clone());
        for m in graph.get(n).into_iter().flatten() {
            match state.get(m).copied().unwrap_or(0) {
                1 => {
                    let start = path.iter().position(|p| p == m).unwrap_or(0);
                    let mut circle: Vec<String> =
                        path[start..].iter().map(|p| p.join("::")).collect();
                    circle.push(m.join("::"));
                    return Some(circle);
                }
                0 => {
                    if let Some(c) = visit(m, graph, state, path) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        path.pop();
        state.insert(n.clone(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in graph.keys() {
        if state.get(n).copied().unwrap_or(0) == 0
            && let Some(c) = visit(n, graph, &mut state, &mut Vec::new())
        {
            return Some(c);
        }
    }
    None
}

#[test]
fn no_crate_has_an_import_circle_between_its_modules() {
    let meta = metadata();
    let mut circles = Vec::new();
    for p in meta["packages"].as_array().expect("packages") {
        let manifest = PathBuf::from(p["manifest_path"].as_str().expect("manifest path"));
        let src = manifest.parent().expect("crate folder").join("src");
        if let Some(c) = find_circle(&import_graph(&src)) {
            circles.push(format!("{}: {}", p["name"], c.join(" -> ")));
        }
    }
    assert!(
        circles.is_empty(),
        "import circles:\n{}",
        circles.join("\n")
    );
}

#[test]
fn the_circle_finder_finds_a_circle_between_siblings_and_none_through_a_parent() {
    let m = |s: &str| s.split("::").map(String::from).collect::<Vec<_>>();
    let src = std::env::temp_dir().join(format!("crate-rules-{}", std::process::id()));
    let write = |rel: &str, text: &str| {
        let path = src.join(rel);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    };
    write("lib.rs", "mod load;\npub use load::{a::A, b::B};\n");
    write("load/mod.rs", "mod a;\nmod b;\npub struct E;\n");
    write(
        "load/a.rs",
        "use super::E;\nuse crate::load::{b::{B}};\npub struct A;\n",
    );
    write("load/b.rs", "// use super::a::A;\npub struct B;\n");
    let g = import_graph(&src);
    assert_eq!(g[&m("load::a")], BTreeSet::from([m("load::b")]));
    assert!(find_circle(&g).is_none());
    write("load/b.rs", "use super::{a::A, E};\npub struct B;\n");
    let circle = find_circle(&import_graph(&src)).expect("a -> b -> a");
    assert_eq!(circle.first(), circle.last());
    std::fs::remove_dir_all(&src).unwrap();
}

/// The most lines a Rust source file of the workspace may hold (ARCHITECTURE.md: small modules
/// named for what they do).
const MAX_FILE_LINES: usize = 800;

/// Every `.rs` file under `dir`, skipping build output and the one-technique fixture's own.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let path = e.path();
        let name = e.file_name();
        if path.is_dir() {
            if name != "target" && name != ".git" && name != "out" {
                rust_files(&path, out);
            }
        } else if path.extension().is_some_and(|x| x == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn no_source_file_is_over_800_lines() {
    let mut files = Vec::new();
    rust_files(&root(), &mut files);
    assert!(files.len() > 100, "found {} source files", files.len());
    let long: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let n = std::fs::read_to_string(f).ok()?.lines().count();
            (n > MAX_FILE_LINES).then(|| format!("{} ({n} lines)", f.display()))
        })
        .collect();
    assert!(long.is_empty(), "over {MAX_FILE_LINES} lines: {long:?}");
}

/// The most lines a function of the workspace may span, signature to closing brace
/// (ARCHITECTURE.md: stage functions named for the stage).
const MAX_FUNCTION_LINES: usize = 150;

/// `text` with string and character literals and comments blanked out (newlines kept), so
/// that braces and `fn` are read from code alone.
fn code_only(text: &str) -> String {
    #[derive(Clone, Copy, PartialEq)]
    enum State {
        Code,
        Str,
        RawStr(usize),
        LineComment,
        BlockComment(usize),
    }
    let chars: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut state = State::Code;
    let mut i = 0;
    let blank = |c: char| if c == '\n' { '\n' } else { ' ' };
    while i < chars.len() {
        let c = chars[i];
        let next = chars.get(i + 1).copied();
        match state {
            State::Code => {
                if c == '/' && next == Some('/') {
                    state = State::LineComment;
                    out.push(' ');
                } else if c == '/' && next == Some('*') {
                    state = State::BlockComment(1);
                    out.push_str("  ");
                    i += 1;
                } else if c == '"' {
                    state = State::Str;
                    out.push(' ');
                } else if c == 'r'
                    && (next == Some('"') || next == Some('#'))
                    && !chars
                        .get(i.wrapping_sub(1))
                        .is_some_and(|p| p.is_alphanumeric() || *p == '_')
                {
                    let hashes = chars[i + 1..].iter().take_while(|&&h| h == '#').count();
                    if chars.get(i + 1 + hashes) == Some(&'"') {
                        state = State::RawStr(hashes);
                        for _ in 0..hashes + 2 {
                            out.push(' ');
                        }
                        i += hashes + 1;
                    } else {
                        out.push(c);
                    }
                } else if c == '\'' {
                    // A character literal ('x', '\n', '\u{..}'), not a lifetime.
                    let close = if next == Some('\\') {
                        chars[i + 2..]
                            .iter()
                            .position(|&x| x == '\'')
                            .map(|p| i + 2 + p)
                    } else if chars.get(i + 2) == Some(&'\'') {
                        Some(i + 2)
                    } else {
                        None
                    };
                    match close {
                        Some(end) => {
                            for _ in i..=end {
                                out.push(' ');
                            }
                            i = end;
                        }
                        None => out.push(c),
                    }
                } else {
                    out.push(c);
                }
            }
            State::Str => {
                if c == '\\' {
                    out.push(' ');
                    if let Some(n) = next {
                        out.push(blank(n));
                    }
                    i += 1;
                } else {
                    if c == '"' {
                        state = State::Code;
                    }
                    out.push(blank(c));
                }
            }
            State::RawStr(hashes) => {
                if c == '"' && chars[i + 1..].iter().take(hashes).all(|&h| h == '#') {
                    state = State::Code;
                    for _ in 0..=hashes {
                        out.push(' ');
                    }
                    i += hashes;
                } else {
                    out.push(blank(c));
                }
            }
            State::LineComment => {
                if c == '\n' {
                    state = State::Code;
                }
                out.push(blank(c));
            }
            State::BlockComment(depth) => {
                if c == '*' && next == Some('/') {
                    state = if depth == 1 {
                        State::Code
                    } else {
                        State::BlockComment(depth - 1)
                    };
                    out.push_str("  ");
                    i += 1;
                } else if c == '/' && next == Some('*') {
                    state = State::BlockComment(depth + 1);
                    out.push_str("  ");
                    i += 1;
                } else {
                    out.push(blank(c));
                }
            }
        }
        i += 1;
    }
    out
}

/// Each function with a body in `text`: its name, first line (1-based) and length in lines.
fn functions(text: &str) -> Vec<(String, usize, usize)> {
    let code = code_only(text);
    let lines: Vec<&str> = code.lines().collect();
    let mut out = Vec::new();
    for (start, line) in lines.iter().enumerate() {
        let mut words = line.split_whitespace().peekable();
        while let Some(w) = words.peek() {
            if w.starts_with("pub") || ["const", "async", "unsafe", "extern"].contains(w) {
                words.next();
            } else {
                break;
            }
        }
        if words.next() != Some("fn") {
            continue;
        }
        let name: String = words
            .next()
            .unwrap_or("")
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        let (mut depth, mut opened) = (0i64, false);
        'body: for (k, l) in lines.iter().enumerate().skip(start) {
            for c in l.chars() {
                match c {
                    '{' => {
                        depth += 1;
                        opened = true;
                    }
                    '}' => depth -= 1,
                    ';' if !opened => break 'body,
                    _ => {}
                }
                if opened && depth == 0 {
                    out.push((name.clone(), start + 1, k - start + 1));
                    break 'body;
                }
            }
        }
    }
    out
}

#[test]
fn the_function_reader_measures_bodies_and_skips_literals_and_comments() {
    let text = "fn a() {\n    let s = \"}}}\";\n    // }\n    let c = '{';\n}\n\
                pub(crate) fn b(x: &'static str) -> u8 {\n    let r = r#\"{\"#;\n    1\n}\n\
                fn declared();\n";
    let f = functions(text);
    assert_eq!(
        f,
        vec![("a".to_string(), 1, 5), ("b".to_string(), 6, 4)],
        "{}",
        code_only(text)
    );
}

#[test]
fn no_function_is_over_150_lines() {
    let mut files = Vec::new();
    rust_files(&root(), &mut files);
    let mut measured = 0;
    let mut long = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).expect("readable source");
        for (name, line, n) in functions(&text) {
            measured += 1;
            if n > MAX_FUNCTION_LINES {
                long.push(format!("{}:{line} {name} ({n} lines)", f.display()));
            }
        }
    }
    assert!(measured > 1000, "measured {measured} functions");
    assert!(
        long.is_empty(),
        "over {MAX_FUNCTION_LINES} lines: {long:#?}"
    );
}
