//! ControllerPort: the controller of one TreeModule port, whichever the
//! configuration asks for — a [`SearchPort`] (Q QueryModules, the paper's §4.5) or
//! a [`BarrelPort`] (Q slots behind one datapath, `Controller::Barrel`). Both have
//! the same outer ports ([`PortIo`]), so this block links the one that exists to
//! its own `io` and the core wires every port the same way, whatever the
//! controller.

use crate::hw::barrel::barrel_port::BarrelPort;
use crate::hw::config::controller::Controller;
use crate::hw::config::core_config::CoreConfig;
use crate::hw::modules::search_port::SearchPort;
use crate::hw::primitives::stream::PortIo;
use rust_hdl::prelude::*;

#[derive(LogicBlock)]
pub struct ControllerPort<const S: usize, const W: usize> {
    pub clock: Signal<In, Clock>,
    pub reset: Signal<In, bool>,
    pub io: PortIo<W>,
    /// One of the two is built (one element), the other is empty.
    modules: Vec<SearchPort<S, W>>,
    barrel: Vec<BarrelPort<W>>,
}

impl<const S: usize, const W: usize> ControllerPort<S, W> {
    pub fn new(cfg: &CoreConfig) -> Self {
        let barrel = cfg.controller == Controller::Barrel;
        ControllerPort {
            clock: Default::default(),
            reset: Default::default(),
            io: Default::default(),
            modules: (0..!barrel as usize)
                .map(|_| SearchPort::new(cfg))
                .collect(),
            barrel: (0..barrel as usize).map(|_| BarrelPort::new(cfg)).collect(),
        }
    }
}

impl<const S: usize, const W: usize> Logic for ControllerPort<S, W> {
    #[hdl_gen]
    fn update(&mut self) {
        for i in 0..self.modules.len() {
            self.modules[i].clock.next = self.clock.val();
            self.modules[i].reset.next = self.reset.val();
            PortIo::<W>::link(&mut self.io, &mut self.modules[i].io);
        }
        for i in 0..self.barrel.len() {
            self.barrel[i].clock.next = self.clock.val();
            self.barrel[i].reset.next = self.reset.val();
            PortIo::<W>::link(&mut self.io, &mut self.barrel[i].io);
        }
    }
}
