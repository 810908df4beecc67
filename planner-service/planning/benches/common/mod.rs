//! A symmetric block shaped like the LGR collocation's KKT blocks, for the benches.
//! `mod common;` in a bench.

use rand::{RngExt, SeedableRng};

/// A KKT-shaped symmetric block of `nx` primal and `m` dual rows (full storage).
pub fn kkt_block(nx: usize, m: usize, seed: u64) -> Vec<f64> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let n = nx + m;
    let mut k = vec![0.0; n * n];
    for i in 0..nx {
        k[i + i * n] = rng.random_range(0.5..2.0);
        for j in 0..i {
            if i / 9 == j / 9 {
                let v: f64 = rng.random_range(-0.3..0.3);
                k[i + j * n] = v;
                k[j + i * n] = v;
            }
        }
    }
    for r in nx..n {
        k[r + r * n] = -1e-8;
        for c in 0..nx {
            if rng.random_range(0.0..1.0) < 0.3 {
                let v = rng.random_range(-1.0..1.0);
                k[r + c * n] = v;
                k[c + r * n] = v;
            }
        }
    }
    k
}
