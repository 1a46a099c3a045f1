//! The core options of the command line. Which core answers and how it is built
//! are the fields of the one description, `hw::config::core_spec::CoreSpec`,
//! flattened here with their own help texts: render and gather take its
//! [`CoreChoice`] (their grid, K and metric follow the photon map and the gather),
//! export-verilog and the lab's bench-core the whole spec ([`CoreArgs`]). Both go
//! through the one validated constructor, `CoreBuilder::from_spec`. `--device`
//! ([`DeviceOpt`]) plans the banked core an FPGA holds; `--core FILE`
//! ([`CoreFileArg`]) gives the whole core from a core file instead.

use super::values::DeviceArg;
use crate::host::device::banked_core;
use crate::host::error::{Error, Result};
use crate::host::gather::FixedCore;
use crate::hw::config::config_builder::CoreBuilder;
use crate::hw::config::core_config::CoreConfig;
use crate::hw::config::core_spec::{CoreChoice, CoreSpec};
use clap::{Args, ValueEnum};
use std::path::PathBuf;

/// `--core FILE`: the whole core from a core description file.
#[derive(Args, Clone, Debug, Default)]
pub struct CoreFileArg {
    /// The whole core from a core description file (TOML; export-verilog writes one
    /// beside the Verilog): one core, one Verilator model, for every map that fits
    /// it. The map is quantized onto the file's coordinate bits and refused if it
    /// does not fit (more than 2^address_bits − 1 photons, k above the file's k).
    /// It replaces the core options, the grid and the metric: giving any of them
    /// with --core is an error. render and gather take it with --backend sw, native
    /// or verilator (sw then answers exactly as the core does).
    #[arg(long = "core", id = "core", value_name = "FILE")]
    pub file: Option<PathBuf>,
}

impl CoreFileArg {
    /// The core of the file given, read and checked, if one is; a core option
    /// given beside it (any field of `spec`) is refused, named as it was written.
    pub fn read(&self, spec: &CoreSpec) -> Result<Option<FixedCore>> {
        self.check_alone(spec)?;
        self.file.as_deref().map(FixedCore::read).transpose()
    }

    /// A core option given beside the file (any field of `spec`) is an error.
    pub fn check_alone(&self, spec: &CoreSpec) -> Result<()> {
        match (&self.file, spec.given().first()) {
            (Some(file), Some((key, _))) => Err(Error::new(format!(
                "{} cannot be used with --core {}: the file gives the whole core",
                flag_of(key),
                file.display()
            ))),
            _ => Ok(()),
        }
    }
}

/// `--device`: the banked core an FPGA holds for the map.
#[derive(Args, Clone, Debug, Default)]
pub struct DeviceOpt {
    /// Plan the banked barrel core this FPGA holds for the map (banks, replicated
    /// levels, datapaths, result streams: `device::plan`, docs/BANKING.md); a map
    /// beyond its BlockRAM gets the external-memory core (the largest cache it holds,
    /// docs/MEMORY_CORE.md), refused, naming the largest, beyond 2^23 − 1 photons.
    #[arg(long, value_enum, conflicts_with_all = ["trees", "core"])]
    pub device: Option<DeviceArg>,
}

impl DeviceOpt {
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
}

/// The command-line spelling of a spec's key (`queries_per_port` →
/// `--queries-per-port`; the two whose flag is not their key by name).
fn flag_of(key: &str) -> String {
    match key {
        "coordinate_bits" => "--bits".into(),
        "pipelined" => "--unpipelined".into(),
        k => format!("--{}", k.replace('_', "-")),
    }
}

/// The first option of `choice` (or `--device`) given that only a simulated core
/// uses, if any. The traversal also steers the software searches.
pub fn hardware_option_given(choice: &CoreChoice, device: &DeviceOpt) -> Option<String> {
    let spec = CoreSpec {
        choice: CoreChoice {
            traversal: None,
            ..choice.clone()
        },
        ..CoreSpec::default()
    };
    spec.given()
        .first()
        .map(|(key, _)| flag_of(key))
        .or(device.device.map(|_| "--device".into()))
}

/// The options of `spec` given, as they are written on a command line (for a
/// report's "regenerate with" line).
pub fn flags(spec: &CoreSpec) -> String {
    spec.given()
        .into_iter()
        .map(|(key, value)| match (key.as_str(), value) {
            ("pipelined", toml::Value::Boolean(false)) => " --unpipelined".into(),
            ("pipelined", _) => String::new(),
            ("coordinate_bits", v) => {
                let w: Vec<String> = v
                    .as_array()
                    .into_iter()
                    .flatten()
                    .map(|x| x.to_string())
                    .collect();
                format!(" --bits {}", w.join(","))
            }
            (k, toml::Value::String(s)) => format!(" {} {s}", flag_of(k)),
            (k, v) => format!(" {} {v}", flag_of(k)),
        })
        .collect()
}

/// A whole core: the spec given (over the default core, or the paper's with
/// `--paper`), planned for `--device`, or a core description file.
#[derive(Args)]
pub struct CoreArgs {
    /// The paper's Table-2 core: K = 10, L1, the modules controller with Q the
    /// issue interval (10-bit coordinates and H = 10 as by default); the options
    /// given beside it change it.
    #[arg(long, conflicts_with = "core")]
    paper: bool,
    #[command(flatten)]
    pub spec: CoreSpec,
    #[command(flatten)]
    pub device: DeviceOpt,
    #[command(flatten)]
    pub file: CoreFileArg,
}

impl CoreArgs {
    /// The core of `--core FILE`, if one was given.
    pub fn fixed(&self) -> Result<Option<FixedCore>> {
        self.file.read(&self.spec)
    }

    /// The spec given over its base: the paper's core with `--paper`, else the
    /// default core.
    pub fn spec(&self) -> CoreSpec {
        if self.paper {
            self.spec.or(&CoreSpec::paper())
        } else {
            self.spec.clone()
        }
    }

    /// The options as a builder (the file's core with `--core`).
    pub fn builder(&self) -> Result<CoreBuilder> {
        if let Some(f) = self.fixed()? {
            return Ok(f.config.to_builder());
        }
        let spec = self.spec();
        let b = &spec.build;
        if self.device.device.is_some() {
            if let Some((key, _)) = [
                ("banks", b.banks.is_some()),
                ("result_streams", b.result_streams.is_some()),
            ]
            .into_iter()
            .find(|(_, given)| *given)
            {
                return Err(Error::new(format!(
                    "{} is planned by --device: give one or the other",
                    flag_of(key)
                )));
            }
        } else if let (Some(p), None) = (b.bank_ports, b.banks) {
            let name = p.to_possible_value().map(|v| v.get_name().to_string());
            return Err(Error::new(format!(
                "--bank-ports {}: without --banks or --device there are no banks",
                name.unwrap_or_default()
            )));
        }
        Ok(CoreBuilder::from_spec(&spec)?)
    }

    /// The core, planned for `--device` on a full map of 2^H − 1 photons.
    pub fn config(&self) -> Result<CoreConfig> {
        self.config_of(self.builder()?)
    }

    /// `spec` (this command's [`CoreArgs::builder`]) built, planned for `--device`
    /// on a full map of 2^H − 1 photons.
    pub fn config_of(&self, spec: CoreBuilder) -> Result<CoreConfig> {
        let (h, layout) = spec.chosen_map();
        let photons = (1usize << h.min(30)) - 1;
        Ok(self
            .device
            .for_device(spec, photons, layout.word_bits())?
            .build()?)
    }
}
