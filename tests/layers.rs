//! The source tree's layering, checked from the code's own imports: lower layers
//! never import higher ones, no two files import each other, the hardware uses no
//! command-line crate, no source file is longer than 600 lines. Layers, lowest first:
//!
//! 0. `hw` — the blocks of the core (ground floor: imports nothing of ours above it)
//! 1. `hw::rtl` — driver, native simulation, export, cross-simulation, shell
//! 2. `host::{error, limits, output, stages}` — the host's plumbing
//! 3. `host::map` — quantizer, kd-tree, kNN
//! 4. `host::{gather, csvio, exact}` — gather backends, their file formats, the
//!    exact re-ranking
//! 5. `host::render` — scene, photons, renderer
//! 6. `host::workload` — benchmark workloads; `host::study` — the speed/error study;
//!    `host::banking` — the banked store's bank-conflict model
//! 7. the binary (`main.rs`, `cli/`)

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

const LAYERS: [(&str, usize); 17] = [
    ("hw::rtl", 1),
    ("hw", 0),
    ("host::error", 2),
    ("host::limits", 2),
    ("host::output", 2),
    ("host::stages", 2),
    ("host::map", 3),
    ("host::device", 3),
    ("host::gather", 4),
    ("host::csvio", 4),
    ("host::exact", 4),
    ("host::render", 5),
    ("host::workload", 6),
    ("host::study", 6),
    ("host::banking", 6),
    // host/mod.rs only declares the modules.
    ("host", 2),
    ("cli", 7),
];

const MAX_LINES: usize = 600;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// `src/hw/rtl/driver.rs` -> `hw::rtl::driver`; `mod.rs` names its folder; the
/// binary's files are `cli::…`.
fn module_of(path: &Path) -> String {
    let rel = path.strip_prefix(root().join("src")).unwrap();
    let mut parts: Vec<String> = rel
        .with_extension("")
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if parts.last().is_some_and(|l| l == "mod") {
        parts.pop();
    }
    match parts.first().map(String::as_str) {
        Some("main") => "cli".into(),
        Some("lib") => "crate".into(),
        _ => parts.join("::"),
    }
}

fn layer(module: &str) -> Option<usize> {
    LAYERS
        .iter()
        .find(|(prefix, _)| module == *prefix || module.starts_with(&format!("{prefix}::")))
        .map(|&(_, l)| l)
}

/// Every `crate::…` / `photon_fpga::…` path in the code (comments skipped), with
/// one level of `{a, b}` groups expanded.
fn imported_paths(text: &str) -> Vec<String> {
    let mut paths = vec![];
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or("");
        for root in ["crate::", "photon_fpga::"] {
            let mut rest = code;
            while let Some(at) = rest.find(root) {
                let tail = &rest[at + root.len()..];
                let end = tail
                    .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                    .unwrap_or(tail.len());
                let path = tail[..end].trim_end_matches(':').to_string();
                if tail[end..].starts_with('{') {
                    let group =
                        &tail[end + 1..tail[end..].find('}').map_or(tail.len(), |i| end + i)];
                    for name in group.split(',') {
                        let name = name.trim().split("::").next().unwrap_or("").trim();
                        if !name.is_empty() && name != "self" {
                            paths.push(format!("{path}::{name}"));
                        }
                    }
                }
                paths.push(path);
                rest = &tail[end..];
            }
        }
    }
    paths
}

/// The longest module of `modules` that `path` names (or lies in).
fn resolve<'a>(path: &str, modules: &'a BTreeSet<String>) -> Option<&'a String> {
    let parts: Vec<&str> = path.split("::").collect();
    (1..=parts.len())
        .rev()
        .map(|n| parts[..n].join("::"))
        .find_map(|p| modules.get(&p))
}

#[test]
fn lower_layers_never_import_higher_ones_and_no_file_imports_its_importer() {
    let mut files = vec![];
    rust_files(&root().join("src"), &mut files);
    let modules: BTreeSet<String> = files.iter().map(|f| module_of(f)).collect();
    let mut imports: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut problems = vec![];
    for f in &files {
        let me = module_of(f);
        if me == "crate" {
            continue;
        }
        let my_layer = layer(&me).unwrap_or_else(|| panic!("{me}: in no layer"));
        let text = std::fs::read_to_string(f).unwrap();
        for path in imported_paths(&text) {
            let Some(target) = resolve(&path, &modules) else {
                continue;
            };
            if *target == me || target == "crate" || me.starts_with(&format!("{target}::")) {
                continue;
            }
            let their = layer(target).unwrap_or_else(|| panic!("{target}: in no layer"));
            if their > my_layer {
                problems.push(format!(
                    "{me} (layer {my_layer}) imports {target} (layer {their})"
                ));
            }
            imports
                .entry(me.clone())
                .or_default()
                .insert(target.clone());
        }
    }
    for (a, targets) in &imports {
        for b in targets {
            if imports.get(b).is_some_and(|t| t.contains(a)) && a < b {
                problems.push(format!("{a} and {b} import each other"));
            }
        }
    }
    assert!(problems.is_empty(), "layering:\n{}", problems.join("\n"));
    // The check itself sees imports: the rtl driver uses the blocks.
    assert!(imports["hw::rtl::driver"].contains("hw::config"));
}

/// The lines of `text` outside comments that name `word` as a path or crate
/// (`word::`, `use word`, `extern crate word`), with their line numbers.
fn uses_of(text: &str, word: &str) -> Vec<(usize, String)> {
    text.lines()
        .enumerate()
        .filter_map(|(i, line)| {
            let code = line.split("//").next().unwrap_or("");
            let named = code
                .split(|c: char| !(c.is_alphanumeric() || c == '_'))
                .any(|token| token == word);
            named.then(|| (i + 1, line.trim().to_string()))
        })
        .collect()
}

/// The hardware layer (`src/hw`, `hw::rtl` included) knows no command line: the
/// CLI's value names and help texts live in `src/cli`, which converts them.
#[test]
fn the_hardware_uses_no_clap() {
    let mut files = vec![];
    rust_files(&root().join("src/hw"), &mut files);
    assert!(files.len() > 20, "src/hw not found");
    let found: Vec<String> = files
        .iter()
        .flat_map(|f| {
            let text = std::fs::read_to_string(f).unwrap();
            uses_of(&text, "clap")
                .into_iter()
                .map(move |(n, l)| format!("{}:{n}: {l}", f.display()))
        })
        .collect();
    assert!(found.is_empty(), "clap under src/hw:\n{}", found.join("\n"));
    // The check itself sees a use: the CLI's value enums derive clap's trait.
    let cli = std::fs::read_to_string(root().join("src/cli/values.rs")).unwrap();
    assert!(!uses_of(&cli, "clap").is_empty());
}

#[test]
fn no_source_file_is_longer_than_600_lines() {
    let mut files = vec![];
    for dir in ["src", "tests", "testbenches", "benches"] {
        rust_files(&root().join(dir), &mut files);
    }
    let long: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let n = std::fs::read_to_string(f).unwrap().lines().count();
            (n > MAX_LINES).then(|| format!("{}: {n} lines", f.display()))
        })
        .collect();
    assert!(
        long.is_empty(),
        "over {MAX_LINES} lines:\n{}",
        long.join("\n")
    );
}

/// README.md stays a page a user reads (what it is, the commands, the design on
/// one page, the headline results); design notes and measurements live in docs/.
#[test]
fn the_readme_is_at_most_300_lines() {
    let n = std::fs::read_to_string(root().join("README.md"))
        .unwrap()
        .lines()
        .count();
    assert!(n <= 300, "README.md: {n} lines");
}
