//! `photon-fpga`: render with photon mapping whose gathers run on the software
//! reference or the simulated FPGA core, gather a user's own photon map, or export
//! the core's Verilog.

fn main() -> std::process::ExitCode {
    photon_fpga::cli::main()
}
