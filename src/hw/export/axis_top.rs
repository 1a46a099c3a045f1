//! `photon_search_axis`: the exported core (or array) behind AXI4-Stream ports, the
//! interface an FPGA engineer plugs a streaming core into (AMD UG1037, the naming of
//! verilog-axis): `aclk`, active-low `aresetn`, slave streams `s_axis_photon` (the
//! tree load) and `s_axis_query`, master stream `m_axis_result` with `tlast` on the
//! last beat of each query's result packet; a core of R > 1 result streams has R
//! master streams, `m_axis_result_0` … `m_axis_result_{R-1}`, each with the same
//! layout (one stream carries a beat a cycle, which a few busy datapaths fill).
//!
//! Why a generated wrapper and not a second core: the core's streams already are
//! valid/ready streams, so the wrapper only renames them, lays each payload out in
//! `tdata` and adapts the reset; the core stays the one that is simulated, tested and
//! cross-simulated. The wrapper is text written around the exported top's ports, as
//! the registered shell is (`shell.rs`).
//!
//! The `tdata` layouts are derived, never written down by hand: every field of the
//! core's payload struct ([`QueryBeat`], [`ResultBeat`], read through rust-hdl's type
//! descriptor) starts on a byte boundary and is padded to whole bytes (zeros above
//! it), and `tdata` is padded to a power-of-two number of bytes, so a DMA engine
//! moves a beat as one aligned little-endian record (no `tkeep`: every byte is
//! valid). The photon load carries just the packed word ([`PhotonLayout`], as wide as
//! the core's word port), the host's tree image in heap order from address 1; the
//! wrapper counts the addresses (1 after reset and after each `tlast`), so a load
//! is one DMA of the word array. Widening a struct field widens its slot here and in
//! the tables, with no other change.
//!
//! Reset: `aresetn` is registered into the core's synchronous reset; while
//! `aresetn` is low or that register is set, every `tvalid` and `tready` the wrapper
//! drives is low, so no beat moves and no aborted result leaves after the reset.

use crate::hw::config::core_config::CoreConfig;
use crate::hw::config::photon_word::PhotonLayout;
use crate::hw::error::HwError;
use crate::hw::export::verilog::Exported;
use crate::hw::primitives::stream::{QueryBeat, ResultBeat};
use rust_hdl::core::type_descriptor::{TypeDescriptor, TypeKind};
use rust_hdl::prelude::Synth;

/// One field of a stream's `tdata`: bits `lsb .. lsb + width` carry it, the slot up
/// to `lsb + slot` is zero above it. `core_lsb` is where the core's packed struct
/// has it (`None` for the photon word's sub-fields and for fields the wrapper makes).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Field {
    pub name: String,
    pub lsb: usize,
    pub width: usize,
    pub slot: usize,
    pub core_lsb: Option<usize>,
}

/// One AXI4-Stream port's `tdata` layout.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StreamLayout {
    /// The port prefix, e.g. `s_axis_query`.
    pub name: &'static str,
    pub tdata_bits: usize,
    pub fields: Vec<Field>,
}

/// The generated top: its Verilog (module `photon_search_axis`, which instantiates
/// the exported `top`), the layouts and the same facts as JSON for testbenches.
#[derive(Clone, Debug)]
pub struct AxisTop {
    pub verilog: String,
    pub streams: Vec<StreamLayout>,
    pub json: String,
}

fn axis_error(msg: impl Into<String>) -> HwError {
    HwError::Export(format!("AXI4-Stream top: {}", msg.into()))
}

fn bits_of(t: &TypeDescriptor) -> usize {
    match &t.kind {
        TypeKind::Bits(n) | TypeKind::Signed(n) => *n,
        TypeKind::Enum(v) => (usize::BITS - v.len().saturating_sub(1).leading_zeros()) as usize,
        TypeKind::Composite(f) => f.iter().map(|f| bits_of(&f.kind)).sum(),
    }
}

/// The fields of a `LogicStruct`, first field in the low bits (as rust-hdl packs
/// it), each in its own byte-aligned slot.
fn struct_layout(
    name: &'static str,
    t: TypeDescriptor,
    port_width: usize,
) -> Result<StreamLayout, HwError> {
    let TypeKind::Composite(members) = t.kind else {
        return Err(axis_error(format!("{} is not a struct", t.name)));
    };
    let (mut core, mut lsb) = (0, 0);
    let mut fields = vec![];
    for m in members {
        let width = bits_of(&m.kind);
        let slot = width.div_ceil(8) * 8;
        fields.push(Field {
            name: m.fieldname.clone(),
            lsb,
            width,
            slot,
            core_lsb: Some(core),
        });
        core += width;
        lsb += slot;
    }
    if core != port_width {
        return Err(axis_error(format!(
            "{} has {core} bits but its core port has {port_width}",
            t.name
        )));
    }
    Ok(StreamLayout {
        name,
        tdata_bits: pow2_bytes(lsb),
        fields,
    })
}

/// `bits` rounded up to a power-of-two number of bytes.
fn pow2_bytes(bits: usize) -> usize {
    bits.div_ceil(8).next_power_of_two() * 8
}

/// The photon stream: the packed word's sub-fields, the word as wide as the port.
fn photon_layout(layout: PhotonLayout, word_port: usize) -> Result<StreamLayout, HwError> {
    if layout.word_bits() as usize > word_port {
        return Err(axis_error(format!(
            "a {}-bit photon word does not fit the core's {word_port}-bit word port",
            layout.word_bits()
        )));
    }
    let mut fields: Vec<Field> = ["x", "y", "z"]
        .iter()
        .enumerate()
        .map(|(a, n)| Field {
            name: n.to_string(),
            lsb: layout.offset(a) as usize,
            width: layout.bits[a] as usize,
            slot: layout.bits[a] as usize,
            core_lsb: None,
        })
        .collect();
    let axis = layout.axis_offset() as usize;
    let rest = pow2_bytes(word_port) - axis;
    fields.push(Field {
        name: "axis".into(),
        lsb: axis,
        width: 2,
        slot: rest,
        core_lsb: None,
    });
    Ok(StreamLayout {
        name: "s_axis_photon",
        tdata_bits: pow2_bytes(word_port),
        fields,
    })
}

/// The layouts of the three streams of `core` (exported for `cfg`).
pub fn stream_layouts(core: &Exported, cfg: &CoreConfig) -> Result<Vec<StreamLayout>, HwError> {
    let width = |name: &str| {
        core.ports
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.width)
            .ok_or_else(|| axis_error(format!("the core has no port `{name}`")))
    };
    Ok(vec![
        photon_layout(cfg.layout, width("load$word")?)?,
        struct_layout(
            "s_axis_query",
            QueryBeat::descriptor(),
            width("query$data")?,
        )?,
        struct_layout(
            "m_axis_result",
            ResultBeat::descriptor(),
            width("result$data")?,
        )?,
    ])
}

/// What a field means, for the tables.
fn meaning(stream: &str, field: &str) -> &'static str {
    match (stream, field) {
        ("s_axis_photon", "x" | "y" | "z") => "grid coordinate",
        ("s_axis_photon", "axis") => "split axis: 0 x, 1 y, 2 z",
        (_, "id") => "query tag (a result returns its low id_bits)",
        ("s_axis_query", "x" | "y" | "z") => "query grid coordinate",
        ("s_axis_query", "radius") => "inclusive radius bound, metric units",
        ("s_axis_query", "k") => "neighbours wanted, 1..=K",
        (_, "header") => "1: header beat (id, count, visited)",
        (_, "last") => "1: last beat of the packet (= tlast)",
        (_, "count") => "header: photons found",
        (_, "visited") => "header: photons read",
        (_, "address") => "entry: heap address of a photon",
        (_, "distance") => "entry: its distance (0 from a K > 64 core: the host computes it)",
        (_, "pair") => "entry: address2/distance2 hold a second photon",
        (_, "address2") => "entry: second photon's heap address",
        (_, "distance2") => "entry: its distance (as distance)",
        _ => "",
    }
}

/// The layouts as a Markdown table: one row per field, its `tdata` bit range (the
/// field's own bits; the rest of its byte slot is zero).
pub fn layout_table(streams: &[StreamLayout]) -> String {
    let mut t = String::from("| stream | tdata bits | field | meaning |\n|---|---|---|---|\n");
    for s in streams {
        for f in &s.fields {
            let bits = if f.width == 1 {
                format!("[{}]", f.lsb)
            } else {
                format!("[{}:{}]", f.lsb + f.width - 1, f.lsb)
            };
            t += &format!(
                "| {} ({} bytes) | {bits} | {} | {} |\n",
                s.name,
                s.tdata_bits / 8,
                f.name,
                meaning(s.name, &f.name)
            );
        }
    }
    t
}

fn json_of(streams: &[StreamLayout], cfg: &CoreConfig) -> String {
    let streams: serde_json::Map<String, serde_json::Value> = streams
        .iter()
        .map(|s| {
            let fields: Vec<serde_json::Value> = s
                .fields
                .iter()
                .map(|f| serde_json::json!({"name": f.name, "lsb": f.lsb, "width": f.width}))
                .collect();
            (
                s.name.to_string(),
                serde_json::json!({"tdata_bits": s.tdata_bits, "fields": fields}),
            )
        })
        .collect();
    let v = serde_json::json!({
        "top": "photon_search_axis",
        "streams": streams,
        "core": {
            "metric": cfg.metric.to_string(),
            "k": cfg.k,
            "coord_bits": cfg.layout.bits,
            "address_bits": cfg.address_bits,
            "max_photons": cfg.tree_words() - 1,
            "id_bits": cfg.id_bits(),
            "dist_bits": cfg.dist_bits(),
            "result_ports": result_ports(cfg),
            "controller": cfg.controller.to_string(),
            "trees": cfg.trees,
            "memory": cfg.memory_layout().map(|m| serde_json::json!({
                "on_chip_levels": m.on_chip_levels,
                "block_levels": m.block_levels,
                "word_bytes": cfg.word_width() / 8,
                "cache_lines": cfg.memory.map(|c| c.cache_lines),
                "data_bits": cfg.memory.map(|c| c.data_bits),
            })),
        }
    });
    let mut s = serde_json::to_string_pretty(&v).expect("a JSON value serialises");
    s.push('\n');
    s
}

/// The result streams' port prefixes: `m_axis_result` for one, else
/// `m_axis_result_0` … `m_axis_result_{R-1}`.
pub fn result_ports(cfg: &CoreConfig) -> Vec<String> {
    match cfg.result_streams {
        1 => vec!["m_axis_result".to_string()],
        r => (0..r).map(|s| format!("m_axis_result_{s}")).collect(),
    }
}

/// `module photon_search_axis` around `core` (exported for `cfg`), its layouts and
/// their JSON. The core's module comes with the export and is instantiated as `top`.
pub fn axis_top(core: &Exported, cfg: &CoreConfig) -> Result<AxisTop, HwError> {
    let ports = result_ports(cfg);
    let streams = stream_layouts(core, cfg)?;
    let (photon, query, result) = (&streams[0], &streams[1], &streams[2]);
    let addr_w = core
        .ports
        .iter()
        .find(|p| p.name == "load$address")
        .map(|p| p.width)
        .ok_or_else(|| axis_error("the core has no port `load$address`"))?;
    let word_w = core
        .ports
        .iter()
        .find(|p| p.name == "load$word")
        .map_or(0, |p| p.width);
    let last_lsb = result
        .fields
        .iter()
        .find(|f| f.name == "last")
        .and_then(|f| f.core_lsb)
        .ok_or_else(|| axis_error("ResultBeat has no `last` field"))?;
    let query_w: usize = query.fields.iter().map(|f| f.width).sum();
    let result_w: usize = result.fields.iter().map(|f| f.width).sum();

    let mut v = String::new();
    v += "// photon_search_axis: the photon-search core behind AXI4-Stream ports.\n";
    v += "// Generated by `photon-fpga export-verilog --interface axis`; instantiates `top`\n";
    v += "// (photon_search_core.v, or photon_search_core_sim.v for event-driven simulators).\n";
    v += &format!(
        "// Core: {} controller, K = {}, H = {} (up to {} photons), {}-bit coordinates, {} metric,\n\
         // T = {}; a result's id carries the low {} bits of its query's id.\n",
        cfg.controller,
        cfg.k,
        cfg.address_bits,
        cfg.tree_words() - 1,
        cfg.layout.bits[0],
        cfg.metric,
        cfg.trees,
        cfg.id_bits()
    );
    v += "//\n// aresetn: active low, synchronous, registered into the core's reset; no beat\n";
    v += "// moves while it or that register is asserted. Load the map after every reset.\n";
    v += "// s_axis_photon: the packed kd-tree words in heap order, address 1 first, tlast on\n";
    v += "// word N (the photon count); taken only while no query is in flight.\n";
    if ports.len() > 1 {
        v += &format!(
            "// {} result streams, m_axis_result_0 .. m_axis_result_{}, each as m_axis_result below:\n\
             // stream s carries the packets of datapaths s*D/R .. (s+1)*D/R - 1 (D = {}).\n",
            ports.len(),
            ports.len() - 1,
            cfg.datapaths()
        );
    }
    let memory = cfg.memory_layout();
    let data_bits = cfg.memory.map_or(0, |m| m.data_bits);
    if let Some(m) = &memory {
        v += &format!(
            "// External memory: the map's levels below the top {t} live in the memory behind\n\
             // m_axi (AXI4 read bursts of {} bytes in {}-bit beats, at byte 0): {}-byte word\n\
             // b*{w} + o holds word o of block b, a subtree of {s} levels (docs/MEMORY.md).\n\
             // Write that image, then stream words 1 .. {} (the on-chip levels) and one beat with\n\
             // tlast whose tdata is N, the photon count. A new map: reset first.\n",
            (cfg.word_width() / 8) << m.block_levels,
            data_bits,
            cfg.word_width() / 8,
            (1u64 << m.on_chip_levels) - 1,
            t = m.on_chip_levels,
            w = m.block_words(),
            s = m.block_levels,
        );
    }
    v += "// s_axis_query: one query a beat. m_axis_result: per query a header beat, then its\n";
    v += "// photons one (or, with pair, two) a beat in found-list order; tlast on the last beat\n";
    v += "// (the header itself when count = 0). Packets of different queries may leave out of\n";
    v += "// order; one packet's beats are contiguous. Unlisted tdata bits are zero.\n//\n";
    v += "// tdata layout (little-endian bytes; each field from a byte boundary):\n";
    for line in layout_table(&streams).lines() {
        v += &format!("//   {line}\n");
    }
    v += "//\n";
    v += &format!(
        "module photon_search_axis (\n\
         \x20   input  wire aclk,\n\
         \x20   input  wire aresetn,\n\
         \x20   input  wire [{}:0] s_axis_photon_tdata,\n\
         \x20   input  wire s_axis_photon_tvalid,\n\
         \x20   output wire s_axis_photon_tready,\n\
         \x20   input  wire s_axis_photon_tlast,\n\
         \x20   input  wire [{}:0] s_axis_query_tdata,\n\
         \x20   input  wire s_axis_query_tvalid,\n\
         \x20   output wire s_axis_query_tready",
        photon.tdata_bits - 1,
        query.tdata_bits - 1,
    );
    for m in &ports {
        v += &format!(
            ",\n\
             \x20   output wire [{}:0] {m}_tdata,\n\
             \x20   output wire {m}_tvalid,\n\
             \x20   input  wire {m}_tready,\n\
             \x20   output wire {m}_tlast",
            result.tdata_bits - 1
        );
    }
    // The memory port, named as AXI4 names it.
    for p in core.ports.iter().filter(|p| p.name.starts_with("m_axi$0$")) {
        let dir = if p.input { "input " } else { "output" };
        // The data as wide as the memory's (the core's port is the widest).
        let width = if p.name.ends_with("$rdata") {
            data_bits as usize
        } else {
            p.width
        };
        let range = if width > 1 {
            format!("[{}:0] ", width - 1)
        } else {
            String::new()
        };
        v += &format!(
            ",\n    {dir} wire {range}m_axi_{}",
            &p.name["m_axi$0$".len()..]
        );
    }
    // One ID (the bursts return in order): ARID is 0 and RID is not looked at.
    if memory.is_some() {
        v += ",\n    output wire [0:0] m_axi_arid,\n    input  wire [0:0] m_axi_rid";
    }
    v += "\n);\n";
    if memory.is_some() {
        v += "    assign m_axi_arid = 1'b0;\n";
    }
    v += "    reg reset_q;\n    always @(posedge aclk) reset_q <= !aresetn;\n";
    v += "    wire run = aresetn && !reset_q;\n\n";
    v += &format!(
        "    // The load's heap address: 1 after reset and after each tlast.\n\
         \x20   reg [{aw}:0] load_address;\n\
         \x20   wire load_ready;\n\
         \x20   wire load_fire = s_axis_photon_tvalid && s_axis_photon_tready;\n\
         \x20   assign s_axis_photon_tready = load_ready && run;\n\
         \x20   always @(posedge aclk)\n\
         \x20       if (reset_q || (load_fire && s_axis_photon_tlast)) load_address <= {addr_w}'d1;\n\
         \x20       else if (load_fire) load_address <= load_address + {addr_w}'d1;\n\n",
        aw = addr_w - 1
    );
    v += &format!(
        "    wire [{}:0] query_data;\n    wire query_ready;\n",
        query_w - 1
    );
    v += "    assign s_axis_query_tready = query_ready && run;\n";
    for f in &query.fields {
        let c = f.core_lsb.expect("a struct field");
        v += &format!(
            "    assign query_data[{}:{c}] = s_axis_query_tdata[{}:{}]; // {}\n",
            c + f.width - 1,
            f.lsb + f.width - 1,
            f.lsb,
            f.name
        );
    }
    for (i, m) in ports.iter().enumerate() {
        v += &format!(
            "\n    wire [{}:0] result_data_{i};\n    wire result_valid_{i};\n",
            result_w - 1
        );
        v += &format!("    assign {m}_tvalid = result_valid_{i} && run;\n");
        v += &format!("    assign {m}_tlast = result_data_{i}[{last_lsb}];\n");
        let mut top = 0;
        for f in &result.fields {
            let c = f.core_lsb.expect("a struct field");
            let pad = f.slot - f.width;
            let src = format!("result_data_{i}[{}:{c}]", c + f.width - 1);
            let val = if pad > 0 {
                format!("{{{pad}'d0, {src}}}")
            } else {
                src
            };
            v += &format!(
                "    assign {m}_tdata[{}:{}] = {val}; // {}\n",
                f.lsb + f.slot - 1,
                f.lsb,
                f.name
            );
            top = f.lsb + f.slot;
        }
        if top < result.tdata_bits {
            v += &format!(
                "    assign {m}_tdata[{}:{top}] = {}'d0;\n",
                result.tdata_bits - 1,
                result.tdata_bits - top
            );
        }
    }
    // Every core port: the streams wired above, clock and reset; status outputs
    // (measurement only) left open; an input the wrapper does not know is an error.
    let mut conns = vec![];
    for p in &core.ports {
        let c = match p.name.as_str() {
            "clock" => "aclk".to_string(),
            "reset" => "reset_q".to_string(),
            "load$valid" => "s_axis_photon_tvalid && run".to_string(),
            "load$ready" => "load_ready".to_string(),
            // In memory the last beat's data is the photon count (its address).
            "load$address" if memory.is_some() => format!(
                "s_axis_photon_tlast ? s_axis_photon_tdata[{}:0] : load_address",
                addr_w - 1
            ),
            "load$address" => "load_address".to_string(),
            "load$word" => format!("s_axis_photon_tdata[{}:0]", word_w - 1),
            "load$last" => "s_axis_photon_tlast".to_string(),
            "query$valid" => "s_axis_query_tvalid && run".to_string(),
            "query$ready" => "query_ready".to_string(),
            "query$data" => "query_data".to_string(),
            "result$valid" => "result_valid_0".to_string(),
            "result$ready" => format!("{}_tready && run", ports[0]),
            "result$data" => "result_data_0".to_string(),
            // Result stream s >= 1 of the core: `more_results$(s-1)$…`.
            name if name.starts_with("more_results$") => {
                let mut parts = name.split('$').skip(1);
                let s: usize = parts
                    .next()
                    .and_then(|i| i.parse().ok())
                    .ok_or_else(|| axis_error(format!("core port `{name}`")))?;
                let s = s + 1;
                match parts.next() {
                    Some("valid") => format!("result_valid_{s}"),
                    Some("ready") => format!("{}_tready && run", ports[s]),
                    Some("data") => format!("result_data_{s}"),
                    _ => return Err(axis_error(format!("unknown core port `{name}`"))),
                }
            }
            name if name.ends_with("$rdata") && (data_bits as usize) < p.width => {
                format!("{{{}'b0, m_axi_rdata}}", p.width - data_bits as usize)
            }
            name if name.starts_with("m_axi$0$") => format!("m_axi_{}", &name["m_axi$0$".len()..]),
            _ if !p.input => String::new(),
            other => return Err(axis_error(format!("unknown core input `{other}`"))),
        };
        conns.push(format!(".{}({c})", p.name));
    }
    v += &format!(
        "\n    top core (\n        {}\n    );\nendmodule\n",
        conns.join(",\n        ")
    );
    let json = json_of(&streams, cfg);
    Ok(AxisTop {
        verilog: v,
        streams,
        json,
    })
}
