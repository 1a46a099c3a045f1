//! `photon-fpga export-verilog`: the configured core's Verilog, its glitch-free
//! rewrite for event-driven simulators and optionally a registered shell.

use crate::cli::core_args::{describe_q, CoreArgs};
use clap::{Args, ValueEnum};
use photon_fpga::host::error::{Error, Result};
use photon_fpga::host::output::Output;
use photon_fpga::hw::rtl::axis_top::axis_top;
use photon_fpga::hw::rtl::export::export_verilog;
use photon_fpga::hw::rtl::shell::registered_shell;
use std::path::PathBuf;

/// `--interface`: which top the export writes beside the core.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum InterfaceArg {
    /// The bare core only: module `top` with rust-hdl's port names and a sync reset.
    Core,
    /// Also DIR/photon_search_axis.v: the core behind AXI4-Stream ports (aclk,
    /// aresetn, s_axis_photon, s_axis_query, m_axis_result), and its tdata layout
    /// as DIR/photon_search_axis.json.
    Axis,
}

#[derive(Args)]
pub struct ExportArgs {
    #[command(flatten)]
    pub core: CoreArgs,
    /// Also write DIR/shell.v: T replicated cores behind registered byte-wide I/O
    /// (for place and route; see src/hw/rtl/shell.rs).
    #[arg(long)]
    pub shell_trees: Option<usize>,
    /// The top to write beside the core.
    #[arg(long, value_enum, default_value_t = InterfaceArg::Core)]
    pub interface: InterfaceArg,
    /// Output directory; the core goes to DIR/photon_search_core.v and its
    /// description (for --core) to DIR/photon_search_core.toml.
    #[arg(long)]
    pub out: PathBuf,
}

pub fn export(args: &ExportArgs) -> Result<()> {
    let cfg = args.core.config()?;
    if args.shell_trees == Some(0) {
        return Err(Error::new("--shell-trees must be at least 1, got 0"));
    }
    // Everything is generated before the directory is made: a failure leaves nothing.
    let exported = export_verilog(&cfg)?;
    let verilog = &exported.verilog;
    // Event-driven simulators (Icarus, ISim, ModelSim) hang on the raw export's
    // glitch loops; this rewrite is what the CI cross-simulation runs under Icarus.
    let sim_verilog = photon_fpga::hw::rtl::export::glitch_free(verilog)?;
    let shell = match args.shell_trees {
        Some(trees) => Some((trees, registered_shell(&exported, trees)?)),
        None => None,
    };
    let axis = match args.interface {
        InterfaceArg::Core => None,
        InterfaceArg::Axis => Some(axis_top(&exported, &cfg)?),
    };
    std::fs::create_dir_all(&args.out)
        .map_err(|e| Error::new(format!("{}: cannot create: {e}", args.out.display())))?;
    let path = args.out.join("photon_search_core.v");
    Output::check(&path, &[])?.write(|w| w.write_all(verilog.as_bytes()))?;
    // The core's description beside it: `--core FILE` runs every map on this core.
    let toml_path = args.out.join(photon_fpga::hw::core_file::CORE_FILE_NAME);
    let description = photon_fpga::hw::core_file::to_toml(&cfg);
    Output::check(&toml_path, &[])?.write(|w| w.write_all(description.as_bytes()))?;
    println!(
        "wrote {}: the core's description (render, gather, bench-core --core FILE)",
        toml_path.display()
    );
    let sim_path = args.out.join("photon_search_core_sim.v");
    Output::check(&sim_path, &[])?.write(|w| w.write_all(sim_verilog.as_bytes()))?;
    println!(
        "wrote {}: the same core for event-driven simulators (glitch-free rewrite)",
        sim_path.display()
    );
    if let Some((trees, shell)) = shell {
        let spath = args.out.join("shell.v");
        Output::check(&spath, &[])?.write(|w| w.write_all(shell.as_bytes()))?;
        println!(
            "wrote {}: {trees} core(s) behind a registered I/O shell",
            spath.display()
        );
    }
    if let Some(axis) = axis {
        let vpath = args.out.join("photon_search_axis.v");
        Output::check(&vpath, &[])?.write(|w| w.write_all(axis.verilog.as_bytes()))?;
        let jpath = args.out.join("photon_search_axis.json");
        Output::check(&jpath, &[])?.write(|w| w.write_all(axis.json.as_bytes()))?;
        println!(
            "wrote {} (and its tdata layout, {}): the core behind AXI4-Stream ports",
            vpath.display(),
            jpath.display()
        );
    }
    println!(
        "wrote {}: {} controller, {} traversal, T = {} tree(s), H = {}, K = {}, {}, {}-bit coordinates, {} metric, {}-bit distances",
        path.display(),
        cfg.controller,
        cfg.traversal,
        cfg.trees,
        cfg.address_bits,
        cfg.k,
        describe_q(&cfg),
        cfg.layout.bits[0],
        cfg.metric,
        cfg.dist_bits()
    );
    Ok(())
}
