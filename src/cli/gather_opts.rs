//! The options every gather shares (render and gather): k, radius, bits, metric,
//! backend, capacity, VCD, threads and the core's options; validated before any
//! work starts.

use super::core_args::{hardware_option_given, CoreFileArg, DeviceOpt};
use crate::host::error::{Error, Result};
use crate::host::gather::{BackendKind, FixedCore, GatherParams, GatherRequest, HW_CAPACITY};
use crate::host::limits::MEMORY_CAPACITY;
use crate::hw::config::config_builder::CoreBuilder;
use crate::hw::config::controller::Controller;
use crate::hw::config::core_config::MAX_HW_COORD_BITS;
use crate::hw::config::core_spec::{CoreBuild, CoreChoice, CoreSpec};
use crate::hw::config::memory_config::MAX_MEMORY_ADDRESS_BITS;
use crate::hw::config::metric::Metric;
use crate::hw::config::photon_word::PhotonLayout;
use clap::Args;
use std::path::PathBuf;

/// Options every gather shares.
#[derive(Args, Clone, Debug)]
pub struct GatherOpts {
    /// Photons gathered per query [default: 32, the default core's found list; with
    /// --core, the file's k].
    #[arg(long)]
    pub k: Option<usize>,
    /// Upper search radius in world units (inclusive); unbounded if absent.
    #[arg(long, allow_negative_numbers = true)]
    pub radius: Option<f64>,
    /// Coordinate bits on the longest axis of the photon bounding box [default: 10]
    /// (the quantized backends sw, rtl and verilator; an error with --backend float).
    /// With --core, the grid has the file's coordinate bits.
    #[arg(long, conflicts_with = "core")]
    pub bits: Option<u32>,
    /// Distance metric (with --core, the file's).
    #[arg(long, value_enum, default_value_t = Metric::L2, conflicts_with = "core")]
    pub metric: Metric,
    /// Who answers the gathers.
    #[arg(long, value_enum, default_value_t = BackendKind::Sw)]
    pub backend: BackendKind,
    /// Largest photon map accepted [default: what the backend can hold: 2^23 - 1
    /// photons for native and verilator (beyond 2^20 - 1 the map is in external
    /// memory: the core --device plans, or the ECP5-85k's), the memory budget for
    /// float and sw].
    #[arg(long)]
    pub capacity: Option<usize>,
    /// With --backend rtl or verilator: stream the simulation's waveform to this
    /// VCD file (also: env PHOTON_FPGA_VCD=path).
    #[arg(long)]
    pub vcd: Option<PathBuf>,
    /// With --backend sw, native or verilator: the float search's exact answers,
    /// from k + m grid candidates per query re-ranked by exact distance on the host
    /// (certified per query; the float search answers the rest). Not with --core:
    /// the exact grid is the map's own, and a core file fixes its grid and K.
    #[arg(long, conflicts_with = "core")]
    pub exact: bool,
    /// With --exact: m, the extra grid candidates per query [default: chosen on a
    /// sample of the queries].
    #[arg(long, requires = "exact")]
    pub refine: Option<usize>,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// The simulated core (--backend rtl or verilator); its grid, K and metric
    /// follow the photon map and the gather. --traversal also steers the software
    /// searches.
    #[command(flatten, next_help_heading = "Core options")]
    pub core: CoreChoice,
    #[command(flatten, next_help_heading = "Core options")]
    pub device: DeviceOpt,
    // `--core FILE`: the whole core from a core description file.
    #[command(flatten, next_help_heading = "Core options")]
    pub core_file: CoreFileArg,
}

impl GatherOpts {
    /// The core options given, as a spec.
    fn choice(&self) -> CoreSpec {
        CoreSpec {
            choice: self.core.clone(),
            ..CoreSpec::default()
        }
    }

    /// The controller chosen, or the default core's.
    fn controller(&self) -> Controller {
        self.core.controller.unwrap_or(Controller::Barrel)
    }

    /// The gather these options ask for, validated whole before any work starts:
    /// the options the backend would ignore refused, the parameters checked as far
    /// as they can be without the photon map, the waveform's path resolved
    /// (`--vcd`, or env PHOTON_FPGA_VCD with a simulating backend).
    pub fn request(&self, default_k: usize) -> Result<GatherRequest> {
        self.check()?;
        let params = self.params(default_k)?;
        params.validate(1)?;
        let gathered_k = if self.exact {
            crate::host::exact::largest_k_prime(
                self.backend,
                params.k,
                self.refine,
                self.controller().max_k(),
            )?
        } else {
            params.k
        };
        let vcd = match &self.vcd {
            Some(p) => Some(p.clone()),
            None if self.backend.simulates() => {
                std::env::var_os(crate::hw::sim::native::VCD_ENV).map(PathBuf::from)
            }
            None => None,
        };
        GatherRequest::new(
            params,
            self.backend,
            self.exact.then_some(self.refine),
            gathered_k,
            vcd,
        )
    }

    /// Options the chosen backend would ignore are errors, not silently dropped.
    fn check(&self) -> Result<()> {
        self.core_file.check_alone(&self.choice())?;
        if self.backend == BackendKind::Float && self.bits.is_some() {
            return Err(Error::new(
                "--bits sets the grid of the quantized backends (sw, native, verilator); \
                 --backend float searches the unquantized positions",
            ));
        }
        if self.backend == BackendKind::Float && self.core_file.file.is_some() {
            return Err(Error::new(
                "--core sets the simulated core and its grid; --backend float searches the \
                 unquantized positions (give --backend sw, native or verilator)",
            ));
        }
        if !self.backend.simulates() {
            if let Some(flag) = hardware_option_given(&self.core, &self.device) {
                return Err(Error::new(format!(
                    "{flag} configures the simulated core; --backend {} runs none \
                     (give --backend native or verilator)",
                    self.backend
                )));
            }
        }
        Ok(())
    }

    /// The gather's parameters, the core's options included, checked as far as
    /// they can be before the photon map exists: a core that cannot be built for
    /// any map (a bad combination, K, Q, T out of range) is refused now.
    fn params(&self, default_k: usize) -> Result<GatherParams> {
        if let Some(fixed) = self.core_file.read(&self.choice())? {
            return self.fixed_params(fixed);
        }
        let hw = self.backend.simulates();
        let k = self.k.unwrap_or(default_k);
        let metric = self.metric;
        let bits = self.bits.unwrap_or(10);
        let controller = self.controller();
        let traversal = if hw {
            self.core
                .traversal
                .unwrap_or(controller.default_traversal())
        } else {
            self.core.traversal.unwrap_or_default()
        };
        if self.exact {
            crate::host::exact::check(self.backend, k, self.refine, controller.max_k())?;
        }
        // The core chosen, its K and metric the gather's.
        let core = CoreBuilder::from_spec(&CoreSpec {
            choice: self.core.clone(),
            build: CoreBuild {
                k: Some(k),
                metric: Some(metric),
                ..CoreBuild::default()
            },
        })?;
        let capacity = match (self.capacity, hw) {
            (Some(c), true) if c > HW_CAPACITY => {
                return Err(Error::new(format!(
                    "--capacity {c} exceeds what --backend {} can hold: the core addresses \
                     at most {HW_CAPACITY} photons ({MAX_MEMORY_ADDRESS_BITS} address bits, the \
                     map in external memory)",
                    self.backend
                )))
            }
            (Some(c), _) => c,
            (None, true) => HW_CAPACITY,
            (None, false) => MEMORY_CAPACITY,
        };
        if hw && k >= 1 {
            // The map sets the grid and H; any grid the quantizer can make is tried
            // later, and the banks (which depend on H) with it; the result streams
            // are checked against the datapaths (one tree of two here) with them.
            core.layout(PhotonLayout::new([bits.clamp(1, MAX_HW_COORD_BITS); 3]))
                .address_bits(1)
                .banking(None)
                .trees(1)
                .result_streams(1)
                .build()?;
            // A device plans the barrel core: a controller that cannot wait is refused now.
            self.device.for_device(core, 1, 1)?;
        }
        Ok(GatherParams {
            k,
            radius: self.radius,
            bits,
            metric,
            traversal,
            capacity,
            core,
            fixed: None,
            device: self.device.device.map(|d| d.device()),
        })
    }

    /// The gather's parameters on the fixed core of `--core FILE`: its grid,
    /// metric and traversal, k up to its K (its K by default), at most the photons
    /// its H holds; refused now, naming the file, if the gather does not fit it.
    fn fixed_params(&self, fixed: FixedCore) -> Result<GatherParams> {
        let c = fixed.config;
        let k = self.k.unwrap_or(c.k);
        let capacity = match self.capacity {
            Some(n) if n > fixed.max_photons() => {
                return Err(Error::new(format!(
                    "--capacity {n} exceeds {}",
                    fixed.photon_limit()
                )))
            }
            Some(n) => n,
            None => fixed.max_photons(),
        };
        fixed.check_gather(k, c.metric, c.traversal)?;
        Ok(GatherParams {
            k,
            radius: self.radius,
            bits: c.layout.bits.into_iter().max().unwrap_or(1),
            metric: c.metric,
            traversal: c.traversal,
            capacity,
            core: c.to_builder(),
            fixed: Some(fixed),
            device: None,
        })
    }
}
