//! The options of a core. [`CoreOpts`] (controller, Q, traversal, trees,
//! pipelining) is shared by every command that builds one: `render` and `gather`
//! (whose grid, K and metric follow the photon map and the gather), and
//! `export-verilog` and `bench-core`, which also take the grid ([`CoreArgs`]).
//! Both go through the one validated constructor, `CoreBuilder::build`. `--core
//! FILE` ([`CoreFileArg`], taken by all four the same way) gives the whole core
//! instead, from a core description file (`hw::config::core_file`).

use super::values::DeviceArg;
use crate::host::device::banked_core;
use crate::host::error::{Error, Result};
use crate::host::gather::FixedCore;
use crate::hw::config::bank_config::BankPorts;
use crate::hw::config::config_builder::CoreBuilder;
use crate::hw::config::controller::Controller;
use crate::hw::config::core_config::{Banking, CoreConfig, MAX_HW_COORD_BITS};
use crate::hw::config::metric::Metric;
use crate::hw::config::photon_word::PhotonLayout;
use crate::hw::config::traversal::Traversal;
use clap::Args;
use clap::ValueEnum;
use std::path::PathBuf;

/// `--core FILE`: the whole core from a core description file.
#[derive(Args, Clone, Debug, Default)]
pub struct CoreFileArg {
    /// The whole core from a core description file (TOML; export-verilog writes one
    /// beside the Verilog): one core, one Verilator model, for every map that fits
    /// it. The map is quantized onto the file's coordinate bits and refused if it
    /// does not fit (more than 2^address_bits − 1 photons, k above the file's k).
    /// It replaces the core options, the grid and the metric: giving any of them
    /// with --core is an error. render and gather take it with --backend sw, rtl or
    /// verilator (sw then answers exactly as the core does).
    #[arg(
        long = "core",
        id = "core",
        value_name = "FILE",
        conflicts_with_all = [
            "controller",
            "traversal",
            "queries_per_port",
            "trees",
            "device",
        ]
    )]
    pub file: Option<PathBuf>,
}

impl CoreFileArg {
    /// The core of the file given, read and checked, if one is.
    pub fn read(&self) -> Result<Option<FixedCore>> {
        self.file.as_deref().map(FixedCore::read).transpose()
    }
}

/// The core's options that do not follow from the photon map.
#[derive(Args, Clone, Debug, Default)]
pub struct CoreOpts {
    /// Who runs a port's queries [default: barrel, the best core measured
    /// (synth/REPORT.md); modules, the paper's, with export-verilog --paper].
    #[arg(long, value_enum)]
    pub controller: Option<Controller>,
    /// How the search climbs back up the tree (changes read counts, never
    /// neighbours) [default: cell with the barrel controller, else remember].
    #[arg(long, value_enum)]
    pub traversal: Option<Traversal>,
    /// Q, the queries a TreeModule port holds at once: QueryModules with
    /// --controller modules [default: the issue interval, so a busy port reads every
    /// cycle; render and gather fit it to their queries], query slots with
    /// --controller barrel [default: 16].
    #[arg(long, value_name = "Q")]
    pub queries_per_port: Option<usize>,
    /// Trees T (the paper's future work): an array of T whole cores, each with its
    /// own copy of the map, behind one set of streams [default: 1].
    #[arg(long)]
    pub trees: Option<usize>,
    /// Plan the banked barrel core this FPGA holds for the map (banks, replicated
    /// levels, datapaths: `device::plan`, docs/BANKING.md); refused, naming the
    /// largest map that fits, if the map does not.
    #[arg(long, value_enum, conflicts_with = "trees")]
    pub device: Option<DeviceArg>,
    /// The options only export-verilog and the lab take ([`CoreDetail`]).
    #[arg(skip)]
    pub detail: CoreDetail,
}

/// The core's options that fix how it is built rather than which core it is:
/// export-verilog (and the lab) take them, and `--core FILE` carries them to
/// render and gather.
#[derive(Args, Clone, Debug, Default)]
pub struct CoreDetail {
    /// Leave out the pipeline registers (BlockRAM read data, result streams): two
    /// cycles less latency, longer critical paths. For before/after timing.
    #[arg(long, conflicts_with = "core")]
    pub unpipelined: bool,
    /// One map banked over B BlockRAM banks (a power of two; --controller barrel)
    /// that every datapath reads through a crossbar: --replicas copies of the top
    /// levels, two datapaths each (docs/BANKING.md) [default: no banks, each tree
    /// holds the whole map].
    #[arg(long, value_name = "B", conflicts_with_all = ["core", "device", "trees"])]
    pub banks: Option<u64>,
    /// Replicas R of the top levels inside one banked core, two datapaths each,
    /// with --banks [default: 1].
    #[arg(long, value_name = "R", requires = "banks")]
    pub replicas: Option<usize>,
    /// Levels of the tree replicated beside each pair of datapaths, with --banks
    /// [default: 10, at least log2 B, below H].
    #[arg(long, value_name = "L", requires = "banks", conflicts_with = "core")]
    pub replicated_levels: Option<u32>,
    /// How each bank's BlockRAM read ports are shared among the datapaths, with
    /// --banks or --device (docs/HARDWARE.md, "The crossbar's area") [default:
    /// shared].
    #[arg(long, value_enum, conflicts_with = "core")]
    pub bank_ports: Option<BankPorts>,
    /// Result streams R: the datapaths' result packets leave on R streams, D / R
    /// datapaths each (a divisor of D = 2 x --replicas with --banks, else of 2); one
    /// stream carries a beat a cycle, which about 8 busy datapaths fill at k = 32
    /// [default: 1; with --device one per 4 datapaths].
    #[arg(long, value_name = "R", conflicts_with_all = ["core", "device"])]
    pub result_streams: Option<usize>,
}

impl CoreOpts {
    /// The controller chosen, or `default`.
    pub fn controller_or(&self, default: Controller) -> Controller {
        // A device plans the banked barrel core.
        let default = if self.device.is_some() {
            Controller::Barrel
        } else {
            default
        };
        self.controller.map_or(default, Into::into)
    }

    /// `b` planned for `--device`, if one was given, for a map of `photons`
    /// photons of `word_bits`-bit words (`device::banked_core`).
    pub fn for_device(
        &self,
        b: CoreBuilder,
        photons: usize,
        word_bits: u32,
    ) -> Result<CoreBuilder> {
        banked_core::for_device_opt(b, photons, word_bits, self.device.map(|d| d.device()))
    }

    /// The traversal chosen, or the default for `controller`: the cell bound with
    /// the barrel controller (the best core measured), else remember.
    pub fn traversal_for(&self, controller: Controller) -> Traversal {
        self.traversal.map_or(
            if controller == Controller::Barrel {
                Traversal::Cell
            } else {
                Traversal::default()
            },
            Into::into,
        )
    }

    /// The first option given that only a simulated core uses, if any.
    pub fn hardware_option_given(&self) -> Option<&'static str> {
        [
            (self.controller.is_some(), "--controller"),
            (self.queries_per_port.is_some(), "--queries-per-port"),
            (self.trees.is_some(), "--trees"),
            (self.detail.replicas.is_some(), "--replicas"),
            (self.detail.unpipelined, "--unpipelined"),
            (self.detail.banks.is_some(), "--banks"),
            (
                self.detail.replicated_levels.is_some(),
                "--replicated-levels",
            ),
            (self.detail.bank_ports.is_some(), "--bank-ports"),
            (self.detail.result_streams.is_some(), "--result-streams"),
            (self.device.is_some(), "--device"),
        ]
        .into_iter()
        .find_map(|(given, name)| given.then_some(name))
    }

    /// The options given, as they are written on a command line (for a report's
    /// "regenerate with" line).
    pub fn flags(&self) -> String {
        fn name<T: clap::ValueEnum>(v: &T) -> String {
            v.to_possible_value()
                .map_or(String::new(), |p| p.get_name().to_string())
        }
        let mut out = String::new();
        if let Some(c) = &self.controller {
            out += &format!(" --controller {}", name(c));
        }
        if let Some(t) = &self.traversal {
            out += &format!(" --traversal {}", name(t));
        }
        for (flag, v) in [
            ("--queries-per-port", self.queries_per_port),
            ("--trees", self.trees),
            ("--replicas", self.detail.replicas),
            ("--banks", self.detail.banks.map(|b| b as usize)),
            (
                "--replicated-levels",
                self.detail.replicated_levels.map(|l| l as usize),
            ),
            ("--result-streams", self.detail.result_streams),
        ] {
            if let Some(v) = v {
                out += &format!(" {flag} {v}");
            }
        }
        if self.detail.unpipelined {
            out += " --unpipelined";
        }
        if let Some(p) = &self.detail.bank_ports {
            out += &format!(" --bank-ports {}", name(p));
        }
        if let Some(d) = &self.device {
            out += &format!(" --device {}", name(d));
        }
        out
    }

    /// These options on top of `base` (grid, K and metric), with the controller
    /// `default_controller` unless one is chosen.
    pub fn builder(
        &self,
        base: CoreBuilder,
        default_controller: Controller,
    ) -> Result<CoreBuilder> {
        let controller = self.controller_or(default_controller);
        let mut b = base
            .controller(controller)
            .traversal(self.traversal_for(controller))
            .trees(self.detail.replicas.or(self.trees).unwrap_or(1))
            .result_streams(self.detail.result_streams.unwrap_or(1))
            .pipelined(!self.detail.unpipelined);
        if let Some(q) = self.queries_per_port {
            b = b.queries_per_port(q);
        }
        if let Some(banks) = self.detail.banks {
            let bits = Banking::bank_bits_for(banks).map_err(|_| {
                Error::new(format!("--banks {banks}: a power of two from 2 to 1024"))
            })?;
            b = b.banks(bits, self.detail.replicated_levels);
        }
        if let Some(p) = self.detail.bank_ports {
            if self.detail.banks.is_none() && self.device.is_none() {
                return Err(Error::new(format!(
                    "--bank-ports {}: without --banks or --device there are no banks",
                    p.to_possible_value()
                        .map_or(String::new(), |v| v.get_name().to_string())
                )));
            }
            b = b.bank_ports(p);
        }
        Ok(b)
    }
}

/// K of the default core: the render's k.
pub const DEFAULT_K: usize = 32;

/// A whole core: its grid, K and metric and [`CoreOpts`] (the best core measured
/// by default, the paper's with `--paper`), or a core description file.
#[derive(Args)]
pub struct CoreArgs {
    /// The paper's Table-2 core: K = 10, L1, the modules controller with Q the
    /// issue interval (10-bit coordinates and H = 10 as by default); the options
    /// given beside it change it.
    #[arg(long, conflicts_with = "core")]
    paper: bool,
    /// Found-list depth K (the largest k a query may ask for) [default: 32, the
    /// render's k; 10 with --paper].
    #[arg(long, conflicts_with = "core")]
    k: Option<usize>,
    /// Coordinate bits on the grid's longest axis, as render's and gather's --bits
    /// (with no map to size the others, every axis).
    #[arg(long, default_value_t = CoreConfig::paper().layout.bits[0], conflicts_with = "core")]
    bits: u32,
    /// Tree height H: the TreeModule holds 2^H photon words.
    #[arg(long, default_value_t = CoreConfig::paper().address_bits, conflicts_with = "core")]
    address_bits: u32,
    /// Distance metric [default: l2; l1, the paper's 12-bit distance, with --paper].
    #[arg(long, value_enum, conflicts_with = "core")]
    metric: Option<Metric>,
    /// Distance bits for the largest initial radius the core is to answer (radii
    /// below 2^b − 1 in the metric on the grid; larger distances saturate):
    /// narrower found lists and bounds for a scene that gathers within a radius
    /// [default: the grid's diagonal, every radius].
    #[arg(long, value_name = "B", conflicts_with = "core")]
    radius_bits: Option<u32>,
    #[command(flatten)]
    pub opts: CoreOpts,
    #[command(flatten)]
    pub detail: CoreDetail,
    #[command(flatten)]
    pub file: CoreFileArg,
}

impl CoreArgs {
    /// The core of `--core FILE`, if one was given.
    pub fn fixed(&self) -> Result<Option<FixedCore>> {
        self.file.read()
    }

    /// The options as a builder (the paper's controller unless one is chosen; the
    /// file's core with `--core`).
    pub fn builder(&self) -> Result<CoreBuilder> {
        if let Some(f) = self.fixed()? {
            return Ok(f.config.to_builder());
        }
        if !(1..=MAX_HW_COORD_BITS).contains(&self.bits) {
            return Err(Error::new(format!(
                "--bits {} is out of range (1..={MAX_HW_COORD_BITS})",
                self.bits
            )));
        }
        // The paper's core (the builder's default), or the best measured: the
        // barrel controller (with the cell traversal), K = 32, L2.
        let (k, metric, controller) = if self.paper {
            (
                CoreConfig::paper().k,
                CoreConfig::paper().metric,
                Controller::Modules,
            )
        } else {
            (DEFAULT_K, Metric::L2, Controller::Barrel)
        };
        let base = CoreConfig::builder()
            .layout(PhotonLayout::new([self.bits; 3]))
            .address_bits(self.address_bits)
            .k(self.k.unwrap_or(k))
            .metric(self.metric.unwrap_or(metric))
            .radius_bits(self.radius_bits);
        let opts = CoreOpts {
            detail: self.detail.clone(),
            ..self.opts.clone()
        };
        opts.builder(base, controller)
    }

    /// The core, planned for `--device` on a full map of 2^H − 1 photons.
    pub fn config(&self) -> Result<CoreConfig> {
        self.config_of(self.builder()?)
    }

    /// `spec` (this command's [`CoreArgs::builder`]) built, planned for `--device`
    /// on a full map of 2^H − 1 photons.
    pub fn config_of(&self, spec: CoreBuilder) -> Result<CoreConfig> {
        let photons = (1usize << self.address_bits.min(30)) - 1;
        let word_bits = PhotonLayout::new([self.bits; 3]).word_bits();
        Ok(self.opts.for_device(spec, photons, word_bits)?.build()?)
    }
}
