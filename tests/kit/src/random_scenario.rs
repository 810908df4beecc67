//! Random well-posed scenarios in the canonical file format, for robustness tests: a mix of
//! models and objectives, 1–2 targets, 3–7 threats placed clear of the start, the targets
//! and the end (so every layout is avoidable), all from one seed.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::fmt::Write;

/// Scenario `index` of the family drawn from `seed`: its name and TOML text.
pub fn random_scenario(seed: u64, index: usize) -> (String, String) {
    let mut rng =
        ChaCha8Rng::seed_from_u64(seed.wrapping_mul(1_000_003).wrapping_add(index as u64));
    let three_d = index % 2 == 1;
    let objective = ["fixed-time", "min-time", "min-time-rendezvous"][index % 3];
    let name = format!(
        "random-{index:02}-{}-{objective}",
        if three_d { "3d" } else { "2d" }
    );
    let speed: f64 = if three_d {
        rng.random_range(200.0..260.0)
    } else {
        rng.random_range(150.0..220.0)
    };
    let z = |rng: &mut ChaCha8Rng| rng.random_range(2000.0..12000.0f64);
    let fmt = |p: &[f64]| {
        let items: Vec<String> = p.iter().map(|v| format!("{v:.1}")).collect();
        format!("[{}]", items.join(", "))
    };
    let start = if three_d {
        vec![0.0, 0.0, 10000.0]
    } else {
        vec![0.0, 0.0]
    };
    let heading: f64 = rng.random_range(-30.0..30.0);
    let n_targets = rng.random_range(1..=2usize);
    let mut keep_clear: Vec<Vec<f64>> = vec![start.clone()];
    let mut targets = Vec::new();
    for k in 0..n_targets {
        let r = rng.random_range(30000.0..50000.0) * (k + 1) as f64 * 0.8;
        let a: f64 = rng.random_range(-0.9..0.9);
        let mut p = vec![r * a.cos(), r * a.sin()];
        if three_d {
            p.push(z(&mut rng));
        }
        keep_clear.push(p.clone());
        targets.push(p);
    }
    let mut text = String::new();
    let _ = writeln!(
        text,
        "name = \"{name}\"\nsummary = \"random robustness scenario {index} (seed {seed})\""
    );
    let _ = writeln!(
        text,
        "model = \"{}\"\nobjective = \"{objective}\"\n",
        if three_d { "3d" } else { "2d" }
    );
    if three_d {
        let _ = writeln!(
            text,
            "[vehicle]\nspeed_mps = {speed:.1}\ngamma_max_deg = 30.0\nnz_min = -1.0\nnz_max = 4.0\nbank_max_deg = 70.0\nnz_rate_max_per_s = 1.0\nbank_rate_max_dps = 30.0\naltitude_min_m = 500.0\n"
        );
    } else {
        let _ = writeln!(
            text,
            "[vehicle]\nspeed_mps = {speed:.1}\nturn_rate_max_dps = 5.0\n"
        );
    }
    let _ = writeln!(
        text,
        "[weights]\nalpha = 0.05\nbeta = 0.95\nstiffness = 30.0\n"
    );
    let _ = writeln!(
        text,
        "[start]\ntime_s = 0.0\nposition_m = {}\nheading_deg = {heading:.1}",
        fmt(&start)
    );
    if three_d {
        let _ = writeln!(text, "gamma_deg = 0.0");
    }
    let _ = writeln!(text);
    for t in &targets {
        let _ = writeln!(text, "[[targets]]\nposition_m = {}\n", fmt(t));
    }
    let last = targets.last().cloned().unwrap_or_else(|| start.clone());
    if objective == "min-time-rendezvous" {
        let route_end = if three_d {
            vec![400000.0, 0.0, 10000.0]
        } else {
            vec![400000.0, 0.0]
        };
        let lead_speed = speed * rng.random_range(0.6..0.8);
        let _ = writeln!(
            text,
            "[lead]\nroute_m = [{}, {}]\nspeed_mps = {lead_speed:.1}\n",
            fmt(&start),
            fmt(&route_end)
        );
        // The rendezvous happens somewhere ahead along +x: keep a corridor clear.
        keep_clear.push(if three_d {
            vec![last[0] + 40000.0, 0.0, 10000.0]
        } else {
            vec![last[0] + 40000.0, 0.0]
        });
    } else {
        let a: f64 = rng.random_range(-0.6..0.6);
        let mut f = vec![last[0] + 40000.0 * a.cos(), last[1] + 40000.0 * a.sin()];
        if three_d {
            f.push(z(&mut rng));
        }
        keep_clear.push(f.clone());
        let path_len: f64 = keep_clear
            .windows(2)
            .map(|w| ((w[1][0] - w[0][0]).powi(2) + (w[1][1] - w[0][1]).powi(2)).sqrt())
            .sum();
        let _ = writeln!(
            text,
            "[final]\nposition_m = {}\nheading_deg = {:.1}",
            fmt(&f),
            rng.random_range(-60.0..60.0f64)
        );
        if three_d {
            let _ = writeln!(text, "gamma_deg = 0.0");
        }
        if objective == "fixed-time" {
            let _ = writeln!(text, "time_s = {:.1}", 1.35 * path_len / speed);
        }
        let _ = writeln!(text);
    }
    let n_threats = rng.random_range(3..=7usize);
    let mut placed = 0;
    let mut tries = 0;
    while placed < n_threats && tries < 1000 {
        tries += 1;
        // Near a leg (so the straight path would cross it), clear of the leg's end points.
        let leg = rng.random_range(0..keep_clear.len() - 1);
        let (a, b) = (&keep_clear[leg], &keep_clear[leg + 1]);
        let f: f64 = rng.random_range(0.25..0.75);
        let side: f64 = rng.random_range(-6000.0..6000.0);
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len = dx.hypot(dy).max(1.0);
        let c: [f64; 2] = [
            a[0] + f * dx - side * dy / len,
            a[1] + f * dy + side * dx / len,
        ];
        let axes: [f64; 2] = [
            rng.random_range(3000.0..12000.0),
            rng.random_range(3000.0..12000.0),
        ];
        let clearance = axes[0].max(axes[1]) + 8000.0;
        if keep_clear
            .iter()
            .any(|p| ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt() < clearance)
        {
            continue;
        }
        let yaw: f64 = rng.random_range(0.0..180.0);
        let _ = writeln!(text, "[[threats]]\nname = \"t{placed}\"");
        if three_d {
            let _ = writeln!(
                text,
                "center_m = [{:.1}, {:.1}, 0.0]\naxes_m = [{:.1}, {:.1}, {:.1}]",
                c[0],
                c[1],
                axes[0],
                axes[1],
                rng.random_range(5000.0..15000.0f64)
            );
        } else {
            let _ = writeln!(
                text,
                "center_m = [{:.1}, {:.1}]\naxes_m = [{:.1}, {:.1}]",
                c[0], c[1], axes[0], axes[1]
            );
        }
        let _ = writeln!(text, "yaw_deg = {yaw:.1}\n");
        placed += 1;
    }
    (name, text)
}
