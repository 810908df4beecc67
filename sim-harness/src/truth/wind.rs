//! The wind: a steady mean plus gusts, one first-order Gauss–Markov process per axis
//! (horizontal in 2-D, all three in 3-D) with the correlation time `L / V` of the Dryden
//! model's scale length `L` at the airspeed `V`.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use wingman_interfaces::Model;
use wingman_planning::scenario::WindSpec;

use super::GaussMarkov;

/// The wind over one flight.
#[derive(Debug, Clone)]
pub struct Wind {
    mean: [f64; 3],
    gusts: [GaussMarkov; 3],
    /// Axes with gusts: 2 in 2-D, 3 in 3-D.
    axes: usize,
    rng: ChaCha8Rng,
}

impl Wind {
    /// The wind of `spec` for a vehicle of `model` flying at `airspeed` m/s.
    pub fn new(spec: &WindSpec, model: Model, airspeed: f64) -> Wind {
        let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);
        // Its own stream: the navigation errors of the same seed draw from another.
        rng.set_stream(super::WIND_STREAM);
        let tau = spec.gust_length_m / airspeed;
        let axes = model.position_dim();
        let gusts = std::array::from_fn(|i| {
            let sigma = if i < axes { spec.gust_sigma_mps } else { 0.0 };
            GaussMarkov::stationary(sigma, tau, &mut rng)
        });
        let mut mean = spec.mean_mps;
        mean[axes..].fill(0.0);
        Wind {
            mean,
            gusts,
            axes,
            rng,
        }
    }

    /// The wind now, m/s.
    pub fn now(&self) -> [f64; 3] {
        std::array::from_fn(|i| self.mean[i] + self.gusts[i].value())
    }

    /// The gusts `h` seconds on.
    pub fn advance(&mut self, h: f64) {
        for g in &mut self.gusts[..self.axes] {
            g.advance(h, &mut self.rng);
        }
    }
}
