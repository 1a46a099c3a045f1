//! What a study sweeps: scenes, coordinate bits, metrics, k, photon counts, and
//! how large its images, references and samples are (full and `--quick`).

use photon_fpga::host::render::scene::Scene;
use photon_fpga::hw::config::config_builder::CoreBuilder;
use photon_fpga::hw::config::controller::Controller;
use photon_fpga::hw::config::metric::Metric;
use photon_fpga::hw::config::traversal::Traversal;
use photon_fpga::hw::sim::native::Engine;

/// Widest coordinate the core holds per axis (`src/hw/config/photon_word.rs`: <= 15 bits).
pub const HW_MAX_BITS: u32 = 15;

/// The scene the study's second row of results comes from: long and flat, with a
/// caustic, where an isotropic grid spends its bits on the length.
pub fn corridor() -> Scene {
    Scene::from_toml_str(
        include_str!("../../../scenes/corridor.toml"),
        "corridor.toml",
    )
    .expect("the built-in corridor scene is valid")
}

/// The core a study simulates and costs unless told otherwise: the barrel
/// controller (the best single core measured, and the one whose found lists reach
/// the paper's k = 500 of §3, Fig. 5), with its default cell traversal.
pub const STUDY_CONTROLLER: Controller = Controller::Barrel;

/// The `--exact` series' coordinate bits: around the paper's 10.
pub const EXACT_BITS: [u32; 3] = [8, 10, 12];

/// The `--exact` series' m: a ladder up to k = 32's found-list headroom (k′ ≤ 64),
/// then the m `--exact` chooses.
fn exact_ms() -> Vec<Option<usize>> {
    [0, 4, 8, 12, 16, 24, 32]
        .into_iter()
        .map(Some)
        .chain([None])
        .collect()
}

#[derive(Clone, Debug)]
pub struct Plan {
    /// (name, scene), first the one the figures and the README's numbers use.
    pub scenes: Vec<(String, Scene)>,
    pub bits: Vec<u32>,
    pub metrics: Vec<Metric>,
    pub ks: Vec<usize>,
    /// Emitted photons; the first is the base count (hardware runs, figures).
    pub photons: Vec<usize>,
    /// The converged reference: float L2 with this many emitted photons and this k.
    pub reference_photons: usize,
    pub reference_k: usize,
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub seed: u64,
    /// Queries simulated per hardware configuration, and at which bits.
    pub hw_sample: usize,
    pub hw_bits: Vec<u32>,
    pub engine: Engine,
    /// The core simulated and costed: its controller, Q, trees and pipelining (K,
    /// grid and metric follow each point of the sweep), and the traversal the
    /// quantized search and the core run (read counts depend on it, neighbours do
    /// not). The paper's core by default.
    pub core: CoreBuilder,
    pub traversal: Traversal,
    /// Queries timed (one thread) per point for the software search's queries/s.
    pub timing_sample: usize,
    /// Fig. 4's emitted photon counts and Fig. 3's fractions of the queries.
    pub fig_photons: Vec<usize>,
    pub fig_query_fractions: Vec<usize>,
    /// Fig. 5/6's k values.
    pub fig_ks: Vec<usize>,
    /// The `--exact` series (first scene, base photon count): its metric and k (the
    /// render's defaults, or the quick sweep's k), its coordinate bits and its m
    /// (`None`: the m `--exact` chooses).
    pub exact_metric: Metric,
    pub exact_k: usize,
    pub exact_bits: Vec<u32>,
    pub exact_ms: Vec<Option<usize>>,
    pub quick: bool,
}

impl Plan {
    /// The full study: both built-in scenes (or `scene`), bits 6..=16.
    pub fn full(scene: Option<(String, Scene)>, engine: Engine) -> Plan {
        let scenes = match scene {
            Some(s) => vec![s],
            None => vec![
                ("cornell".to_string(), Scene::cornell_box()),
                ("corridor".to_string(), corridor()),
            ],
        };
        Plan {
            scenes,
            bits: (6..=16).collect(),
            metrics: vec![Metric::L1, Metric::L2],
            ks: vec![10, 32, 64, 100, 500],
            photons: vec![200_000, 50_000],
            reference_photons: 2_000_000,
            reference_k: 1000,
            width: 128,
            height: 128,
            spp: 1,
            seed: 1,
            hw_sample: 400,
            hw_bits: vec![10],
            engine,
            core: CoreBuilder::default(),
            traversal: Traversal::default(),
            timing_sample: 2000,
            fig_photons: vec![25_000, 50_000, 100_000, 200_000, 400_000],
            fig_query_fractions: vec![8, 4, 2, 1],
            fig_ks: vec![10, 32, 64, 100, 500],
            exact_metric: Metric::L2,
            exact_k: 32,
            exact_bits: EXACT_BITS.to_vec(),
            exact_ms: exact_ms(),
            quick: false,
        }
    }

    /// `--quick`: a sweep small enough for a debug-build test (under a minute): the
    /// first scene only, a 32 x 32 image, a few thousand photons, bits {6, 10, 16},
    /// k = 10, the native simulation on a handful of queries; the `--exact` series
    /// at k = 10.
    pub fn quick(scene: Option<(String, Scene)>) -> Plan {
        let scene = scene.unwrap_or_else(|| ("cornell".to_string(), Scene::cornell_box()));
        Plan {
            scenes: vec![scene],
            bits: vec![6, 10, 16],
            metrics: vec![Metric::L1, Metric::L2],
            ks: vec![10],
            photons: vec![3000],
            reference_photons: 30_000,
            reference_k: 100,
            width: 32,
            height: 32,
            spp: 1,
            seed: 1,
            hw_sample: 80,
            hw_bits: vec![10],
            engine: Engine::Native,
            core: CoreBuilder::default(),
            traversal: Traversal::default(),
            timing_sample: 200,
            fig_photons: vec![1000, 3000],
            fig_query_fractions: vec![2, 1],
            fig_ks: vec![10, 32],
            exact_metric: Metric::L2,
            exact_k: 10,
            exact_bits: EXACT_BITS.to_vec(),
            exact_ms: exact_ms(),
            quick: true,
        }
    }

    /// The largest k the study's core holds (its controller's K limit); larger k
    /// are software-only points of the sweep.
    pub fn hw_max_k(&self) -> usize {
        self.core.chosen_controller().max_k()
    }

    /// Whether the core can run a gather of `k` photons on a `bits`-bit grid.
    pub fn hw_capable(&self, k: usize, bits: u32) -> bool {
        k <= self.hw_max_k() && bits <= HW_MAX_BITS
    }
}
