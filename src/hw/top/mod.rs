//! The core as the host sees it (§4): `PhotonSearchCore` with its load, query and
//! result valid/ready streams (`primitives::stream`), the `Dispatcher` handing queries to a port
//! with room, each port a `ControllerPort` (either controller behind one bundle),
//! `PacketMerge` putting the ports' packets onto R result streams; and
//! `PhotonSearchArray`, T whole cores side by side (§5's future work).

pub mod array;
pub mod controller_port;
pub mod core;
pub mod dispatcher;
pub mod packet_merge;
