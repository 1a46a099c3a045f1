//! The options every gather shares (render and gather): k, radius, bits, metric,
//! traversal, backend, VCD, threads; validated before any work starts.

use clap::Args;
use photon_fpga::host::error::{Error, Result};
use photon_fpga::host::gather::{BackendKind, GatherParams, DEFAULT_CAPACITY};
use photon_fpga::host::output::{Output, Staged};
use photon_fpga::hw::metric::Metric;
use photon_fpga::hw::rtl::native::SimOptions;
use photon_fpga::hw::traversal::Traversal;
use std::path::PathBuf;

/// Options every gather shares.
#[derive(Args, Clone, Debug)]
pub struct GatherOpts {
    /// Photons gathered per query [default: 10 for gather, 32 for render: the core's largest found list].
    #[arg(long)]
    pub k: Option<usize>,
    /// Upper search radius in world units (inclusive); unbounded if absent.
    #[arg(long, allow_negative_numbers = true)]
    pub radius: Option<f64>,
    /// Coordinate bits on the longest axis of the photon bounding box [default: 10]
    /// (the quantized backends sw and rtl; an error with --backend float).
    #[arg(long)]
    pub bits: Option<u32>,
    /// Distance metric: l2 (squared Euclidean) or l1 (Manhattan).
    #[arg(long, default_value_t = Metric::L2)]
    pub metric: Metric,
    /// How the search climbs back up: remember (each level's axis distance, no
    /// re-reads) or reread (the paper's). Changes read counts, never neighbours.
    #[arg(long, default_value_t = Traversal::default())]
    pub traversal: Traversal,
    /// Who answers the gathers: float, sw or rtl.
    #[arg(long, default_value_t = BackendKind::Sw)]
    pub backend: BackendKind,
    /// Largest photon map accepted.
    #[arg(long, default_value_t = DEFAULT_CAPACITY)]
    pub capacity: usize,
    /// With --backend rtl or verilator: stream the simulation's waveform to this
    /// VCD file (also: env PHOTON_FPGA_VCD=path).
    #[arg(long)]
    pub vcd: Option<PathBuf>,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
}

impl GatherOpts {
    /// The waveform output (`--vcd` or env PHOTON_FPGA_VCD; rtl and verilator), checked now
    /// and staged: the simulator writes a temporary file that becomes the VCD only
    /// when the whole run succeeds.
    pub fn vcd(&self, inputs: &[&std::path::Path]) -> Result<Option<Staged>> {
        let path = match &self.vcd {
            Some(p) => p.clone(),
            None if self.backend.simulates() => {
                match std::env::var_os(photon_fpga::hw::rtl::native::VCD_ENV) {
                    Some(p) => PathBuf::from(p),
                    None => return Ok(None),
                }
            }
            None => return Ok(None),
        };
        if !self.backend.simulates() {
            return Err(Error::new("--vcd needs --backend rtl or verilator"));
        }
        Ok(Some(Output::check(&path, inputs)?.stage()?))
    }

    pub fn sim(&self, vcd: &Option<Staged>) -> SimOptions {
        SimOptions {
            vcd: vcd.as_ref().map(|v| v.path().to_path_buf()),
            ..SimOptions::default()
        }
    }

    /// Options the chosen backend would ignore are errors, not silently dropped.
    pub fn check(&self) -> Result<()> {
        if self.backend == BackendKind::Float && self.bits.is_some() {
            return Err(Error::new(
                "--bits sets the grid of the quantized backends (sw, rtl); \
                 --backend float searches the unquantized positions",
            ));
        }
        Ok(())
    }

    pub fn params(&self, default_k: usize) -> GatherParams {
        GatherParams {
            k: self.k.unwrap_or(default_k),
            radius: self.radius,
            bits: self.bits.unwrap_or(10),
            metric: self.metric,
            traversal: self.traversal,
            capacity: self.capacity,
        }
    }
}
