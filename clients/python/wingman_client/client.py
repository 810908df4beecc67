"""One vehicle's services from a client's side: publishers of the planner's inputs,
subscribers of its plans and status, and the wake events (docs/INTERFACES.md,
"Writing a client")."""

import ctypes
import time

import iceoryx2 as iox2

from . import contract as c

#: The planner's input services, which a client publishes.
INPUTS = ("Tasking", "LeadRoute", "LeadState", "Threats", "Tracks", "Ownship")
#: The inputs whose publishers keep a history for a planner that joins later.
HISTORY = tuple(n for n in INPUTS if c.SETTINGS[n]["history_size"] > 0)


class PlannerTimeout(RuntimeError):
    """The planner did not echo the last input in time."""


def _copy(sample, message_type):
    """A copy of a received sample's payload (the sample goes back to the publisher)."""
    value = message_type()
    ctypes.memmove(ctypes.byref(value), sample.payload_ptr, ctypes.sizeof(message_type))
    sample.delete()
    return value


class Client:
    """The services of `vehicle_id`, opened or created with the contract's settings (either
    side may start first; `create=False`: opened only, they must exist). Inputs carry this
    sender's id and one sequence counter across all input services."""

    def __init__(self, vehicle_id: str, sender_id: int = c.SENDER_HARNESS, create: bool = True):
        iox2.set_log_level_from_env_or(iox2.LogLevel.Error)
        self.vehicle_id = vehicle_id
        self.sender_id = sender_id
        self.create = create
        self.sequence = 0
        self.node = iox2.NodeBuilder.new().create(iox2.ServiceType.Ipc)
        self.publishers = {
            name: self._pubsub(name).publisher_builder().max_loaned_samples(1).create()
            for name in INPUTS
        }
        self._plans = self._subscriber("Plan")
        self._status = self._subscriber("Status")
        self._wake = (
            self._event("PlannerWake")
            .notifier_builder()
            .default_event_id(iox2.EventId.new(c.WAKE_INPUT))
            .create()
        )
        self._woken = self._event("HarnessWake").listener_builder().create()
        #: The newest `PlannerStatus` received (None before the first).
        self.status = None
        #: Every `Plan` received, oldest first.
        self.plans = []

    def _name(self, service: str):
        return iox2.ServiceName.new(f"wingman/{self.vehicle_id}/{c.SERVICES[service]}")

    def _pubsub(self, service: str):
        s = c.SETTINGS[service]
        builder = (
            self.node.service_builder(self._name(service))
            .publish_subscribe(c.MESSAGES[service])
            .enable_safe_overflow(True)
            .history_size(s["history_size"])
            .subscriber_max_buffer_size(s["subscriber_max_buffer_size"])
            .max_publishers(s["max_publishers"])
            .max_subscribers(s["max_subscribers"])
            .max_nodes(s["max_nodes"])
        )
        return builder.open_or_create() if self.create else builder.open()

    def _subscriber(self, service: str):
        s = c.SETTINGS[service]
        return (
            self._pubsub(service)
            .subscriber_builder()
            .buffer_size(s["subscriber_max_buffer_size"])
            .history_request(s["history_size"])
            .create()
        )

    def _event(self, service: str):
        s = c.SETTINGS[service]
        builder = (
            self.node.service_builder(self._name(service))
            .event()
            .max_notifiers(s["max_notifiers"])
            .max_listeners(s["max_listeners"])
            .max_nodes(s["max_nodes"])
        )
        return builder.open_or_create() if self.create else builder.open()

    @classmethod
    def connect(cls, vehicle_id: str, timeout_s: float = 30.0, **kwargs) -> "Client":
        """A client of services that another process (the planner) creates: waits until they
        exist, then opens them (never creates them)."""
        deadline = time.monotonic() + timeout_s
        while True:
            try:
                return cls(vehicle_id, create=False, **kwargs)
            except (iox2.PublishSubscribeOpenError, iox2.EventOpenError):
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.05)

    def publish(self, service: str, message, mission_time_s: float) -> int:
        """Stamps `message`'s header (this sender, the next sequence, the mission time) and
        publishes it on `service`; returns its sequence. Call `notify` (or `sync`) after."""
        self.sequence += 1
        message.header = c.Header(
            c.PROTOCOL_VERSION, self.sender_id, self.sequence, round(mission_time_s * 1e9)
        )
        self.publishers[service].send_copy(message)
        return self.sequence

    def notify(self) -> None:
        """Hands the history services' samples to subscribers that joined since (a planner
        started or restarted after them), then wakes the planner (`WAKE_INPUT`)."""
        for name in HISTORY:
            self.publishers[name].update_connections()
        self._wake.notify()

    def poll(self) -> list:
        """Takes the plans and status that arrived; returns the new plans."""
        # The status first: the planner publishes a plan before the status that follows
        # it, so plans read after a status include every plan that status counts.
        while (sample := self._status.receive()) is not None:
            first = self.status is None
            self.status = _copy(sample, c.PlannerStatus)
            if first:
                # A planner that already served this sender id (an earlier run of this
                # client) refuses a sequence that does not grow: number on above the
                # highest it accepted, as a restarted harness does.
                self.sequence = max(self.sequence, self.status.last_input_sequence)
        new = []
        while (sample := self._plans.receive()) is not None:
            new.append(_copy(sample, c.Plan))
        self.plans.extend(new)
        return new

    def sync(self, timeout_s: float = 60.0) -> list:
        """Lock-step barrier: notifies the planner and waits until its status echoes this
        client's last sequence and it is not planning. Returns the plans that came. The
        planner echoes only accepted messages: after one it rejects (`messages_rejected`
        grows), wait with `wait_for` on that count instead."""
        rejected = None if self.status is None else self.status.messages_rejected
        self.notify()
        new = []
        deadline = time.monotonic() + timeout_s
        while True:
            new.extend(self.poll())
            s = self.status
            if (
                s is not None
                and s.last_input_sequence >= self.sequence
                and s.state != c.PLANNER_STATE_PLANNING
            ):
                return new
            if time.monotonic() > deadline:
                raise PlannerTimeout(
                    f"no echo of sequence {self.sequence} within {timeout_s} s "
                    f"(last status: {None if s is None else s.last_input_sequence}; "
                    f"messages rejected {rejected} before the barrier, "
                    f"{None if s is None else s.messages_rejected} now)"
                )
            self._wait()

    def wait_for(self, predicate, timeout_s: float = 60.0):
        """Notifies the planner and waits until `predicate(status)` holds (for a message the
        echo does not cover: one whose header the planner cannot read). Returns the status."""
        self.notify()
        deadline = time.monotonic() + timeout_s
        while True:
            self.poll()
            if self.status is not None and predicate(self.status):
                return self.status
            if time.monotonic() > deadline:
                raise PlannerTimeout(f"the planner's status did not change within {timeout_s} s")
            self._wait()

    def _wait(self) -> None:
        """Waits up to 100 ms for `wake/harness` (a signal's interruption is a wake-up)."""
        try:
            self._woken.timed_wait(iox2.Duration.from_millis(100))
        except iox2.ListenerWaitError:
            pass

    def wait_for_status(self, timeout_s: float = 30.0):
        """Waits for the planner's first heartbeat; returns it."""
        deadline = time.monotonic() + timeout_s
        while self.status is None:
            self.poll()
            if time.monotonic() > deadline:
                raise PlannerTimeout(f"no status from the planner within {timeout_s} s")
            time.sleep(0.05)
        return self.status
