//! The navigation solution: the true state with correlated errors on the position (each
//! axis) and the heading, first-order Gauss–Markov processes of one correlation time.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use wingman_interfaces::Model;
use wingman_planning::scenario::AircraftSpec;

use super::GaussMarkov;

/// The navigation errors of one flight.
#[derive(Debug, Clone)]
pub struct Navigation {
    /// Errors of x, y, z (0 in 2-D) and the heading.
    errors: [GaussMarkov; 4],
    model: Model,
    rng: ChaCha8Rng,
}

impl Navigation {
    /// The navigation errors of `spec` for a vehicle of `model`.
    pub fn new(spec: &AircraftSpec, model: Model) -> Navigation {
        let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);
        // Its own stream: the gusts of the same seed draw from another.
        rng.set_stream(super::NAVIGATION_STREAM);
        let dim = model.position_dim();
        let errors = std::array::from_fn(|i| {
            let sigma = match i {
                3 => spec.nav_heading_sigma,
                _ if i < dim => spec.nav_sigma_m,
                _ => 0.0,
            };
            GaussMarkov::stationary(sigma, spec.nav_tau_s, &mut rng)
        });
        Navigation { errors, model, rng }
    }

    /// The state the navigation solution reports for the true state `x`.
    pub fn sense(&self, x: &[f64; 7]) -> [f64; 7] {
        let mut seen = *x;
        let e = |i: usize| self.errors[i].value();
        match self.model {
            Model::TwoD => {
                seen[0] += e(0);
                seen[1] += e(1);
                seen[2] += e(3);
            }
            Model::ThreeD => {
                seen[0] += e(0);
                seen[1] += e(1);
                seen[2] += e(2);
                seen[4] += e(3);
            }
        }
        seen
    }

    /// The errors `h` seconds on.
    pub fn advance(&mut self, h: f64) {
        for e in &mut self.errors {
            e.advance(h, &mut self.rng);
        }
    }
}

#[cfg(test)]
mod tests {
    use wingman_planning::scenario::bundled;

    use super::*;

    /// Exact navigation reports the true state; noisy navigation errs on the position
    /// and the heading only (2-D: x, y, heading; 3-D: x, y, z, heading), by its errors'
    /// spread (over 2 000 independent samples: within 15 % of sigma).
    #[test]
    fn errors_fall_on_the_position_and_heading_with_their_spread() {
        let sc = bundled("3d-replan-popups").unwrap().unwrap();
        let x = [1.0, 2.0, 3000.0, 0.1, 0.2, 1.0, 0.3];
        let exact = Navigation::new(&AircraftSpec::ideal(&sc.vehicle), Model::ThreeD);
        assert_eq!(exact.sense(&x), x);
        let noisy_spec = AircraftSpec {
            nav_sigma_m: 20.0,
            nav_heading_sigma: 0.01,
            nav_tau_s: 1.0,
            ..AircraftSpec::ideal(&sc.vehicle)
        };
        for (model, moved) in [
            (Model::TwoD, [true, true, true, false, false, false, false]),
            (Model::ThreeD, [true, true, true, false, true, false, false]),
        ] {
            let mut nav = Navigation::new(&noisy_spec, model);
            let mut sq = [0.0; 7];
            let n = 2000;
            for _ in 0..n {
                // Ten correlation times apart: independent samples.
                nav.advance(10.0);
                let seen = nav.sense(&x);
                for i in 0..7 {
                    sq[i] += (seen[i] - x[i]).powi(2) / n as f64;
                }
            }
            for i in 0..7 {
                let heading = (model == Model::TwoD && i == 2) || i == 4;
                let sigma = if heading { 0.01 } else { 20.0 };
                if moved[i] {
                    let spread = sq[i].sqrt();
                    assert!(
                        (spread / sigma - 1.0).abs() < 0.15,
                        "{model:?} {i}: {spread}"
                    );
                } else {
                    assert_eq!(sq[i], 0.0, "{model:?} {i}");
                }
            }
        }
    }
}
