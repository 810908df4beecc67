//! A rogue process on a vehicle's services: a publisher of every input service of the
//! planner that sends whatever it is given (the fault and fuzz tests).

use wingman_interfaces::*;
use wingman_ipc::{self as ipc, InputPublishers, Ipc};

/// A publisher of every input service that sends whatever bytes it is given (a rogue
/// process on the vehicle's services).
pub struct Rogue {
    pub ports: InputPublishers,
    _node: iceoryx2::node::Node<Ipc>,
}

impl Rogue {
    pub fn new(v: &str) -> Rogue {
        let node = ipc::node(&format!("rogue-{v}"), false).unwrap();
        Rogue {
            ports: InputPublishers::open(&node, v).unwrap(),
            _node: node,
        }
    }
}

/// Sends `m` on `p` after checking it is invalid (so the expected count is exact).
pub fn send_invalid<M: Message + 'static>(
    p: &iceoryx2::port::publisher::Publisher<Ipc, M, ()>,
    m: M,
) {
    assert!(m.validate().is_err(), "meant to be invalid: {m:?}");
    p.send_copy(m).unwrap();
}
