//! The library's layers hold, read from the code: which file imports which
//! (`crate::…`, `super::…`, `self::…` paths, grouped imports included,
//! test modules and comments left out). No file imports from a higher
//! layer than its own (the layers of `src/lib.rs`'s documentation), and no
//! files import each other in a circle, but a `mod.rs` and the files of its
//! own folder (a facade and what it re-exports).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The library's layers, lowest first (`src/lib.rs`): a top-level module's
/// layer.
const LAYERS: &[&[&str]] = &[
    &["physics"],
    &["msgs"],
    &[
        "config",
        "range_watch",
        "signal",
        "table",
        "expression",
        "clock",
        "stats",
        "text",
        "output",
        "interrupt",
        "analysis",
    ],
    &["link", "transport"],
    &["contacts", "node", "record", "bag"],
    &["replay", "offline", "fit", "studies", "plot", "bench"],
];

/// Every `.rs` file under `dir`, as its path relative to `root`.
fn rust_files(root: &Path, dir: &Path, out: &mut Vec<String>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(root, &p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            let rel = p.strip_prefix(root).unwrap().to_string_lossy();
            out.push(rel.replace('\\', "/"));
        }
    }
}

/// The module path of a file (`fit/report.rs` → [fit, report]; a `mod.rs`
/// is its folder's module; `lib.rs` the root).
fn module_of(file: &str) -> Vec<String> {
    let mut parts: Vec<String> = file
        .trim_end_matches(".rs")
        .split('/')
        .map(str::to_string)
        .collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib")) {
        parts.pop();
    }
    parts
}

/// The code of a file before its test module, comments dropped.
fn code(text: &str) -> String {
    let text = text.split("#[cfg(test)]\nmod tests").next().unwrap_or(text);
    text.lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The paths a file's code names from `crate`, `super` or `self`, each as
/// its segments after the keyword, grouped imports expanded one level.
fn named_paths(code: &str) -> Vec<(String, Vec<String>)> {
    let mut out = Vec::new();
    let bytes = code.as_bytes();
    for kw in ["crate::", "super::", "self::"] {
        for (at, _) in code.match_indices(kw) {
            let before = at.checked_sub(1).map(|i| bytes[i] as char);
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            let mut segs = Vec::new();
            let mut rest = &code[at + kw.len()..];
            loop {
                let name: String = rest
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if name.is_empty() {
                    break;
                }
                rest = &rest[name.len()..];
                segs.push(name);
                match rest.strip_prefix("::") {
                    Some(r) => rest = r,
                    None => break,
                }
            }
            let head = kw.trim_end_matches("::").to_string();
            if let Some(group) = rest.strip_prefix('{') {
                let group = &group[..group.find('}').unwrap_or(0)];
                for item in group.split(',') {
                    let mut s = segs.clone();
                    s.extend(
                        item.trim()
                            .split(" as ")
                            .next()
                            .unwrap_or("")
                            .split("::")
                            .filter(|p| !p.is_empty() && *p != "self")
                            .map(str::to_string),
                    );
                    out.push((head.clone(), s));
                }
            } else {
                out.push((head, segs));
            }
        }
    }
    out
}

/// The import graph of the library: file → the files it imports from.
fn graph(root: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut files = Vec::new();
    rust_files(root, root, &mut files);
    files.retain(|f| f != "main.rs" && !f.starts_with("cli/"));
    let by_module: BTreeMap<Vec<String>, String> =
        files.iter().map(|f| (module_of(f), f.clone())).collect();
    let resolve = |parts: &[String]| {
        (1..=parts.len())
            .rev()
            .find_map(|k| by_module.get(&parts[..k]).cloned())
    };
    let mut g = BTreeMap::new();
    for f in &files {
        let me = module_of(f);
        let text = std::fs::read_to_string(root.join(f)).unwrap();
        let mut uses = BTreeSet::new();
        for (head, mut segs) in named_paths(&code(&text)) {
            let mut base = match head.as_str() {
                "crate" => Vec::new(),
                "self" => me.clone(),
                _ => me[..me.len().saturating_sub(1)].to_vec(),
            };
            while segs.first().is_some_and(|s| s == "super") {
                base.pop();
                segs.remove(0);
            }
            base.extend(segs);
            if let Some(t) = resolve(&base) {
                if t != *f {
                    uses.insert(t);
                }
            }
        }
        g.insert(f.clone(), uses);
    }
    g
}

fn layer(file: &str) -> usize {
    let top = module_of(file).into_iter().next().unwrap_or_default();
    LAYERS
        .iter()
        .position(|l| l.contains(&top.as_str()))
        .unwrap_or_else(|| panic!("{file}: its module `{top}` has no layer in LAYERS"))
}

/// Whether `a` → `b` is a facade's edge: a `mod.rs` and a file of its folder.
fn facade(a: &str, b: &str) -> bool {
    let folder = |m: &str| m.strip_suffix("mod.rs").map(str::to_string);
    let inside = |m: &str, f: &str| folder(m).is_some_and(|d| f.starts_with(&d));
    inside(b, a) || inside(a, b)
}

/// The circles of `g` (strongly connected sets of more than one file).
fn circles(g: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    // Reachability by search from every file: small enough (~200 files).
    let reach = |from: &str| {
        let mut seen = BTreeSet::new();
        let mut todo = vec![from.to_string()];
        while let Some(f) = todo.pop() {
            for t in g.get(&f).into_iter().flatten() {
                if seen.insert(t.clone()) {
                    todo.push(t.clone());
                }
            }
        }
        seen
    };
    let reaches: BTreeMap<&String, BTreeSet<String>> = g.keys().map(|f| (f, reach(f))).collect();
    let mut out: Vec<Vec<String>> = Vec::new();
    for f in g.keys() {
        let mut c: Vec<String> = reaches[f]
            .iter()
            .filter(|t| *t != f && reaches[*t].contains(f))
            .cloned()
            .collect();
        if !c.is_empty() {
            c.push(f.clone());
            c.sort();
            if !out.contains(&c) {
                out.push(c);
            }
        }
    }
    out
}

#[test]
fn no_file_of_the_library_imports_from_a_higher_layer_or_in_a_circle() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let full = graph(&root);
    let edges: usize = full.values().map(BTreeSet::len).sum();
    assert!(edges > 400, "{edges} imports found: the scan reads nothing");
    let mut up = Vec::new();
    for (a, uses) in &full {
        for b in uses {
            if layer(b) > layer(a) {
                up.push(format!("{a} imports {b}, a higher layer"));
            }
        }
    }
    let without_facades: BTreeMap<String, BTreeSet<String>> = full
        .iter()
        .map(|(a, uses)| {
            let kept = uses.iter().filter(|b| !facade(a, b)).cloned().collect();
            (a.clone(), kept)
        })
        .collect();
    let circles = circles(&without_facades);
    println!(
        "{} files, {edges} imports between them: {} upward, {} circles",
        full.len(),
        up.len(),
        circles.len()
    );
    assert!(up.is_empty(), "{}", up.join("\n"));
    assert!(circles.is_empty(), "{circles:?}");
}

#[test]
fn the_scan_finds_a_grouped_import_and_a_super_path() {
    let paths = named_paths("use super::{a::X, b};\nlet y = crate::fit::report::g(1);");
    assert!(paths.contains(&("super".into(), vec!["a".into(), "X".into()])));
    assert!(paths.contains(&("super".into(), vec!["b".into()])));
    assert!(paths.contains(&(
        "crate".into(),
        vec!["fit".into(), "report".into(), "g".into()]
    )));
    assert!(facade("fit/mod.rs", "fit/report.rs"));
    assert!(!facade("fit/report.rs", "fit/select.rs"));
    let g: BTreeMap<String, BTreeSet<String>> =
        [("a.rs", ["b.rs"]), ("b.rs", ["a.rs"]), ("c.rs", ["a.rs"])]
            .into_iter()
            .map(|(k, v)| (k.to_string(), v.iter().map(|s| s.to_string()).collect()))
            .collect();
    assert_eq!(
        circles(&g),
        vec![vec!["a.rs".to_string(), "b.rs".to_string()]]
    );
}
