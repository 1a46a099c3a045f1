//! BankMap: where a kd-tree node of the banked photon store lives. The top `L`
//! levels (heap addresses below `2^L`, read by every query) are in the
//! datapath's own replica, at their address; every node below is in bank
//! `low ^ fold(high)` at row `high`, for `B = 2^b` banks, `low` the address's low
//! `b` bits and `high` the rest: the XOR-fold mapping, chosen by the measurements
//! of the lab's bank model (`photon-fpga-lab banking`, docs/BANKING.md): it
//! spreads the reads as evenly as a hash and needs no table, the row being the
//! address's high bits. [`BankMapping::Modulo`] leaves the fold out (bank = `low`),
//! to measure what the fold buys. For `2^L >= B` the
//! (bank, row) pairs of distinct addresses differ, and each bank holds
//! `(N >> b) + 1` rows. Combinational: an XOR of the address's `b`-bit groups.

use crate::hw::config::bank_config::BankMapping;
use crate::hw::config::core_config::Addr;
use crate::hw::primitives::bank_bus::{BankIndex, BankRow};
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct BankMap {
    /// A heap address (1-based).
    pub address: Signal<In, Addr>,
    /// The node is in the replica (its row there is `address`).
    pub replicated: Signal<Out, bool>,
    /// Its bank and row, for a node below the replica.
    pub bank: Signal<Out, BankIndex>,
    pub row: Signal<Out, BankRow>,
    /// `2^L`, `b`, the low-`b`-bits mask, and the shift of each further group.
    first_banked: Constant<Addr>,
    bank_bits: Constant<Addr>,
    low_mask: Constant<Addr>,
    group_shift: Vec<Constant<Addr>>,
    fold: Signal<Local, Addr>,
}

impl BankMap {
    /// `L` replicated levels (0..=24) over `2^bank_bits` banks (bank_bits 0..=10,
    /// `2^L >= 2^bank_bits`), for addresses of `address_bits` (1..=24) bits, the
    /// bank picked by `mapping`.
    pub fn new(
        replicated_levels: u32,
        bank_bits: u32,
        address_bits: u32,
        mapping: BankMapping,
    ) -> Self {
        assert!(replicated_levels <= 24 && bank_bits <= 10 && (1..=24).contains(&address_bits));
        assert!(
            bank_bits <= replicated_levels,
            "2^L >= B keeps (bank, row) unique"
        );
        let groups = match (bank_bits, mapping) {
            (0, _) => 0,
            // The low group alone.
            (_, BankMapping::Modulo) => 1,
            (b, BankMapping::Xor) => address_bits.div_ceil(b),
        };
        BankMap {
            address: Default::default(),
            replicated: Default::default(),
            bank: Default::default(),
            row: Default::default(),
            first_banked: Constant::new(Addr::from(1u64 << replicated_levels)),
            bank_bits: Constant::new(Addr::from(bank_bits as u64)),
            low_mask: Constant::new(Addr::from((1u64 << bank_bits) - 1)),
            group_shift: (1..groups)
                .map(|g| Constant::new(Addr::from((g * bank_bits) as u64)))
                .collect(),
            fold: Default::default(),
        }
    }
}

impl Logic for BankMap {
    #[hdl_gen]
    fn update(&mut self) {
        self.replicated.next = self.address.val() < self.first_banked.val();
        self.fold.next = self.address.val() & self.low_mask.val();
        for g in 0..self.group_shift.len() {
            self.fold.next = self.fold.val()
                ^ ((self.address.val() >> self.group_shift[g].val()) & self.low_mask.val());
        }
        self.bank.next = bit_cast::<12, 24>(self.fold.val());
        self.row.next = self.address.val() >> self.bank_bits.val();
    }
}
