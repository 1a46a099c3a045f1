//! The hardware testbenches in one test binary (one rust-hdl link instead of one
//! per file): one module per block or concern, each checked against the software
//! search, brute force or an independent model.

mod common;
mod hw_array;
mod hw_ascent;
mod hw_axis;
mod hw_bank_crossbar;
mod hw_banked;
mod hw_blocks;
mod hw_cache_bank;
mod hw_config;
mod hw_core;
mod hw_cornell;
mod hw_deep_lists;
mod hw_dispatcher;
mod hw_found_heap;
mod hw_found_rule;
mod hw_free_pick;
mod hw_line_fill;
mod hw_lut_ram;
mod hw_max_finder;
mod hw_memory_core;
mod hw_mux_trees;
mod hw_offer_queue;
mod hw_packet_merge;
mod hw_path_write;
mod hw_port;
mod hw_priority_encoder;
mod hw_query_limits;
mod hw_query_module;
mod hw_result_readout;
mod hw_result_register;
mod hw_search_module;
mod hw_slot_readout;
mod hw_slot_store;
mod hw_verilator;
mod hw_verilog;
mod hw_xsim;
