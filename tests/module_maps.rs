//! The maps of the source tree stay true: every module that declares child
//! modules (`lib.rs`, `main.rs`, each `mod.rs`) lists every one of them in
//! its doc comment's file table, one row per file (`| \`name.rs\` | job |`),
//! folder (`| \`name/\` | job |`) or module link (`| [\`name\`] | job |`), and the table lists nothing that is not
//! there. A new file without its line in the parent's table fails here.
//!
//! What a module reads that is not Rust (a folder of `.msg` definitions, a
//! data file beside the code) is part of the map too: every entry of a
//! module's folder that is neither a `.rs` file nor a module folder has its
//! row (`| \`legacy/\` | job |`, `| \`table.csv\` | job |`).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The roots whose module trees are checked.
const ROOTS: [&str; 3] = ["src", "python/src", "capi/src"];

/// Every `lib.rs`, `main.rs` and `mod.rs` under `dir`.
fn parents(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            parents(&p, out);
        } else if matches!(
            p.file_name().and_then(|n| n.to_str()),
            Some("lib.rs" | "main.rs" | "mod.rs")
        ) {
            out.push(p);
        }
    }
}

/// The child modules a file declares (`mod x;`, `pub mod x;`,
/// `pub(crate) mod x;`), each checked to have its file (`x.rs` or `x/mod.rs`).
fn declared(text: &str, dir: &Path) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for line in text.lines() {
        let l = line.trim();
        let rest = l
            .strip_prefix("pub(crate) mod ")
            .or_else(|| l.strip_prefix("pub(super) mod "))
            .or_else(|| l.strip_prefix("pub mod "))
            .or_else(|| l.strip_prefix("mod "));
        let Some(rest) = rest else { continue };
        let Some(name) = rest.strip_suffix(';') else {
            continue; // an inline module `mod x { ... }` has no file
        };
        let name = name.trim();
        assert!(
            dir.join(format!("{name}.rs")).is_file() || dir.join(name).join("mod.rs").is_file(),
            "{}: `mod {name};` has no file",
            dir.display()
        );
        out.insert(name.to_string());
    }
    out
}

/// The entries of `dir` that are neither Rust files nor module folders
/// (folders without a `mod.rs`, files of other kinds), as a table row
/// names them: `name/` for a folder, the file's name for a file.
fn non_rust(dir: &Path) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for e in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_str().unwrap().to_string();
        if p.is_dir() {
            if !p.join("mod.rs").is_file() {
                out.insert(format!("{name}/"));
            }
        } else if p.extension().and_then(|x| x.to_str()) != Some("rs") {
            out.insert(name);
        }
    }
    out
}

/// The first cells of the doc comment's table rows that are code spans,
/// as written (`` `x.rs` `` → `x.rs`, `` `x/` `` → `x/`).
fn raw_rows(text: &str) -> BTreeSet<String> {
    text.lines()
        .filter_map(|line| line.trim_start().strip_prefix("//! | "))
        .map(|row| row.split('|').next().unwrap_or("").trim())
        .filter(|cell| cell.starts_with('`'))
        .map(|cell| cell.trim_matches('`').to_string())
        .collect()
}

/// The modules named in the doc comment's table rows, by the first cell:
/// a file (`` `x.rs` ``), a folder (`` `x/` ``) or a link (``[`x`]``,
/// ``[`mod@x`]``).
fn listed(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for line in text.lines() {
        let Some(row) = line.trim_start().strip_prefix("//! | ") else {
            continue;
        };
        let cell = row.split('|').next().unwrap_or("").trim();
        if !(cell.starts_with('`') || cell.starts_with("[`")) {
            continue; // a header, a rule or a table of symbols
        }
        let name = cell
            .trim_start_matches('[')
            .trim_end_matches(']')
            .trim_matches('`');
        // A link disambiguated for rustdoc (`mod@bench`: a module and a macro).
        let name = name.strip_prefix("mod@").unwrap_or(name);
        let name = name
            .strip_suffix(".rs")
            .or_else(|| name.strip_suffix('/'))
            .unwrap_or(name);
        if !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            out.insert(name.to_string());
        }
    }
    out
}

#[test]
fn every_module_file_has_its_line_in_its_parents_file_table() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut problems = Vec::new();
    let mut checked = 0;
    for r in ROOTS {
        let mut files = Vec::new();
        parents(&root.join(r), &mut files);
        for f in files {
            let text = std::fs::read_to_string(&f).unwrap();
            let dir = f.parent().unwrap();
            let children = declared(&text, dir);
            if children.is_empty() {
                continue;
            }
            checked += 1;
            let rows = listed(&text);
            let rel = f.strip_prefix(root).unwrap().display().to_string();
            let others = non_rust(dir);
            let raw = raw_rows(&text);
            for o in others.difference(&raw) {
                problems.push(format!(
                    "{rel}: `{o}` (not Rust, read beside the code) is missing from the file table"
                ));
            }
            let other_modules: BTreeSet<String> = others
                .iter()
                .map(|o| o.trim_end_matches('/').to_string())
                .collect();
            for c in children.difference(&rows) {
                problems.push(format!("{rel}: `{c}` is missing from the file table"));
            }
            let this = f.file_stem().unwrap().to_str().unwrap().to_string();
            for c in rows.difference(&children) {
                if *c != this && !other_modules.contains(c) {
                    problems.push(format!(
                        "{rel}: the file table lists `{c}`, which is no module"
                    ));
                }
            }
        }
    }
    assert!(checked >= 20, "only {checked} parent modules found");
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The files of `fit/` named by `super::NAME` / `crate::fit::NAME` in
/// `text` (its code before its test module, comments dropped), including
/// those of grouped imports (`use super::{a::X, b};`).
fn sibling_uses(text: &str, siblings: &BTreeSet<String>) -> BTreeSet<String> {
    let code = text.split("#[cfg(test)]\nmod tests").next().unwrap_or(text);
    let code: String = code
        .lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n");
    let mut out = BTreeSet::new();
    let mut add = |name: &str| {
        let name = name.trim_matches(|c: char| !c.is_alphanumeric() && c != '_');
        if siblings.contains(name) {
            out.insert(name.to_string());
        }
    };
    for prefix in ["super::", "crate::fit::"] {
        for (at, _) in code.match_indices(prefix) {
            let rest = &code[at + prefix.len()..];
            if let Some(group) = rest.strip_prefix('{') {
                for item in group[..group.find('}').unwrap_or(0)].split(',') {
                    add(item.trim().split("::").next().unwrap_or(""));
                }
            } else {
                let name: String = rest
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                // A sibling module only if a path goes on from it.
                if rest[name.len()..].starts_with("::") {
                    add(&name);
                }
            }
        }
    }
    out
}

#[test]
fn the_calibration_reads_top_down_every_file_using_only_files_below_it() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/fit");
    let map = std::fs::read_to_string(dir.join("mod.rs")).unwrap();
    // The file table's order is the reading order.
    let order: Vec<String> = map
        .lines()
        .filter_map(|l| l.strip_prefix("//! | `"))
        .filter_map(|l| l.split('`').next())
        .filter_map(|f| f.strip_suffix(".rs"))
        .map(str::to_string)
        .collect();
    let siblings: BTreeSet<String> = order.iter().cloned().collect();
    assert!(order.len() > 20, "{order:?}");
    assert_eq!(order[0], "request", "the flow comes first");
    // Shared by every file: the errors and the units.
    let everywhere = ["error", "units"];
    let mut edges = 0;
    let mut up = Vec::new();
    for (i, f) in order.iter().enumerate() {
        let text = std::fs::read_to_string(dir.join(format!("{f}.rs"))).unwrap();
        for used in sibling_uses(&text, &siblings) {
            if used == *f || everywhere.contains(&used.as_str()) {
                continue;
            }
            edges += 1;
            let j = order.iter().position(|o| *o == used).unwrap();
            if j < i {
                up.push(format!("{f}.rs uses {used}.rs, above it"));
            }
        }
    }
    assert!(edges > 40, "{edges} uses found: the scan reads nothing");
    assert!(up.is_empty(), "{}", up.join("\n"));
}

/// The fields of `pub struct NAME { ... }` in `text`.
fn struct_fields(text: &str, name: &str) -> Vec<String> {
    let start = text
        .find(&format!("pub struct {name} {{"))
        .unwrap_or_else(|| panic!("no struct {name}"));
    let body = &text[start..];
    let body = &body[..body.find("\n}\n").expect("the struct ends")];
    body.lines()
        .skip(1)
        .filter_map(|l| {
            let l = l.strip_prefix("    ")?;
            if l.starts_with(' ') || l.starts_with("//") || l.starts_with('#') {
                return None;
            }
            let l = l
                .trim_start_matches("pub(crate) ")
                .trim_start_matches("pub ");
            let (name, _) = l.split_once(':')?;
            name.chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
                .then(|| name.to_string())
        })
        .collect()
}

/// Whether `text` names `self.FIELD` (the field, not a longer name).
fn uses_field(text: &str, field: &str) -> bool {
    let pat = format!("self.{field}");
    text.match_indices(&pat).any(|(i, _)| {
        text[i + pat.len()..]
            .chars()
            .next()
            .is_none_or(|c| !(c.is_ascii_alphanumeric() || c == '_'))
    })
}

/// The files that hold part of `Solver`'s or `Loop`'s methods are headed by
/// the fields they use, and the header stays true: it lists exactly the
/// struct's fields the file's code names (`self.field`).
#[test]
fn each_file_of_the_solvers_and_the_loops_methods_is_headed_by_the_fields_it_uses() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (defn, name, dir) in [
        ("src/physics/solver/mod.rs", "Solver", "src/physics/solver"),
        ("src/node/mod.rs", "Loop", "src/node"),
    ] {
        let fields = struct_fields(&std::fs::read_to_string(root.join(defn)).unwrap(), name);
        assert!(fields.len() > 10, "{name}: {fields:?}");
        let mut headed = 0;
        for e in std::fs::read_dir(root.join(dir)).unwrap() {
            let p = e.unwrap().path();
            if p.file_name().is_some_and(|n| n == "mod.rs")
                || p.extension().is_none_or(|x| x != "rs")
            {
                continue;
            }
            let text = std::fs::read_to_string(&p).unwrap();
            if !text.contains(&format!("impl {name} {{")) {
                continue;
            }
            headed += 1;
            let marker = format!("//! `{name}`'s fields this file uses: ");
            let line = text
                .lines()
                .find_map(|l| l.strip_prefix(marker.as_str()))
                .unwrap_or_else(|| panic!("{}: no line `{marker}…`", p.display()));
            let listed: BTreeSet<String> = line
                .trim_end_matches('.')
                .split(", ")
                .map(|f| f.trim_matches('`').to_string())
                .collect();
            let code: String = text
                .lines()
                .filter(|l| !l.trim_start().starts_with("//"))
                .collect::<Vec<_>>()
                .join("\n");
            let used: BTreeSet<String> = fields
                .iter()
                .filter(|f| uses_field(&code, f))
                .cloned()
                .collect();
            assert_eq!(listed, used, "{}: the header's fields", p.display());
        }
        assert!(headed >= 4, "{name}: {headed} files");
    }
}
