//! Settings of the seed families and the error of building seeds.

/// Bad seed settings or a problem the seeds cannot be built for.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SeedError {
    /// A setting is out of range.
    #[error("seed settings: {0}")]
    Settings(String),
    /// The problem lacks what its objective needs, or holds non-finite numbers.
    #[error("seed problem: {0}")]
    Problem(String),
}

/// Settings of the seed families (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct SeedSettings {
    /// Bulge ratios `b` (bulge point `b · d` off the leg's midpoint), each used to the left
    /// and to the right. Default `[0.25, 0.5]` (the reference's multistart ratios).
    pub bulge_ratios: Vec<f64>,
    /// Number of random seeds. Default 8.
    pub random_seeds: usize,
    /// Largest random bulge ratio. Default 0.6.
    pub random_bulge_max: f64,
    /// Add the length-matched family for `fixed-time` objectives. Default true.
    pub fit_fixed_time: bool,
    /// Add the [`Altitude::High`] profile in 3-D. Default true.
    pub high_profile: bool,
    /// Add the [`Altitude::Early`] and [`Altitude::Late`] profiles in 3-D (descend or
    /// climb early, or late). Default false.
    pub early_late_profiles: bool,
    /// Plateau of the high profile above the higher end of a leg, as a fraction of that
    /// end's altitude. Default 0.1 (15 km ends: a 16.5 km plateau, above threats topping
    /// out at 15 km).
    pub high_margin: f64,
    /// Ramp angle of the high profile as a fraction of `gamma_max`. Default 0.6.
    pub ramp_gamma_ratio: f64,
    /// Most seeds produced; with many legs the arc combinations are subsampled. Default 128.
    pub max_seeds: usize,
    /// Points of each seed's polyline. Default 384.
    pub points_per_seed: usize,
    /// Bisector scan: bulge ratios tried per leg, evenly over `[-scan_max, scan_max]`
    /// (0 turns the scan off). Default 65.
    pub scan_steps: usize,
    /// Largest ratio of the scan. Default 0.8.
    pub scan_max: f64,
    /// Local minima kept per leg (the cheapest). Default 3.
    pub scan_minima: usize,
    /// Scanned combinations (cheapest first) polished in context. Default 8.
    pub scan_polish: usize,
    /// Seed of the random families (ChaCha8).
    pub rng_seed: u64,
}

impl Default for SeedSettings {
    fn default() -> Self {
        SeedSettings {
            bulge_ratios: vec![0.25, 0.5],
            random_seeds: 8,
            random_bulge_max: 0.6,
            fit_fixed_time: true,
            high_profile: true,
            early_late_profiles: false,
            high_margin: 0.1,
            ramp_gamma_ratio: 0.6,
            max_seeds: 128,
            points_per_seed: 384,
            scan_steps: 65,
            scan_max: 0.8,
            scan_minima: 3,
            scan_polish: 8,
            rng_seed: 0x5eed,
        }
    }
}

impl SeedSettings {
    /// Sets [`SeedSettings::bulge_ratios`].
    pub fn with_bulge_ratios(mut self, ratios: &[f64]) -> Self {
        self.bulge_ratios = ratios.to_vec();
        self
    }
    /// Sets [`SeedSettings::random_seeds`].
    pub fn with_random_seeds(mut self, n: usize) -> Self {
        self.random_seeds = n;
        self
    }
    /// Sets [`SeedSettings::random_bulge_max`].
    pub fn with_random_bulge_max(mut self, b: f64) -> Self {
        self.random_bulge_max = b;
        self
    }
    /// Sets [`SeedSettings::fit_fixed_time`].
    pub fn with_fit_fixed_time(mut self, on: bool) -> Self {
        self.fit_fixed_time = on;
        self
    }
    /// Sets [`SeedSettings::high_profile`].
    pub fn with_high_profile(mut self, on: bool) -> Self {
        self.high_profile = on;
        self
    }
    /// Sets [`SeedSettings::early_late_profiles`].
    pub fn with_early_late_profiles(mut self, on: bool) -> Self {
        self.early_late_profiles = on;
        self
    }
    /// Sets [`SeedSettings::high_margin`].
    pub fn with_high_margin(mut self, m: f64) -> Self {
        self.high_margin = m;
        self
    }
    /// Sets [`SeedSettings::max_seeds`].
    pub fn with_max_seeds(mut self, n: usize) -> Self {
        self.max_seeds = n;
        self
    }
    /// Sets [`SeedSettings::points_per_seed`].
    pub fn with_points_per_seed(mut self, n: usize) -> Self {
        self.points_per_seed = n;
        self
    }
    /// Sets [`SeedSettings::scan_steps`].
    pub fn with_scan_steps(mut self, n: usize) -> Self {
        self.scan_steps = n;
        self
    }
    /// Sets [`SeedSettings::scan_minima`].
    pub fn with_scan_minima(mut self, n: usize) -> Self {
        self.scan_minima = n;
        self
    }
    /// Sets [`SeedSettings::rng_seed`].
    pub fn with_rng_seed(mut self, seed: u64) -> Self {
        self.rng_seed = seed;
        self
    }

    /// Checks every setting is in range.
    pub fn validate(&self) -> Result<(), SeedError> {
        let bad = |m: &str| Err(SeedError::Settings(m.to_string()));
        if self.bulge_ratios.len() > 8
            || self
                .bulge_ratios
                .iter()
                .any(|b| !(b.is_finite() && *b > 0.0 && *b <= 4.0))
        {
            return bad("bulge_ratios: at most 8 ratios, each in (0, 4]");
        }
        if !(self.random_bulge_max.is_finite() && (0.0..=4.0).contains(&self.random_bulge_max)) {
            return bad("random_bulge_max must be in [0, 4]");
        }
        if !(self.high_margin.is_finite() && (0.0..=10.0).contains(&self.high_margin)) {
            return bad("high_margin must be in [0, 10]");
        }
        if !(self.ramp_gamma_ratio.is_finite()
            && self.ramp_gamma_ratio > 0.0
            && self.ramp_gamma_ratio <= 1.0)
        {
            return bad("ramp_gamma_ratio must be in (0, 1]");
        }
        if self.max_seeds == 0 || self.max_seeds > 4096 {
            return bad("max_seeds must be in 1..=4096");
        }
        if !(16..=100_000).contains(&self.points_per_seed) {
            return bad("points_per_seed must be in 16..=100000");
        }
        if self.scan_steps == 1 || self.scan_steps > 1001 {
            return bad("scan_steps must be 0 or in 2..=1001");
        }
        if !(self.scan_max.is_finite() && self.scan_max > 0.0 && self.scan_max <= 4.0) {
            return bad("scan_max must be in (0, 4]");
        }
        if self.scan_minima > 16 {
            return bad("scan_minima must be at most 16");
        }
        if self.random_seeds > self.max_seeds {
            return bad("random_seeds must not exceed max_seeds");
        }
        Ok(())
    }
}
