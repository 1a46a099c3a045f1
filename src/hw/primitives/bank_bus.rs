//! The bank read bus (paper §4.1's BlockRAM read, spread over banks): the bundles
//! between a datapath's read issue, the bank crossbar and a bank's BlockRAM port.
//! A request names its bank, the row in the bank and a tag; the answer returns the
//! word with the tag.

use crate::hw::config::core_config::Addr;
use crate::hw::primitives::block_ram::BramWord;
use rust_hdl::prelude::*;

/// A bank's index (up to 1,024 banks), two bits to spare: a bank port's index
/// (bank × ports + port, what a requester's word is selected by) has the same type.
pub type BankIndex = Bits<12>;
/// A row in a bank (a heap address's high bits: as wide as an address, so that
/// a bank is a [`TreeModule`](crate::hw::store::tree_module::TreeModule) without casts).
pub type BankRow = Addr;
/// The tag a requester gives a read, returned with its word (e.g. the slot).
pub type BankTag = Bits<8>;

/// One requester's read requests, a valid/ready stream: the bank, the row in it
/// and the requester's tag.
#[derive(LogicInterface, Default)]
#[join = "BankRequester"]
pub struct BankClient {
    pub valid: Signal<In, bool>,
    pub ready: Signal<Out, bool>,
    pub bank: Signal<In, BankIndex>,
    pub row: Signal<In, BankRow>,
    pub tag: Signal<In, BankTag>,
}

/// The requester's side of a [`BankClient`].
#[derive(LogicInterface, Default)]
#[join = "BankClient"]
pub struct BankRequester {
    pub valid: Signal<Out, bool>,
    pub ready: Signal<In, bool>,
    pub bank: Signal<Out, BankIndex>,
    pub row: Signal<Out, BankRow>,
    pub tag: Signal<Out, BankTag>,
}

/// One requester's answers (flip-flops; no back-pressure: the barrel datapath
/// takes a read's word in the cycle it arrives): a read's word and its request's
/// tag.
#[derive(LogicInterface, Default)]
#[join = "BankAnswerIn"]
pub struct BankAnswer {
    pub valid: Signal<Out, bool>,
    pub tag: Signal<Out, BankTag>,
    pub word: Signal<Out, BramWord>,
}

/// The requester's side of a [`BankAnswer`].
#[derive(LogicInterface, Default)]
#[join = "BankAnswer"]
pub struct BankAnswerIn {
    pub valid: Signal<In, bool>,
    pub tag: Signal<In, BankTag>,
    pub word: Signal<In, BramWord>,
}

/// One bank's read port, seen from the crossbar: a BlockRAM read (`word` is the
/// row enabled in the previous cycle).
#[derive(LogicInterface, Default)]
#[join = "BankMemoryPort"]
pub struct BankPort {
    pub enable: Signal<Out, bool>,
    pub row: Signal<Out, BankRow>,
    pub word: Signal<In, BramWord>,
}

/// The memory's side of a [`BankPort`].
#[derive(LogicInterface, Default)]
#[join = "BankPort"]
pub struct BankMemoryPort {
    pub enable: Signal<In, bool>,
    pub row: Signal<In, BankRow>,
    pub word: Signal<Out, BramWord>,
}
