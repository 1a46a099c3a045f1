pub mod host;
pub mod hw;
