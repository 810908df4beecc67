//! A client's side of one vehicle's services: what the harness, the tests and any other
//! Rust client of the planner open, in one place and one order.

use iceoryx2::node::Node;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::UpdateConnections;
use wingman_interfaces::{
    LeadRoute, LeadState, OwnshipState, Plan, PlannerStatus, Service, Tasking, ThreatReport,
    TrackFix,
};

use crate::{Ipc, IpcError, WAKE_INPUT, listener, notifier, open_event, open_publish_subscribe};
use crate::{publisher, subscriber};

/// A publisher of every input service of the planner.
pub struct InputPublishers {
    pub tasking: Publisher<Ipc, Tasking, ()>,
    pub route: Publisher<Ipc, LeadRoute, ()>,
    pub lead_state: Publisher<Ipc, LeadState, ()>,
    pub threats: Publisher<Ipc, ThreatReport, ()>,
    pub tracks: Publisher<Ipc, TrackFix, ()>,
    pub ownship: Publisher<Ipc, OwnshipState, ()>,
}

impl InputPublishers {
    /// Opens the input services of `vehicle_id` on `node` and a publisher of each.
    pub fn open(node: &Node<Ipc>, vehicle_id: &str) -> Result<InputPublishers, IpcError> {
        let v = vehicle_id;
        Ok(InputPublishers {
            tasking: publisher(&open_publish_subscribe(node, v)?)?,
            route: publisher(&open_publish_subscribe(node, v)?)?,
            lead_state: publisher(&open_publish_subscribe(node, v)?)?,
            threats: publisher(&open_publish_subscribe(node, v)?)?,
            tracks: publisher(&open_publish_subscribe(node, v)?)?,
            ownship: publisher(&open_publish_subscribe(node, v)?)?,
        })
    }

    /// Hands each publisher's history to subscribers that joined since (a restarted
    /// planner gets the tasking, route and threats this way).
    pub fn update_connections(&self) {
        let _ = self.tasking.update_connections();
        let _ = self.route.update_connections();
        let _ = self.lead_state.update_connections();
        let _ = self.threats.update_connections();
        let _ = self.tracks.update_connections();
        let _ = self.ownship.update_connections();
    }
}

/// A client's ports: the input publishers, subscribers of the planner's `plan` and
/// `status`, a notifier of `wake/planner` (with [`WAKE_INPUT`]) and a listener of
/// `wake/harness`.
pub struct ClientPorts {
    pub inputs: InputPublishers,
    pub plan: Subscriber<Ipc, Plan, ()>,
    pub status: Subscriber<Ipc, PlannerStatus, ()>,
    pub wake: Notifier<Ipc>,
    pub listener: Listener<Ipc>,
}

impl ClientPorts {
    /// Opens every service of `vehicle_id` a client uses, on `node`.
    pub fn open(node: &Node<Ipc>, vehicle_id: &str) -> Result<ClientPorts, IpcError> {
        let v = vehicle_id;
        Ok(ClientPorts {
            inputs: InputPublishers::open(node, v)?,
            plan: subscriber(&open_publish_subscribe(node, v)?)?,
            status: subscriber(&open_publish_subscribe(node, v)?)?,
            wake: notifier(&open_event(node, v, Service::PlannerWake)?, WAKE_INPUT)?,
            listener: listener(&open_event(node, v, Service::HarnessWake)?)?,
        })
    }

    /// Takes up new publishers of `plan` and `status` (a restarted planner's).
    pub fn update_subscriptions(&self) {
        let _ = self.plan.update_connections();
        let _ = self.status.update_connections();
    }
}
