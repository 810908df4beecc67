//! The dense Bunch–Kaufman kernels of the structured KKT backend on blocks shaped like the
//! LGR collocation's (a primal part with 9×9 node blocks, defect rows 30 % dense, a small
//! negative dual diagonal): 42 rows (a 2-D block), 64 and 96 (3-D ranking and working
//! meshes), and with the pivot groups out of the blocks 25 and 30 (2-D ranking and
//! working), 48 and 72 (3-D). Blocked (`dsytrf`-style panels) against unblocked, each on the dispatched
//! (AVX2 where present) and the baseline SSE2 path; and one single-column solve.
//!
//! `cargo bench -p wingman-planning --bench kkt`

use criterion::{Criterion, criterion_group, criterion_main};
use wingman_planning::linalg::bunch_kaufman as bk;

mod common;
use common::kkt_block;

fn factor(c: &mut Criterion) {
    let mut g = c.benchmark_group("bunch_kaufman");
    for (nx, m) in [
        (24, 18),
        (36, 28),
        (52, 44),
        (15, 10),
        (18, 12),
        (28, 20),
        (42, 30),
    ] {
        let n = nx + m;
        let k = kkt_block(nx, m, n as u64);
        let mut a = k.clone();
        let mut piv = vec![0i32; n];
        let mut work = vec![0.0; bk::work_len(n)];
        type Factor = fn(&mut [f64], usize, &mut [i32], &mut [f64]) -> Option<bk::Inertia>;
        let paths: [(&str, Factor, bool); 4] = [
            ("blocked", bk::factor, true),
            ("unblocked", bk::factor, false),
            ("blocked sse2", bk::factor_portable, true),
            ("unblocked sse2", bk::factor_portable, false),
        ];
        for (name, f, blocked) in paths {
            g.bench_function(format!("factor n={n} {name}"), |b| {
                b.iter(|| {
                    a.copy_from_slice(&k);
                    let w: &mut [f64] = if blocked { &mut work } else { &mut [] };
                    f(&mut a, n, &mut piv, w).expect("nonsingular")
                })
            });
        }
        a.copy_from_slice(&k);
        bk::factor(&mut a, n, &mut piv, &mut work).expect("nonsingular");
        let rhs: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let mut x = rhs.clone();
        g.bench_function(format!("solve n={n}"), |b| {
            b.iter(|| {
                x.copy_from_slice(&rhs);
                bk::solve(&a, n, &piv, &mut x);
            })
        });
    }
    g.finish();
}

criterion_group!(benches, factor);
criterion_main!(benches);
