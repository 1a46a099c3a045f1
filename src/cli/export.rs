//! `photon-fpga export-verilog`: the configured core's Verilog, its glitch-free
//! rewrite for event-driven simulators and optionally a registered shell.

use crate::cli::core_args::CoreArgs;
use crate::host::error::{Error, Result};
use crate::host::output::Output;
use crate::hw::export::axis_top::axis_top;
use crate::hw::export::shell::registered_shell;
use crate::hw::export::verilog::{export_verilog, without_status};
use clap::{Args, ValueEnum};
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
    /// (for place and route; see src/hw/export/shell.rs).
    #[arg(long)]
    pub shell_trees: Option<usize>,
    /// The top to write beside the core.
    #[arg(long, value_enum, default_value_t = InterfaceArg::Core)]
    pub interface: InterfaceArg,
    /// Keep the top's measurement outputs (which ports read, every slot busy):
    /// for the lab's reads-per-cycle measurement of the exported Verilog
    /// (synth/report.py), not for a design built into a system.
    #[arg(long, hide = true)]
    pub status_ports: bool,
    /// Output directory; the core goes to DIR/photon_search_core.v and its
    /// description (for --core) to DIR/photon_search_core.toml.
    #[arg(long)]
    pub out: PathBuf,
}

/// The core's Verilog in the output directory.
const CORE_VERILOG: &str = "photon_search_core.v";

pub fn export(args: &ExportArgs) -> Result<()> {
    let cfg = args.core.config()?;
    if args.shell_trees == Some(0) {
        return Err(Error::new("--shell-trees must be at least 1, got 0"));
    }
    // Everything is generated before the directory is made: a failure leaves nothing.
    // The measurement outputs only when a measurement asks for them.
    let exported = match export_verilog(&cfg)? {
        e if args.status_ports => e,
        e => without_status(&e)?,
    };
    let verilog = &exported.verilog;
    // Event-driven simulators (Icarus, ISim, ModelSim) hang on the raw export's
    // glitch loops; this rewrite is what the CI cross-simulation runs under Icarus.
    let sim_verilog = crate::hw::export::verilog::glitch_free(verilog)?;
    let shell = match args.shell_trees {
        Some(trees) => Some((trees, registered_shell(&exported, trees)?)),
        None => None,
    };
    let axis = match args.interface {
        InterfaceArg::Core => None,
        InterfaceArg::Axis => Some(axis_top(&exported, &cfg)?),
    };
    // Every file, then every check (none may replace the --core file it was made
    // from), then the writes: a refused output leaves the directory as it was.
    let description = crate::hw::config::core_file::to_toml(&cfg);
    let mut files: Vec<(&str, &str, String)> = vec![
        (CORE_VERILOG, verilog, String::new()),
        (
            crate::hw::config::core_file::CORE_FILE_NAME,
            &description,
            "the core's description (render, gather --core FILE)".into(),
        ),
        (
            "photon_search_core_sim.v",
            &sim_verilog,
            "the same core for event-driven simulators (glitch-free rewrite)".into(),
        ),
    ];
    if let Some((trees, shell)) = &shell {
        let what = format!("{trees} core(s) behind a registered I/O shell");
        files.push(("shell.v", shell, what));
    }
    if let Some(axis) = &axis {
        let what = "the core behind AXI4-Stream ports".to_string();
        files.push(("photon_search_axis.v", &axis.verilog, what));
        let what = "the AXI4-Stream top's tdata layout".to_string();
        files.push(("photon_search_axis.json", &axis.json, what));
    }
    let inputs: Vec<&std::path::Path> = args.core.file.file.iter().map(|p| p.as_path()).collect();
    let is_dir = args.out.is_dir();
    if !is_dir && args.out.exists() {
        return Err(Error::new(format!(
            "{}: not a directory",
            args.out.display()
        )));
    }
    if is_dir {
        for (name, ..) in &files {
            Output::check(&args.out.join(name), &inputs)?;
        }
    }
    std::fs::create_dir_all(&args.out)
        .map_err(|e| Error::new(format!("{}: cannot create: {e}", args.out.display())))?;
    let path = args.out.join(CORE_VERILOG);
    for (name, text, what) in &files {
        let p = args.out.join(name);
        Output::check(&p, &inputs)?.write(|w| w.write_all(text.as_bytes()))?;
        if !what.is_empty() {
            println!("wrote {}: {what}", p.display());
        }
    }
    println!("wrote {}: {cfg}", path.display());
    Ok(())
}
