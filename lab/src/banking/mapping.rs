//! Where a kd-tree node lives: the top `L` levels replicated beside every datapath
//! (read by every query: the root, then its children, ...), each node below in one
//! of `B = 2^b` banks. QuickNN (Pinkham et al., HPCA 2020) and ParallelNN keep the
//! top of the tree next to every query engine for the same reason.
//!
//! The first four mappings are bijections onto (bank, row = `addr >> b`) when
//! `2^L >= B` (every aligned group of `B` heap addresses then lies in one level),
//! so a bank's row is the address's high bits and its storage is balanced to one
//! row. `Subtree` keeps whole subtrees in one bank (its row is a permutation of
//! the address bits that depends on the node's level: a shifter).

/// A mapping of the nodes below the replicated levels onto banks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mapping {
    /// `addr mod B`: the low address bits, i.e. the last `b` branch decisions.
    Modulo,
    /// The low `b` bits XOR every other `b`-bit group of the address: all branch
    /// decisions mixed in, a tree of XOR gates in hardware.
    XorFold,
    /// `(addr + level) mod B`: each level's rows rotated by one bank.
    LevelSkew,
    /// The low `b` bits XOR a multiplicative hash of the row (Knuth's 2^32/φ).
    Hash,
    /// Whole subtrees per bank: the subtree under level `L + b` (its root's low `b`
    /// address bits); the levels between `L` and `L + b` by `Modulo`.
    Subtree,
}

impl Mapping {
    pub const ALL: [Mapping; 5] = [
        Mapping::Modulo,
        Mapping::XorFold,
        Mapping::LevelSkew,
        Mapping::Hash,
        Mapping::Subtree,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Mapping::Modulo => "addr mod B",
            Mapping::XorFold => "XOR-fold",
            Mapping::LevelSkew => "level-skewed",
            Mapping::Hash => "hash",
            Mapping::Subtree => "subtree per bank",
        }
    }
}

/// Heap level of a 1-based address (the root, 1, is level 0).
pub fn level(addr: u32) -> u32 {
    31 - addr.leading_zeros()
}

/// The replicated levels, the bank count and the mapping below them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BankMap {
    pub mapping: Mapping,
    /// `b`: `B = 2^b` banks.
    pub bank_bits: u32,
    /// `L`: levels `0..L` (addresses below `2^L`) are replicated.
    pub replicated: u32,
}

impl BankMap {
    pub fn banks(&self) -> usize {
        1 << self.bank_bits
    }

    /// The bank holding `addr` (>= 1), or `None` for a replicated node.
    pub fn bank(&self, addr: u32) -> Option<u32> {
        let lvl = level(addr);
        if lvl < self.replicated {
            return None;
        }
        let b = self.bank_bits;
        let mask = (1u32 << b) - 1;
        if b == 0 {
            return Some(0);
        }
        let (low, row) = (addr & mask, addr >> b);
        Some(match self.mapping {
            Mapping::Modulo => low,
            Mapping::XorFold => {
                let (mut x, mut r) = (low, row);
                while r != 0 {
                    x ^= r & mask;
                    r >>= b;
                }
                x
            }
            Mapping::LevelSkew => (addr.wrapping_add(lvl)) & mask,
            Mapping::Hash => low ^ (row.wrapping_mul(0x9E37_79B1) >> (32 - b)),
            Mapping::Subtree => {
                let top = self.replicated + b;
                if lvl < top {
                    low
                } else {
                    (addr >> (lvl - top)) & mask
                }
            }
        })
    }

    /// Nodes per bank for a tree of `n` photons (addresses `1..=n`).
    pub fn occupancy(&self, n: usize) -> Vec<u64> {
        let mut occ = vec![0u64; self.banks()];
        for a in 1..=n as u32 {
            if let Some(b) = self.bank(a) {
                occ[b as usize] += 1;
            }
        }
        occ
    }
}
