//! The swarm's iteration loop does not allocate: with a warm workspace, a run of 60
//! iterations makes exactly as many allocations as a run of 5 (the seeds, the worker
//! threads and the returned trajectory allocate the same in both), with one thread and
//! with two. The counter is global (every thread's allocations count), so this file holds
//! a single test.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use wingman_planner::clock::{Deadline, ManualClock};
use wingman_planner::problem::Problem;
use wingman_planner::scenario;
use wingman_planner::swarm::{self, SwarmSettings, SwarmWorkspace};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System.alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations_in(f: impl FnOnce()) -> usize {
    let before = ALLOCATIONS.load(Ordering::SeqCst);
    f();
    ALLOCATIONS.load(Ordering::SeqCst) - before
}

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
