//! `SearchTop`: what the simulation driver needs from a top-level block. Two blocks
//! are tops: [`PhotonSearchCore`] (one tree, T = 1) and [`PhotonSearchArray`] (T
//! replicated trees). Both have the same stream bundles and status outputs, so one
//! driver, one cross-simulation and one Verilog testbench serve both.

use crate::hw::config::core_config::CoreConfig;
use crate::hw::config::memory_config::MEMORY_PORT_BITS;
use crate::hw::primitives::axi4_read::AxiReadMaster;
use crate::hw::primitives::stream::{LoadIn, QueryBeat, ResultBeat, StreamIn, StreamOut};
use crate::hw::top::array::PhotonSearchArray;
use crate::hw::top::core::PhotonSearchCore;
use rust_hdl::prelude::*;

/// Mutable access to a top's ports (see `core.rs` for the stream protocol).
pub struct TopIo<'a, const W: usize> {
    pub clock: &'a mut Signal<In, Clock>,
    pub reset: &'a mut Signal<In, bool>,
    pub load: &'a mut LoadIn<W>,
    pub query: &'a mut StreamIn<QueryBeat>,
    pub result: &'a mut StreamOut<ResultBeat>,
    /// Result streams 1..R (empty with one).
    pub more_results: &'a mut Vec<StreamOut<ResultBeat>>,
}

/// A top-level block with `W`-bit photon words.
pub trait SearchTop<const W: usize>: Block + Sized {
    /// Elaborate the top for `cfg` (validated by the caller).
    fn elaborate(cfg: &CoreConfig) -> Self;
    /// The ports, for driving inputs and sampling outputs.
    fn io(&mut self) -> TopIo<'_, W>;
    /// Tree `t`'s status this cycle: port A reads, port B reads, all its
    /// QueryModules are busy (for the reads-per-cycle measurement).
    fn tree_status(&self, t: usize) -> [bool; 3];
    /// The AXI4 master of a core whose map is in external memory.
    fn memory_port(&mut self) -> Option<&mut AxiReadMaster<MEMORY_PORT_BITS>> {
        None
    }
}

macro_rules! top_io {
    ($s:expr) => {
        TopIo {
            clock: &mut $s.clock,
            reset: &mut $s.reset,
            load: &mut $s.load,
            query: &mut $s.query,
            result: &mut $s.result,
            more_results: &mut $s.more_results,
        }
    };
}

fn status<const S: usize, const W: usize>(core: &PhotonSearchCore<S, W>) -> [bool; 3] {
    [
        core.port_a_reading.val(),
        core.port_b_reading.val(),
        core.all_busy.val(),
    ]
}

impl<const S: usize, const W: usize> SearchTop<W> for PhotonSearchCore<S, W> {
    fn elaborate(cfg: &CoreConfig) -> Self {
        PhotonSearchCore::new(cfg)
    }
    fn io(&mut self) -> TopIo<'_, W> {
        top_io!(self)
    }
    fn tree_status(&self, t: usize) -> [bool; 3] {
        // Banks: tree t's two datapaths (ports 2t and 2t + 1).
        match self.ports_reading.get(2 * t..2 * t + 2) {
            Some([a, b]) => [a.val(), b.val(), self.all_busy.val()],
            _ => status(self),
        }
    }
    fn memory_port(&mut self) -> Option<&mut AxiReadMaster<MEMORY_PORT_BITS>> {
        self.m_axi.first_mut()
    }
}

impl<const S: usize, const W: usize> SearchTop<W> for PhotonSearchArray<S, W> {
    fn elaborate(cfg: &CoreConfig) -> Self {
        PhotonSearchArray::new(cfg)
    }
    fn io(&mut self) -> TopIo<'_, W> {
        top_io!(self)
    }
    fn tree_status(&self, t: usize) -> [bool; 3] {
        status(&self.trees[t])
    }
}
