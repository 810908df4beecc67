//! The moving threats' filters as the planner runs them (same reports, same fixes, same
//! code), so the plots can show what the planner estimated.

use wingman_interfaces::Plan;
use wingman_planning::estimation::{Estimate, GaussMarkov, KalmanFilter, Road};

use super::EstimateSnapshot;

/// The moving threats' filters as the planner runs them (same reports, same fixes, same
/// code), so the plots can show what the planner estimated.
pub(super) struct Mirror {
    filters: Vec<Option<(KalmanFilter, Road<3>, f64)>>,
}

impl Mirror {
    /// No filter yet for each of `moving` threats.
    pub(super) fn new(moving: usize) -> Mirror {
        Mirror {
            filters: vec![None; moving],
        }
    }

    pub(super) fn report(&mut self, k: usize, r: &wingman_interfaces::ThreatReport) {
        let make = || -> Option<(KalmanFilter, Road<3>, f64)> {
            let model = GaussMarkov::new(r.accel_tau_s, r.accel_sigma_mps2).ok()?;
            let road = Road::<3>::new(r.road()).ok()?;
            let est = Estimate::new(
                r.estimate_time_s,
                nalgebra::Vector3::from(r.estimate_mean),
                nalgebra::Matrix3::from_row_slice(&r.estimate_covariance),
            )
            .ok()?;
            Some((KalmanFilter::new(model, 1.0, est).ok()?, road, 1.0))
        };
        if let Some(slot) = self.filters.get_mut(k) {
            *slot = make();
        }
    }

    pub(super) fn fix(&mut self, k: usize, f: &wingman_interfaces::TrackFix) {
        let Some(Some((filter, road, sigma))) = self.filters.get_mut(k) else {
            return;
        };
        if f.sigma_m != *sigma
            && let Ok(nf) = KalmanFilter::new(*filter.model(), f.sigma_m, *filter.estimate())
        {
            *filter = nf;
            *sigma = f.sigma_m;
        }
        if filter.predict_to(f.time_s).is_ok() {
            let _ = filter.update_position(road, &f.position_m);
        }
    }

    /// Records every moving threat's estimate as `plan` was made from it.
    pub(super) fn snapshot(&self, plan: &Plan, out: &mut Vec<EstimateSnapshot>) {
        for threat in 0..self.filters.len() {
            if let Some(estimate) = self.estimate(threat) {
                out.push(EstimateSnapshot {
                    plan_id: plan.plan_id,
                    threat,
                    at_s: plan.created_at_s,
                    estimate,
                });
            }
        }
    }

    fn estimate(&self, k: usize) -> Option<Estimate> {
        self.filters
            .get(k)
            .and_then(|f| f.as_ref())
            .map(|(f, _, _)| *f.estimate())
    }
}
