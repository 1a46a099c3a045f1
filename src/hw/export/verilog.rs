//! The Verilog export of the configured core and all post-processing of rust-hdl's
//! text, in one place: `check_all` (which `generate_verilog` would otherwise turn
//! into a panic), `generate_verilog`, the top's port list (from the block, not
//! parsed from text) and the glitch-free rewrite for event-driven simulators.
//! rust-hdl is pinned (`=0.46.0`) because [`glitch_free`] reads its exact output;
//! tests/golden checks that output against a golden file.

use crate::hw::config::core_config::{dispatch_widths, CoreConfig};
use crate::hw::error::HwError;
use crate::hw::export::ports::{self, Port};
use crate::hw::top::array::PhotonSearchArray;
use crate::hw::top::core::PhotonSearchCore;
use rust_hdl::prelude::*;

fn export_error(msg: impl Into<String>) -> HwError {
    HwError::Export(msg.into())
}

/// The exported design: its Verilog (top module `top`) and the top's ports.
#[derive(Clone, Debug)]
pub struct Exported {
    pub verilog: String,
    pub ports: Vec<Port>,
}

/// The Verilog of the whole core for `cfg` (the array of T cores for T > 1).
pub fn export_verilog(cfg: &CoreConfig) -> Result<Exported, HwError> {
    cfg.validate()?;
    dispatch_widths!(cfg, export(cfg))
}

fn export<const S: usize, const W: usize>(cfg: &CoreConfig) -> Result<Exported, HwError> {
    if !cfg.is_array() {
        export_block(PhotonSearchCore::<S, W>::new(cfg))
    } else {
        export_block(PhotonSearchArray::<S, W>::new(cfg))
    }
}

/// Check and export any block as `module top`.
pub fn export_block<U: Block>(mut uut: U) -> Result<Exported, HwError> {
    uut.connect_all();
    check_all(&uut).map_err(|e| export_error(format!("circuit check failed: {e:?}")))?;
    Ok(Exported {
        verilog: generate_verilog(&uut),
        ports: ports::ports(&uut),
    })
}

/// The top's outputs that exist only for measurement: which ports read in a
/// cycle and whether every query slot is busy, from which a simulation of the
/// Verilog (Verilator) counts reads per cycle as the native simulation does by
/// looking inside (`sim::sim_stats`). A design built into a system has no use
/// for them.
pub fn is_status_port(name: &str) -> bool {
    matches!(
        name,
        "port_a_reading"
            | "port_b_reading"
            | "all_busy"
            | "trees_reading_a"
            | "trees_reading_b"
            | "trees_busy"
    ) || name.starts_with("ports_reading$")
}

/// `e` without its measurement outputs ([`is_status_port`]): they leave the top's
/// port list and their declarations become internal (synthesis then removes the
/// logic that only they read). Nothing else of the text changes.
pub fn without_status(e: &Exported) -> Result<Exported, HwError> {
    let dropped: Vec<&str> = e
        .ports
        .iter()
        .filter(|p| !p.input && is_status_port(&p.name))
        .map(|p| p.name.as_str())
        .collect();
    let mut out = String::with_capacity(e.verilog.len());
    let (mut in_top, mut header, mut declared) = (false, false, 0usize);
    for line in e.verilog.split_inclusive('\n') {
        if let Some(args) = line.strip_prefix("module top(") {
            let args = args
                .trim_end()
                .strip_suffix(");")
                .ok_or_else(|| export_error("the top's header is not on one line"))?;
            let kept: Vec<&str> = args.split(',').filter(|a| !dropped.contains(a)).collect();
            out.push_str(&format!("module top({});\n", kept.join(",")));
            (in_top, header) = (true, true);
            continue;
        }
        if in_top && line.starts_with("endmodule") {
            in_top = false;
        }
        // A declaration `output reg  [w:0] name;` (or wire) of a dropped port.
        let decl = line.trim_start();
        let name = decl
            .trim_end()
            .strip_suffix(';')
            .and_then(|d| d.rsplit(' ').next())
            .unwrap_or("");
        if in_top && decl.starts_with("output ") && dropped.contains(&name) {
            out.push_str(&line.replacen("output ", "", 1));
            declared += 1;
            continue;
        }
        out.push_str(line);
    }
    if !header || declared != dropped.len() {
        return Err(export_error(format!(
            "the top's measurement outputs: {declared} of {} declarations found",
            dropped.len()
        )));
    }
    Ok(Exported {
        verilog: out,
        ports: e
            .ports
            .iter()
            .filter(|p| !dropped.contains(&p.name.as_str()))
            .cloned()
            .collect(),
    })
}

/// Suffix of the shadow variables [`glitch_free`] introduces.
pub const SHADOW_SUFFIX: &str = "__xs";

fn is_ident_start(c: u8) -> bool {
    c.is_ascii_alphabetic() || c == b'_'
}

fn is_ident_char(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_' || c == b'$'
}

/// Replace every identifier of `names` in `line` by its shadow (identifiers right
/// after a `'` are number bases/digits, e.g. `32'hff`, and are left alone).
fn shadow_line(line: &str, names: &std::collections::HashSet<String>) -> String {
    let b = line.as_bytes();
    let mut out = String::with_capacity(line.len() + 16);
    let mut i = 0;
    while i < b.len() {
        if is_ident_start(b[i]) && (i == 0 || !is_ident_char(b[i - 1])) {
            let start = i;
            while i < b.len() && is_ident_char(b[i]) {
                i += 1;
            }
            let tok = &line[start..i];
            out.push_str(tok);
            if (start == 0 || b[start - 1] != b'\'') && names.contains(tok) {
                out.push_str(SHADOW_SUFFIX);
            }
        } else {
            // Copy one whole UTF-8 character.
            let ch = line[i..].chars().next().expect("in bounds");
            out.push(ch);
            i += ch.len_utf8();
        }
    }
    out
}

/// A semantically identical rewrite of rust-hdl's Verilog for event-driven
/// simulators. rust-hdl writes each module's logic as one `always @(*)` block that
/// assigns defaults and then overrides them (`x = 0; if (c) x = y;`), so a variable
/// can glitch within one execution of the block. Icarus Verilog wakes every block
/// sensitive to a variable on each such glitch; two blocks feeding each other
/// glitches (a SearchPort and its QueryModules on the result path) then wake each
/// other forever at one simulation time: the raw export hangs Icarus at the first
/// result beat. The rewrite lets every `always @(*) begin … end` block compute into
/// shadow variables (`name__xs`, same declaration) and copy them to the real ones
/// at its end, so each variable changes at most once per execution. Nothing else
/// changes (same expressions, same order), so a precedence bug in the export stays
/// a precedence bug here.
pub fn glitch_free(verilog: &str) -> Result<String, HwError> {
    use std::collections::{HashMap, HashSet};
    const START: &str = "    always @(*) begin";
    const END: &str = "    end";
    let lines: Vec<&str> = verilog.lines().collect();
    let mut out: Vec<String> = Vec::with_capacity(lines.len() + 1024);
    // Declarations of the current module: name -> "[w:0] " or "".
    let mut decls: HashMap<String, String> = HashMap::new();
    let mut i = 0;
    let mut blocks = 0;
    while i < lines.len() {
        let line = lines[i];
        let t = line.trim_start();
        if t.starts_with("module ") {
            decls.clear();
        }
        let decl = t
            .strip_prefix("output reg")
            .or_else(|| t.strip_prefix("reg"));
        if let Some(rest) = decl.filter(|r| r.starts_with(' ') && r.ends_with(';')) {
            let rest = rest.trim().trim_end_matches(';').trim();
            let (width, name) = match rest.rfind(']') {
                Some(p) => (format!("{} ", &rest[..=p]), rest[p + 1..].trim()),
                None => (String::new(), rest),
            };
            if !name.is_empty() && name.bytes().all(is_ident_char) {
                decls.insert(name.to_string(), width);
            }
        }
        if line != START {
            out.push(line.to_string());
            i += 1;
            continue;
        }
        let end = (i + 1..lines.len())
            .find(|&j| lines[j] == END)
            .ok_or_else(|| export_error(format!("line {}: always block without end", i + 1)))?;
        let body = &lines[i + 1..end];
        let mut assigned: Vec<String> = vec![];
        let mut seen = HashSet::new();
        for l in body {
            let t = l.trim_start();
            let n = t.bytes().take_while(|&c| is_ident_char(c)).count();
            if n == 0 || !is_ident_start(t.as_bytes()[0]) {
                continue;
            }
            let rest = t[n..].trim_start();
            if rest.starts_with('=') && !rest.starts_with("==") {
                let name = t[..n].to_string();
                if !decls.contains_key(&name) {
                    return Err(export_error(format!(
                        "line {}: no reg declaration of `{name}`",
                        i + 1
                    )));
                }
                if seen.insert(name.clone()) {
                    assigned.push(name);
                }
            }
        }
        for name in &assigned {
            out.push(format!("    reg {}{name}{SHADOW_SUFFIX};", decls[name]));
        }
        out.push(line.to_string());
        for l in body {
            out.push(shadow_line(l, &seen));
        }
        for name in &assigned {
            out.push(format!("        {name} = {name}{SHADOW_SUFFIX};"));
        }
        out.push(lines[end].to_string());
        blocks += 1;
        i = end + 1;
    }
    if blocks == 0 {
        return Err(export_error("no `always @(*)` block found to rewrite"));
    }
    let mut s = out.join("\n");
    s.push('\n');
    Ok(s)
}
