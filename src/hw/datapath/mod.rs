//! The search datapath both controllers share (§4.3): `SearchModule` runs
//! `DistModule` (the photon's distance and the split-axis distance, the paper's
//! AxisDistModule) and `NextIndexModule` in parallel, one photon per cycle; the
//! found-list insertion rule, a query's initial radius and k, and the pruning bounds
//! of the cell traversal (§2.2, `CellBound`, `FarCellDist`).

pub mod cell_bound;
pub mod dist_module;
pub mod far_cell_dist;
pub mod found_rule;
pub mod next_index;
pub mod query_limits;
pub mod search_module;
