//! Random well-posed scenarios in the canonical file format, for robustness tests: a mix of
//! models and objectives, 1–2 targets, 3–7 threats placed clear of the start, the targets
//! and the end (so every layout is avoidable), all from one seed.
//!
//! Every part is drawn from the one stream in the order of the file's sections: the speed,
//! the start heading, the targets, the lead or the final point, the threats.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::fmt::Write;

/// The model, objective and speed of one scenario: what every section depends on.
struct Shape {
    three_d: bool,
    objective: &'static str,
    speed: f64,
}

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
    let shape = Shape {
        three_d,
        objective,
        speed,
    };
    let start = if three_d {
        vec![0.0, 0.0, 10000.0]
    } else {
        vec![0.0, 0.0]
    };
    let heading: f64 = rng.random_range(-30.0..30.0);
    let targets = draw_targets(&mut rng, three_d);
    let mut keep_clear: Vec<Vec<f64>> = vec![start.clone()];
    keep_clear.extend(targets.iter().cloned());

    let mut text = String::new();
    write_header(&mut text, &name, seed, index, &shape);
    write_start(&mut text, &start, heading, three_d);
    for t in &targets {
        let _ = writeln!(text, "[[targets]]\nposition_m = {}\n", position(t));
    }
    let last = targets.last().cloned().unwrap_or_else(|| start.clone());
    if objective == "min-time-rendezvous" {
        write_lead(&mut text, &mut rng, &shape, &start);
        // The rendezvous happens somewhere ahead along +x: keep a corridor clear.
        keep_clear.push(if three_d {
            vec![last[0] + 40000.0, 0.0, 10000.0]
        } else {
            vec![last[0] + 40000.0, 0.0]
        });
    } else {
        write_final(&mut text, &mut rng, &shape, &last, &mut keep_clear);
    }
    write_threats(&mut text, &mut rng, three_d, &keep_clear);
    (name, text)
}

/// A position as a TOML array, to 0.1 m.
fn position(p: &[f64]) -> String {
    let items: Vec<String> = p.iter().map(|v| format!("{v:.1}")).collect();
    format!("[{}]", items.join(", "))
}

/// A random altitude of a target or end point.
fn altitude(rng: &mut ChaCha8Rng) -> f64 {
    rng.random_range(2000.0..12000.0f64)
}

/// 1–2 targets ahead of the start, each further out than the last.
fn draw_targets(rng: &mut ChaCha8Rng, three_d: bool) -> Vec<Vec<f64>> {
    let n_targets = rng.random_range(1..=2usize);
    let mut targets = Vec::new();
    for k in 0..n_targets {
        let r = rng.random_range(30000.0..50000.0) * (k + 1) as f64 * 0.8;
        let a: f64 = rng.random_range(-0.9..0.9);
        let mut p = vec![r * a.cos(), r * a.sin()];
        if three_d {
            p.push(altitude(rng));
        }
        targets.push(p);
    }
    targets
}

/// The name, summary, model and objective, the vehicle and the weights.
fn write_header(text: &mut String, name: &str, seed: u64, index: usize, shape: &Shape) {
    let Shape {
        three_d,
        objective,
        speed,
    } = *shape;
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
}

/// The `[start]` section.
fn write_start(text: &mut String, start: &[f64], heading: f64, three_d: bool) {
    let _ = writeln!(
        text,
        "[start]\ntime_s = 0.0\nposition_m = {}\nheading_deg = {heading:.1}",
        position(start)
    );
    if three_d {
        let _ = writeln!(text, "gamma_deg = 0.0");
    }
    let _ = writeln!(text);
}

/// The `[lead]` of a rendezvous: a straight route along +x, slower than the vehicle.
fn write_lead(text: &mut String, rng: &mut ChaCha8Rng, shape: &Shape, start: &[f64]) {
    let route_end = if shape.three_d {
        vec![400000.0, 0.0, 10000.0]
    } else {
        vec![400000.0, 0.0]
    };
    let lead_speed = shape.speed * rng.random_range(0.6..0.8);
    let _ = writeln!(
        text,
        "[lead]\nroute_m = [{}, {}]\nspeed_mps = {lead_speed:.1}\n",
        position(start),
        position(&route_end)
    );
}

/// The `[final]` point 40 km beyond the last target (added to `keep_clear`), and for a
/// fixed-time scenario a final time with some slack over the straight path.
fn write_final(
    text: &mut String,
    rng: &mut ChaCha8Rng,
    shape: &Shape,
    last: &[f64],
    keep_clear: &mut Vec<Vec<f64>>,
) {
    let a: f64 = rng.random_range(-0.6..0.6);
    let mut f = vec![last[0] + 40000.0 * a.cos(), last[1] + 40000.0 * a.sin()];
    if shape.three_d {
        f.push(altitude(rng));
    }
    keep_clear.push(f.clone());
    let path_len: f64 = keep_clear
        .windows(2)
        .map(|w| ((w[1][0] - w[0][0]).powi(2) + (w[1][1] - w[0][1]).powi(2)).sqrt())
        .sum();
    let _ = writeln!(
        text,
        "[final]\nposition_m = {}\nheading_deg = {:.1}",
        position(&f),
        rng.random_range(-60.0..60.0f64)
    );
    if shape.three_d {
        let _ = writeln!(text, "gamma_deg = 0.0");
    }
    if shape.objective == "fixed-time" {
        let _ = writeln!(text, "time_s = {:.1}", 1.35 * path_len / shape.speed);
    }
    let _ = writeln!(text);
}

/// 3–7 `[[threats]]` near the legs between the `keep_clear` points and clear of them (at
/// most 1000 tries).
fn write_threats(text: &mut String, rng: &mut ChaCha8Rng, three_d: bool, keep_clear: &[Vec<f64>]) {
    let n_threats = rng.random_range(3..=7usize);
    let mut placed = 0;
    let mut tries = 0;
    while placed < n_threats && tries < 1000 {
        tries += 1;
        let Some((c, axes)) = draw_footprint(rng, keep_clear) else {
            continue;
        };
        write_threat(text, rng, placed, c, axes, three_d);
        placed += 1;
    }
}

/// The center and axes of a threat near a leg (so the straight path would cross it), or
/// `None` when it comes too near one of the `keep_clear` points.
fn draw_footprint(rng: &mut ChaCha8Rng, keep_clear: &[Vec<f64>]) -> Option<([f64; 2], [f64; 2])> {
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
    let too_near = keep_clear
        .iter()
        .any(|p| ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt() < clearance);
    (!too_near).then_some((c, axes))
}

/// One `[[threats]]` section named `t{placed}`, with a random yaw (and height in 3-D).
fn write_threat(
    text: &mut String,
    rng: &mut ChaCha8Rng,
    placed: usize,
    c: [f64; 2],
    axes: [f64; 2],
    three_d: bool,
) {
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
}
