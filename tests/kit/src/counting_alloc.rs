//! A counting global allocator for no-allocation tests. The count is per thread (a
//! `const`-initialised thread-local, which itself never allocates), so tests running in
//! parallel do not disturb each other. A test binary installs it with
//! [`counting_allocator!`](crate::counting_allocator) and counts with [`allocations_in`].

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The counting allocator: the system allocator, with every allocation and reallocation
/// counted on the calling thread.
pub struct Counting;

/// Allocations of every thread of the process.
static PROCESS_ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        PROCESS_ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System.alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        PROCESS_ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// Installs [`Counting`] as the test binary's global allocator.
#[macro_export]
macro_rules! counting_allocator {
    () => {
        #[global_allocator]
        static COUNTING_ALLOCATOR: $crate::counting_alloc::Counting =
            $crate::counting_alloc::Counting;
    };
}

/// Allocations made on this thread while running `f`.
pub fn allocations_in(f: impl FnOnce()) -> usize {
    let before = ALLOCATIONS.with(Cell::get);
    f();
    ALLOCATIONS.with(Cell::get) - before
}

/// Allocations made by every thread of the process while running `f` (a test that counts
/// this way must be alone in its test binary).
pub fn process_allocations_in(f: impl FnOnce()) -> usize {
    let before = PROCESS_ALLOCATIONS.load(Ordering::SeqCst);
    f();
    PROCESS_ALLOCATIONS.load(Ordering::SeqCst) - before
}
