//! `SearchTop`: what the host side (the simulation driver, the cross-simulation
//! recorder, the Verilog export) needs from a top-level block. Two blocks are tops:
//! [`PhotonSearchCore`] (one tree, T = 1) and [`PhotonSearchArray`] (T replicated
//! trees). Both have the same stream ports with the same names and widths, so one
//! driver and one Verilog testbench serve both.

use crate::hw::array::PhotonSearchArray;
use crate::hw::config::{Addr, Coord, CoreConfig, Count, Dist, QueryId, ReadCount, Word};
use crate::hw::core::PhotonSearchCore;
use rust_hdl::prelude::*;

/// Mutable access to every port of a top (see `core.rs` for the stream protocol).
pub struct TopPorts<'a, const W: usize> {
    pub clock: &'a mut Signal<In, Clock>,
    pub reset: &'a mut Signal<In, bool>,
    pub load_valid: &'a mut Signal<In, bool>,
    pub load_ready: &'a mut Signal<Out, bool>,
    pub load_address: &'a mut Signal<In, Addr>,
    pub load_word: &'a mut Signal<In, Word<W>>,
    pub load_last: &'a mut Signal<In, bool>,
    pub query_valid: &'a mut Signal<In, bool>,
    pub query_ready: &'a mut Signal<Out, bool>,
    pub query_id: &'a mut Signal<In, QueryId>,
    pub query_x: &'a mut Signal<In, Coord>,
    pub query_y: &'a mut Signal<In, Coord>,
    pub query_z: &'a mut Signal<In, Coord>,
    pub query_radius: &'a mut Signal<In, Dist>,
    pub query_k: &'a mut Signal<In, Count>,
    pub result_valid: &'a mut Signal<Out, bool>,
    pub result_ready: &'a mut Signal<In, bool>,
    pub result_header: &'a mut Signal<Out, bool>,
    pub result_last: &'a mut Signal<Out, bool>,
    pub result_id: &'a mut Signal<Out, QueryId>,
    pub result_count: &'a mut Signal<Out, Count>,
    pub result_visited: &'a mut Signal<Out, ReadCount>,
    pub result_address: &'a mut Signal<Out, Addr>,
    pub result_dist: &'a mut Signal<Out, Dist>,
    pub port_a_reading: &'a mut Signal<Out, bool>,
    pub port_b_reading: &'a mut Signal<Out, bool>,
    pub all_busy: &'a mut Signal<Out, bool>,
}

/// A top-level block with `W`-bit photon words.
pub trait SearchTop<const W: usize>: Block + Sized {
    /// Elaborate the top for `cfg` (validated by the caller).
    fn elaborate(cfg: &CoreConfig) -> Self;
    /// Every port, for driving inputs and sampling outputs.
    fn ports(&mut self) -> TopPorts<'_, W>;
    /// Tree `t`'s status this cycle: port A reads, port B reads, all its
    /// QueryModules are busy (for the reads-per-cycle measurement).
    fn tree_status(&self, t: usize) -> [bool; 3];
}

/// `ports()` for a block with the top's field names.
macro_rules! top_ports {
    ($s:expr) => {
        TopPorts {
            clock: &mut $s.clock,
            reset: &mut $s.reset,
            load_valid: &mut $s.load_valid,
            load_ready: &mut $s.load_ready,
            load_address: &mut $s.load_address,
            load_word: &mut $s.load_word,
            load_last: &mut $s.load_last,
            query_valid: &mut $s.query_valid,
            query_ready: &mut $s.query_ready,
            query_id: &mut $s.query_id,
            query_x: &mut $s.query_x,
            query_y: &mut $s.query_y,
            query_z: &mut $s.query_z,
            query_radius: &mut $s.query_radius,
            query_k: &mut $s.query_k,
            result_valid: &mut $s.result_valid,
            result_ready: &mut $s.result_ready,
            result_header: &mut $s.result_header,
            result_last: &mut $s.result_last,
            result_id: &mut $s.result_id,
            result_count: &mut $s.result_count,
            result_visited: &mut $s.result_visited,
            result_address: &mut $s.result_address,
            result_dist: &mut $s.result_dist,
            port_a_reading: &mut $s.port_a_reading,
            port_b_reading: &mut $s.port_b_reading,
            all_busy: &mut $s.all_busy,
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

    fn ports(&mut self) -> TopPorts<'_, W> {
        top_ports!(self)
    }

    fn tree_status(&self, _t: usize) -> [bool; 3] {
        status(self)
    }
}

impl<const S: usize, const W: usize> SearchTop<W> for PhotonSearchArray<S, W> {
    fn elaborate(cfg: &CoreConfig) -> Self {
        PhotonSearchArray::new(cfg)
    }

    fn ports(&mut self) -> TopPorts<'_, W> {
        top_ports!(self)
    }

    fn tree_status(&self, t: usize) -> [bool; 3] {
        status(&self.trees[t])
    }
}
