//! A drawn mission written as a scenario file (`scenarios/FORMAT.md`), in the order of
//! its draw.

use std::fmt::Write;

use super::{Mission, MovingThreat, StaticThreat};

impl Mission {
    /// The scenario file.
    pub(super) fn to_toml(&self, name: &str, summary: &str) -> String {
        let mut s = String::new();
        let model = if self.three_d { "3d" } else { "2d" };
        let _ = writeln!(
            s,
            "name = \"{name}\"\nsummary = \"{summary}\"\nmodel = \"{model}\"\nobjective = \"{}\"\n",
            self.objective
        );
        self.write_vehicle(&mut s);
        let _ = writeln!(
            s,
            "[start]\ntime_s = 0.0\nposition_m = {}\nheading_deg = {:.1}{}\n",
            self.point(&self.start),
            self.heading_deg,
            if self.three_d {
                "\ngamma_deg = 0.0"
            } else {
                ""
            }
        );
        for t in &self.targets {
            let _ = writeln!(s, "[[targets]]\nposition_m = {}\n", self.point(t));
        }
        self.write_end(&mut s);
        for (k, t) in self.threats.iter().enumerate() {
            self.write_static(&mut s, &format!("t{k}"), t);
        }
        for (k, t) in self.popups.iter().enumerate() {
            self.write_static(&mut s, &format!("popup-{k}"), t);
        }
        for (k, m) in self.moving.iter().enumerate() {
            self.write_moving(&mut s, k, m);
        }
        if let Some((at, turn, speed)) = self.lead_turn {
            let from = [self.lead_speed * at, 0.0, self.start[2]];
            let to = [
                from[0] + 400_000.0 * turn.cos(),
                400_000.0 * turn.sin(),
                self.start[2],
            ];
            let _ = writeln!(
                s,
                "[[events]]\nat_s = {at:.1}\nkind = \"lead-route\"\nroute_m = [{}, {}]\nspeed_mps = {speed:.1}\n",
                self.point(&from),
                self.point(&to)
            );
        }
        if let Some(w) = &self.wind {
            let _ = writeln!(
                s,
                "[wind]\nmean_mps = [{:.2}, {:.2}]\ngusts = \"{}\"\nseed = {}\n\n[aircraft]\nresponse_s = {:.2}\nnav_sigma_m = {:.1}\nnav_heading_sigma_deg = {:.2}\nnav_tau_s = 60.0\nseed = {}\n",
                w.mean[0],
                w.mean[1],
                w.gusts,
                w.seed,
                w.response_s,
                w.nav_sigma_m,
                w.nav_heading_sigma_deg,
                w.aircraft_seed
            );
        }
        s
    }

    fn write_vehicle(&self, s: &mut String) {
        if self.three_d {
            let _ = writeln!(
                s,
                "[vehicle]\nspeed_mps = {:.1}\ngamma_max_deg = 30.0\nnz_min = -1.0\nnz_max = 4.0\nbank_max_deg = 70.0\nnz_rate_max_per_s = 1.0\nbank_rate_max_dps = 30.0\naltitude_min_m = 500.0\n",
                self.speed
            );
        } else {
            let _ = writeln!(
                s,
                "[vehicle]\nspeed_mps = {:.1}\nturn_rate_max_dps = 5.0\n",
                self.speed
            );
        }
        let _ = writeln!(
            s,
            "[weights]\nalpha = 0.05\nbeta = 0.95\nstiffness = 30.0\n"
        );
    }

    /// `[final]` or `[lead]`.
    fn write_end(&self, s: &mut String) {
        if let Some((f, heading)) = &self.final_point {
            let _ = write!(
                s,
                "[final]\nposition_m = {}\nheading_deg = {heading:.1}\n",
                self.point(f)
            );
            if self.three_d {
                let _ = writeln!(s, "gamma_deg = 0.0");
            }
            if let Some(t) = self.final_time {
                let _ = writeln!(s, "time_s = {t:.1}");
            }
            let _ = writeln!(s);
        } else {
            let end = [400_000.0, 0.0, self.start[2]];
            let _ = writeln!(
                s,
                "[lead]\nroute_m = [{}, {}]\nspeed_mps = {:.1}\n",
                self.point(&self.start),
                self.point(&end),
                self.lead_speed
            );
        }
    }

    fn write_static(&self, s: &mut String, name: &str, t: &StaticThreat) {
        let fp = &t.footprint;
        let _ = writeln!(s, "[[threats]]\nname = \"{name}\"");
        if self.three_d {
            let _ = writeln!(
                s,
                "center_m = [{:.1}, {:.1}, 0.0]\naxes_m = [{:.1}, {:.1}, {:.1}]\nexponents = [{:.1}, {:.1}, 2.0]",
                fp.center[0],
                fp.center[1],
                fp.axes[0],
                fp.axes[1],
                t.height,
                fp.exponent,
                fp.exponent
            );
        } else {
            let _ = writeln!(
                s,
                "center_m = [{:.1}, {:.1}]\naxes_m = [{:.1}, {:.1}]\nexponents = [{:.1}, {:.1}]",
                fp.center[0], fp.center[1], fp.axes[0], fp.axes[1], fp.exponent, fp.exponent
            );
        }
        let _ = writeln!(s, "yaw_deg = {:.1}", fp.yaw_deg);
        if let Some(at) = t.appears_at_s {
            let _ = writeln!(s, "appears_at_s = {at:.1}");
        }
        let _ = writeln!(s);
    }

    fn write_moving(&self, s: &mut String, k: usize, m: &MovingThreat) {
        let road: Vec<String> = m
            .road
            .iter()
            .map(|p| self.point(&[p[0], p[1], 0.0]))
            .collect();
        let axes = if self.three_d {
            format!("[{:.1}, {:.1}, {:.1}]", m.axes[0], m.axes[1], m.axes[2])
        } else {
            format!("[{:.1}, {:.1}]", m.axes[0], m.axes[1])
        };
        let _ = writeln!(
            s,
            "[[moving_threats]]\nname = \"mobile-{k}\"\nroad_m = [{}]\naxes_m = {axes}\ninitial_distance_m = {:.1}\ninitial_speed_mps = {:.1}\naccel_sigma_mps2 = {:.2}\naccel_tau_s = 60.0\ninitial_sigma = [500.0, 3.0, 0.3]\nappears_at_s = {:.1}\n[moving_threats.sensor]\nrate_hz = 1.0\nsigma_m = {:.1}\n[moving_threats.truth]\nseed = {}\n",
            road.join(", "),
            m.initial_distance,
            m.initial_speed,
            m.accel_sigma,
            m.appears_at_s,
            m.sensor_sigma,
            m.truth_seed
        );
    }

    /// A point as a TOML array (2 or 3 coordinates), to 0.1 m.
    fn point(&self, p: &[f64; 3]) -> String {
        if self.three_d {
            format!("[{:.1}, {:.1}, {:.1}]", p[0], p[1], p[2])
        } else {
            format!("[{:.1}, {:.1}]", p[0], p[1])
        }
    }
}
