//! BankStore: the banked part of one photon map (`CoreConfig::banking`): B =
//! 2^b BlockRAM banks, each a dual-port [`TreeModule`] of 2^(H−b) rows, behind a
//! [`BankCrossbar`] with one or two read ports per bank (the second recovers most
//! of what bank conflicts cost: the lab's bank model, docs/BANKING.md). A node's bank and row are the [`BankMap`]'s (XOR-fold);
//! the levels above it live in the datapaths' replicas, not here.
//!
//! Loading: a written word goes to its bank and row through port A (the core
//! loads a map only while no query is in flight, so no read competes with it).
//!
//! With the map in external memory (`CoreConfig::memory`) the banks are
//! [`CacheBank`]s of the levels below the replicas, read through the same
//! crossbar (its words one bit wider: the miss flag; its grants registered, so
//! `ready` comes a cycle late, `BankCrossbar::with_late_ready`), and one [`LineFill`]
//! brings their missing blocks through the `m_axi` port (one burst a block of
//! `2^s` words, one or two photon words a beat: the memory's data width), the banks' fill
//! requests taking turns (round robin); every bank sees every
//! fill's writes and keeps those of its own lines (line mod B). The requests,
//! the picks and the grants are registered ([`FillArbiter`]): the banks are spread over
//! the chip with their datapaths, and a request's arbitration, the chosen
//! block's trip across the chip and the grant's trip back each get a cycle. Nothing is
//! loaded into them: the map's image is in memory.

use crate::hw::config::bank_config::BankPorts;
use crate::hw::config::core_config::ModuleMask;
use crate::hw::config::core_config::{Addr, CoreConfig, Word};
use crate::hw::config::memory_config::MEMORY_PORT_BITS;
use crate::hw::memory::cache_bank::CacheBank;
use crate::hw::memory::cache_port::{LineShape, TagShape};
use crate::hw::memory::fill_arbiter::FillArbiter;
use crate::hw::memory::line_fill::LineFill;
use crate::hw::primitives::axi4_read::AxiReadMaster;
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
    /// With external memory: the memory's read port (none otherwise).
    pub m_axi: Vec<AxiReadMaster<MEMORY_PORT_BITS>>,
    map: BankMap,
    /// (Without banks, [`BankCrossbar::placeholder`]: rust-hdl's `#[hdl_gen]`
    /// cannot index into an element of a `Vec`, so a crossbar is always there;
    /// synthesis removes it, nothing reading its outputs.)
    crossbar: BankCrossbar,
    /// 64-bit ports, as the crossbar's words (each only as wide as a photon word).
    banks: Vec<TreeModule<64>>,
    wide_word: Signal<Local, BramWord>,
    bank_id: Vec<Constant<BankIndex>>,
    /// With external memory (empty otherwise): the cache's banks, the fill, the
    /// round robin of the banks' fill requests and each bank's bit in it.
    caches: Vec<CacheBank>,
    fill: Vec<LineFill<MEMORY_PORT_BITS>>,
    fill_turn: Vec<FillArbiter>,
    fill_asking: Vec<Signal<Local, ModuleMask>>,
    cache_bit: Vec<Constant<ModuleMask>>,
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
        // In memory the banks are the cache; a bank's answer carries a miss flag.
        let memory = cfg.memory.filter(|_| banks > 0);
        let fills = usize::from(memory.is_some());
        let (banks, caches) = if memory.is_some() {
            (0, banks)
        } else {
            (banks, 0)
        };
        let answer_bits = cfg.layout.word_bits() + fills as u32;
        BankStore {
            clock: Default::default(),
            reset: Default::default(),
            write_enable: Default::default(),
            write_address: Default::default(),
            write_word: Default::default(),
            clients: (0..clients).map(|_| Default::default()).collect(),
            answers: (0..clients).map(|_| Default::default()).collect(),
            m_axi: (0..fills).map(|_| Default::default()).collect(),
            map: BankMap::new(levels, bank_bits, cfg.address_bits, cfg.bank_mapping()),
            crossbar: if caches > 0 {
                BankCrossbar::with_late_ready(clients, caches, ports, answer_bits, tag_bits.max(1))
            } else if banks > 0 {
                BankCrossbar::new(clients, banks, ports, answer_bits, tag_bits.max(1))
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
            caches: memory
                .iter()
                .flat_map(|m| {
                    let lines = m.bank_lines(bank_bits);
                    let blocks = cfg
                        .memory_layout()
                        .expect("a validated core's layout")
                        .blocks();
                    let tags = TagShape::new(m.tags, blocks, bank_bits, lines.trailing_zeros());
                    (0..caches).map(move |j| {
                        CacheBank::new(
                            j as u32,
                            bank_bits,
                            lines as usize,
                            ports.ports(),
                            LineShape {
                                block_levels: m.block_levels,
                                word_bits: cfg.layout.word_bits(),
                                lane_shift: m.words_per_beat(W).trailing_zeros(),
                                lane_bits: W as u32,
                            },
                            tags,
                        )
                    })
                })
                .collect(),
            fill: memory
                .iter()
                .map(|m| {
                    LineFill::new(
                        0,
                        (W as u64 / 8) << m.block_levels,
                        u64::from(m.data_bits / 8),
                    )
                })
                .collect(),
            fill_turn: (0..fills).map(|_| FillArbiter::new(caches)).collect(),
            fill_asking: (0..fills).map(|_| Default::default()).collect(),
            cache_bit: (0..caches)
                .map(|j| Constant::new(ModuleMask::from(1u64 << j)))
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
        for j in 0..self.crossbar.second.len().min(self.banks.len()) {
            self.banks[j].b_address.next = self.crossbar.second[j].row.val();
            self.crossbar.second[j].word.next = self.banks[j].b_read_data.val();
        }
        // The cache: each bank read like a BlockRAM bank, every fill's writes
        // offered to every bank, one fill request a cycle with the banks in turn.
        for j in 0..self.caches.len() {
            self.caches[j].clock.next = self.clock.val();
            self.caches[j].reset.next = self.reset.val();
            self.caches[j].read.enable.next = self.crossbar.banks[j].enable.val();
            self.caches[j].read.row.next = self.crossbar.banks[j].row.val();
            self.crossbar.banks[j].word.next = self.caches[j].read.word.val();
            self.caches[j].second.enable.next = false;
            self.caches[j].second.row.next = 0.into();
            self.caches[j].fill_taken.next = false;
        }
        for j in 0..self.crossbar.second.len().min(self.caches.len()) {
            self.caches[j].second.enable.next = self.crossbar.second[j].enable.val();
            self.caches[j].second.row.next = self.crossbar.second[j].row.val();
            self.crossbar.second[j].word.next = self.caches[j].second.word.val();
        }
        for m in 0..self.fill.len() {
            self.fill[m].clock.next = self.clock.val();
            self.fill[m].reset.next = self.reset.val();
            self.fill_turn[m].clock.next = self.clock.val();
            self.fill_turn[m].reset.next = self.reset.val();
            AxiReadMaster::<MEMORY_PORT_BITS>::link(&mut self.m_axi[m], &mut self.fill[m].m_axi);
            self.fill_asking[m].next = 0.into();
            for j in 0..self.caches.len() {
                self.caches[j].write_enable.next = self.fill[m].write_enable.val();
                self.caches[j].write_index.next = self.fill[m].write_index.val();
                self.caches[j].write_data.next = self.fill[m].write_data.val();
                self.caches[j].filled_valid.next = self.fill[m].filled_valid.val();
                self.caches[j].filled_line.next = self.fill[m].filled_line.val();
                if self.caches[j].fill_valid.val() {
                    self.fill_asking[m].next = self.fill_asking[m].val() | self.cache_bit[j].val();
                }
            }
            self.fill_turn[m].requests.next = self.fill_asking[m].val();
            self.fill_turn[m].fill_ready.next = self.fill[m].fill_ready.val();
            self.fill[m].fill_valid.next = self.fill_turn[m].fill_valid.val();
            self.fill[m].fill_block.next = self.fill_turn[m].fill_block.val();
            self.fill[m].fill_line.next = self.fill_turn[m].fill_line.val();
            self.fill_turn[m].chosen_block.next = 0.into();
            self.fill_turn[m].chosen_line.next = 0.into();
            for j in 0..self.caches.len() {
                if (self.fill_turn[m].choice.val() & self.cache_bit[j].val()) != 0 {
                    self.fill_turn[m].chosen_block.next = self.caches[j].fill_block.val();
                    self.fill_turn[m].chosen_line.next = self.caches[j].fill_line.val();
                }
                self.caches[j].fill_taken.next =
                    (self.fill_turn[m].taken.val() & self.cache_bit[j].val()) != 0;
            }
        }
    }
}
