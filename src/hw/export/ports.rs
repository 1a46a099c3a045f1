//! The ports of a top-level block, read from the block itself (rust-hdl's `Probe`
//! visits every signal; the top's own parameters are its ports), with their
//! current values. The cross-simulation's stimulus and response columns, its
//! Verilog testbench and the registered shell all take their port lists from here,
//! so adding a port to the core needs no second list anywhere.

use rust_hdl::core::atom::{Atom, AtomKind};
use rust_hdl::prelude::*;

/// One port of the exported `top` module, named as in the Verilog (`bundle$member`
/// for a member of a `LogicInterface`; `bundle$i$member` for a member of the i-th
/// of a `Vec` of them, whose bundle is then `bundle$i`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Port {
    pub name: String,
    pub input: bool,
    pub width: usize,
}

impl Port {
    /// The bundle this port belongs to (`query` for `query$valid`, `clients$0` for
    /// `clients$0$valid`), if any.
    pub fn bundle(&self) -> Option<&str> {
        self.name.rsplit_once('$').map(|(b, _)| b)
    }

    /// The member name within its bundle, or the whole name.
    pub fn member(&self) -> &str {
        self.name.rsplit_once('$').map_or(&self.name, |(_, m)| m)
    }

    /// Hexadecimal digits of a value of this port (Verilog's `%h` width).
    pub fn hex_digits(&self) -> usize {
        self.width.div_ceil(4)
    }
}

/// Collects the top's own atoms (depth 1), optionally with their values.
struct TopAtoms {
    depth: usize,
    namespace: Vec<String>,
    ports: Vec<Port>,
    values: Option<Vec<String>>,
}

impl Probe for TopAtoms {
    fn visit_start_scope(&mut self, _name: &str, _node: &dyn Block) {
        self.depth += 1;
    }
    fn visit_end_scope(&mut self, _name: &str, _node: &dyn Block) {
        self.depth -= 1;
    }
    fn visit_start_namespace(&mut self, name: &str, _node: &dyn Block) {
        if self.depth == 1 {
            self.namespace.push(name.to_string());
        }
    }
    fn visit_end_namespace(&mut self, _name: &str, _node: &dyn Block) {
        if self.depth == 1 {
            self.namespace.pop();
        }
    }
    fn visit_atom(&mut self, name: &str, atom: &dyn Atom) {
        let input = match atom.kind() {
            AtomKind::InputParameter => true,
            AtomKind::OutputParameter => false,
            _ => return,
        };
        if self.depth != 1 {
            return;
        }
        let mut full = self.namespace.join("$");
        if !full.is_empty() {
            full.push('$');
        }
        full.push_str(name);
        let width = atom.bits();
        if let Some(values) = &mut self.values {
            values.push(hex(atom, width));
        }
        self.ports.push(Port {
            name: full,
            input,
            width,
        });
    }
}

/// `atom`'s value as zero-padded lowercase hex of `width` bits (Verilog's `%h`).
fn hex(atom: &dyn Atom, width: usize) -> String {
    let lit = format!("{:x}", atom.verilog());
    let digits = lit.split_once("'h").map_or(lit.as_str(), |(_, d)| d);
    format!("{digits:0>w$}", w = width.div_ceil(4))
}

fn visit(top: &dyn Block, values: bool) -> TopAtoms {
    let mut probe = TopAtoms {
        depth: 0,
        namespace: vec![],
        ports: vec![],
        values: values.then(Vec::new),
    };
    top.accept("top", &mut probe);
    probe
}

/// The ports of `top` in declaration order.
pub fn ports(top: &dyn Block) -> Vec<Port> {
    visit(top, false).ports
}

/// The current value of every port of `top`, in [`ports`] order, as hex.
pub fn values(top: &dyn Block) -> Vec<String> {
    visit(top, true).values.unwrap_or_default()
}
