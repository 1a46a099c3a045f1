//! The measured alternatives: every (mapping, query order, D, B, L, issue policy)
//! point run through the bank model on one image's read stream.

use super::mapping::{BankMap, Mapping};
use super::order::QueryOrder;
use super::sim::{run, Issue, Machine, Measured};
use super::stream::ImageStream;
use rayon::prelude::*;

/// The barrel port's slots and slot loop (`hw::barrel::barrel_port`: a read issued in
/// stage F returns to stage A four cycles later and reaches F again seven stages
/// on), plus the interconnect's registers (`hw::store::read_issue`: the offer, the bank
/// port's row and the answer; a read from the replica is registered alike).
pub const SLOTS: usize = 16;
pub const BARREL_LOOP: u64 = 11;
pub const INTERCONNECT_CYCLES: u64 = 3;

/// One point of the sweep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    pub mapping: Mapping,
    pub order: QueryOrder,
    pub datapaths: usize,
    pub bank_bits: u32,
    pub replicated: u32,
    pub issue: Issue,
    pub bank_ports: usize,
}

impl Point {
    pub fn machine(&self) -> Machine {
        Machine {
            datapaths: self.datapaths,
            slots: SLOTS,
            loop_cycles: BARREL_LOOP + INTERCONNECT_CYCLES,
            bank_ports: self.bank_ports,
            map: BankMap {
                mapping: self.mapping,
                bank_bits: self.bank_bits,
                replicated: self.replicated,
            },
            issue: self.issue,
        }
    }
}

/// Run every point on `stream` (in parallel); results in the points' order. The
/// query orders are computed once each.
pub fn measure(stream: &ImageStream, points: &[Point]) -> Vec<Measured> {
    let bits = stream.tree.layout.bits.into_iter().max().unwrap_or(1);
    let orders: Vec<(QueryOrder, Vec<usize>)> = QueryOrder::ALL
        .iter()
        .map(|&o| (o, o.permutation(&stream.queries, stream.width, bits)))
        .collect();
    points
        .par_iter()
        .map(|p| {
            let order = &orders.iter().find(|(o, _)| *o == p.order).unwrap().1;
            let m = run(&p.machine(), &stream.reads, order);
            assert_eq!(m.reads, stream.total_reads(), "a read lost or duplicated");
            m
        })
        .collect()
}
