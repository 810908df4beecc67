//! Building a seed's path: its spline sampled into a polyline with arc lengths, gates and
//! altitudes, ending at the final point or at the lead.

use super::context::Context;
use super::families::Spec;
use super::seed::{Seed, SeedLabel};
use super::spline::{MAX_NODES, dist2};

impl Context<'_> {
    /// Builds one seed into `seed`; false when its geometry is degenerate.
    pub(super) fn build_seed(&self, spec: &Spec, seed: &mut Seed) -> bool {
        seed.reset();
        let (end, meet) = match (self.end, self.lead) {
            (Some(e), _) => (e, None),
            (None, Some(lead)) => match self.meeting_time(lead, &spec.bulges, spec.altitude) {
                Some((t, r)) => (self.lead_end(lead, t), Some((t, r))),
                None => return false,
            },
            (None, None) => return false,
        };
        let Some(geo) = self.geometry(&spec.bulges, spec.altitude, &end) else {
            return false;
        };
        let nodes = geo.spline.nodes();
        let total: f64 = geo.seg_len[..nodes - 1].iter().sum();
        // Sample each segment with a share of the points proportional to its length.
        let mut node_index = [0usize; MAX_NODES];
        let mut s_acc = 0.0;
        for (i, index) in node_index.iter_mut().enumerate().take(nodes - 1) {
            let share = if total > 0.0 {
                geo.seg_len[i] / total
            } else {
                1.0 / (nodes - 1) as f64
            };
            let count = ((self.points as f64 * share).round() as usize).max(2);
            *index = seed.points.len();
            let (p0, _) = geo.spline.eval(i, 0.0);
            let mut prev = p0;
            for j in 0..count {
                let (p, _) = geo.spline.eval(i, j as f64 / count as f64);
                s_acc += dist2(&prev, &p);
                prev = p;
                seed.points.push([p[0], p[1], 0.0]);
                seed.arc.push(s_acc);
            }
            let (p1, _) = geo.spline.eval(i, 1.0);
            s_acc += dist2(&prev, &p1);
        }
        let (pe, _) = geo.spline.eval(nodes - 2, 1.0);
        node_index[nodes - 1] = seed.points.len();
        seed.points.push([pe[0], pe[1], 0.0]);
        seed.arc.push(s_acc);
        // Altitudes from each leg's profile over the leg's own arc length.
        let mut first = 0;
        for g in 0..self.legs {
            let last = node_index[geo.gate_nodes[g]];
            let s0 = seed.arc[first];
            let prof = &geo.profiles[g];
            let scale = {
                // The profile was built on the spline's exact length; map the polyline's.
                let poly = seed.arc[last] - s0;
                if poly > 0.0 {
                    prof.s[prof.n - 1] / poly
                } else {
                    1.0
                }
            };
            for k in first..=last {
                seed.points[k][2] = if self.spatial {
                    prof.z_at((seed.arc[k] - s0) * scale)
                } else {
                    0.0
                };
            }
            seed.gates[g] = last;
            first = last;
        }
        seed.n_gates = self.legs;
        seed.length = geo.length;
        seed.start_heading = self.heading0;
        seed.start_gamma = self.gamma0;
        seed.end_heading = end.heading;
        seed.end_gamma = end.gamma;
        seed.label = SeedLabel {
            kind: spec.kind,
            legs: self.legs,
            bulges: spec.bulges,
            altitude: spec.altitude,
            spatial: self.spatial,
        };
        if let Some((t, r)) = meet {
            seed.rendezvous_time = Some(t);
            seed.rendezvous_residual = r;
        }
        seed.points.iter().flatten().all(|v| v.is_finite())
    }
}
