//! `photon-fpga-lab study`: speed against error. Every point of a sweep over
//! coordinate bits, metric, k and photon count gets its image error (against the
//! float render with the same photons and queries and against a converged float
//! reference), kNN recall and gather-radius error beside its cost in photon reads,
//! the software search's measured speed and the hardware's simulated reads per
//! cycle times the clock `synth/results.json` gives; plus the paper's Figs. 3–6
//! from the project's own runs.
//!
//! One job per file: `plan` (what is swept), `metrics` (the error measures),
//! `hwcost` (simulated reads per cycle and `synth/results.json`), `sweep` (the runs),
//! `figures` (Figs. 3–6 data), `pareto` and `plots` (with `plot_axes`: readable
//! ticks, labels that do not overlap) and `report` (the files written);
//! `exact_series` (the `--exact` re-ranking's certified share and reads against m)
//! and `exact_report` (its CSV and section).

pub mod exact_report;
pub mod exact_series;
pub mod figures;
pub mod hwcost;
pub mod metrics;
pub mod pareto;
pub mod plan;
pub mod plot_axes;
pub mod plots;
pub mod report;
pub mod sweep;
