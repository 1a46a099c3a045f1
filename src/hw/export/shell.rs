//! A registered I/O shell around one or more exported cores, for place and route.
//!
//! The core's streams are a few hundred pins wide, more than an FPGA package has, and
//! unregistered pins would put pad delays on the timed paths. The shell shifts all
//! core inputs in through an 8-bit port, holds them in registers (one set per tree,
//! so replicated trees stay distinct and synthesis cannot merge them), captures every
//! core output into a register and reads it out 8 bits at a time. Every core input
//! and output stays observable, so nothing is optimised away, and every path that
//! remains is register to register.
//!
//! With `trees > 1` this is also the paper's future work (§5): T complete copies of
//! the core (tree, SearchModules, QueryModules), each serving its own queries.

use crate::hw::error::HwError;
use crate::hw::export::ports::Port;
use crate::hw::export::verilog::Exported;

/// `module shell`: `trees` copies of the exported core behind registered, byte-wide
/// I/O (the Verilog of the shell alone; the core's module comes with the export).
pub fn registered_shell(core: &Exported, trees: usize) -> Result<String, HwError> {
    if trees == 0 {
        return Err(HwError::Export(
            "registered shell: at least one core, got 0".into(),
        ));
    }
    let ports = &core.ports;
    let data_in: Vec<&Port> = ports
        .iter()
        .filter(|p| p.input && p.name != "clock" && p.name != "reset")
        .collect();
    let outs: Vec<&Port> = ports.iter().filter(|p| !p.input).collect();
    let in_w: usize = data_in.iter().map(|p| p.width).sum::<usize>().max(8);
    let out_w: usize = outs.iter().map(|p| p.width).sum();
    let all_out = out_w * trees;
    let bytes = all_out.div_ceil(8);
    let sel_w = (usize::BITS - bytes.max(2).leading_zeros()) as usize;
    let mut v = String::new();
    v += &format!(
        "// Registered I/O shell: {trees} core(s), {in_w} input bits shifted in, \
         {all_out} output bits read out a byte at a time.\n\
         module shell(clock, reset, din, din_shift, apply, tree_sel, out_capture, out_sel, dout);\n\
         \x20   input wire clock;\n    input wire reset;\n    input wire [7:0] din;\n\
         \x20   input wire din_shift;\n    input wire apply;\n    input wire [7:0] tree_sel;\n\
         \x20   input wire out_capture;\n    input wire [{}:0] out_sel;\n    output reg [7:0] dout;\n\
         \x20   reg reset_q;\n    reg [{}:0] shift_in;\n\
         \x20   always @(posedge clock) reset_q <= reset;\n\
         \x20   always @(posedge clock) if (din_shift) shift_in <= {{shift_in[{}:0], din}};\n",
        sel_w - 1,
        in_w - 1,
        in_w - 9
    );
    for t in 0..trees {
        v += &format!(
            "    reg [{}:0] in_{t};\n    wire [{}:0] out_{t};\n\
             \x20   always @(posedge clock) if (apply && (tree_sel == 8'd{t})) in_{t} <= shift_in;\n",
            in_w - 1,
            out_w - 1
        );
        let mut conns = vec![".clock(clock)".to_string(), ".reset(reset_q)".to_string()];
        let (mut ib, mut ob) = (0, 0);
        for p in ports {
            if p.name == "clock" || p.name == "reset" {
                continue;
            }
            let (bus, base) = if p.input {
                ib += p.width;
                (format!("in_{t}"), ib - p.width)
            } else {
                ob += p.width;
                (format!("out_{t}"), ob - p.width)
            };
            conns.push(format!(".{}({bus}[{}:{base}])", p.name, base + p.width - 1));
        }
        v += &format!(
            "    top core_{t}(\n        {}\n    );\n",
            conns.join(",\n        ")
        );
    }
    let mut concat: Vec<String> = (0..trees).rev().map(|t| format!("out_{t}")).collect();
    if bytes * 8 > all_out {
        concat.insert(0, format!("{}'d0", bytes * 8 - all_out));
    }
    v += &format!(
        "    reg [{}:0] captured;\n\
         \x20   always @(posedge clock) if (out_capture) captured <= {{{}}};\n\
         \x20   always @(posedge clock) dout <= captured[out_sel * 8 +: 8];\nendmodule\n",
        bytes * 8 - 1,
        concat.join(", ")
    );
    Ok(v)
}
