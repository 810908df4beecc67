"""The wingman planner's message contract (protocol 5), as Python ctypes.

Generated from the Rust code (`WINGMAN_BLESS=1 cargo test -p wingman-ipc --test contract`);
do not edit. Layouts are little-endian and `repr(C)` with no implicit padding;
docs/INTERFACES.md says what each field means.
"""

import ctypes

PROTOCOL_VERSION = 5
MAX_TARGETS = 8
MAX_PHASES = 9
MAX_ROUTE_POINTS = 16
MAX_ROAD_POINTS = 16
MAX_PLAN_SAMPLES = 2048
MAX_PLAN_CUTS = 64
STATE_DIM = 7
CONTROL_DIM = 2
THREAT_NAME_LEN = 24
SENDER_PLANNER = 1
SENDER_HARNESS = 2
OWNSHIP_HOLDING = 1
STALE_TASKING = 1
STALE_LEAD = 2
STALE_OWNSHIP = 4
STALE_TRACKS = 8

WAKE_INPUT = 1  # a client (the harness) notifies wake/planner after publishing inputs
WAKE_SOLVER = 2  # the planner's solve thread notifies wake/planner after a plan (internal)
WAKE_HARNESS = 3  # the planner notifies wake/harness after each plan or status

# Service name suffixes: "wingman/" + vehicle id + "/" + suffix.
SERVICES = {
    "Tasking": "tasking",
    "LeadRoute": "lead/route",
    "LeadState": "lead/state",
    "Threats": "threats",
    "Tracks": "tracks",
    "Ownship": "ownship",
    "Plan": "plan",
    "Status": "status",
    "PlannerWake": "wake/planner",
    "HarnessWake": "wake/harness",
}

# The settings iceoryx2 compares when a second process opens a service.
SETTINGS = {
    "Tasking": {"history_size": 1, "subscriber_max_buffer_size": 4, "max_publishers": 2, "max_subscribers": 4, "max_nodes": 16},
    "LeadRoute": {"history_size": 1, "subscriber_max_buffer_size": 4, "max_publishers": 2, "max_subscribers": 4, "max_nodes": 16},
    "LeadState": {"history_size": 0, "subscriber_max_buffer_size": 4, "max_publishers": 2, "max_subscribers": 4, "max_nodes": 16},
    "Threats": {"history_size": 32, "subscriber_max_buffer_size": 64, "max_publishers": 2, "max_subscribers": 4, "max_nodes": 16},
    "Tracks": {"history_size": 0, "subscriber_max_buffer_size": 32, "max_publishers": 2, "max_subscribers": 4, "max_nodes": 16},
    "Ownship": {"history_size": 0, "subscriber_max_buffer_size": 4, "max_publishers": 2, "max_subscribers": 4, "max_nodes": 16},
    "Plan": {"history_size": 1, "subscriber_max_buffer_size": 2, "max_publishers": 2, "max_subscribers": 4, "max_nodes": 16},
    "Status": {"history_size": 1, "subscriber_max_buffer_size": 4, "max_publishers": 2, "max_subscribers": 8, "max_nodes": 16},
    "PlannerWake": {"max_notifiers": 8, "max_listeners": 4, "max_nodes": 16},
    "HarnessWake": {"max_notifiers": 8, "max_listeners": 4, "max_nodes": 16},
}

# Model: Vehicle model; the wire value is the model's dimension.
MODEL_TWO_D = 2
MODEL_THREE_D = 3

# Objective: What the plan optimises and how it ends (FORMULATION.md §4).
OBJECTIVE_FIXED_TIME = 0
OBJECTIVE_MIN_TIME = 1
OBJECTIVE_MIN_TIME_RENDEZVOUS = 2

# ThreatKind: Kind of a threat report.
THREAT_KIND_STATIC = 0
THREAT_KIND_MOVING = 1

# Trigger: Why a plan was made.
TRIGGER_INITIAL = 0
TRIGGER_POP_UP = 1
TRIGGER_TASKING = 2
TRIGGER_LEAD_ROUTE = 3
TRIGGER_SCHEDULED_REPLAN = 4
TRIGGER_DEVIATION = 5
TRIGGER_EXPIRY = 6
TRIGGER_RESTART = 7
TRIGGER_REFINE = 8
TRIGGER_LEAD_OFF_ROUTE = 9

# Quality: How good a plan is.
QUALITY_OPTIMAL = 0
QUALITY_FEASIBLE = 1
QUALITY_SWARM_ONLY = 2
QUALITY_DEGRADED = 3

# PlanPath: Which path of the planner made a plan.
PLAN_PATH_GLOBAL = 0
PLAN_PATH_WARM = 1

# PlannerState: What the planner is doing.
PLANNER_STATE_IDLE = 0
PLANNER_STATE_PLANNING = 1
PLANNER_STATE_DEGRADED = 2


class Header(ctypes.Structure):
    """Starts every message. A sender's `sequence` grows by one per message it publishes, one counter across all its services, so that the planner's status can echo the last input it accepted. On each input service the planner accepts a message only if its `sequence` is greater than the one of the sender's previous accepted message there and its `mission_time_ns` (the sender's mission clock when it published) not smaller: a repeat or a step back is rejected."""

    _fields_ = [
        ("protocol_version", ctypes.c_uint32),
        ("sender_id", ctypes.c_uint32),
        ("sequence", ctypes.c_uint64),
        ("mission_time_ns", ctypes.c_int64),
    ]

    SIZE = 24
    ALIGN = 8

    @staticmethod
    def type_name() -> str:
        return "wingman::Header"


class VehicleLimits(ctypes.Structure):
    """Limits of the vehicle (FORMULATION.md §2). 2-D uses `speed_mps` and `turn_rate_max_rps`; 3-D uses the others."""

    _fields_ = [
        ("speed_mps", ctypes.c_double),
        ("turn_rate_max_rps", ctypes.c_double),
        ("gamma_max_rad", ctypes.c_double),
        ("nz_min", ctypes.c_double),
        ("nz_max", ctypes.c_double),
        ("bank_max_rad", ctypes.c_double),
        ("nz_rate_max_per_s", ctypes.c_double),
        ("bank_rate_max_rps", ctypes.c_double),
        ("altitude_min_m", ctypes.c_double),
    ]

    SIZE = 72
    ALIGN = 8

    @staticmethod
    def type_name() -> str:
        return "wingman::VehicleLimits"


class Weights(ctypes.Structure):
    """Weights of the cost (FORMULATION.md §3–4)."""

    _fields_ = [
        ("alpha", ctypes.c_double),
        ("beta", ctypes.c_double),
        ("stiffness", ctypes.c_double),
    ]

    SIZE = 24
    ALIGN = 8

    @staticmethod
    def type_name() -> str:
        return "wingman::Weights"


class PlanSample(ctypes.Structure):
    """One sample of a planned trajectory."""

    _fields_ = [
        ("t_s", ctypes.c_double),
        ("state", (ctypes.c_double * 7)),
        ("control", (ctypes.c_double * 2)),
    ]

    SIZE = 80
    ALIGN = 8

    @staticmethod
    def type_name() -> str:
        return "wingman::PlanSample"


class PlanCut(ctypes.Structure):
    """A place where the plan's compute deadline changed the course of its computation: a solve stopped after so many iterations, the swarm after so many rounds, a start not solved, a path not run. Opaque to clients (`site` names the planner's work, `step` how far it got); a replay feeds a plan's cuts back to the planner so that it takes the same course (docs/ARCHITECTURE.md, "Deadline cuts")."""

    _fields_ = [
        ("site", ctypes.c_uint32),
        ("step", ctypes.c_uint32),
    ]

    SIZE = 8
    ALIGN = 4

    @staticmethod
    def type_name() -> str:
        return "wingman::PlanCut"


class Tasking(ctypes.Structure):
    """The mission task from the lead (harness → planner). A new `revision` replaces the whole tasking. For `MinTimeRendezvous` the lead's path comes in `LeadRoute`."""

    _fields_ = [
        ("header", Header),
        ("revision", ctypes.c_uint32),
        ("model", ctypes.c_uint32),
        ("objective", ctypes.c_uint32),
        ("target_count", ctypes.c_uint32),
        ("limits", VehicleLimits),
        ("weights", Weights),
        ("start_time_s", ctypes.c_double),
        ("start_state", (ctypes.c_double * 7)),
        ("final_state", (ctypes.c_double * 7)),
        ("final_time_s", ctypes.c_double),
        ("targets_m", ((ctypes.c_double * 3) * 8)),
        ("wind_mps", (ctypes.c_double * 3)),
    ]

    SIZE = 480
    ALIGN = 8

    @staticmethod
    def type_name() -> str:
        return "wingman::Tasking"


class LeadState(ctypes.Structure):
    """The lead's state from the datalink (periodic)."""

    _fields_ = [
        ("header", Header),
        ("time_s", ctypes.c_double),
        ("position_m", (ctypes.c_double * 3)),
        ("heading_rad", ctypes.c_double),
        ("gamma_rad", ctypes.c_double),
        ("speed_mps", ctypes.c_double),
        ("route_revision", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
    ]

    SIZE = 88
    ALIGN = 8

    @staticmethod
    def type_name() -> str:
        return "wingman::LeadState"


class LeadRoute(ctypes.Structure):
    """The lead's route: it flies the polyline at constant speed, at the first point at `start_time_s`, and keeps its last heading past the last point. Re-sent whenever it changes, with a larger `revision`."""

    _fields_ = [
        ("header", Header),
        ("revision", ctypes.c_uint32),
        ("point_count", ctypes.c_uint32),
        ("start_time_s", ctypes.c_double),
        ("speed_mps", ctypes.c_double),
        ("points_m", ((ctypes.c_double * 3) * 16)),
    ]

    SIZE = 432
    ALIGN = 8

    @staticmethod
    def type_name() -> str:
        return "wingman::LeadRoute"


class ThreatReport(ctypes.Structure):
    """A threat from the onboard sensor: a static superquadric (FORMULATION.md §3) or a threat moving along a known road (§5) with the estimate of its distance along the road. Sent when the threat becomes known; the latest report per `threat_id` wins."""

    _fields_ = [
        ("header", Header),
        ("threat_id", ctypes.c_uint32),
        ("kind", ctypes.c_uint32),
        ("appeared_at_s", ctypes.c_double),
        ("name", (ctypes.c_uint8 * 24)),
        ("center_m", (ctypes.c_double * 3)),
        ("axes_m", (ctypes.c_double * 3)),
        ("exponents", (ctypes.c_double * 3)),
        ("yaw_rad", ctypes.c_double),
        ("road_point_count", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("road_m", ((ctypes.c_double * 3) * 16)),
        ("estimate_time_s", ctypes.c_double),
        ("estimate_mean", (ctypes.c_double * 3)),
        ("estimate_covariance", (ctypes.c_double * 9)),
        ("accel_sigma_mps2", ctypes.c_double),
        ("accel_tau_s", ctypes.c_double),
    ]

    SIZE = 656
    ALIGN = 8

    @staticmethod
    def type_name() -> str:
        return "wingman::ThreatReport"


class TrackFix(ctypes.Structure):
    """One measured position of a moving threat from the onboard sensor."""

    _fields_ = [
        ("header", Header),
        ("threat_id", ctypes.c_uint32),
        ("reserved", ctypes.c_uint32),
        ("time_s", ctypes.c_double),
        ("position_m", (ctypes.c_double * 3)),
        ("sigma_m", ctypes.c_double),
    ]

    SIZE = 72
    ALIGN = 8

    @staticmethod
    def type_name() -> str:
        return "wingman::TrackFix"


class OwnshipState(ctypes.Structure):
    """The wingman's state from the inner-loop tracker (periodic)."""

    _fields_ = [
        ("header", Header),
        ("time_s", ctypes.c_double),
        ("model", ctypes.c_uint32),
        ("flags", ctypes.c_uint32),
        ("plan_id", ctypes.c_uint64),
        ("state", (ctypes.c_double * 7)),
        ("control", (ctypes.c_double * 2)),
        ("cross_track_m", ctypes.c_double),
        ("along_track_m", ctypes.c_double),
        ("vertical_m", ctypes.c_double),
    ]

    SIZE = 144
    ALIGN = 8

    @staticmethod
    def type_name() -> str:
        return "wingman::OwnshipState"


class Plan(ctypes.Structure):
    """A plan for the tracker (planner → harness). The tracker flies the newest plan whose `start_time_s` has come, interpolating the samples linearly in time, until `valid_until_s`."""

    _fields_ = [
        ("header", Header),
        ("plan_id", ctypes.c_uint64),
        ("trigger", ctypes.c_uint32),
        ("quality", ctypes.c_uint32),
        ("model", ctypes.c_uint32),
        ("phase_count", ctypes.c_uint32),
        ("sample_count", ctypes.c_uint32),
        ("has_next_replan", ctypes.c_uint32),
        ("path", ctypes.c_uint32),
        ("cut_count", ctypes.c_uint32),
        ("created_at_s", ctypes.c_double),
        ("start_time_s", ctypes.c_double),
        ("valid_until_s", ctypes.c_double),
        ("cost", ctypes.c_double),
        ("final_time_s", ctypes.c_double),
        ("compute_ms", ctypes.c_double),
        ("next_replan_s", ctypes.c_double),
        ("phase_end_s", (ctypes.c_double * 9)),
        ("cuts", (PlanCut * 64)),
        ("samples", (PlanSample * 2048)),
    ]

    SIZE = 164544
    ALIGN = 8

    @staticmethod
    def type_name() -> str:
        return "wingman::Plan"


class PlannerStatus(ctypes.Structure):
    """The planner's heartbeat (periodic and after every change)."""

    _fields_ = [
        ("header", Header),
        ("state", ctypes.c_uint32),
        ("stale_inputs", ctypes.c_uint32),
        ("last_input_sequence", ctypes.c_uint64),
        ("current_plan_id", ctypes.c_uint64),
        ("messages_received", ctypes.c_uint64),
        ("messages_rejected", ctypes.c_uint64),
        ("messages_lost", ctypes.c_uint64),
        ("plans_made", ctypes.c_uint64),
        ("triggers_coalesced", ctypes.c_uint64),
        ("triggers_deferred", ctypes.c_uint64),
        ("popups_clear", ctypes.c_uint64),
        ("last_plan_compute_ms", ctypes.c_double),
        ("budget_remaining_ms", ctypes.c_double),
    ]

    SIZE = 120
    ALIGN = 8

    @staticmethod
    def type_name() -> str:
        return "wingman::PlannerStatus"


MESSAGES = {
    "Tasking": Tasking,
    "LeadRoute": LeadRoute,
    "LeadState": LeadState,
    "Threats": ThreatReport,
    "Tracks": TrackFix,
    "Ownship": OwnshipState,
    "Plan": Plan,
    "Status": PlannerStatus,
}
