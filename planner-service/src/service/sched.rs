//! The message thread's place in the kernel's scheduler: a short time slice, so that a
//! message wakes it at once on a core another process keeps busy.
//!
//! Linux's fair scheduler (EEVDF, kernel 6.6 and later) lets a woken thread preempt the
//! running one when the woken thread's virtual deadline is earlier; the deadline is its
//! eligible time plus its slice. With the default slice (a few ms) a thread woken by an
//! `OwnshipState` may wait up to a slice behind a busy process of the same weight before
//! it runs; with a slice of 0.1 ms its deadline comes first and it runs at once. The
//! thread's share of the CPU does not change (that is its weight: `nice`, the unit's
//! `CPUWeight=`); only *when* it runs. The message thread works microseconds per message,
//! so a short slice costs nothing. Kernels since 6.12 take a fair thread's slice from
//! `sched_attr::sched_runtime` (0.1–100 ms, no privilege needed); older kernels ignore it,
//! and the service says so in its log and runs on with the default.
//!
//! Only the calling thread is changed, and the threads it starts afterwards (they inherit
//! it): the service sets it after the solve thread is started, so the solve thread and the
//! swarm's workers it starts keep the default slice (they run for a plan's whole budget; a
//! short slice would only make them switch more often).

use std::time::Duration;

/// `struct sched_attr` of `sched_setattr(2)` (`SCHED_ATTR_SIZE_VER1`, 56 bytes).
#[repr(C)]
#[derive(Debug, Default, Clone, Copy)]
struct SchedAttr {
    size: u32,
    sched_policy: u32,
    sched_flags: u64,
    sched_nice: i32,
    sched_priority: u32,
    sched_runtime: u64,
    sched_deadline: u64,
    sched_period: u64,
    sched_util_min: u32,
    sched_util_max: u32,
}

/// `SCHED_OTHER` and `SCHED_BATCH`: the fair policies a slice applies to.
const SCHED_OTHER: u32 = 0;
const SCHED_BATCH: u32 = 3;

/// Shortest and longest slice the kernel accepts for a fair thread.
pub const MIN_SLICE: Duration = Duration::from_micros(100);
pub const MAX_SLICE: Duration = Duration::from_millis(100);

/// What [`set_thread_slice`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SliceOutcome {
    /// The calling thread's slice is now the one asked for.
    Applied(Duration),
    /// The kernel took the call but reports another slice (a kernel before 6.12, which
    /// has no per-thread slice): the default stays.
    NotSupported,
    /// The thread runs under a real-time or deadline policy (set by whoever started the
    /// service, e.g. the unit's `CPUSchedulingPolicy=`): left as it is.
    NotFair(u32),
}

/// Sets the calling thread's fair-scheduler slice to `slice` (clamped to
/// [`MIN_SLICE`]..=[`MAX_SLICE`]), keeping its policy and nice value.
pub fn set_thread_slice(slice: Duration) -> std::io::Result<SliceOutcome> {
    let slice = slice.clamp(MIN_SLICE, MAX_SLICE);
    match set_runtime(slice.as_nanos() as u64)? {
        Some(policy) => Ok(SliceOutcome::NotFair(policy)),
        None => Ok(match thread_slice()? {
            Some(now) if now == slice => SliceOutcome::Applied(slice),
            _ => SliceOutcome::NotSupported,
        }),
    }
}

/// Gives the calling thread the kernel's default slice again (a fair thread only).
pub fn reset_thread_slice() -> std::io::Result<()> {
    set_runtime(0).map(|_| ())
}

/// Sets the calling fair thread's `sched_runtime` (0: the default slice), keeping its
/// policy and nice value; `Some(policy)` (and nothing changed) if it is not fair.
fn set_runtime(ns: u64) -> std::io::Result<Option<u32>> {
    let mut attr = thread_attr()?;
    if attr.sched_policy != SCHED_OTHER && attr.sched_policy != SCHED_BATCH {
        return Ok(Some(attr.sched_policy));
    }
    attr.size = size_of::<SchedAttr>() as u32;
    attr.sched_flags = 0;
    attr.sched_runtime = ns;
    // SAFETY: `attr` is a valid, initialised `sched_attr` of the size it states; pid 0 is
    // the calling thread; the kernel only reads it.
    let rc = unsafe {
        libc::syscall(
            libc::SYS_sched_setattr,
            0 as libc::pid_t,
            &attr as *const SchedAttr,
            0 as libc::c_uint,
        )
    };
    if rc != 0 {
        return Err(std::io::Error::last_os_error());
    }
    Ok(None)
}

/// The calling thread's fair-scheduler slice as the kernel reports it (`None`: not a fair
/// thread, or a kernel that does not report it).
pub fn thread_slice() -> std::io::Result<Option<Duration>> {
    let attr = thread_attr()?;
    let fair = attr.sched_policy == SCHED_OTHER || attr.sched_policy == SCHED_BATCH;
    Ok((fair && attr.sched_runtime > 0).then(|| Duration::from_nanos(attr.sched_runtime)))
}

/// The running kernel's release as (major, minor), from `/proc/sys/kernel/osrelease`
/// ((0, 0) if it cannot be read): per-thread slices need 6.12.
pub fn kernel_release() -> (u32, u32) {
    let r = std::fs::read_to_string("/proc/sys/kernel/osrelease").unwrap_or_default();
    let mut it = r.trim().split(|c: char| !c.is_ascii_digit());
    let mut num = || it.next().and_then(|v| v.parse().ok()).unwrap_or(0);
    (num(), num())
}

fn thread_attr() -> std::io::Result<SchedAttr> {
    let mut attr = SchedAttr::default();
    // SAFETY: `attr` is writable for the size passed; pid 0 is the calling thread.
    let rc = unsafe {
        libc::syscall(
            libc::SYS_sched_getattr,
            0 as libc::pid_t,
            &mut attr as *mut SchedAttr,
            size_of::<SchedAttr>() as libc::c_uint,
            0 as libc::c_uint,
        )
    };
    if rc != 0 {
        return Err(std::io::Error::last_os_error());
    }
    Ok(attr)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_slice_set_is_the_slice_the_kernel_reports_and_a_thread_started_before_keeps_its_own() {
        let mine = thread_slice().expect("sched_getattr");
        let set = std::thread::spawn(|| {
            let before = thread_slice().expect("sched_getattr");
            let outcome = set_thread_slice(Duration::from_micros(250)).expect("sched_setattr");
            let after = thread_slice().expect("sched_getattr");
            reset_thread_slice().expect("sched_setattr");
            assert_eq!(thread_slice().expect("sched_getattr"), before, "reset");
            (before, outcome, after)
        })
        .join()
        .expect("thread");
        let (before, outcome, after) = set;
        if kernel_release() >= (6, 12) {
            assert_eq!(outcome, SliceOutcome::Applied(Duration::from_micros(250)));
            assert_eq!(after, Some(Duration::from_micros(250)));
            assert_ne!(before, Some(Duration::from_micros(250)));
        } else {
            assert_ne!(outcome, SliceOutcome::Applied(Duration::from_micros(250)));
        }
        // This thread, started before, keeps the slice it had.
        assert_eq!(thread_slice().expect("sched_getattr"), mine);
    }

    #[test]
    fn a_slice_outside_the_kernels_range_is_clamped() {
        std::thread::spawn(|| {
            let outcome = set_thread_slice(Duration::from_micros(1)).expect("sched_setattr");
            if kernel_release() >= (6, 12) {
                assert_eq!(outcome, SliceOutcome::Applied(MIN_SLICE));
            }
            let outcome = set_thread_slice(Duration::from_secs(1)).expect("sched_setattr");
            if kernel_release() >= (6, 12) {
                assert_eq!(outcome, SliceOutcome::Applied(MAX_SLICE));
            }
        })
        .join()
        .expect("thread");
    }
}
