//! A short run of the input fuzzer (`wingman_tests::fuzz`; the `fuzz_inputs` binary runs
//! a million cases): random and mutated input messages through `validate()` and a
//! running planner service's message loop. It fails on a non-finite number past
//! `validate()`, a message the service rejects that passed `validate()` (or one it lets
//! through that failed it), a message the service does not read, an invalid plan or
//! status, or a service that panics or stops.

use wingman_testkit::process::vehicle;
use wingman_tests::fuzz;

#[test]
fn twenty_thousand_fuzzed_inputs_are_checked_counted_and_survived() {
    wingman_ipc::logging::init();
    for seed in [1, 2] {
        let s = fuzz::run(10_000, seed, &vehicle(&format!("fuzz-in-{seed}")), |_| {})
            .unwrap_or_else(|f| panic!("seed {seed}: {f}"));
        assert_eq!(s.cases, 10_000);
        assert_eq!(s.valid + s.invalid, s.cases);
        // Both kinds are exercised: the mutated messages that stay valid reach the
        // handlers, the others are rejected.
        assert!(
            s.valid > 1000 && s.invalid > 1000,
            "seed {seed}: {} valid, {} invalid",
            s.valid,
            s.invalid
        );
    }
}
