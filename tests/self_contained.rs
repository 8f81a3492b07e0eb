//! The repository stands alone: no file of it names a path outside it (a
//! parent-folder path that climbs out of the clone, a machine's absolute
//! path), every local link of the README and the docs leads to a file that
//! is there, and every path the README's Layout lists exists. A clone with nothing beside
//! it builds, runs, tests and documents itself.

use std::path::{Component, Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Folders that hold no file of the project's own text: build output,
/// git, generated or fuzzing data, recordings.
const SKIPPED_DIRS: &[&str] = &[
    ".git",
    "target",
    "out",
    "fuzz/corpus",
    "fuzz/artifacts",
    "fuzz/target",
    "fuzz/coverage",
    "fuzz/logs",
    "data",
    "__pycache__",
];

/// The kinds of text files that can name a path: source, tests, scripts,
/// docs, configuration.
const TEXT_EXTENSIONS: &[&str] = &[
    "rs", "md", "sh", "py", "pyi", "yaml", "yml", "toml", "c", "h", "msg", "xml", "txt", "cfg",
];

fn text_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap().map(Result::unwrap) {
        let p = e.path();
        let rel = p
            .strip_prefix(root())
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        if p.is_dir() {
            let skipped = SKIPPED_DIRS.contains(&rel.as_str())
                || rel.ends_with("__pycache__")
                || rel.ends_with(".egg-info");
            if !skipped {
                text_files(&p, out);
            }
        } else {
            let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
            let in_ci = rel.starts_with(".ci/");
            if TEXT_EXTENSIONS.contains(&ext) || in_ci {
                out.push(p);
            }
        }
    }
}

/// `p` with `.` and `..` resolved lexically; None when it climbs above
/// its start.
fn normalise(p: &Path) -> Option<PathBuf> {
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    return None;
                }
            }
            Component::Normal(n) => out.push(n),
            _ => return None,
        }
    }
    Some(out)
}

/// A path that climbs one folder (spelt in pieces, so that this file does
/// not name one itself).
const UP: &str = concat!("..", "/");

/// The top folders of machines' absolute paths (a user's home, a build
/// machine's work tree).
const MACHINE_TOPS: &[&str] = &["work", "home", "root", "Users"];

/// A path inside the clone's build output (`target/`, `out/`): made by a
/// build or a run, so it need not exist in a fresh clone to stay inside.
fn generated(p: &Path) -> bool {
    p.starts_with("target") || p.starts_with("out")
}

fn path_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || "_./-".contains(c)
}

/// What `text` (the content of `file`, a path relative to the repository)
/// names outside the repository: every parent-folder path that resolves, from the
/// file's folder or one of its parents up to the top, to nothing inside
/// the repository; and every absolute path of a machine.
fn outside(text: &str, file: &Path, exists: &dyn Fn(&Path) -> bool) -> Vec<String> {
    let mut found = Vec::new();
    let chars: Vec<char> = text.chars().collect();
    for i in 0..chars.len() {
        let start = i == 0 || !path_char(chars[i - 1]);
        if !start {
            continue;
        }
        let token: String = chars[i..].iter().take_while(|c| path_char(**c)).collect();
        if token.starts_with(UP) {
            let inside = file.ancestors().skip(1).any(|dir| {
                normalise(&dir.join(&token))
                    .is_some_and(|p| !p.as_os_str().is_empty() && (exists(&p) || generated(&p)))
            });
            if !inside {
                found.push(token);
            }
        }
    }
    for top in MACHINE_TOPS {
        let machine = format!("/{top}/");
        for (at, _) in text.match_indices(&machine) {
            let before = text[..at].chars().next_back();
            if before.is_none_or(|c| !path_char(c) && c != ':') {
                let token: String = text[at..].chars().take_while(|c| path_char(*c)).collect();
                found.push(token);
            }
        }
    }
    found
}

#[test]
fn no_file_of_the_repository_names_a_path_outside_it() {
    let root = root();
    let mut files = Vec::new();
    text_files(&root, &mut files);
    assert!(files.len() > 100, "{} files", files.len());
    let exists = |p: &Path| root.join(p).exists();
    let mut bad = Vec::new();
    for f in &files {
        let Ok(text) = std::fs::read_to_string(f) else {
            continue;
        };
        let rel = f.strip_prefix(&root).unwrap();
        for t in outside(&text, rel, &exists) {
            bad.push(format!("{}: {t}", rel.display()));
        }
    }
    assert!(
        bad.is_empty(),
        "paths outside the repository:\n{}",
        bad.join("\n")
    );
}

#[test]
fn the_guard_finds_a_path_that_climbs_out_and_a_machines_path_and_passes_one_that_stays() {
    let exists = |p: &Path| {
        ["README.md", "examples/c/friction_step.c", "capi/include"]
            .iter()
            .any(|e| p == Path::new(e))
    };
    let f = Path::new("docs/calibrate.sh");
    let shared = format!("{UP}shared/data/oring-seal");
    assert_eq!(outside(&format!("DATA={shared}"), f, &exists), [shared]);
    let readme = format!("see `{UP}README.md`");
    assert_eq!(outside(&readme, f, &exists), Vec::<String>::new());
    let include = format!("cc {UP}{UP}capi/include");
    let c = Path::new("examples/c/x.c");
    assert_eq!(outside(&include, c, &exists), Vec::<String>::new());
    // From a nested file, a path relative to a parent folder that exists.
    let example = format!("root.join(\"{UP}examples/c/friction_step.c\")");
    let test = Path::new("capi/tests/c_example.rs");
    assert_eq!(outside(&example, test, &exists), Vec::<String>::new());
    // A build's output inside the clone, absent from a fresh one.
    let lib = format!("{UP}{UP}target/release/libx.a");
    assert_eq!(outside(&lib, c, &exists), Vec::<String>::new());
    let machine = format!("/{}/shared/data", MACHINE_TOPS[0]);
    let text = format!("data in {machine}");
    assert_eq!(outside(&text, f, &exists), [machine]);
    // A URL's path is no machine's.
    let url = format!("https://example.org/{}/x", MACHINE_TOPS[1]);
    assert_eq!(outside(&url, f, &exists), Vec::<String>::new());
}

/// Local link targets of markdown `text`: `](target)` that is not a URL or
/// an anchor, without its `#fragment`.
fn local_links(text: &str) -> Vec<String> {
    text.match_indices("](")
        .filter_map(|(at, _)| {
            let rest = &text[at + 2..];
            let target = &rest[..rest.find(')')?];
            let target = target.split('#').next().unwrap_or("").trim();
            let url = target.contains("://") || target.starts_with("mailto:");
            (!target.is_empty() && !url).then(|| target.to_string())
        })
        .collect()
}

#[test]
fn every_local_link_of_the_readme_and_the_docs_leads_to_a_file_in_the_repository() {
    let root = root();
    let mut docs = vec![root.join("README.md")];
    for d in ["docs", "data", "python", "fuzz", "capi", "msg"] {
        let dir = root.join(d);
        for e in std::fs::read_dir(&dir)
            .into_iter()
            .flatten()
            .map(Result::unwrap)
        {
            if e.path().extension().is_some_and(|x| x == "md") {
                docs.push(e.path());
            }
        }
    }
    let mut bad = Vec::new();
    let mut links = 0;
    for f in &docs {
        let text = std::fs::read_to_string(f).unwrap();
        for l in local_links(&text) {
            links += 1;
            let resolved = normalise(&f.parent().unwrap().strip_prefix(&root).unwrap().join(&l));
            if !resolved.is_some_and(|p| root.join(p).exists()) {
                bad.push(format!("{}: {l}", f.strip_prefix(&root).unwrap().display()));
            }
        }
    }
    assert!(links > 0);
    assert!(bad.is_empty(), "broken local links:\n{}", bad.join("\n"));
}

#[test]
fn every_path_the_readmes_layout_lists_exists() {
    let root = root();
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let layout = readme
        .split("## Layout")
        .nth(1)
        .expect("the README has a Layout section");
    let block = layout
        .split("```")
        .nth(1)
        .expect("the Layout section has a code block");
    let mut listed = Vec::new();
    let mut missing = Vec::new();
    for line in block.lines() {
        let Some(first) = line.split_whitespace().next() else {
            continue;
        };
        if line.starts_with(' ') || !(first.contains('/') || first.contains('.')) {
            continue;
        }
        let path = first.trim_end_matches('/');
        listed.push(path.to_string());
        if !root.join(path).exists() {
            missing.push(first.to_string());
        }
    }
    assert!(listed.len() > 20, "{} paths", listed.len());
    assert!(
        missing.is_empty(),
        "listed in the Layout, not there: {missing:?}"
    );
    // And the other way: every module of src/ (a file or a folder) is
    // listed, but the crate's root and the binary's.
    let mut unlisted = Vec::new();
    for e in std::fs::read_dir(root.join("src"))
        .unwrap()
        .map(Result::unwrap)
    {
        let name = e.file_name().to_string_lossy().into_owned();
        if name == "lib.rs" || name == "main.rs" {
            continue;
        }
        let path = format!("src/{name}");
        if !listed.contains(&path) {
            unlisted.push(path);
        }
    }
    unlisted.sort();
    assert!(
        unlisted.is_empty(),
        "in src/, not in the README's Layout: {unlisted:?}"
    );
}
