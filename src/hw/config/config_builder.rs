//! [`CoreBuilder`]: the one way to make a [`CoreConfig`]. Every option has a
//! default and is set by name; [`CoreBuilder::build`] checks them together, so a
//! combination the datapath cannot build (the barrel controller with the re-read
//! ascent, Q under the other controller's name, K, Q, T or H out of range) is
//! refused when the configuration is made, with the option and its value named.

use crate::hw::config::bank_config::{BankMapping, BankPorts};
use crate::hw::config::controller::Controller;
use crate::hw::config::core_config::{
    Banking, CoreConfig, BARREL_SLOTS, MAX_HW_COORD_BITS, MAX_QUERIES_PER_PORT,
};
use crate::hw::config::core_spec::CoreSpec;
use crate::hw::config::memory_config::{CacheTags, ExternalMemory};
use crate::hw::config::metric::Metric;
use crate::hw::config::photon_word::{PhotonLayout, TreeImage};
use crate::hw::config::traversal::Traversal;
use crate::hw::error::HwError;

/// The one way to make a [`CoreConfig`]: every option with a default, set by name,
/// checked together by [`CoreBuilder::build`]. Q is given under the name of the
/// chosen controller (modules or slots per port); left unset it is the
/// controller's default (the issue interval for QueryModules, [`BARREL_SLOTS`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CoreBuilder {
    layout: PhotonLayout,
    address_bits: u32,
    k: usize,
    metric: Metric,
    pipelined: bool,
    trees: usize,
    traversal: Traversal,
    controller: Controller,
    queries_per_port: Option<usize>,
    /// Bank bits and the replicated levels (None: derived when built), and how
    /// the banks' ports are shared.
    banking: Option<(u32, Option<u32>)>,
    bank_ports: Option<BankPorts>,
    bank_mapping: BankMapping,
    result_streams: usize,
    radius_bits: Option<u32>,
    /// With banks: the external memory's cache lines (None: the map on chip)
    /// and its data width (None: the default).
    cache_lines: Option<u32>,
    memory_data_bits: Option<u32>,
    cache_tags: Option<CacheTags>,
}

impl Default for CoreBuilder {
    /// The paper's grid, K and metric (§4, §5), one pipelined tree of QueryModules
    /// with the default traversal, Q the issue interval.
    fn default() -> Self {
        CoreBuilder {
            layout: PhotonLayout::paper(),
            address_bits: 10,
            k: 10,
            metric: Metric::L1,
            pipelined: true,
            trees: 1,
            traversal: Traversal::default(),
            controller: Controller::default(),
            queries_per_port: None,
            banking: None,
            bank_ports: None,
            bank_mapping: BankMapping::default(),
            result_streams: 1,
            radius_bits: None,
            cache_lines: None,
            memory_data_bits: None,
            cache_tags: None,
        }
    }
}

impl CoreBuilder {
    /// Per-axis coordinate widths (1..=[`MAX_HW_COORD_BITS`](crate::hw::config::core_config::MAX_HW_COORD_BITS) each).
    pub fn layout(self, layout: PhotonLayout) -> Self {
        CoreBuilder { layout, ..self }
    }
    /// Address bits H (1..=[`MAX_ADDRESS_BITS`](crate::hw::config::core_config::MAX_ADDRESS_BITS)).
    pub fn address_bits(self, address_bits: u32) -> Self {
        CoreBuilder {
            address_bits,
            ..self
        }
    }
    /// Found-list depth K (1..=[`MAX_K`](crate::hw::config::core_config::MAX_K)).
    pub fn k(self, k: usize) -> Self {
        CoreBuilder { k, ..self }
    }
    pub fn metric(self, metric: Metric) -> Self {
        CoreBuilder { metric, ..self }
    }
    pub fn pipelined(self, pipelined: bool) -> Self {
        CoreBuilder { pipelined, ..self }
    }
    /// Replicated trees T (1..=[`MAX_TREES`](crate::hw::config::core_config::MAX_TREES)), or with
    /// banks replicas of the top levels (1..=[`MAX_BANKED_TREES`](crate::hw::config::core_config::MAX_BANKED_TREES)).
    pub fn trees(self, trees: usize) -> Self {
        CoreBuilder { trees, ..self }
    }
    pub fn traversal(self, traversal: Traversal) -> Self {
        CoreBuilder { traversal, ..self }
    }
    pub fn controller(self, controller: Controller) -> Self {
        CoreBuilder { controller, ..self }
    }
    /// A banked store (`Controller::Barrel` only), or one whole tree per core.
    pub fn banking(self, banking: Option<Banking>) -> Self {
        CoreBuilder {
            banking: banking.map(|b| (b.bank_bits, Some(b.replicated_levels))),
            bank_ports: banking.map_or(self.bank_ports, |b| Some(b.ports)),
            bank_mapping: banking.map_or(self.bank_mapping, |b| b.mapping),
            ..self
        }
    }
    /// How the banks' read ports are shared (with banks; default
    /// [`BankPorts::default`]).
    pub fn bank_ports(self, bank_ports: BankPorts) -> Self {
        CoreBuilder {
            bank_ports: Some(bank_ports),
            ..self
        }
    }
    /// How a banked node picks its bank (with banks; default [`BankMapping::Xor`]).
    pub fn bank_mapping(self, bank_mapping: BankMapping) -> Self {
        CoreBuilder {
            bank_mapping,
            ..self
        }
    }
    /// 2^`bank_bits` banks with `replicated_levels` levels replicated, or
    /// [`Banking::default_levels`] for the H the core is built with.
    pub fn banks(self, bank_bits: u32, replicated_levels: Option<u32>) -> Self {
        CoreBuilder {
            banking: Some((bank_bits, replicated_levels)),
            ..self
        }
    }

    /// Distance bits for a scene's largest initial radius
    /// ([`CoreConfig::radius_bits`]; `None`: the grid's diagonal).
    pub fn radius_bits(self, radius_bits: Option<u32>) -> Self {
        CoreBuilder {
            radius_bits,
            ..self
        }
    }

    /// With banks, the map's levels below the replicas in external memory behind
    /// a cache of `cache_lines` lines ([`ExternalMemory`]); `None`: on chip.
    pub fn cache_lines(self, cache_lines: Option<u32>) -> Self {
        CoreBuilder {
            cache_lines,
            ..self
        }
    }

    /// With `cache_lines`, the memory's AXI4 data width in bits (`None`: the
    /// default, [`ExternalMemory::new`]).
    pub fn memory_data_bits(self, memory_data_bits: Option<u32>) -> Self {
        CoreBuilder {
            memory_data_bits,
            ..self
        }
    }

    /// With `cache_lines`, where the banks keep their tags (`None`: the default,
    /// [`CacheTags::BlockRam`]).
    pub fn cache_tags(self, cache_tags: Option<CacheTags>) -> Self {
        CoreBuilder { cache_tags, ..self }
    }

    /// Result streams R (a divisor of the datapaths; more than one needs banks or a
    /// single tree).
    pub fn result_streams(self, result_streams: usize) -> Self {
        CoreBuilder {
            result_streams,
            ..self
        }
    }
    /// Q, the queries a TreeModule port holds at once: its QueryModules
    /// (`Controller::Modules`) or its barrel datapath's query slots
    /// (`Controller::Barrel`); 1..=[`MAX_QUERIES_PER_PORT`].
    pub fn queries_per_port(self, q: usize) -> Self {
        CoreBuilder {
            queries_per_port: Some(q),
            ..self
        }
    }
    /// Forget a Q given before: the controller's default again.
    pub fn default_queries_per_port(self) -> Self {
        CoreBuilder {
            queries_per_port: None,
            ..self
        }
    }
    /// The core `spec` describes: each field it leaves out is the default core's
    /// ([`CoreSpec::default_core`]; the traversal and Q its controller's
    /// defaults, the grid and H the builder's). Checked together when built.
    pub fn from_spec(spec: &CoreSpec) -> Result<Self, HwError> {
        CoreBuilder::default().with_spec(&spec.or(&CoreSpec::default_core()))
    }

    /// The fields `spec` gives, set on this builder (a given controller without
    /// a traversal or Q brings its own defaults). Combinations that belong to no
    /// core (replicas or bank options without banks, trees with banks) and
    /// widths out of range are refused, named as the file names them.
    pub fn with_spec(self, spec: &CoreSpec) -> Result<Self, HwError> {
        let fail = |m: String| Err(HwError::Config(m));
        let (c, b) = (&spec.choice, &spec.build);
        let mut out = self;
        if let Some(controller) = c.controller {
            out = out.controller(controller).default_queries_per_port();
            out.traversal = controller.default_traversal();
        }
        if let Some(t) = c.traversal {
            out = out.traversal(t);
        }
        if let Some(q) = c.queries_per_port {
            out = out.queries_per_port(q);
        }
        if let Some(w) = b.coordinate_bits {
            if !w.0.iter().all(|b| (1..=MAX_HW_COORD_BITS).contains(b)) {
                return fail(format!(
                    "coordinate_bits = {:?}: each width must be 1..={MAX_HW_COORD_BITS}",
                    w.0
                ));
            }
            out = out.layout(PhotonLayout::new(w.0));
        }
        if let Some(h) = b.address_bits {
            out = out.address_bits(h);
        }
        if let Some(k) = b.k {
            out = out.k(k);
        }
        if let Some(m) = b.metric {
            out = out.metric(m);
        }
        if let Some(r) = b.radius_bits {
            out = out.radius_bits(Some(r));
        }
        if let Some(p) = b.pipelined {
            out = out.pipelined(p);
        }
        if let Some(r) = b.result_streams {
            out = out.result_streams(r);
        }
        match (b.banks, c.trees, b.replicas) {
            (Some(_), Some(t), _) if t != 1 => {
                return fail(format!(
                    "trees = {t} with banks: a banked core is one tree, its copies of the \
                     top levels are replicas"
                ))
            }
            (Some(banks), _, r) => {
                out = out
                    .banks(Banking::bank_bits_for(banks)?, b.replicated_levels)
                    .trees(r.unwrap_or(1));
            }
            (None, t, None) => out = out.trees(t.unwrap_or(out.trees)),
            (None, _, Some(r)) => {
                return fail(format!(
                    "replicas = {r} without banks: only a banked store replicates its top levels"
                ))
            }
        }
        if b.banks.is_none() {
            if let Some(l) = b.replicated_levels {
                return fail(format!(
                    "replicated_levels = {l} without banks: only a banked store replicates levels"
                ));
            }
            if let Some(m) = b.bank_map {
                return fail(format!(
                    "bank_map = {m} without banks: only a banked store maps nodes to banks"
                ));
            }
            if let Some(l) = b.cache_lines {
                return fail(format!(
                    "cache_lines = {l} without banks: the cache is the banked store's banks"
                ));
            }
        }
        if let Some(m) = b.bank_map {
            out = out.bank_mapping(m);
        }
        if let Some(p) = b.bank_ports {
            out = out.bank_ports(p);
        }
        if b.cache_lines.is_some() {
            out = out.cache_lines(b.cache_lines);
        }
        match (b.memory_data_bits, b.cache_lines) {
            (Some(d), None) => {
                return fail(format!(
                    "memory_data_bits = {d} without cache_lines: only an external memory has a \
                     data width"
                ))
            }
            (d, _) => out = out.memory_data_bits(d),
        }
        match (b.cache_tags, b.cache_lines) {
            (Some(t), None) => {
                return fail(format!(
                    "cache_tags = \"{}\" without cache_lines: only an external memory's \
                     cache has tags",
                    t.name()
                ))
            }
            (t, _) => out = out.cache_tags(t),
        }
        Ok(out)
    }

    /// The grid of `tree`: its coordinate widths and the smallest H that holds it
    /// ("model only what the scene needs").
    pub fn for_map(self, tree: TreeImage<'_>) -> Self {
        self.layout(tree.layout)
            .address_bits(tree.address_bits().max(1))
    }

    /// The address bits H and the grid chosen (a map of up to `2^H − 1` photons).
    pub fn chosen_map(&self) -> (u32, PhotonLayout) {
        (self.address_bits, self.layout)
    }

    /// The controller chosen (the default one unless `controller` was called).
    pub fn chosen_controller(&self) -> Controller {
        self.controller
    }

    /// The distance bits given for a largest radius, if they were.
    pub fn given_radius_bits(&self) -> Option<u32> {
        self.radius_bits
    }

    /// The bank-port mode given, if one was (else [`BankPorts::default`], and a
    /// device's plan may choose it).
    pub fn given_bank_ports(&self) -> Option<BankPorts> {
        self.bank_ports
    }

    /// The cache lines given (an external-memory core asked for), if any.
    pub fn given_cache_lines(&self) -> Option<u32> {
        self.cache_lines
    }

    /// The Q given for the chosen controller, if one was (else its default is used,
    /// and a host may size Q from the queries: [`CoreConfig::fit_queries_per_port`]).
    pub fn given_queries_per_port(&self) -> Option<usize> {
        self.queries_per_port
    }

    /// The configuration, or the first option the datapath cannot build, named
    /// with its value.
    pub fn build(self) -> Result<CoreConfig, HwError> {
        let fail = |m: String| Err(HwError::Config(m));
        if self.controller == Controller::Barrel && !self.traversal.remembers() {
            return fail(format!(
                "traversal = {} with controller barrel: the barrel controller needs a traversal \
                 that remembers the path (remember, cell)",
                self.traversal
            ));
        }
        let mut cfg = CoreConfig {
            layout: self.layout,
            address_bits: self.address_bits,
            k: self.k,
            queries_per_port: 1,
            metric: self.metric,
            pipelined: self.pipelined,
            trees: self.trees,
            traversal: self.traversal,
            controller: self.controller,
            banking: self.banking.map(|(bank_bits, levels)| Banking {
                bank_bits,
                replicated_levels: levels
                    .unwrap_or_else(|| Banking::default_levels(bank_bits, self.address_bits)),
                ports: self.bank_ports.unwrap_or_default(),
                mapping: self.bank_mapping,
            }),
            result_streams: self.result_streams,
            radius_bits: self.radius_bits,
            memory: self.cache_lines.map(|l| {
                let m = ExternalMemory::new(l).with_tags(self.cache_tags.unwrap_or_default());
                self.memory_data_bits.map_or(m, |d| m.with_data_bits(d))
            }),
        };
        cfg.queries_per_port = match self.given_queries_per_port() {
            Some(q) => q,
            None if self.controller == Controller::Barrel => BARREL_SLOTS,
            None => cfg.issue_interval().min(MAX_QUERIES_PER_PORT),
        };
        cfg.validate()?;
        Ok(cfg)
    }

    /// [`CoreBuilder::for_map`], built, and checked to hold `tree`.
    pub fn build_for(self, tree: TreeImage<'_>) -> Result<CoreConfig, HwError> {
        let cfg = self.for_map(tree).build()?;
        cfg.check_map(tree)?;
        Ok(cfg)
    }
}

impl From<CoreConfig> for CoreBuilder {
    /// A builder holding every option of `cfg` (Q under its controller's name), to
    /// derive a variant: `CoreBuilder::from(cfg).trees(2).build()`.
    fn from(cfg: CoreConfig) -> Self {
        CoreBuilder {
            layout: cfg.layout,
            address_bits: cfg.address_bits,
            k: cfg.k,
            metric: cfg.metric,
            pipelined: cfg.pipelined,
            trees: cfg.trees,
            traversal: cfg.traversal,
            controller: cfg.controller,
            queries_per_port: None,
            banking: None,
            bank_ports: None,
            bank_mapping: BankMapping::default(),
            result_streams: cfg.result_streams,
            radius_bits: cfg.radius_bits,
            cache_lines: cfg.memory.map(|m| m.cache_lines),
            memory_data_bits: cfg.memory.map(|m| m.data_bits),
            cache_tags: cfg.memory.map(|m| m.tags),
        }
        .queries_per_port(cfg.queries_per_port)
        .banking(cfg.banking)
    }
}

impl CoreConfig {
    /// A builder with the defaults of [`CoreBuilder::default`].
    pub fn builder() -> CoreBuilder {
        CoreBuilder::default()
    }

    /// This configuration's options in a builder, to derive a variant (the
    /// variant is checked again when built).
    pub fn to_builder(self) -> CoreBuilder {
        CoreBuilder::from(self)
    }

    /// The paper's core (§4, §5): 10-bit coordinates in a 32-bit word, K = 10, two
    /// ports. The metric is L1, the paper's 12-bit "absolute distance": with a 12-bit
    /// distance one QueryModule issues a read every `8 + 12 = 20` cycles here, 18
    /// unpipelined (the paper's Verilog needed 21), and Q = 21 per port as in the
    /// paper keeps every port busy with slack. H = 10 holds the paper's 1023-photon map.
    pub fn paper() -> Self {
        Self::paper_builder()
            .build()
            .expect("the paper's core is within every limit")
    }

    /// [`CoreConfig::paper`]'s options in a builder.
    pub fn paper_builder() -> CoreBuilder {
        CoreBuilder::default().queries_per_port(21)
    }

    /// "Model only what the scene needs": the default core ([`CoreBuilder::default`]'s
    /// controller, traversal and pipelining) for `tree` and `k` (H = the tree
    /// height, the tree's own coordinate widths, K = k) with Q set to the issue
    /// interval of a QueryModule, so a port reads every cycle when all its
    /// QueryModules are busy. Other options: `CoreConfig::builder()...build_for(tree)`.
    pub fn for_map(tree: TreeImage<'_>, k: usize, metric: Metric) -> Result<Self, HwError> {
        CoreConfig::builder().k(k).metric(metric).build_for(tree)
    }
}
