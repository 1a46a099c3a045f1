//! The core's streams, written once: the payloads as `LogicStruct`s (one signal
//! carries a whole beat, so a beat moves through a mux, a register or a fan-out in
//! one assignment) and valid/ready bundles as `LogicInterface`s, in the naming of
//! verilog-axis (`valid`, `ready`, `data`, `last`). A beat moves when `valid` and
//! `ready` are both high at a rising clock edge.
//!
//! `StreamIn<T>` is the sink side (the block receives `data`), `StreamOut<T>` the
//! source side. In the exported Verilog a bundle's members are ports named
//! `bundle$member` (e.g. `query$valid`) and a struct is one packed vector whose
//! fields are slices, first field in the low bits.

use crate::hw::config::core_config::{
    Addr, Coord, Count, Dist, ModuleIndex, QueryId, ReadCount, Word,
};
use crate::hw::primitives::bank_bus::{BankAnswerIn, BankRequester};
use rust_hdl::prelude::*;

/// One query: grid coordinates, an inclusive integer radius bound in the metric
/// (larger values saturate to the 32-bit maximum) and k (1..=K).
#[derive(Clone, Copy, Debug, PartialEq, Default, LogicStruct)]
pub struct QueryBeat {
    pub id: QueryId,
    pub x: Coord,
    pub y: Coord,
    pub z: Coord,
    pub radius: Dist,
    pub k: Count,
}

/// One beat of a result packet: a header (`header`; id, found count and photons
/// read meaningful; `last` iff count = 0), then the found photons in list-slot
/// order (id, heap address and distance meaningful), one per beat — or two, the
/// second in `address2`/`distance2` when `pair` is set (a BarrelPort sends pairs:
/// an array of barrel cores answers more queries per cycle than one photon per
/// beat carries) — `last` on the final one. The beats of one packet are
/// contiguous; packets of different queries may leave out of order. A core with
/// found heaps (K > 64) sends zero distances: its read-out keeps addresses only,
/// and the host, which has the map and the query, computes them
/// (`CoreConfig::sends_distances`).
#[derive(Clone, Copy, Debug, PartialEq, Default, LogicStruct)]
pub struct ResultBeat {
    pub header: bool,
    pub last: bool,
    pub id: QueryId,
    pub count: Count,
    pub visited: ReadCount,
    pub address: Addr,
    /// Named `distance`, not `dist`: SystemVerilog reserves `dist`.
    pub distance: Dist,
    /// A second photon in this beat: the next list slot's.
    pub pair: bool,
    pub address2: Addr,
    pub distance2: Dist,
}

/// A valid/ready stream into a block.
#[derive(LogicInterface, Default)]
#[join = "StreamOut"]
pub struct StreamIn<T: Synth> {
    pub valid: Signal<In, bool>,
    pub ready: Signal<Out, bool>,
    pub data: Signal<In, T>,
}

/// A valid/ready stream out of a block.
#[derive(LogicInterface, Default)]
#[join = "StreamIn"]
pub struct StreamOut<T: Synth> {
    pub valid: Signal<Out, bool>,
    pub ready: Signal<In, bool>,
    pub data: Signal<Out, T>,
}

/// The photon load stream: heap address and packed word (`W` bits, see
/// `CoreConfig::word_width`), `last` on the final word (its address is the photon
/// count N). Its members are separate signals because the word's width is a const
/// generic, which rust-hdl's `LogicStruct` cannot carry.
#[derive(LogicInterface, Default)]
pub struct LoadIn<const W: usize> {
    pub valid: Signal<In, bool>,
    pub ready: Signal<Out, bool>,
    pub address: Signal<In, Addr>,
    pub word: Signal<In, Word<W>>,
    pub last: Signal<In, bool>,
}

/// The outer ports of one TreeModule port's controller (paper §4.5), the same for
/// a [`SearchPort`](crate::hw::modules::search_port::SearchPort) and a
/// [`BarrelPort`](crate::hw::barrel::barrel_port::BarrelPort): the photon count, the
/// TreeModule port (read address now, word next cycle), the query and result
/// streams and the status (a read this cycle; every query of the port busy; none).
/// The core wires either controller through it once; clock and reset are separate.
#[derive(LogicInterface, Default)]
pub struct PortIo<const W: usize> {
    pub photon_count: Signal<In, Addr>,
    pub ram_address: Signal<Out, Addr>,
    pub ram_data: Signal<In, Word<W>>,
    pub query: StreamIn<QueryBeat>,
    pub result: StreamOut<ResultBeat>,
    pub reading: Signal<Out, bool>,
    pub all_busy: Signal<Out, bool>,
    pub idle: Signal<Out, bool>,
    /// With a banked store (`CoreConfig::banking`, barrel controller only): the
    /// reads below the replicated levels, to the banks, and their words.
    pub bank: BankRequester,
    pub bank_answer: BankAnswerIn,
}

/// A photon read and its context, from a QueryModule through the port arbiter to
/// the SearchModule (paper §4.5: the SearchModule carries the QueryModule's id so
/// that all of a port's QueryModules can share it). The SearchModule's pipeline
/// carries it along with the word.
#[derive(Clone, Copy, Debug, PartialEq, Default, LogicStruct)]
pub struct ReadRequest {
    /// Index of the requesting QueryModule within its port.
    pub query_module: ModuleIndex,
    pub address: Addr,
    /// The traversal step: climbing (`up`) from the right or the left child.
    pub up: bool,
    pub came_from_right: bool,
    pub x: Coord,
    pub y: Coord,
    pub z: Coord,
    pub radius: Dist,
    pub full: bool,
}

/// What the SearchModule answers about one read, broadcast to the port's
/// QueryModules; the one whose index is `query_module` takes it.
#[derive(Clone, Copy, Debug, PartialEq, Default, LogicStruct)]
pub struct ReadResult {
    pub query_module: ModuleIndex,
    pub address: Addr,
    /// A first (downward) visit whose photon is within the radius.
    pub in_range: bool,
    pub distance: Dist,
    pub next_address: Addr,
    pub next_up: bool,
    pub next_came_from_right: bool,
    pub done: bool,
    /// For the path memory (`Traversal::Remember`): the photon's axis distance and
    /// whether its far child is still to be visited.
    pub axis_dist: Dist,
    pub far_pending: bool,
    /// The photon's split axis (`Traversal::Cell`: which offset its far cell changes).
    pub axis: Bits<2>,
}
