//! The photon map (paper §2.2, §4.1): quantization onto the hardware's grid, the
//! left-balanced kd-tree and its packed words, and the software kNN search that is
//! the reference for every hardware gather (plus kiddo as the CPU yardstick).

pub mod kdtree;
pub mod knn;
pub mod quantize;
pub mod scalar;
