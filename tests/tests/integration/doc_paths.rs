//! Every file or folder the docs name exists in the repository: the Markdown in `docs/` and
//! `docs/reference/`, the README, CONTRIBUTING.md and CHANGELOG.md. A name in backticks or a link target counts as a path
//! when it ends in a file extension or a `/`, or when it contains a `/` after a folder that
//! exists; it resolves when it exists relative to the repository's root, `docs/`, a crate's folder
//! or its `src/`, or as the end of a path in the repository (a table's `bvh/mod.rs` under its
//! folder), or, for a bare file name, anywhere in it. Generated outputs (`target/…` and the files
//! `ppis` writes), commands' placeholders (`OUT`, `SCENE`, `NAME`, `…`) and the public USD assets
//! beside the repository (`../shared/usd-assets/`, third-party files that stay out of its history:
//! docs/usd.md) are not paths of the repository. Any other path outside it (`../…`) fails, even
//! where it exists on the machine that runs the test: a clean clone does not have it.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

const EXTENSIONS: [&str; 17] = [
    "rs", "md", "py", "sh", "json", "toml", "h", "c", "exr", "hdr", "png", "csv", "ply", "usda", "usdc", "usdz", "txt",
];
const CRATES: [&str; 5] = ["sampler-core", "sampler-capi", "host-std", "host-usd", "tests"];
const PLACEHOLDERS: [&str; 10] = ["OUT", "SCENE", "DIR", "FILE", "NAME", "…", "...", "<", "*", "{"];
/// Files `ppis render` and `ppis report` write, named in the docs as outputs.
const OUTPUTS: [&str; 8] = [
    "render.exr",
    "render.png",
    "reference.exr",
    "error_vs_time.csv",
    "report.md",
    "error_vs_k.csv",
    "error_vs_k.md",
    "error_vs_k.png",
];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Every file's name and its path from the root in the repository (outside `target/` and
/// `.git`), with `/` between the folders.
fn files(dir: &Path, prefix: &str, names: &mut HashSet<String>, paths: &mut Vec<String>) {
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        if path.is_dir() {
            if name != "target" && name != ".git" {
                files(&path, &format!("{prefix}{name}/"), names, paths);
            }
        } else {
            paths.push(format!("{prefix}{name}"));
            names.insert(name);
        }
    }
}

/// The folders a relative path is looked up from.
fn bases(doc_dir: &Path) -> Vec<PathBuf> {
    let root = root();
    let mut bases = vec![root.clone(), root.join("docs"), doc_dir.to_path_buf()];
    for c in CRATES {
        bases.push(root.join(c));
        bases.push(root.join(c).join("src"));
    }
    bases
}

/// The candidates a doc's text names as paths: backticked names and link targets, outside fenced
/// code blocks (commands, whose arguments are placeholders).
fn candidates(text: &str) -> Vec<String> {
    let mut prose = String::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
        } else if !fenced {
            prose.push_str(line);
            prose.push('\n');
        }
    }
    let text = prose.as_str();
    let mut out = Vec::new();
    for (k, chunk) in text.split('`').enumerate() {
        if k % 2 == 1 {
            out.push(chunk.to_string());
        }
    }
    for part in text.split("](").skip(1) {
        if let Some(end) = part.find(')') {
            out.push(part[..end].to_string());
        }
    }
    out
}

/// The path a candidate names, if it names one: without a `#anchor` or `::item`, and only when
/// it looks like a path of the repository.
fn as_path<'c>(candidate: &'c str, doc_dir: &Path) -> Option<&'c str> {
    let c = candidate.trim();
    let c = c.split('#').next()?;
    let c = c.split("::").next()?;
    let c = c.trim_end_matches([',', '.', ':', ';']);
    if c.is_empty() || c.contains(char::is_whitespace) || c.contains("://") || c.starts_with('-') {
        return None;
    }
    if c.starts_with("../shared/usd-assets/") || c.starts_with("target/") || c.starts_with('$') || c.starts_with('/') {
        return None;
    }
    if PLACEHOLDERS.iter().any(|p| c.contains(p)) || OUTPUTS.contains(&c) {
        return None;
    }
    // Formulas (`4π/4^k`, `spp/P`) are not paths: a path is made of these characters, and a
    // name without an extension is one when it ends in `/` or starts at a folder that exists.
    if !c.chars().all(|ch| ch.is_ascii_alphanumeric() || "_-./".contains(ch)) {
        return None;
    }
    let file = c.trim_end_matches('/');
    let has_extension = Path::new(file).extension().is_some_and(|e| EXTENSIONS.contains(&&*e.to_string_lossy()));
    let first = c.split('/').next().unwrap_or("");
    let under_a_folder = c.contains('/') && bases(doc_dir).iter().any(|b| b.join(first).is_dir());
    (has_extension || c.ends_with('/') || under_a_folder).then_some(c)
}

fn resolves(path: &str, doc_dir: &Path, names: &HashSet<String>, paths: &[String]) -> bool {
    let path = path.trim_end_matches('/');
    if bases(doc_dir).iter().any(|b| b.join(path).exists()) {
        return true;
    }
    if !path.contains('/') {
        return names.contains(path);
    }
    let tail = format!("/{path}");
    paths.iter().any(|p| p.ends_with(&tail) || p.contains(&format!("{tail}/")))
}

#[test]
fn every_path_the_docs_name_exists() {
    let root = root();
    let (mut names, mut paths) = (HashSet::new(), Vec::new());
    files(&root, "", &mut names, &mut paths);
    let mut docs: Vec<PathBuf> =
        ["README.md", "CONTRIBUTING.md", "CHANGELOG.md"].iter().map(|d| root.join(d)).collect();
    // docs/ and its folders (docs/reference/), but not the reports `ppis report` writes.
    for dir in [root.join("docs"), root.join("docs/reference")] {
        for entry in std::fs::read_dir(dir).unwrap().flatten() {
            if entry.path().extension().is_some_and(|e| e == "md") {
                docs.push(entry.path());
            }
        }
    }
    let mut missing = Vec::new();
    let mut checked = 0;
    for doc in &docs {
        let text = std::fs::read_to_string(doc).unwrap();
        let doc_dir = doc.parent().unwrap();
        let name = doc.strip_prefix(&root).unwrap_or(doc).display().to_string();
        for candidate in candidates(&text) {
            if let Some(path) = as_path(&candidate, doc_dir) {
                checked += 1;
                if path.starts_with("../") || !resolves(path, doc_dir, &names, &paths) {
                    missing.push(format!("{name}: {path}"));
                }
            }
        }
    }
    assert!(checked > 100, "only {checked} paths found in the docs: the extraction is broken");
    assert!(missing.is_empty(), "{} paths in the docs do not exist:\n{}", missing.len(), missing.join("\n"));
}
