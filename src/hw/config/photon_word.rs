//! `PhotonWord`: the packed photon layout shared by the host's kd-tree packing and the
//! hardware TreeModule (paper §4: 10-bit x, y, z + a 2-bit split axis = a 32-bit word).
//!
//! Layout, LSB first: `x` (`bits[0]`), `y` (`bits[1]`), `z` (`bits[2]`), then the
//! 2-bit split axis (0 = x, 1 = y, 2 = z). Each axis carries only the bits its own
//! extent needs (see `host::map::quantize`), so a flat scene packs into a narrower word.

/// Widest coordinate an axis may carry. 16 bits keeps a word within 50 bits and the
/// squared-L2 distance within 35 bits, and bounds what a user can ask of the hardware.
pub const MAX_COORD_BITS: u32 = 16;

/// Field widths of one packed photon word.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PhotonLayout {
    /// Coordinate bits of x, y and z.
    pub bits: [u32; 3],
}

impl PhotonLayout {
    /// A layout with the given per-axis coordinate widths (each 1..=`MAX_COORD_BITS`).
    pub fn new(bits: [u32; 3]) -> Self {
        assert!(
            bits.iter().all(|&b| (1..=MAX_COORD_BITS).contains(&b)),
            "coordinate widths must be 1..={MAX_COORD_BITS}, got {bits:?}"
        );
        PhotonLayout { bits }
    }

    /// The paper's layout: 10 bits on every axis, a 32-bit word.
    pub fn paper() -> Self {
        Self::new([10, 10, 10])
    }

    /// Bit offset of axis `a`'s coordinate within the word.
    pub fn offset(&self, a: usize) -> u32 {
        self.bits[..a].iter().sum()
    }

    /// Bit offset of the 2-bit split-axis field.
    pub fn axis_offset(&self) -> u32 {
        self.bits.iter().sum()
    }

    /// Total word width: the three coordinates plus the 2-bit split axis.
    pub fn word_bits(&self) -> u32 {
        self.axis_offset() + 2
    }

    /// Largest coordinate value axis `a` can hold.
    pub fn coord_max(&self, a: usize) -> u32 {
        (1u32 << self.bits[a]) - 1
    }

    /// Pack coordinates and split axis into a word. Coordinates must fit their fields.
    pub fn pack(&self, coords: [u32; 3], axis: u8) -> u64 {
        debug_assert!(axis < 3);
        let mut w = (axis as u64) << self.axis_offset();
        for (a, &c) in coords.iter().enumerate() {
            debug_assert!(c <= self.coord_max(a), "coordinate {c} overflows axis {a}");
            w |= (c as u64) << self.offset(a);
        }
        w
    }

    /// Coordinate `a` of a packed word.
    #[inline]
    pub fn coord(&self, word: u64, a: usize) -> u32 {
        ((word >> self.offset(a)) & self.coord_max(a) as u64) as u32
    }

    /// Split axis of a packed word.
    #[inline]
    pub fn axis(&self, word: u64) -> u8 {
        ((word >> self.axis_offset()) & 3) as u8
    }

    /// Unpack a word into its coordinates and split axis.
    pub fn unpack(&self, word: u64) -> ([u32; 3], u8) {
        (
            [
                self.coord(word, 0),
                self.coord(word, 1),
                self.coord(word, 2),
            ],
            self.axis(word),
        )
    }
}

/// What the core loads: the packed words of a left-balanced kd-tree in heap order
/// (`words[0]` unused, photons at addresses 1..=N) and their layout. The host's
/// packed tree lends one out; the hardware needs nothing else from the map.
#[derive(Clone, Copy, Debug)]
pub struct TreeImage<'a> {
    pub layout: PhotonLayout,
    pub words: &'a [u64],
}

impl TreeImage<'_> {
    /// Photon count N.
    pub fn len(&self) -> usize {
        self.words.len().saturating_sub(1)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Address bits H that hold addresses 1..=N.
    pub fn address_bits(&self) -> u32 {
        usize::BITS - self.len().leading_zeros()
    }
}
