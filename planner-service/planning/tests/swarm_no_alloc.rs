//! The swarm's iteration loop does not allocate: with a warm workspace, a run of 60
//! iterations makes exactly as many allocations as a run of 5 (the seeds, the worker
//! threads and the returned trajectory allocate the same in both), with one thread and
//! with two. The counter is global (every thread's allocations count), so this file holds
//! a single test.

use wingman_planning::clock::{Deadline, ManualClock};
use wingman_planning::problem::Problem;
use wingman_planning::scenario;
use wingman_planning::swarm::{self, SwarmSettings, SwarmWorkspace};
use wingman_testkit::counting_alloc::process_allocations_in as allocations_in;

wingman_testkit::counting_allocator!();

#[test]
fn the_iteration_loop_does_not_allocate() {
    let clock = ManualClock::new();
    for name in [
        "2d-min-time-rendezvous-avoidable",
        "3d-min-time-moving-threat",
    ] {
        let sc = scenario::bundled(name)
            .unwrap_or_else(|| panic!("{name}"))
            .unwrap_or_else(|e| panic!("{e}"));
        let p = Problem::from_scenario(&sc).unwrap_or_else(|e| panic!("{e}"));
        for threads in [1, 2] {
            let base = SwarmSettings::default()
                .with_threads(threads)
                .with_particles(8)
                .with_groups(2)
                .with_stall_iterations(1_000_000)
                .with_max_iterations(60);
            let mut ws = SwarmWorkspace::new(&base);
            let run = |ws: &mut SwarmWorkspace, iterations: usize| {
                let s = base.clone().with_max_iterations(iterations);
                let o = swarm::run(&p, &s, ws, Deadline::never(&clock))
                    .unwrap_or_else(|e| panic!("{e}"));
                assert_eq!(o.iterations, iterations);
            };
            // Warm-up: the seeds' buffers grow to this problem's size.
            run(&mut ws, 60);
            let few = allocations_in(|| run(&mut ws, 5));
            let many = allocations_in(|| run(&mut ws, 60));
            assert_eq!(
                few, many,
                "{name}, {threads} thread(s): 5 iterations allocate {few} times, 60 iterations {many}"
            );
        }
    }
}
