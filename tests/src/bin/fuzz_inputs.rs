//! `fuzz_inputs`: random and mutated bytes of every input message through `validate()`
//! and a planner service's message loop, seeded (`wingman_tests::fuzz`).
//!
//!     cargo run --release -p wingman-tests --bin fuzz_inputs -- --cases 1000000 --seed 1
//!
//! Prints the progress and a summary; exits 1 with the failing case (its type and bytes)
//! on the first failure.

use std::io::Write;
use std::process::ExitCode;

use wingman_tests::fuzz;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().collect();
    let value = |name: &str, default: u64| -> Result<u64, String> {
        match args.iter().position(|a| a == name) {
            None => Ok(default),
            Some(i) => args
                .get(i + 1)
                .and_then(|v| v.parse().ok())
                .ok_or_else(|| format!("{name} takes a whole number")),
        }
    };
    let (cases, seed) = match (value("--cases", 1_000_000), value("--seed", 1)) {
        (Ok(c), Ok(s)) => (c, s),
        (Err(e), _) | (_, Err(e)) => {
            eprintln!("fuzz_inputs: {e}\nusage: fuzz_inputs [--cases N] [--seed S]");
            return ExitCode::from(2);
        }
    };
    let vehicle = format!("fuzz-{}", std::process::id());
    let started = std::time::Instant::now();
    let step = (cases / 20).max(1);
    let mut next = step;
    let progress = |done: u64| {
        if done >= next || done == cases {
            let elapsed = started.elapsed().as_secs_f64();
            let left = elapsed / done as f64 * (cases - done) as f64;
            eprint!("\r{done} of {cases} cases, {elapsed:.0} s, about {left:.0} s left   ");
            let _ = std::io::stderr().flush();
            next = done + step;
        }
    };
    match fuzz::run(cases, seed, &vehicle, progress) {
        Ok(s) => {
            eprintln!();
            println!(
                "{} cases (seed {seed}) in {:.1} s: {} passed validate() and reached the \
                 handlers, {} failed it and were rejected, every one counted; {} plans \
                 published, every plan and status valid; no panic",
                s.cases,
                s.elapsed.as_secs_f64(),
                s.valid,
                s.invalid,
                s.plans
            );
            ExitCode::SUCCESS
        }
        Err(f) => {
            eprintln!();
            eprintln!("fuzz_inputs: FAILED: {f}");
            ExitCode::FAILURE
        }
    }
}
