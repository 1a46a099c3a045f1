//! FoundRule against knn.rs's found-list step written out afresh: for every
//! count, k and full flag (and random entry names), where the photon goes and
//! whether the list fills or needs a new maximum.

use photon_fpga::hw::config::core_config::CoreConfig;
use photon_fpga::hw::datapath::found_rule::FoundRule;
use rand::Rng;
use rust_hdl::prelude::*;

use crate::common::{rng, settle};

#[test]
fn insertion_follows_the_found_list() {
    let mut r = rng(21);
    for k_max in [1usize, 10, 32, 64] {
        let cfg = CoreConfig {
            k: k_max,
            ..CoreConfig::paper()
        };
        let mut uut = FoundRule::<Bits<8>>::new(&cfg);
        uut.connect_all();
        check_all(&uut).unwrap();
        for k in 1..=k_max as u64 {
            for count in 0..=k {
                // Only a full list is at count = k; a list below k is not full.
                for full in [false, true] {
                    if full != (count == k) {
                        continue;
                    }
                    for insert in [false, true] {
                        let (append_at, max_at) = (r.gen_range(0..64u64), r.gen_range(0..64u64));
                        uut.insert.next = insert;
                        uut.full.next = full;
                        uut.count.next = count.into();
                        uut.k.next = k.into();
                        uut.append_at.next = append_at.into();
                        uut.max_at.next = max_at.into();
                        settle(&mut uut);
                        let what = format!("k {k}, count {count}, full {full}, insert {insert}");
                        let at = if full { max_at } else { append_at };
                        assert_eq!(uut.at.val().to_u64(), at, "{what}");
                        let appends = insert && !full;
                        assert_eq!(uut.appends.val(), appends, "{what}");
                        if appends {
                            assert_eq!(uut.next_count.val().to_u64(), count + 1, "{what}");
                        }
                        let fills = appends && count + 1 == k;
                        assert_eq!(uut.fills.val(), fills, "{what}");
                        assert_eq!(uut.run_max.val(), fills || (insert && full), "{what}");
                        assert_eq!(uut.fills_next.val(), count + 2 == k, "{what}");
                    }
                }
            }
        }
    }
}
