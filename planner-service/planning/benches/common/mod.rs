//! For the benches: a symmetric block shaped like the LGR collocation's KKT blocks, the
//! host's speed, percentiles. `mod common;` in a bench.

#![allow(dead_code)]

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

/// The host's speed now: a fixed workload (400 dense Bunch–Kaufman factorisations of one
/// 72 × 72 KKT-shaped block, the planner's hottest kernel) run on two threads at once, as
/// the planner runs; the slower thread's median of three timings, in ms. Timed before
/// every round of plans, so that their times can be read against the speed the host had
/// while they ran (a shared VM's speed swings by up to 1.8× within minutes;
/// docs/decisions/0024-measuring-on-a-noisy-host.md).
pub fn host_reference_ms() -> f64 {
    std::thread::scope(|s| {
        let other = s.spawn(reference_workload_ms);
        let here = reference_workload_ms();
        here.max(other.join().expect("the reference workload does not panic"))
    })
}

/// One thread's part of [`host_reference_ms`]: the block of the kkt bench's `n = 72`
/// case (42 primal and 30 dual rows).
fn reference_workload_ms() -> f64 {
    use wingman_planning::linalg::bunch_kaufman as bk;
    const N: usize = 72;
    let k = kkt_block(42, 30, N as u64);
    let mut a = k.clone();
    let mut piv = vec![0i32; N];
    let mut work = vec![0.0; bk::work_len(N)];
    let mut times: Vec<f64> = (0..3)
        .map(|_| {
            let began = std::time::Instant::now();
            for _ in 0..400 {
                a.copy_from_slice(&k);
                std::hint::black_box(bk::factor(&mut a, N, &mut piv, &mut work))
                    .expect("the reference block is nonsingular");
            }
            began.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[1]
}

pub fn percentile(sorted: &[f64], p: f64) -> f64 {
    let k = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted[k.min(sorted.len() - 1)]
}
