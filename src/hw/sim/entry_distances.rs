//! The distances of a heap core's result entries, filled in by the driver.
//!
//! A core whose found lists are heaps (`CoreConfig::uses_found_heap`) sends its
//! entries' addresses with zero distances: its read-out keeps one BlockRAM word
//! of address per entry, not address and distance (`SlotReadout` says why). The
//! driver knows each query and the map it was answered on, so it computes each
//! distance as the core's DistModule does, on the grid.

use crate::hw::config::metric::Metric;
use crate::hw::config::photon_word::{PhotonLayout, TreeImage};
use crate::hw::error::HwError;

/// The map the core holds (the last one loaded): its layout and its words by
/// heap address.
#[derive(Clone, Debug, Default)]
pub struct HeldMap(Option<(PhotonLayout, Vec<u64>)>);

impl HeldMap {
    /// The core loaded `image`.
    pub fn load(&mut self, image: TreeImage<'_>) {
        self.0 = Some((image.layout, image.words.to_vec()));
    }

    /// The distance of each `(address, distance)` entry of query `id` at `coords`.
    pub fn fill(
        &self,
        metric: Metric,
        id: u32,
        coords: [u32; 3],
        found: &mut [(u32, u64)],
    ) -> Result<(), HwError> {
        let (layout, words) = self
            .0
            .as_ref()
            .ok_or_else(|| HwError::Simulation("results before any map was loaded".into()))?;
        for (addr, dist) in found {
            let word = words
                .get(*addr as usize)
                .filter(|_| *addr != 0)
                .ok_or_else(|| {
                    HwError::Simulation(format!(
                        "query {id}: result entry at address {addr}, outside the map's 1..={}",
                        words.len().saturating_sub(1)
                    ))
                })?;
            *dist = metric.dist(coords, layout.unpack(*word).0);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Squared L2 by hand, on two maps loaded in turn; a bad address is an error.
    #[test]
    fn distances_come_from_the_map_last_loaded() {
        let layout = PhotonLayout::paper();
        let first = [[0, 0, 0], [3, 4, 0], [10, 0, 7]];
        let second = [[0, 0, 0], [1, 1, 1], [2, 0, 5]];
        let words =
            |pts: &[[u32; 3]]| -> Vec<u64> { pts.iter().map(|&p| layout.pack(p, 0)).collect() };
        let (w1, w2) = (words(&first), words(&second));
        let mut held = HeldMap::default();
        let mut found = vec![(1, 0), (2, 0)];
        let e = held.fill(Metric::L2, 7, [1, 2, 3], &mut found).unwrap_err();
        assert!(e.to_string().contains("before any map"), "{e}");
        held.load(TreeImage { layout, words: &w1 });
        held.fill(Metric::L2, 7, [1, 2, 3], &mut found).unwrap();
        // (1,2,3) to (3,4,0): 4 + 4 + 9; to (10,0,7): 81 + 4 + 16.
        assert_eq!(found, vec![(1, 17), (2, 101)]);
        held.load(TreeImage { layout, words: &w2 });
        let mut found = vec![(2, 0), (1, 0)];
        held.fill(Metric::L2, 7, [1, 2, 3], &mut found).unwrap();
        // (1,2,3) to (2,0,5): 1 + 4 + 4; to (1,1,1): 0 + 1 + 4.
        assert_eq!(found, vec![(2, 9), (1, 5)]);
        // L1 on the same map: |1−2| + |2−0| + |3−5|.
        let mut found = vec![(2, 0)];
        held.fill(Metric::L1, 7, [1, 2, 3], &mut found).unwrap();
        assert_eq!(found, vec![(2, 5)]);
        for bad in [0, 3] {
            let mut found = vec![(bad, 0)];
            let e = held.fill(Metric::L2, 8, [0; 3], &mut found).unwrap_err();
            assert!(e.to_string().contains(&format!("address {bad}")), "{e}");
        }
    }
}
