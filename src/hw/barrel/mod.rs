//! The barrel controller (`--controller barrel`): a port's Q queries as slots in
//! LUT-RAM and BlockRAM behind one pipelined datapath, a read every cycle while any
//! slot can issue (the paper's §4.5 goal without Q copies of the QueryModule).
//! `store::read_issue` sends a slot's read to the replica or a bank, and parks it
//! while its bank is busy; found lists of K ≤ 64 sit under a comparator tree (`FoundMax`, the
//! §4.4 maximum), deeper ones (to 512, §3's 500 neighbours) in per-slot max-heaps
//! (`FoundHeap`, `HeapStage`); `Ascent` keeps the pruning bounds of the path
//! (with external memory written a stage later, `PathWrite`).

pub mod ascent;
pub mod barrel_port;
pub mod found_heap;
pub mod found_max;
pub mod heap_stage;
pub mod path_write;
pub mod slot_readout;
pub mod slot_store;
