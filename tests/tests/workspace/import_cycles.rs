//! Dependencies between the files of one crate point one way
//! (ARCHITECTURE's rule): a file that names `crate::a` depends on `a`,
//! and no chain of such names may lead back to where it started. The
//! circles that remain are listed here, each to be cut; the test fails when
//! a new one appears, and when a listed one is gone (so the list only
//! shrinks).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use rtgi_tests::workspace_root;

/// The circles not yet cut, as sorted lists of module paths, by crate.
const KNOWN: &[(&str, &[&str])] = &[
    // The scalar triangle tests and the SIMD kernels share hit types both ways.
    ("crates/accel", &["simd::packet_triangles", "simd::triangles", "triangle"]),
    // `rtgi trace` takes its Args from cli.rs, and `rtgi rays`, whose Args cli.rs gathers, takes the ray
    // record's size from trace_cmd.rs; the rest of the app's circle is cut (issue 48).
    ("apps/rtgi", &["cli", "rays_cmd", "trace_cmd"]),
];

/// Every module of the crate at `crate_dir` (its `src`), by path (`simd::triangles`), with its source.
fn modules(crate_dir: &Path) -> BTreeMap<String, String> {
    fn walk(dir: &Path, src: &Path, found: &mut BTreeMap<String, String>) {
        for entry in std::fs::read_dir(dir).expect("a source folder").flatten() {
            let path = entry.path();
            if path.is_dir() {
                walk(&path, src, found);
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let relative = path.strip_prefix(src).unwrap().with_extension("");
            let mut parts: Vec<String> = relative.iter().map(|p| p.to_string_lossy().into_owned()).collect();
            if parts.last().is_some_and(|p| p == "mod") {
                parts.pop();
            }
            if parts == ["lib"] || parts == ["main"] || parts.is_empty() {
                continue;
            }
            found.insert(parts.join("::"), std::fs::read_to_string(&path).unwrap());
        }
    }
    let src = crate_dir.join("src");
    let mut found = BTreeMap::new();
    walk(&src, &src, &mut found);
    found
}

/// The modules each module names through `crate::` or `super::`, outside
/// comments and its tests.
fn dependencies(modules: &BTreeMap<String, String>) -> BTreeMap<String, BTreeSet<String>> {
    let mut graph = BTreeMap::new();
    for (name, source) in modules {
        let code = source.split("#[cfg(test)]").next().unwrap_or("");
        let mut named = BTreeSet::new();
        for line in code.lines().filter(|l| !l.trim_start().starts_with("//")) {
            for (prefix, base) in [
                ("crate::", Vec::new()),
                ("super::", {
                    let mut parent: Vec<&str> = name.split("::").collect();
                    parent.pop();
                    parent
                }),
            ] {
                for (at, _) in line.match_indices(prefix) {
                    // `$crate::` in macros names the crate too.
                    let path: Vec<&str> = line[at + prefix.len()..]
                        .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':'))
                        .next()
                        .unwrap_or("")
                        .split("::")
                        .collect();
                    let mut full: Vec<&str> = base.clone();
                    full.extend(path);
                    // The longest prefix that is a module.
                    if let Some(module) =
                        (1..=full.len()).rev().map(|k| full[..k].join("::")).find(|m| modules.contains_key(m))
                        && &module != name
                    {
                        named.insert(module);
                    }
                }
            }
        }
        graph.insert(name.clone(), named);
    }
    graph
}

/// The strongly connected components of more than one module (Tarjan), each sorted.
fn circles(graph: &BTreeMap<String, BTreeSet<String>>) -> BTreeSet<Vec<String>> {
    struct State<'a> {
        graph: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        found: BTreeSet<Vec<String>>,
    }
    fn visit<'a>(v: &'a str, s: &mut State<'a>) {
        let i = s.index.len();
        s.index.insert(v, i);
        s.low.insert(v, i);
        s.stack.push(v);
        for w in &s.graph[v] {
            if !s.index.contains_key(w.as_str()) {
                visit(w, s);
                let low = s.low[v].min(s.low[w.as_str()]);
                s.low.insert(v, low);
            } else if s.stack.contains(&w.as_str()) {
                let low = s.low[v].min(s.index[w.as_str()]);
                s.low.insert(v, low);
            }
        }
        if s.low[v] == s.index[v] {
            let at = s.stack.iter().position(|&x| x == v).unwrap();
            let mut component: Vec<String> = s.stack.drain(at..).map(str::to_owned).collect();
            if component.len() > 1 {
                component.sort();
                s.found.insert(component);
            }
        }
    }
    let mut state =
        State { graph, index: BTreeMap::new(), low: BTreeMap::new(), stack: Vec::new(), found: BTreeSet::new() };
    for v in graph.keys() {
        if !state.index.contains_key(v.as_str()) {
            visit(v, &mut state);
        }
    }
    state.found
}

#[test]
fn the_files_of_a_crate_import_one_another_one_way() {
    let root = workspace_root();
    let mut crates: Vec<String> = std::fs::read_dir(root.join("crates"))
        .unwrap()
        .flatten()
        .filter(|e| e.path().join("src").is_dir())
        .map(|e| format!("crates/{}", e.file_name().to_string_lossy()))
        .collect();
    crates.push("apps/rtgi".to_owned());
    crates.sort();
    assert!(crates.len() >= 7, "{crates:?}");
    let mut problems = Vec::new();
    for krate in &crates {
        let found = circles(&dependencies(&modules(&root.join(krate))));
        let known: BTreeSet<Vec<String>> = KNOWN
            .iter()
            .filter(|(k, _)| k == krate)
            .map(|(_, modules)| modules.iter().map(|m| m.to_string()).collect())
            .collect();
        for circle in found.difference(&known) {
            problems.push(format!("{krate}: these files import one another in a circle: {}", circle.join(", ")));
        }
        for circle in known.difference(&found) {
            problems.push(format!("{krate}: the circle {} is cut: take it off KNOWN", circle.join(", ")));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn a_circle_is_found_through_crate_and_super_paths() {
    let modules: BTreeMap<String, String> = [
        ("a", "use crate::b::Thing;"),
        ("b", "fn f() { crate::c::g() }"),
        ("c", "// crate::a in a comment is no import\nuse super::a;"),
        ("d::e", "use super::f::X;"),
        ("d::f", "use crate::d::e::Y;"),
        ("g", "use crate::a;"),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_owned(), v.to_owned()))
    .collect();
    let found = circles(&dependencies(&modules));
    let expected: BTreeSet<Vec<String>> = [vec!["a", "b", "c"], vec!["d::e", "d::f"]]
        .into_iter()
        .map(|c| c.into_iter().map(String::from).collect())
        .collect();
    assert_eq!(found, expected);
}
