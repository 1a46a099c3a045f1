//! BankStore: the banked part of one photon map (`CoreConfig::banking`): B =
//! 2^b BlockRAM banks, each a dual-port [`TreeModule`] of 2^(H−b) rows, behind a
//! [`BankCrossbar`] with one or two read ports per bank (the second recovers most
//! of what bank conflicts cost: the lab's bank model, docs/BANKING.md). A node's bank and row are the [`BankMap`]'s (XOR-fold);
//! the levels above it live in the datapaths' replicas, not here.
//!
//! Loading: a written word goes to its bank and row through port A (the core
//! loads a map only while no query is in flight, so no read competes with it).

use crate::hw::config::bank_config::BankPorts;
use crate::hw::config::core_config::{Addr, CoreConfig, Word};
use crate::hw::primitives::bank_bus::{BankAnswer, BankClient, BankIndex};
use crate::hw::primitives::block_ram::BramWord;
use crate::hw::store::bank_crossbar::BankCrossbar;
use crate::hw::store::bank_map::BankMap;
use crate::hw::store::read_issue::ReadIssue;
use crate::hw::store::tree_module::TreeModule;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct BankStore<const W: usize> {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    /// A map word to store (below the replicated levels), by heap address.
    pub write_enable: Signal<In, bool>,
    pub write_address: Signal<In, Addr>,
    pub write_word: Signal<In, Word<W>>,
    /// Per datapath: its reads and their words (none without banks).
    pub clients: Vec<BankClient>,
    pub answers: Vec<BankAnswer>,
    map: BankMap,
    /// (Without banks, [`BankCrossbar::placeholder`]: rust-hdl's `#[hdl_gen]`
    /// cannot index into an element of a `Vec`, so a crossbar is always there;
    /// synthesis removes it, nothing reading its outputs.)
    crossbar: BankCrossbar,
    /// 64-bit ports, as the crossbar's words (each only as wide as a photon word).
    banks: Vec<TreeModule<64>>,
    wide_word: Signal<Local, BramWord>,
    bank_id: Vec<Constant<BankIndex>>,
}

impl<const W: usize> BankStore<W> {
    /// The banks of `cfg` (none if it has no banking).
    pub fn new(cfg: &CoreConfig) -> Self {
        let (banks, bank_bits, levels, ports) =
            cfg.banking.map_or((0, 0, 0, BankPorts::One), |b| {
                (
                    1usize << b.bank_bits,
                    b.bank_bits,
                    b.replicated_levels,
                    b.ports,
                )
            });
        let clients = if banks > 0 { cfg.datapaths() } else { 0 };
        let tag_bits = ReadIssue::<W>::tag_bits(cfg);
        let row_bits = cfg.address_bits - bank_bits;
        BankStore {
            clock: Default::default(),
            reset: Default::default(),
            write_enable: Default::default(),
            write_address: Default::default(),
            write_word: Default::default(),
            clients: (0..clients).map(|_| Default::default()).collect(),
            answers: (0..clients).map(|_| Default::default()).collect(),
            map: BankMap::new(levels, bank_bits, cfg.address_bits, cfg.bank_mapping()),
            crossbar: if banks > 0 {
                BankCrossbar::new(
                    clients,
                    banks,
                    ports,
                    cfg.layout.word_bits(),
                    tag_bits.max(1),
                )
            } else {
                BankCrossbar::placeholder(cfg.layout.word_bits(), tag_bits.max(1))
            },
            banks: (0..banks)
                .map(|_| TreeModule::new(row_bits.max(1), cfg.layout.word_bits()))
                .collect(),
            wide_word: Default::default(),
            bank_id: (0..banks)
                .map(|j| Constant::new(BankIndex::from(j as u64)))
                .collect(),
        }
    }
}

impl<const W: usize> Logic for BankStore<W> {
    #[hdl_gen]
    fn update(&mut self) {
        self.map.address.next = self.write_address.val();
        self.wide_word.next = bit_cast::<64, W>(self.write_word.val());
        self.crossbar.clock.next = self.clock.val();
        self.crossbar.reset.next = self.reset.val();
        for i in 0..self.crossbar.clients.len() {
            self.crossbar.clients[i].valid.next = false;
            self.crossbar.clients[i].bank.next = 0.into();
            self.crossbar.clients[i].row.next = 0.into();
            self.crossbar.clients[i].tag.next = 0.into();
        }
        for j in 0..self.crossbar.banks.len() {
            self.crossbar.banks[j].word.next = 0.into();
        }
        for i in 0..self.clients.len() {
            self.crossbar.clients[i].valid.next = self.clients[i].valid.val();
            self.crossbar.clients[i].bank.next = self.clients[i].bank.val();
            self.crossbar.clients[i].row.next = self.clients[i].row.val();
            self.crossbar.clients[i].tag.next = self.clients[i].tag.val();
            self.clients[i].ready.next = self.crossbar.clients[i].ready.val();
            self.answers[i].valid.next = self.crossbar.answers[i].valid.val();
            self.answers[i].tag.next = self.crossbar.answers[i].tag.val();
            self.answers[i].word.next = self.crossbar.answers[i].word.val();
        }
        for j in 0..self.banks.len() {
            self.banks[j].clock.next = self.clock.val();
            self.banks[j].a_write_enable.next =
                self.write_enable.val() && (self.map.bank.val() == self.bank_id[j].val());
            self.banks[j].a_write_data.next = self.wide_word.val();
            if self.write_enable.val() {
                self.banks[j].a_address.next = self.map.row.val();
            } else {
                self.banks[j].a_address.next = self.crossbar.banks[j].row.val();
            }
            self.banks[j].b_address.next = 0.into();
            self.crossbar.banks[j].word.next = self.banks[j].a_read_data.val();
        }
        for j in 0..self.crossbar.second.len() {
            self.banks[j].b_address.next = self.crossbar.second[j].row.val();
            self.crossbar.second[j].word.next = self.banks[j].b_read_data.val();
        }
    }
}
