//! The source tree's layering, checked from the code's own imports: lower layers
//! never import higher ones, no two files import each other, the hardware uses no
//! command-line crate, no source file is longer than 600 lines. Layers, lowest first:
//!
//! 0. `hw::config::core_config`, `hw::error` — what a core is, and what can go wrong with it
//! 1. `hw::primitives` — RAMs, arbiters, encoders, register slices
//! 2. `hw::store` — the TreeModule and the banked store; `hw::memory` — the levels
//!    in external memory
//! 3. `hw::datapath` — the search both controllers share
//! 4. `hw::modules`, `hw::barrel` — the two controllers (neither imports the other)
//! 5. `hw::top` — the core, the array and their streams
//! 6. `hw::export` — the Verilog export, the shell, the AXI4-Stream top
//! 7. `hw::sim` — the simulation driver, native simulation and Verilator
//! 8. `host::{error, limits, output, stages}` — the host's plumbing
//! 9. `host::map` — quantizer, kd-tree, kNN
//! 10. `host::{gather, csvio, exact}` — gather backends, their file formats, the
//!     exact re-ranking
//! 11. `host::render` — scene, photons, renderer
//! 12. the product's command line (`cli/`, `main.rs`)
//!
//! The lab crate (`lab/src`) sits on top of all of it, and nothing of the product
//! imports it:
//!
//! 13. `lab::workload` — benchmark workloads; `lab::cpu_ref` — kiddo, the CPU yardstick
//! 14. `lab::banking` — the bank-conflict model; `lab::memory` — the external-memory
//!     cache model (it uses `banking`'s streams and orders); `lab::study` — the
//!     speed/error study
//! 15. the lab's command line (`lab::cli`, its `main.rs`)

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

const LAYERS: [(&str, usize); 32] = [
    ("hw::config::core_config", 0),
    ("hw::error", 0),
    ("hw::primitives", 1),
    ("hw::store", 2),
    ("hw::memory", 2),
    ("hw::datapath", 3),
    ("hw::modules", 4),
    ("hw::barrel", 4),
    ("hw::top", 5),
    ("hw::export", 6),
    ("hw::sim", 7),
    // hw/mod.rs only declares the folders (and `many`, which every block may use).
    ("hw", 0),
    ("host::error", 8),
    ("host::limits", 8),
    ("host::output", 8),
    ("host::stages", 8),
    ("host::map", 9),
    ("host::device", 9),
    ("host::gather", 10),
    ("host::csvio", 10),
    ("host::exact", 10),
    ("host::render", 11),
    // host/mod.rs only declares the modules.
    ("host", 8),
    ("cli", 12),
    ("lab::workload", 13),
    ("lab::cpu_ref", 13),
    ("lab::lookups", 13),
    ("lab::banking", 14),
    ("lab::memory", 14),
    ("lab::study", 14),
    ("lab::cli", 15),
    // lab/src/lib.rs only declares the modules.
    ("lab", 13),
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

/// `src/hw/sim/driver.rs` -> `hw::sim::driver`; `mod.rs` names its folder; the
/// binary's files are `cli::…`; the lab's are `lab::…` (`lab/src/study/plan.rs` ->
/// `lab::study::plan`).
fn module_of(path: &Path) -> String {
    if let Ok(rel) = path.strip_prefix(root().join("lab/src")) {
        let inner = module_in(rel);
        return match inner.as_str() {
            "cli" | "crate" => format!("lab::{}", if inner == "crate" { "" } else { "cli" })
                .trim_end_matches("::")
                .to_string(),
            _ => format!("lab::{inner}"),
        };
    }
    module_in(path.strip_prefix(root().join("src")).unwrap())
}

/// A file's module within its crate's `src`.
fn module_in(rel: &Path) -> String {
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

/// Every `crate::…` / `photon_fpga::…` / `photon_fpga_lab::…` path in the code
/// (comments skipped), with one level of `{a, b}` groups expanded, as a module of
/// the two crates: in the lab, `crate::x` is `lab::x`.
fn imported_paths(text: &str, in_lab: bool) -> Vec<String> {
    let mut paths = vec![];
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or("");
        for root in ["crate::", "photon_fpga::", "photon_fpga_lab::"] {
            let prefix = match root {
                "photon_fpga_lab::" => "lab::",
                "crate::" if in_lab => "lab::",
                _ => "",
            };
            let mut paths_here = vec![];
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
                            paths_here.push(format!("{prefix}{path}::{name}"));
                        }
                    }
                }
                let before = &rest[..at];
                let whole_word = !before.ends_with(|c: char| c.is_alphanumeric() || c == '_');
                if whole_word {
                    paths_here.push(format!("{prefix}{path}"));
                } else {
                    paths_here.clear();
                }
                paths.append(&mut paths_here);
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
    rust_files(&root().join("lab/src"), &mut files);
    let modules: BTreeSet<String> = files.iter().map(|f| module_of(f)).collect();
    let mut imports: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut problems = vec![];
    for f in &files {
        let me = module_of(f);
        if me == "crate" || me == "lab" {
            continue;
        }
        let my_layer = layer(&me).unwrap_or_else(|| panic!("{me}: in no layer"));
        let text = std::fs::read_to_string(f).unwrap();
        for path in imported_paths(&text, me.starts_with("lab")) {
            let Some(target) = resolve(&path, &modules) else {
                continue;
            };
            if *target == me
                || target == "crate"
                || target == "lab"
                || me.starts_with(&format!("{target}::"))
            {
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
    // The check itself sees imports: the rtl driver uses the blocks, the lab's
    // study the product's renderer and its own plan.
    assert!(imports["hw::sim::driver"].contains("hw::config::core_config"));
    assert!(imports["lab::study::sweep"].contains("host::render"));
    assert!(imports["lab::study::sweep"].contains("lab::study::plan"));
}

/// The product carries no measurement tool: kiddo and plotters are the lab's
/// dependencies only (`cargo tree -p photon-fpga -e normal` lists neither).
#[test]
fn the_product_depends_on_no_lab_crate() {
    let manifest = std::fs::read_to_string(root().join("Cargo.toml")).unwrap();
    let deps = manifest
        .split("[dependencies]")
        .nth(1)
        .and_then(|s| s.split("\n[").next())
        .expect("a [dependencies] table");
    for lab_only in ["kiddo", "plotters", "photon-fpga-lab"] {
        assert!(
            !deps.lines().any(|l| l.trim_start().starts_with(lab_only)),
            "the product depends on {lab_only}"
        );
    }
    let lab = std::fs::read_to_string(root().join("lab/Cargo.toml")).unwrap();
    assert!(lab.contains("kiddo") && lab.contains("plotters"));
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

/// The hardware layer (`src/hw`, `hw::sim` and `hw::export` included) knows no
/// command line: its enums derive clap's `ValueEnum` only behind the `cli` feature
/// (`#[cfg_attr(feature = "cli", …)]`), so their names and help texts are written
/// once, at their definitions, and the hardware builds without clap.
#[test]
fn the_hardware_uses_clap_only_behind_the_cli_feature() {
    let mut files = vec![];
    rust_files(&root().join("src/hw"), &mut files);
    assert!(files.len() > 20, "src/hw not found");
    let mut behind_feature = 0;
    let found: Vec<String> = files
        .iter()
        .flat_map(|f| {
            let text = std::fs::read_to_string(f).unwrap();
            uses_of(&text, "clap")
                .into_iter()
                .filter(|(_, l)| {
                    let ok = l.starts_with("#[cfg_attr(feature = \"cli\",");
                    behind_feature += ok as usize;
                    !ok
                })
                .map(move |(n, l)| format!("{}:{n}: {l}", f.display()))
                .collect::<Vec<_>>()
        })
        .collect();
    assert!(found.is_empty(), "clap under src/hw:\n{}", found.join("\n"));
    // The check itself sees uses: the library's enums derive the trait.
    assert!(behind_feature >= 5, "{behind_feature}");
    let cli = std::fs::read_to_string(root().join("src/cli/values.rs")).unwrap();
    assert!(!uses_of(&cli, "clap").is_empty());
}

#[test]
fn no_source_file_is_longer_than_600_lines() {
    let mut files = vec![];
    // The product's sources and tests, the lab's (its benches live in lab/benches).
    for dir in [
        "src",
        "tests",
        "testbenches",
        "lab/src",
        "lab/tests",
        "lab/benches",
    ] {
        let d = root().join(dir);
        assert!(d.is_dir(), "{} is not a folder", d.display());
        rust_files(&d, &mut files);
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

/// `src/hw` shows the block diagram: its top level holds the folders and at most
/// a few files (`mod.rs`, `error.rs`), each folder a `mod.rs` that says what it
/// holds; and the two controllers share only what lies below them.
#[test]
fn the_hardware_is_in_folders_by_role() {
    let hw = root().join("src/hw");
    let mut top_files = vec![];
    for e in std::fs::read_dir(&hw).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            let m = std::fs::read_to_string(p.join("mod.rs"))
                .unwrap_or_else(|_| panic!("{}: no mod.rs", p.display()));
            assert!(
                m.starts_with("//! "),
                "{}: mod.rs says nothing",
                p.display()
            );
        } else {
            top_files.push(p);
        }
    }
    assert!(top_files.len() <= 12, "src/hw top level: {top_files:?}");
    let mut files = vec![];
    rust_files(&hw, &mut files);
    for f in files {
        let me = module_of(&f);
        let text = std::fs::read_to_string(&f).unwrap();
        for (mine, theirs) in [("hw::modules", "hw::barrel"), ("hw::barrel", "hw::modules")] {
            if me.starts_with(mine) {
                let crossing: Vec<String> = imported_paths(&text, false)
                    .into_iter()
                    .filter(|p| p.starts_with(theirs))
                    .collect();
                assert!(crossing.is_empty(), "{me} imports {crossing:?}");
            }
        }
    }
}
