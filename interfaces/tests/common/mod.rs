//! One filled, valid instance of every message, with distinct values in every field so a
//! moved or resized field changes the golden bytes.
#![allow(dead_code)]

use wingman_interfaces::*;

pub fn header(seq: u64) -> Header {
    Header::new(SENDER_HARNESS, seq, 1_234_567_890 + seq as i64)
}

pub fn tasking() -> Tasking {
    let mut m = Tasking::zeroed();
    m.header = header(1);
    m.revision = 3;
    m.model = Model::ThreeD.to_wire();
    m.objective = Objective::MinTime.to_wire();
    m.target_count = 2;
    m.limits = VehicleLimits {
        speed_mps: 250.0,
        turn_rate_max_rps: 0.0,
        gamma_max_rad: 0.5235987755982988,
        nz_min: -1.0,
        nz_max: 4.0,
        bank_max_rad: 1.2217304763960306,
        nz_rate_max_per_s: 1.0,
        bank_rate_max_rps: 0.5235987755982988,
        altitude_min_m: 500.0,
    };
    m.weights = Weights {
        alpha: 0.05,
        beta: 0.95,
        stiffness: 30.0,
    };
    m.start_time_s = 0.5;
    m.start_state = [1.0, 2.0, 15000.0, 0.01, 0.2, 1.0, 0.0];
    m.final_state = [100000.0, 20000.0, 12000.0, 0.0, -0.3, 1.0, 0.0];
    m.final_time_s = 0.0;
    m.targets_m[0] = [60000.0, 80000.0, 2000.0];
    m.targets_m[1] = [70000.0, 50000.0, 3000.0];
    m
}

pub fn lead_state() -> LeadState {
    LeadState {
        header: header(2),
        time_s: 12.5,
        position_m: [2250.0, -10.0, 15000.0],
        heading_rad: 0.1,
        gamma_rad: -0.02,
        speed_mps: 180.0,
        route_revision: 2,
        reserved: 0,
    }
}

pub fn lead_route() -> LeadRoute {
    let mut m = LeadRoute::zeroed();
    m.header = header(3);
    m.revision = 2;
    m.point_count = 3;
    m.start_time_s = 450.0;
    m.speed_mps = 180.0;
    m.points_m[0] = [81000.0, 0.0, 15000.0];
    m.points_m[1] = [150000.0, 40000.0, 15000.0];
    m.points_m[2] = [300000.0, 40000.0, 15000.0];
    m
}

pub fn threat_static() -> ThreatReport {
    let mut m = ThreatReport::zeroed();
    m.header = header(4);
    m.threat_id = 5;
    m.kind = ThreatKind::Static.to_wire();
    m.appeared_at_s = 300.0;
    m.name = threat_name("popup-far");
    m.center_m = [20000.0, 140000.0, 0.0];
    m.axes_m = [10000.0, 11000.0, 12000.0];
    m.exponents = [2.0, 2.0, 8.0];
    m.yaw_rad = 0.35;
    m
}

pub fn threat_moving() -> ThreatReport {
    let mut m = ThreatReport::zeroed();
    m.header = header(5);
    m.threat_id = 6;
    m.kind = ThreatKind::Moving.to_wire();
    m.appeared_at_s = 60.0;
    m.name = threat_name("mobile-sam");
    m.axes_m = [10000.0, 10000.0, 12000.0];
    m.road_point_count = 2;
    m.road_m[0] = [70000.0, 0.0, 0.0];
    m.road_m[1] = [100000.0, 150000.0, 0.0];
    m.estimate_time_s = 60.0;
    m.estimate_mean = [58900.0, 15.0, 0.0];
    m.estimate_covariance = [250000.0, 1.5, 0.1, 1.5, 9.0, 0.2, 0.1, 0.2, 0.09];
    m.accel_sigma_mps2 = 0.3;
    m.accel_tau_s = 60.0;
    m
}

pub fn track_fix() -> TrackFix {
    TrackFix {
        header: header(6),
        threat_id: 6,
        reserved: 0,
        time_s: 61.0,
        position_m: [80100.0, 58700.0, 0.0],
        sigma_m: 200.0,
    }
}

pub fn ownship() -> OwnshipState {
    OwnshipState {
        header: header(7),
        time_s: 13.0,
        model: Model::ThreeD.to_wire(),
        flags: OWNSHIP_HOLDING,
        plan_id: 4,
        state: [3250.0, 12.0, 15001.0, 0.001, 0.05, 1.01, 0.02],
        control: [0.001, -0.002],
        cross_track_m: 1.5,
        along_track_m: -2.5,
        vertical_m: 0.75,
    }
}

pub fn plan() -> Plan {
    let mut m = Plan::zeroed();
    m.header = Header::new(SENDER_PLANNER, 8, 2_000_000_000);
    m.plan_id = 4;
    m.trigger = Trigger::PopUp.to_wire();
    m.quality = Quality::Feasible.to_wire();
    m.model = Model::ThreeD.to_wire();
    m.phase_count = 2;
    m.sample_count = 3;
    m.has_next_replan = 1;
    m.path = PlanPath::Warm.to_wire();
    m.cut_count = 2;
    m.cuts[0] = PlanCut {
        site: 0x0207_0003,
        step: 0,
    };
    m.cuts[1] = PlanCut {
        site: 0x0203_0000,
        step: 41,
    };
    m.created_at_s = 60.0;
    m.start_time_s = 60.25;
    m.valid_until_s = 95.0;
    m.cost = 41.5;
    m.final_time_s = 700.0;
    m.compute_ms = 187.5;
    m.next_replan_s = 95.0;
    m.phase_end_s[0] = 300.0;
    m.phase_end_s[1] = 700.0;
    for (k, t) in [60.25, 300.0, 700.0].into_iter().enumerate() {
        m.samples[k] = PlanSample {
            t_s: t,
            state: [
                k as f64 * 1000.0,
                2.0,
                15000.0,
                0.0,
                0.1 * k as f64,
                1.0,
                0.0,
            ],
            control: [0.01 * k as f64, -0.01],
        };
    }
    m
}

pub fn status() -> PlannerStatus {
    PlannerStatus {
        header: Header::new(SENDER_PLANNER, 9, 2_100_000_000),
        state: PlannerState::Planning.to_wire(),
        stale_inputs: STALE_LEAD | STALE_TRACKS,
        last_input_sequence: 77,
        current_plan_id: 4,
        messages_received: 1000,
        messages_rejected: 3,
        messages_lost: 6,
        plans_made: 4,
        triggers_coalesced: 12,
        triggers_deferred: 2,
        popups_clear: 1,
        last_plan_compute_ms: 187.5,
        budget_remaining_ms: 812.5,
    }
}
