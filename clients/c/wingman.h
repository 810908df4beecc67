/* wingman.h: the wingman planner's message contract for C and C++ (protocol 5).
 * Generated from the Rust code (`WINGMAN_BLESS=1 cargo test -p wingman-ipc --test
 * contract`); do not edit. Layouts are little-endian, `#[repr(C)]`, with no implicit
 * padding; docs/INTERFACES.md says what each field means. */
#ifndef WINGMAN_H
#define WINGMAN_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
#define WINGMAN_STATIC_ASSERT(c, m) static_assert(c, m)
#define WINGMAN_ALIGNOF(t) alignof(t)
#else
#define WINGMAN_STATIC_ASSERT(c, m) _Static_assert(c, m)
#define WINGMAN_ALIGNOF(t) _Alignof(t)
#endif

/* Constants */
#define WINGMAN_PROTOCOL_VERSION 5
#define WINGMAN_MAX_TARGETS 8
#define WINGMAN_MAX_PHASES 9
#define WINGMAN_MAX_ROUTE_POINTS 16
#define WINGMAN_MAX_ROAD_POINTS 16
#define WINGMAN_MAX_PLAN_SAMPLES 2048
#define WINGMAN_MAX_PLAN_CUTS 64
#define WINGMAN_STATE_DIM 7
#define WINGMAN_CONTROL_DIM 2
#define WINGMAN_THREAT_NAME_LEN 24
#define WINGMAN_SENDER_PLANNER 1
#define WINGMAN_SENDER_HARNESS 2
#define WINGMAN_OWNSHIP_HOLDING 1
#define WINGMAN_STALE_TASKING 1
#define WINGMAN_STALE_LEAD 2
#define WINGMAN_STALE_OWNSHIP 4
#define WINGMAN_STALE_TRACKS 8

/* Wake event ids */
#define WINGMAN_WAKE_INPUT 1 /* a client (the harness) notifies wake/planner after publishing inputs */
#define WINGMAN_WAKE_SOLVER 2 /* the planner's solve thread notifies wake/planner after a plan (internal) */
#define WINGMAN_WAKE_HARNESS 3 /* the planner notifies wake/harness after each plan or status */

/* Service names: "wingman/" <vehicle id> "/" suffix */
#define WINGMAN_SERVICE_TASKING "tasking"
#define WINGMAN_SERVICE_LEAD_ROUTE "lead/route"
#define WINGMAN_SERVICE_LEAD_STATE "lead/state"
#define WINGMAN_SERVICE_THREATS "threats"
#define WINGMAN_SERVICE_TRACKS "tracks"
#define WINGMAN_SERVICE_OWNSHIP "ownship"
#define WINGMAN_SERVICE_PLAN "plan"
#define WINGMAN_SERVICE_STATUS "status"
#define WINGMAN_SERVICE_PLANNER_WAKE "wake/planner"
#define WINGMAN_SERVICE_HARNESS_WAKE "wake/harness"

/* Enum values (u32 fields) */
#define WINGMAN_MODEL_TWO_D 2
#define WINGMAN_MODEL_THREE_D 3
#define WINGMAN_OBJECTIVE_FIXED_TIME 0
#define WINGMAN_OBJECTIVE_MIN_TIME 1
#define WINGMAN_OBJECTIVE_MIN_TIME_RENDEZVOUS 2
#define WINGMAN_THREAT_KIND_STATIC 0
#define WINGMAN_THREAT_KIND_MOVING 1
#define WINGMAN_TRIGGER_INITIAL 0
#define WINGMAN_TRIGGER_POP_UP 1
#define WINGMAN_TRIGGER_TASKING 2
#define WINGMAN_TRIGGER_LEAD_ROUTE 3
#define WINGMAN_TRIGGER_SCHEDULED_REPLAN 4
#define WINGMAN_TRIGGER_DEVIATION 5
#define WINGMAN_TRIGGER_EXPIRY 6
#define WINGMAN_TRIGGER_RESTART 7
#define WINGMAN_TRIGGER_REFINE 8
#define WINGMAN_TRIGGER_LEAD_OFF_ROUTE 9
#define WINGMAN_QUALITY_OPTIMAL 0
#define WINGMAN_QUALITY_FEASIBLE 1
#define WINGMAN_QUALITY_SWARM_ONLY 2
#define WINGMAN_QUALITY_DEGRADED 3
#define WINGMAN_PLAN_PATH_GLOBAL 0
#define WINGMAN_PLAN_PATH_WARM 1
#define WINGMAN_PLANNER_STATE_IDLE 0
#define WINGMAN_PLANNER_STATE_PLANNING 1
#define WINGMAN_PLANNER_STATE_DEGRADED 2

/* Structs inside messages */

/* Starts every message. A sender's `sequence` grows by one per message it publishes, one counter across all its services, so that the planner's status can echo the last input it accepted. On each input service the planner accepts a message only if its `sequence` is greater than the one of the sender's previous accepted message there and its `mission_time_ns` (the sender's mission clock when it published) not smaller: a repeat or a step back is rejected. */
typedef struct wingman_Header {
    uint32_t protocol_version; /* `PROTOCOL_VERSION` of the sender. */
    uint32_t sender_id; /* Who sent it: 1 planner, 2 harness, other values for test tools. */
    uint64_t sequence; /* The sender's message counter, one across all its services, starting at 1. */
    int64_t mission_time_ns; /* Mission time at publication. [ns] */
#ifdef __cplusplus
    static constexpr const char *IOX2_TYPE_NAME = "wingman::Header";
#endif
} wingman_Header;
#define WINGMAN_HEADER_TYPE_NAME "wingman::Header"
WINGMAN_STATIC_ASSERT(sizeof(wingman_Header) == 24, "size of wingman_Header");
WINGMAN_STATIC_ASSERT(WINGMAN_ALIGNOF(wingman_Header) == 8, "alignment of wingman_Header");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Header, protocol_version) == 0, "offset of wingman_Header.protocol_version");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Header, sender_id) == 4, "offset of wingman_Header.sender_id");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Header, sequence) == 8, "offset of wingman_Header.sequence");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Header, mission_time_ns) == 16, "offset of wingman_Header.mission_time_ns");

/* Limits of the vehicle (FORMULATION.md §2). 2-D uses `speed_mps` and `turn_rate_max_rps`; 3-D uses the others. */
typedef struct wingman_VehicleLimits {
    double speed_mps; /* Constant airspeed V. [m/s] */
    double turn_rate_max_rps; /* 2-D: bound on |u| = |psi'|. [rad/s] */
    double gamma_max_rad; /* 3-D: bound on |gamma|. [rad] */
    double nz_min; /* 3-D: lower bound on the load factor Nz. [g] */
    double nz_max; /* 3-D: upper bound on Nz. [g] */
    double bank_max_rad; /* 3-D: bound on |mu|. [rad] */
    double nz_rate_max_per_s; /* 3-D: bound on |u1| = |Nz'|. [1/s] */
    double bank_rate_max_rps; /* 3-D: bound on |u2| = |mu'|. [rad/s] */
    double altitude_min_m; /* 3-D: lowest altitude z. [m] */
#ifdef __cplusplus
    static constexpr const char *IOX2_TYPE_NAME = "wingman::VehicleLimits";
#endif
} wingman_VehicleLimits;
#define WINGMAN_VEHICLE_LIMITS_TYPE_NAME "wingman::VehicleLimits"
WINGMAN_STATIC_ASSERT(sizeof(wingman_VehicleLimits) == 72, "size of wingman_VehicleLimits");
WINGMAN_STATIC_ASSERT(WINGMAN_ALIGNOF(wingman_VehicleLimits) == 8, "alignment of wingman_VehicleLimits");
WINGMAN_STATIC_ASSERT(offsetof(wingman_VehicleLimits, speed_mps) == 0, "offset of wingman_VehicleLimits.speed_mps");
WINGMAN_STATIC_ASSERT(offsetof(wingman_VehicleLimits, turn_rate_max_rps) == 8, "offset of wingman_VehicleLimits.turn_rate_max_rps");
WINGMAN_STATIC_ASSERT(offsetof(wingman_VehicleLimits, gamma_max_rad) == 16, "offset of wingman_VehicleLimits.gamma_max_rad");
WINGMAN_STATIC_ASSERT(offsetof(wingman_VehicleLimits, nz_min) == 24, "offset of wingman_VehicleLimits.nz_min");
WINGMAN_STATIC_ASSERT(offsetof(wingman_VehicleLimits, nz_max) == 32, "offset of wingman_VehicleLimits.nz_max");
WINGMAN_STATIC_ASSERT(offsetof(wingman_VehicleLimits, bank_max_rad) == 40, "offset of wingman_VehicleLimits.bank_max_rad");
WINGMAN_STATIC_ASSERT(offsetof(wingman_VehicleLimits, nz_rate_max_per_s) == 48, "offset of wingman_VehicleLimits.nz_rate_max_per_s");
WINGMAN_STATIC_ASSERT(offsetof(wingman_VehicleLimits, bank_rate_max_rps) == 56, "offset of wingman_VehicleLimits.bank_rate_max_rps");
WINGMAN_STATIC_ASSERT(offsetof(wingman_VehicleLimits, altitude_min_m) == 64, "offset of wingman_VehicleLimits.altitude_min_m");

/* Weights of the cost (FORMULATION.md §3–4). */
typedef struct wingman_Weights {
    double alpha; /* Time against running cost, in [0, 1]. */
    double beta; /* Exposure against control effort, in [0, 1]. */
    double stiffness; /* Stiffness s of the exposure sigmoid, > 0. */
#ifdef __cplusplus
    static constexpr const char *IOX2_TYPE_NAME = "wingman::Weights";
#endif
} wingman_Weights;
#define WINGMAN_WEIGHTS_TYPE_NAME "wingman::Weights"
WINGMAN_STATIC_ASSERT(sizeof(wingman_Weights) == 24, "size of wingman_Weights");
WINGMAN_STATIC_ASSERT(WINGMAN_ALIGNOF(wingman_Weights) == 8, "alignment of wingman_Weights");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Weights, alpha) == 0, "offset of wingman_Weights.alpha");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Weights, beta) == 8, "offset of wingman_Weights.beta");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Weights, stiffness) == 16, "offset of wingman_Weights.stiffness");

/* One sample of a planned trajectory. */
typedef struct wingman_PlanSample {
    double t_s; /* Mission time. [s] */
    double state[7]; /* State (model order, zero-padded). [m, rad, g] */
    double control[2]; /* Control (model order, zero-padded). [rad/s, 1/s] */
#ifdef __cplusplus
    static constexpr const char *IOX2_TYPE_NAME = "wingman::PlanSample";
#endif
} wingman_PlanSample;
#define WINGMAN_PLAN_SAMPLE_TYPE_NAME "wingman::PlanSample"
WINGMAN_STATIC_ASSERT(sizeof(wingman_PlanSample) == 80, "size of wingman_PlanSample");
WINGMAN_STATIC_ASSERT(WINGMAN_ALIGNOF(wingman_PlanSample) == 8, "alignment of wingman_PlanSample");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlanSample, t_s) == 0, "offset of wingman_PlanSample.t_s");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlanSample, state) == 8, "offset of wingman_PlanSample.state");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlanSample, control) == 64, "offset of wingman_PlanSample.control");

/* A place where the plan's compute deadline changed the course of its computation: a solve stopped after so many iterations, the swarm after so many rounds, a start not solved, a path not run. Opaque to clients (`site` names the planner's work, `step` how far it got); a replay feeds a plan's cuts back to the planner so that it takes the same course (docs/ARCHITECTURE.md, "Deadline cuts"). */
typedef struct wingman_PlanCut {
    uint32_t site; /* The work that was cut. [code] */
    uint32_t step; /* How far it got when it was cut. */
#ifdef __cplusplus
    static constexpr const char *IOX2_TYPE_NAME = "wingman::PlanCut";
#endif
} wingman_PlanCut;
#define WINGMAN_PLAN_CUT_TYPE_NAME "wingman::PlanCut"
WINGMAN_STATIC_ASSERT(sizeof(wingman_PlanCut) == 8, "size of wingman_PlanCut");
WINGMAN_STATIC_ASSERT(WINGMAN_ALIGNOF(wingman_PlanCut) == 4, "alignment of wingman_PlanCut");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlanCut, site) == 0, "offset of wingman_PlanCut.site");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlanCut, step) == 4, "offset of wingman_PlanCut.step");

/* Messages */

/* The mission task from the lead (harness → planner). A new `revision` replaces the whole tasking. For `MinTimeRendezvous` the lead's path comes in `LeadRoute`. */
typedef struct wingman_Tasking {
    wingman_Header header; /* Common header. */
    uint32_t revision; /* Grows with every change of tasking; starts at 1. */
    uint32_t model; /* `Model` value (2 or 3). [enum] */
    uint32_t objective; /* `Objective` value. [enum] */
    uint32_t target_count; /* Number of valid entries in `targets_m`. */
    wingman_VehicleLimits limits; /* Vehicle limits. */
    wingman_Weights weights; /* Cost weights. */
    double start_time_s; /* Mission time of `start_state`. [s] */
    double start_state[7]; /* State at `start_time_s` (model order, zero-padded): the first plan starts here. [m, rad, g] */
    double final_state[7]; /* Final state for `FixedTime` and `MinTime` (model order, zero-padded); zeros for a rendezvous. [m, rad, g] */
    double final_time_s; /* Fixed final time for `FixedTime`; 0 otherwise. [s] */
    double targets_m[8][3]; /* Intermediate targets in order, `[x, y, z]` (z = 0 in 2-D); `target_count` valid. [m] */
    double wind_mps[3]; /* The steady wind to plan in, `[x, y, z]` (the air mass's velocity; z = 0 in 2-D; zeros: still air). Slower than `limits.speed_mps`. [m/s] */
#ifdef __cplusplus
    static constexpr const char *IOX2_TYPE_NAME = "wingman::Tasking";
#endif
} wingman_Tasking;
#define WINGMAN_TASKING_TYPE_NAME "wingman::Tasking"
WINGMAN_STATIC_ASSERT(sizeof(wingman_Tasking) == 480, "size of wingman_Tasking");
WINGMAN_STATIC_ASSERT(WINGMAN_ALIGNOF(wingman_Tasking) == 8, "alignment of wingman_Tasking");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Tasking, header) == 0, "offset of wingman_Tasking.header");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Tasking, revision) == 24, "offset of wingman_Tasking.revision");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Tasking, model) == 28, "offset of wingman_Tasking.model");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Tasking, objective) == 32, "offset of wingman_Tasking.objective");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Tasking, target_count) == 36, "offset of wingman_Tasking.target_count");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Tasking, limits) == 40, "offset of wingman_Tasking.limits");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Tasking, weights) == 112, "offset of wingman_Tasking.weights");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Tasking, start_time_s) == 136, "offset of wingman_Tasking.start_time_s");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Tasking, start_state) == 144, "offset of wingman_Tasking.start_state");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Tasking, final_state) == 200, "offset of wingman_Tasking.final_state");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Tasking, final_time_s) == 256, "offset of wingman_Tasking.final_time_s");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Tasking, targets_m) == 264, "offset of wingman_Tasking.targets_m");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Tasking, wind_mps) == 456, "offset of wingman_Tasking.wind_mps");

/* The lead's state from the datalink (periodic). */
typedef struct wingman_LeadState {
    wingman_Header header; /* Common header. */
    double time_s; /* Mission time of the state. [s] */
    double position_m[3]; /* Position `[x, y, z]` (z = 0 in 2-D). [m] */
    double heading_rad; /* Heading chi (psi in 2-D), counter-clockwise from +x. [rad] */
    double gamma_rad; /* Flight-path angle gamma (0 in 2-D). [rad] */
    double speed_mps; /* Ground speed of the lead. [m/s] */
    uint32_t route_revision; /* `revision` of the `LeadRoute` the lead is flying. */
    uint32_t reserved; /* Zero; keeps the next field 8-byte aligned. */
#ifdef __cplusplus
    static constexpr const char *IOX2_TYPE_NAME = "wingman::LeadState";
#endif
} wingman_LeadState;
#define WINGMAN_LEAD_STATE_TYPE_NAME "wingman::LeadState"
WINGMAN_STATIC_ASSERT(sizeof(wingman_LeadState) == 88, "size of wingman_LeadState");
WINGMAN_STATIC_ASSERT(WINGMAN_ALIGNOF(wingman_LeadState) == 8, "alignment of wingman_LeadState");
WINGMAN_STATIC_ASSERT(offsetof(wingman_LeadState, header) == 0, "offset of wingman_LeadState.header");
WINGMAN_STATIC_ASSERT(offsetof(wingman_LeadState, time_s) == 24, "offset of wingman_LeadState.time_s");
WINGMAN_STATIC_ASSERT(offsetof(wingman_LeadState, position_m) == 32, "offset of wingman_LeadState.position_m");
WINGMAN_STATIC_ASSERT(offsetof(wingman_LeadState, heading_rad) == 56, "offset of wingman_LeadState.heading_rad");
WINGMAN_STATIC_ASSERT(offsetof(wingman_LeadState, gamma_rad) == 64, "offset of wingman_LeadState.gamma_rad");
WINGMAN_STATIC_ASSERT(offsetof(wingman_LeadState, speed_mps) == 72, "offset of wingman_LeadState.speed_mps");
WINGMAN_STATIC_ASSERT(offsetof(wingman_LeadState, route_revision) == 80, "offset of wingman_LeadState.route_revision");
WINGMAN_STATIC_ASSERT(offsetof(wingman_LeadState, reserved) == 84, "offset of wingman_LeadState.reserved");

/* The lead's route: it flies the polyline at constant speed, at the first point at `start_time_s`, and keeps its last heading past the last point. Re-sent whenever it changes, with a larger `revision`. */
typedef struct wingman_LeadRoute {
    wingman_Header header; /* Common header. */
    uint32_t revision; /* Grows with every change of route; starts at 1. */
    uint32_t point_count; /* Number of valid entries in `points_m` (2 or more). */
    double start_time_s; /* Mission time at which the lead is at `points_m[0]`. [s] */
    double speed_mps; /* Constant speed along the route. [m/s] */
    double points_m[16][3]; /* Route polyline `[x, y, z]` (z = 0 in 2-D); `point_count` valid. [m] */
#ifdef __cplusplus
    static constexpr const char *IOX2_TYPE_NAME = "wingman::LeadRoute";
#endif
} wingman_LeadRoute;
#define WINGMAN_LEAD_ROUTE_TYPE_NAME "wingman::LeadRoute"
WINGMAN_STATIC_ASSERT(sizeof(wingman_LeadRoute) == 432, "size of wingman_LeadRoute");
WINGMAN_STATIC_ASSERT(WINGMAN_ALIGNOF(wingman_LeadRoute) == 8, "alignment of wingman_LeadRoute");
WINGMAN_STATIC_ASSERT(offsetof(wingman_LeadRoute, header) == 0, "offset of wingman_LeadRoute.header");
WINGMAN_STATIC_ASSERT(offsetof(wingman_LeadRoute, revision) == 24, "offset of wingman_LeadRoute.revision");
WINGMAN_STATIC_ASSERT(offsetof(wingman_LeadRoute, point_count) == 28, "offset of wingman_LeadRoute.point_count");
WINGMAN_STATIC_ASSERT(offsetof(wingman_LeadRoute, start_time_s) == 32, "offset of wingman_LeadRoute.start_time_s");
WINGMAN_STATIC_ASSERT(offsetof(wingman_LeadRoute, speed_mps) == 40, "offset of wingman_LeadRoute.speed_mps");
WINGMAN_STATIC_ASSERT(offsetof(wingman_LeadRoute, points_m) == 48, "offset of wingman_LeadRoute.points_m");

/* A threat from the onboard sensor: a static superquadric (FORMULATION.md §3) or a threat moving along a known road (§5) with the estimate of its distance along the road. Sent when the threat becomes known; the latest report per `threat_id` wins. */
typedef struct wingman_ThreatReport {
    wingman_Header header; /* Common header. */
    uint32_t threat_id; /* Unique per threat for the whole mission, never 0. */
    uint32_t kind; /* `ThreatKind` value. [enum] */
    double appeared_at_s; /* Mission time at which the threat became known (0 or less: before take-off). [s] */
    uint8_t name[24]; /* Name for people: UTF-8, NUL-padded. */
    double center_m[3]; /* Static: centre `[x, y, z]` (z = 0 in 2-D). Moving: unused (zeros). [m] */
    double axes_m[3]; /* Static: semi-axes. Moving: keep-out semi-axes when the position is certain (along the road, across, up). 2-D: the third is unused (zero). [m] */
    double exponents[3]; /* Static: exponents per axis (2 for an ellipsoid). Moving: unused (zeros). */
    double yaw_rad; /* Static: yaw of the threat's x-axis, counter-clockwise from +x. [rad] */
    uint32_t road_point_count; /* Moving: number of valid entries in `road_m` (2 or more). Static: 0. */
    uint32_t reserved; /* Zero; keeps the next field 8-byte aligned. */
    double road_m[16][3]; /* Moving: road polyline `[x, y, z]`; `road_point_count` valid. [m] */
    double estimate_time_s; /* Moving: mission time of the estimate below. [s] */
    double estimate_mean[3]; /* Moving: estimated `[d, v, a]` along the road. [m, m/s, m/s^2] */
    double estimate_covariance[9]; /* Moving: covariance of the estimate, row-major 3 x 3, symmetric. [m^2, ...] */
    double accel_sigma_mps2; /* Moving: standard deviation of the Gauss–Markov acceleration. [m/s^2] */
    double accel_tau_s; /* Moving: correlation time tau of the acceleration. [s] */
#ifdef __cplusplus
    static constexpr const char *IOX2_TYPE_NAME = "wingman::ThreatReport";
#endif
} wingman_ThreatReport;
#define WINGMAN_THREAT_REPORT_TYPE_NAME "wingman::ThreatReport"
WINGMAN_STATIC_ASSERT(sizeof(wingman_ThreatReport) == 656, "size of wingman_ThreatReport");
WINGMAN_STATIC_ASSERT(WINGMAN_ALIGNOF(wingman_ThreatReport) == 8, "alignment of wingman_ThreatReport");
WINGMAN_STATIC_ASSERT(offsetof(wingman_ThreatReport, header) == 0, "offset of wingman_ThreatReport.header");
WINGMAN_STATIC_ASSERT(offsetof(wingman_ThreatReport, threat_id) == 24, "offset of wingman_ThreatReport.threat_id");
WINGMAN_STATIC_ASSERT(offsetof(wingman_ThreatReport, kind) == 28, "offset of wingman_ThreatReport.kind");
WINGMAN_STATIC_ASSERT(offsetof(wingman_ThreatReport, appeared_at_s) == 32, "offset of wingman_ThreatReport.appeared_at_s");
WINGMAN_STATIC_ASSERT(offsetof(wingman_ThreatReport, name) == 40, "offset of wingman_ThreatReport.name");
WINGMAN_STATIC_ASSERT(offsetof(wingman_ThreatReport, center_m) == 64, "offset of wingman_ThreatReport.center_m");
WINGMAN_STATIC_ASSERT(offsetof(wingman_ThreatReport, axes_m) == 88, "offset of wingman_ThreatReport.axes_m");
WINGMAN_STATIC_ASSERT(offsetof(wingman_ThreatReport, exponents) == 112, "offset of wingman_ThreatReport.exponents");
WINGMAN_STATIC_ASSERT(offsetof(wingman_ThreatReport, yaw_rad) == 136, "offset of wingman_ThreatReport.yaw_rad");
WINGMAN_STATIC_ASSERT(offsetof(wingman_ThreatReport, road_point_count) == 144, "offset of wingman_ThreatReport.road_point_count");
WINGMAN_STATIC_ASSERT(offsetof(wingman_ThreatReport, reserved) == 148, "offset of wingman_ThreatReport.reserved");
WINGMAN_STATIC_ASSERT(offsetof(wingman_ThreatReport, road_m) == 152, "offset of wingman_ThreatReport.road_m");
WINGMAN_STATIC_ASSERT(offsetof(wingman_ThreatReport, estimate_time_s) == 536, "offset of wingman_ThreatReport.estimate_time_s");
WINGMAN_STATIC_ASSERT(offsetof(wingman_ThreatReport, estimate_mean) == 544, "offset of wingman_ThreatReport.estimate_mean");
WINGMAN_STATIC_ASSERT(offsetof(wingman_ThreatReport, estimate_covariance) == 568, "offset of wingman_ThreatReport.estimate_covariance");
WINGMAN_STATIC_ASSERT(offsetof(wingman_ThreatReport, accel_sigma_mps2) == 640, "offset of wingman_ThreatReport.accel_sigma_mps2");
WINGMAN_STATIC_ASSERT(offsetof(wingman_ThreatReport, accel_tau_s) == 648, "offset of wingman_ThreatReport.accel_tau_s");

/* One measured position of a moving threat from the onboard sensor. */
typedef struct wingman_TrackFix {
    wingman_Header header; /* Common header. */
    uint32_t threat_id; /* `threat_id` of the moving threat's `ThreatReport`. */
    uint32_t reserved; /* Zero; keeps the next field 8-byte aligned. */
    double time_s; /* Mission time of the measurement. [s] */
    double position_m[3]; /* Measured position `[x, y, z]` (z = 0 in 2-D). [m] */
    double sigma_m; /* Standard deviation of the measurement along each axis. [m] */
#ifdef __cplusplus
    static constexpr const char *IOX2_TYPE_NAME = "wingman::TrackFix";
#endif
} wingman_TrackFix;
#define WINGMAN_TRACK_FIX_TYPE_NAME "wingman::TrackFix"
WINGMAN_STATIC_ASSERT(sizeof(wingman_TrackFix) == 72, "size of wingman_TrackFix");
WINGMAN_STATIC_ASSERT(WINGMAN_ALIGNOF(wingman_TrackFix) == 8, "alignment of wingman_TrackFix");
WINGMAN_STATIC_ASSERT(offsetof(wingman_TrackFix, header) == 0, "offset of wingman_TrackFix.header");
WINGMAN_STATIC_ASSERT(offsetof(wingman_TrackFix, threat_id) == 24, "offset of wingman_TrackFix.threat_id");
WINGMAN_STATIC_ASSERT(offsetof(wingman_TrackFix, reserved) == 28, "offset of wingman_TrackFix.reserved");
WINGMAN_STATIC_ASSERT(offsetof(wingman_TrackFix, time_s) == 32, "offset of wingman_TrackFix.time_s");
WINGMAN_STATIC_ASSERT(offsetof(wingman_TrackFix, position_m) == 40, "offset of wingman_TrackFix.position_m");
WINGMAN_STATIC_ASSERT(offsetof(wingman_TrackFix, sigma_m) == 64, "offset of wingman_TrackFix.sigma_m");

/* The wingman's state from the inner-loop tracker (periodic). */
typedef struct wingman_OwnshipState {
    wingman_Header header; /* Common header. */
    double time_s; /* Mission time of the state. [s] */
    uint32_t model; /* `Model` value (2 or 3). [enum] */
    uint32_t flags; /* Bit 0 (`OWNSHIP_HOLDING`): flying a safe hold. Other bits are zero. [bits] */
    uint64_t plan_id; /* `plan_id` of the plan being flown (0: none). */
    double state[7]; /* Full state (model order, zero-padded). [m, rad, g] */
    double control[2]; /* Control applied (model order, zero-padded). [rad/s, 1/s] */
    double cross_track_m; /* Signed distance from the plan across its track (positive left). [m] */
    double along_track_m; /* Signed distance from the plan's point at `time_s` along its track (positive ahead). [m] */
    double vertical_m; /* Height above the plan's point at `time_s` (0 in 2-D). [m] */
#ifdef __cplusplus
    static constexpr const char *IOX2_TYPE_NAME = "wingman::OwnshipState";
#endif
} wingman_OwnshipState;
#define WINGMAN_OWNSHIP_STATE_TYPE_NAME "wingman::OwnshipState"
WINGMAN_STATIC_ASSERT(sizeof(wingman_OwnshipState) == 144, "size of wingman_OwnshipState");
WINGMAN_STATIC_ASSERT(WINGMAN_ALIGNOF(wingman_OwnshipState) == 8, "alignment of wingman_OwnshipState");
WINGMAN_STATIC_ASSERT(offsetof(wingman_OwnshipState, header) == 0, "offset of wingman_OwnshipState.header");
WINGMAN_STATIC_ASSERT(offsetof(wingman_OwnshipState, time_s) == 24, "offset of wingman_OwnshipState.time_s");
WINGMAN_STATIC_ASSERT(offsetof(wingman_OwnshipState, model) == 32, "offset of wingman_OwnshipState.model");
WINGMAN_STATIC_ASSERT(offsetof(wingman_OwnshipState, flags) == 36, "offset of wingman_OwnshipState.flags");
WINGMAN_STATIC_ASSERT(offsetof(wingman_OwnshipState, plan_id) == 40, "offset of wingman_OwnshipState.plan_id");
WINGMAN_STATIC_ASSERT(offsetof(wingman_OwnshipState, state) == 48, "offset of wingman_OwnshipState.state");
WINGMAN_STATIC_ASSERT(offsetof(wingman_OwnshipState, control) == 104, "offset of wingman_OwnshipState.control");
WINGMAN_STATIC_ASSERT(offsetof(wingman_OwnshipState, cross_track_m) == 120, "offset of wingman_OwnshipState.cross_track_m");
WINGMAN_STATIC_ASSERT(offsetof(wingman_OwnshipState, along_track_m) == 128, "offset of wingman_OwnshipState.along_track_m");
WINGMAN_STATIC_ASSERT(offsetof(wingman_OwnshipState, vertical_m) == 136, "offset of wingman_OwnshipState.vertical_m");

/* A plan for the tracker (planner → harness). The tracker flies the newest plan whose `start_time_s` has come, interpolating the samples linearly in time, until `valid_until_s`. */
typedef struct wingman_Plan {
    wingman_Header header; /* Common header. */
    uint64_t plan_id; /* Grows with every plan; starts at 1. */
    uint32_t trigger; /* `Trigger` value. [enum] */
    uint32_t quality; /* `Quality` value. [enum] */
    uint32_t model; /* `Model` value (2 or 3). [enum] */
    uint32_t phase_count; /* Number of valid entries in `phase_end_s` (targets + 1). */
    uint32_t sample_count; /* Number of valid entries in `samples` (2 or more). */
    uint32_t has_next_replan; /* 1 if `next_replan_s` holds a scheduled re-plan time, else 0. [bool] */
    uint32_t path; /* `PlanPath` value: the path whose plan this is. [enum] */
    uint32_t cut_count; /* Number of valid entries in `cuts` (0: the deadline cut nothing; the plan is what its inputs and seed make on any machine). */
    double created_at_s; /* Mission time of the trigger that caused the plan. [s] */
    double start_time_s; /* Commit time: the tracker switches to this plan here (first sample's time). [s] */
    double valid_until_s; /* The plan may be flown until here (its end, or the next scheduled re-plan). [s] */
    double cost; /* Objective value of the plan (FORMULATION.md §4). */
    double final_time_s; /* Planned final time tf (last sample's time). [s] */
    double compute_ms; /* Wall-clock compute time of the plan. [ms] */
    double next_replan_s; /* Scheduled re-plan time t_r (FORMULATION.md §6), valid if `has_next_replan`. [s] */
    double phase_end_s[9]; /* Mission time at which each phase ends (phase g ends on target g; the last on the final point or the rendezvous). [s] */
    wingman_PlanCut cuts[64]; /* Where the deadline cut the computation, sorted; `cut_count` valid. */
    wingman_PlanSample samples[2048]; /* Trajectory samples in increasing time; `sample_count` valid. */
#ifdef __cplusplus
    static constexpr const char *IOX2_TYPE_NAME = "wingman::Plan";
#endif
} wingman_Plan;
#define WINGMAN_PLAN_TYPE_NAME "wingman::Plan"
WINGMAN_STATIC_ASSERT(sizeof(wingman_Plan) == 164544, "size of wingman_Plan");
WINGMAN_STATIC_ASSERT(WINGMAN_ALIGNOF(wingman_Plan) == 8, "alignment of wingman_Plan");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, header) == 0, "offset of wingman_Plan.header");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, plan_id) == 24, "offset of wingman_Plan.plan_id");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, trigger) == 32, "offset of wingman_Plan.trigger");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, quality) == 36, "offset of wingman_Plan.quality");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, model) == 40, "offset of wingman_Plan.model");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, phase_count) == 44, "offset of wingman_Plan.phase_count");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, sample_count) == 48, "offset of wingman_Plan.sample_count");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, has_next_replan) == 52, "offset of wingman_Plan.has_next_replan");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, path) == 56, "offset of wingman_Plan.path");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, cut_count) == 60, "offset of wingman_Plan.cut_count");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, created_at_s) == 64, "offset of wingman_Plan.created_at_s");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, start_time_s) == 72, "offset of wingman_Plan.start_time_s");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, valid_until_s) == 80, "offset of wingman_Plan.valid_until_s");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, cost) == 88, "offset of wingman_Plan.cost");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, final_time_s) == 96, "offset of wingman_Plan.final_time_s");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, compute_ms) == 104, "offset of wingman_Plan.compute_ms");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, next_replan_s) == 112, "offset of wingman_Plan.next_replan_s");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, phase_end_s) == 120, "offset of wingman_Plan.phase_end_s");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, cuts) == 192, "offset of wingman_Plan.cuts");
WINGMAN_STATIC_ASSERT(offsetof(wingman_Plan, samples) == 704, "offset of wingman_Plan.samples");

/* The planner's heartbeat (periodic and after every change). */
typedef struct wingman_PlannerStatus {
    wingman_Header header; /* Common header. */
    uint32_t state; /* `PlannerState` value. [enum] */
    uint32_t stale_inputs; /* Bits `STALE_*` of inputs that stopped arriving. [bits] */
    uint64_t last_input_sequence; /* Highest header `sequence` of an accepted input message, over all input services (a rejected message's is not echoed; a lock-step client waits for it). */
    uint64_t current_plan_id; /* `plan_id` of the newest published plan (0: none). */
    uint64_t messages_received; /* Messages taken from every input service. */
    uint64_t messages_rejected; /* Messages rejected and dropped: failed `validate()`, or a header that does not follow the sender's previous one on its service. */
    uint64_t messages_lost; /* Messages lost before the planner read them (a subscriber buffer overflowed): the gaps in each sender's `sequence`, counted one pass after a later one is read. */
    uint64_t plans_made; /* Plans published. */
    uint64_t triggers_coalesced; /* Triggers folded into a plan already pending. */
    uint64_t triggers_deferred; /* Triggers held back by the minimum spacing or the duty-cycle cap. */
    uint64_t popups_clear; /* Pop-ups assessed as clear of the plan (no re-plan). */
    double last_plan_compute_ms; /* Compute time of the newest plan. [ms] */
    double budget_remaining_ms; /* Compute time left in the duty-cycle window. [ms] */
#ifdef __cplusplus
    static constexpr const char *IOX2_TYPE_NAME = "wingman::PlannerStatus";
#endif
} wingman_PlannerStatus;
#define WINGMAN_PLANNER_STATUS_TYPE_NAME "wingman::PlannerStatus"
WINGMAN_STATIC_ASSERT(sizeof(wingman_PlannerStatus) == 120, "size of wingman_PlannerStatus");
WINGMAN_STATIC_ASSERT(WINGMAN_ALIGNOF(wingman_PlannerStatus) == 8, "alignment of wingman_PlannerStatus");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlannerStatus, header) == 0, "offset of wingman_PlannerStatus.header");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlannerStatus, state) == 24, "offset of wingman_PlannerStatus.state");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlannerStatus, stale_inputs) == 28, "offset of wingman_PlannerStatus.stale_inputs");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlannerStatus, last_input_sequence) == 32, "offset of wingman_PlannerStatus.last_input_sequence");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlannerStatus, current_plan_id) == 40, "offset of wingman_PlannerStatus.current_plan_id");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlannerStatus, messages_received) == 48, "offset of wingman_PlannerStatus.messages_received");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlannerStatus, messages_rejected) == 56, "offset of wingman_PlannerStatus.messages_rejected");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlannerStatus, messages_lost) == 64, "offset of wingman_PlannerStatus.messages_lost");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlannerStatus, plans_made) == 72, "offset of wingman_PlannerStatus.plans_made");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlannerStatus, triggers_coalesced) == 80, "offset of wingman_PlannerStatus.triggers_coalesced");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlannerStatus, triggers_deferred) == 88, "offset of wingman_PlannerStatus.triggers_deferred");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlannerStatus, popups_clear) == 96, "offset of wingman_PlannerStatus.popups_clear");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlannerStatus, last_plan_compute_ms) == 104, "offset of wingman_PlannerStatus.last_plan_compute_ms");
WINGMAN_STATIC_ASSERT(offsetof(wingman_PlannerStatus, budget_remaining_ms) == 112, "offset of wingman_PlannerStatus.budget_remaining_ms");

#endif /* WINGMAN_H */
