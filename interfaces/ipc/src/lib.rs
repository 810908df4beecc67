//! What the planner process and the harness process (or any other client written in Rust)
//! share at run time, so that both open every service identically:
//!
//! - this module: the iceoryx2 services, their quality of service, the wake event ids, the
//!   port helpers and the dead-node clean-up;
//! - [`client`]: a client's side of a vehicle's services (the harness's, the tests');
//! - [`contract`]: the services' settings and wake ids for other languages, generated
//!   into `docs/INTERFACES.md` and `docs/contract.json`;
//! - [`config`]: the planner's configuration file, `planner.toml` (the harness writes one
//!   for every planner it starts);
//! - [`logging`]: the log set-up of both binaries.
//!
//! The iceoryx2 side of the contract: the quality
//! of service of every service in one function ([`qos`]), and the helpers that open a
//! service and create its ports with it. Whoever starts first creates a service with these
//! settings; the other opens it and iceoryx2 checks they match, so **both processes must
//! use these helpers** (the harness calls [`open_publish_subscribe`], [`publisher`],
//! [`subscriber`] and [`open_event`] too).
//!
//! History: `tasking`, `lead/route` and `threats` keep their latest samples, so a
//! restarted planner gets the world from them; `plan` keeps the latest plan for a
//! restarted tracker. A publisher delivers its history to a subscriber that joined when it
//! next sends or calls `update_connections()`: publishers of history services call it on
//! every heartbeat (the planner) or step (the harness).
//!
//! Wake-ups: the harness notifies `wake/planner` ([`WAKE_INPUT`]) after each publication
//! and the planner's solve thread notifies it ([`WAKE_SOLVER`]) after each plan; the
//! planner notifies `wake/harness` after each plan or status.

pub mod client;
pub mod config;
pub mod contract;
pub mod logging;

pub use client::{ClientPorts, InputPublishers};
pub use config::{ConfigError, ServiceConfig};

use std::time::Duration;

use iceoryx2::node::{Node, NodeBuilder, NodeState};
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::{CallbackProgression, Config, EventId, NodeName, ServiceName};
use iceoryx2::service::port_factory::{event, publish_subscribe};
use wingman_interfaces::{Message, Service, service_name};

/// The iceoryx2 service variant of the whole system (inter-process, single-threaded
/// ports).
pub type Ipc = iceoryx2::service::ipc::Service;

/// Port factory of a message's publish-subscribe service.
pub type PubSub<M> = publish_subscribe::PortFactory<Ipc, M, ()>;
/// Port factory of an event service.
pub type Event = event::PortFactory<Ipc>;

/// Event id the harness (or any input publisher) notifies `wake/planner` with.
pub const WAKE_INPUT: EventId = EventId::new(1);
/// Event id the planner's solve thread notifies `wake/planner` with after a plan.
pub const WAKE_SOLVER: EventId = EventId::new(2);
/// Event id the planner notifies `wake/harness` with after a plan or status.
pub const WAKE_HARNESS: EventId = EventId::new(3);

/// Quality of service of one service.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Qos {
    /// Samples a publisher keeps for subscribers that join later (0: none).
    pub history_size: usize,
    /// Samples a subscriber buffers; the oldest is dropped when it overflows.
    pub subscriber_buffer: usize,
    pub max_publishers: usize,
    pub max_subscribers: usize,
    pub max_nodes: usize,
}

/// The quality of service of `service`. Pub-sub services overflow safely (the oldest
/// buffered sample gives way), so a slow reader never blocks a writer; the planner counts
/// what it loses anyway (`PlannerStatus::messages_lost`). A client that publishes at most a
/// buffer's worth on a service between two notifications loses nothing.
///
/// | service | history | buffer | what matters | why |
/// |---|---:|---:|---|---|
/// | `tasking` | 1 | 4 | every one (commands) | a restarted planner gets the tasking |
/// | `lead/route` | 1 | 4 | every one | … and the lead's route |
/// | `lead/state` | 0 | 4 | the newest | periodic |
/// | `threats` | 32 | 64 | every one | every known threat (16 static + 8 moving fit); a burst of pop-ups |
/// | `tracks` | 0 | 32 | every one | fixes of up to 8 moving threats between two wake-ups |
/// | `ownship` | 0 | 4 | the newest | periodic |
/// | `plan` | 1 | 2 | a restarted tracker gets the current plan (160 KiB each) |
/// | `status` | 1 | 4 | a late subscriber gets the newest heartbeat |
pub const fn qos(service: Service) -> Qos {
    let (history_size, subscriber_buffer, max_publishers, max_subscribers) = match service {
        Service::Tasking | Service::LeadRoute => (1, 4, 2, 4),
        Service::LeadState | Service::Ownship => (0, 4, 2, 4),
        Service::Threats => (32, 64, 2, 4),
        Service::Tracks => (0, 32, 2, 4),
        // Two publishers: a restarted planner's while a crashed one's is not yet removed.
        Service::Plan => (1, 2, 2, 4),
        Service::Status => (1, 4, 2, 8),
        // Event services: notifiers and listeners.
        Service::PlannerWake | Service::HarnessWake => (0, 0, 8, 4),
    };
    Qos {
        history_size,
        subscriber_buffer,
        max_publishers,
        max_subscribers,
        max_nodes: 16,
    }
}

/// An iceoryx2 call that failed, with what was being done.
#[derive(Debug, thiserror::Error)]
#[error("{what}: {detail}")]
pub struct IpcError {
    pub what: String,
    pub detail: String,
}

fn ipc_err(what: impl Into<String>, e: impl core::fmt::Debug) -> IpcError {
    IpcError {
        what: what.into(),
        detail: format!("{e:?}"),
    }
}

/// The iceoryx2 name of a service of `vehicle_id`.
pub fn iceoryx_name(vehicle_id: &str, service: Service) -> Result<ServiceName, IpcError> {
    let name = service_name(vehicle_id, service).map_err(|e| ipc_err("service name", e))?;
    ServiceName::new(&name).map_err(|e| ipc_err(format!("service name {name}"), e))
}

/// Opens (or creates) the publish-subscribe service of message `M` with its [`qos`].
pub fn open_publish_subscribe<M: Message + 'static>(
    node: &Node<Ipc>,
    vehicle_id: &str,
) -> Result<PubSub<M>, IpcError> {
    let name = iceoryx_name(vehicle_id, M::SERVICE)?;
    let q = qos(M::SERVICE);
    node.service_builder(&name)
        .publish_subscribe::<M>()
        .enable_safe_overflow(true)
        .history_size(q.history_size)
        .subscriber_max_buffer_size(q.subscriber_buffer)
        .max_publishers(q.max_publishers)
        .max_subscribers(q.max_subscribers)
        .max_nodes(q.max_nodes)
        .open_or_create()
        .map_err(|e| ipc_err(format!("open service {}", name.as_str()), e))
}

/// A subscriber with the service's buffer, asking for its whole history.
pub fn subscriber<M: Message + 'static>(
    factory: &PubSub<M>,
) -> Result<Subscriber<Ipc, M, ()>, IpcError> {
    let q = qos(M::SERVICE);
    factory
        .subscriber_builder()
        .buffer_size(q.subscriber_buffer)
        .history_request(q.history_size)
        .create()
        .map_err(|e| ipc_err(format!("subscriber of {}", M::NAME), e))
}

/// A publisher (one loan at a time).
pub fn publisher<M: Message + 'static>(
    factory: &PubSub<M>,
) -> Result<Publisher<Ipc, M, ()>, IpcError> {
    factory
        .publisher_builder()
        .max_loaned_samples(1)
        .create()
        .map_err(|e| ipc_err(format!("publisher of {}", M::NAME), e))
}

/// Opens (or creates) an event service (`Service::PlannerWake` or `Service::HarnessWake`).
pub fn open_event(node: &Node<Ipc>, vehicle_id: &str, service: Service) -> Result<Event, IpcError> {
    let name = iceoryx_name(vehicle_id, service)?;
    let q = qos(service);
    node.service_builder(&name)
        .event()
        .max_notifiers(q.max_publishers)
        .max_listeners(q.max_subscribers)
        .max_nodes(q.max_nodes)
        .open_or_create()
        .map_err(|e| ipc_err(format!("open event service {}", name.as_str()), e))
}

/// A listener of an event service.
pub fn listener(factory: &Event) -> Result<Listener<Ipc>, IpcError> {
    factory
        .listener_builder()
        .create()
        .map_err(|e| ipc_err("listener", e))
}

/// A notifier of an event service that notifies with `id`.
pub fn notifier(factory: &Event, id: EventId) -> Result<Notifier<Ipc>, IpcError> {
    factory
        .notifier_builder()
        .default_event_id(id)
        .create()
        .map_err(|e| ipc_err("notifier", e))
}

/// A node named `name` (e.g. `wingman-planner-w1`).
pub fn node(name: &str, handle_signals: bool) -> Result<Node<Ipc>, IpcError> {
    use iceoryx2::prelude::SignalHandlingMode;
    let node_name = NodeName::new(name).map_err(|e| ipc_err(format!("node name {name}"), e))?;
    NodeBuilder::new()
        .name(&node_name)
        .signal_handling_mode(if handle_signals {
            SignalHandlingMode::HandleTerminationRequests
        } else {
            SignalHandlingMode::Disabled
        })
        .create::<Ipc>()
        .map_err(|e| ipc_err(format!("node {name}"), e))
}

/// What the dead-node clean-up did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Cleanup {
    /// Nodes whose process was gone and whose resources were removed.
    pub removed: u32,
    /// Dead nodes whose resources could not be removed (e.g. permissions).
    pub failed: u32,
}

/// Removes the iceoryx2 resources (shared memory, ports, service entries) of every node
/// whose process died without cleaning up, so a crashed predecessor cannot block this
/// process from opening its services. Uses iceoryx2's dead-node API (`Node::list`, then
/// `DeadNodeView::blocking_remove_stale_resources`).
pub fn remove_dead_nodes(timeout: Duration) -> Result<Cleanup, IpcError> {
    let mut dead = Vec::new();
    Node::<Ipc>::list(Config::global_config(), |state| {
        if let NodeState::Dead(view) = state {
            dead.push(view);
        }
        CallbackProgression::Continue
    })
    .map_err(|e| ipc_err("list iceoryx2 nodes", e))?;
    let mut report = Cleanup::default();
    for view in dead {
        match view.blocking_remove_stale_resources(timeout) {
            Ok(()) => report.removed += 1,
            Err(e) => {
                tracing::warn!(error = ?e, "cannot remove the resources of a dead iceoryx2 node");
                report.failed += 1;
            }
        }
    }
    Ok(report)
}
