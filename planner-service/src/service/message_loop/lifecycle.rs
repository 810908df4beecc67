//! The plan lifecycle as explicit states: what the loop is doing about its next plan
//! ([`PlanLifecycle`]) and, before its first plan is triggered, about that one
//! ([`FirstPlan`]). Both are plain `Copy` values: a transition allocates nothing.

use std::time::Duration;

use crate::service::solver::Ticket;
use crate::service::triggers::TriggerSet;

/// Triggers waiting for a plan.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Pending {
    pub(super) set: TriggerSet,
    /// Mission time of the newest trigger folded in.
    pub(super) created_at_s: f64,
}

/// What the loop is doing about its next plan, one state at a time:
///
/// ```text
///           triggers folded in            gate admits: plan submitted
///   Idle ─────────────────────► Triggered ──────────────────────────► Planning ──┐
///    ▲                          │      │ gate refuses                 ▲  triggers │
///    │ nothing to start from,   │      ▼                              │  coalesce │
///    │ mission over, an error   │   Deferred ───── gate admits ───────┘  into its │
///    └──────────────────────────┘      (more triggers join it)           follow-up │
///    ▲                                                                              │
///    └──── result taken: Idle, or Triggered with the follow-up (same pass) ◄────────┘
/// ```
///
/// `Triggered` and `Deferred` always hold at least one trigger; `Planning`'s follow-up may
/// be empty (no follow-up).
#[derive(Debug, Clone, Copy, Default)]
pub(super) enum PlanLifecycle {
    /// Nothing triggered and no plan computed.
    #[default]
    Idle,
    /// Triggers that the compute gate has not been asked about yet. Only inside a pass:
    /// from a batch folded in (or a finished plan's follow-up) to `try_start`.
    Triggered(Pending),
    /// Triggers the compute gate deferred (counted once in `triggers_deferred`, however
    /// many join them); the WaitSet wakes at `wake_at`, when the gate will admit them.
    Deferred {
        pending: Pending,
        wake_at: Option<Duration>,
    },
    /// A plan is computed by the solve thread (at most one at a time). `follow_up`: the
    /// triggers raised meanwhile, coalesced into one follow-up plan with the newest world.
    Planning { ticket: Ticket, follow_up: Pending },
}

impl PlanLifecycle {
    /// A plan is computed.
    pub(super) fn is_planning(&self) -> bool {
        matches!(self, PlanLifecycle::Planning { .. })
    }

    /// The triggers waiting for a plan: the triggered or deferred ones, or those of the
    /// follow-up of the plan computed.
    pub(super) fn pending(&self) -> TriggerSet {
        match self {
            PlanLifecycle::Idle => TriggerSet::EMPTY,
            PlanLifecycle::Triggered(p) | PlanLifecycle::Deferred { pending: p, .. } => p.set,
            PlanLifecycle::Planning { follow_up, .. } => follow_up.set,
        }
    }

    /// Folds triggers raised at mission time `now_s` into the pending ones (a plan in
    /// flight: into its follow-up; a deferred plan stays deferred).
    pub(super) fn fold(&mut self, set: TriggerSet, now_s: f64) {
        match self {
            PlanLifecycle::Idle if set.is_empty() => {}
            PlanLifecycle::Idle => {
                *self = PlanLifecycle::Triggered(Pending {
                    set,
                    created_at_s: now_s,
                })
            }
            PlanLifecycle::Triggered(p)
            | PlanLifecycle::Deferred { pending: p, .. }
            | PlanLifecycle::Planning { follow_up: p, .. } => {
                p.set = p.set.union(set);
                p.created_at_s = now_s;
            }
        }
    }

    /// The gate refused the pending triggers: deferred until `wake_at`. Returns whether
    /// they were deferred just now (not already).
    pub(super) fn defer(&mut self, wake_at: Option<Duration>) -> bool {
        match *self {
            PlanLifecycle::Triggered(pending) => {
                *self = PlanLifecycle::Deferred { pending, wake_at };
                true
            }
            PlanLifecycle::Deferred { pending, .. } => {
                *self = PlanLifecycle::Deferred { pending, wake_at };
                false
            }
            PlanLifecycle::Idle | PlanLifecycle::Planning { .. } => false,
        }
    }

    /// The plan computed is done: its follow-up, if any, is triggered.
    pub(super) fn plan_done(&mut self) {
        if let PlanLifecycle::Planning { follow_up, .. } = *self {
            *self = if follow_up.set.is_empty() {
                PlanLifecycle::Idle
            } else {
                PlanLifecycle::Triggered(follow_up)
            };
        }
    }

    /// Drops the pending triggers (a plan in flight stays in flight, without follow-up).
    pub(super) fn drop_pending(&mut self) {
        *self = match *self {
            PlanLifecycle::Planning { ticket, .. } => PlanLifecycle::Planning {
                ticket,
                follow_up: Pending::default(),
            },
            _ => PlanLifecycle::Idle,
        };
    }

    /// When a deferred plan is due (wall clock).
    pub(super) fn deferred_until(&self) -> Option<Duration> {
        match self {
            PlanLifecycle::Deferred { pending, wake_at } if !pending.set.is_empty() => *wake_at,
            _ => None,
        }
    }
}

/// The first plan before it is triggered.
///
/// Not a state of [`PlanLifecycle`]: the two overlap. A failed first plan waits for its
/// retry while the triggers raised during that attempt (a pop-up) are planned or deferred;
/// a tasking or route that arrives while the first plan is deferred makes it due again (it
/// joins the deferred triggers). Nor is it the same as holding a plan
/// (`MessageLoop::has_plan`): in the first case, the plan of those other triggers may be
/// held before the retry comes, which is then still raised.
#[derive(Debug, Clone, Copy, Default)]
pub(super) enum FirstPlan {
    /// No first plan waits: no tasking yet, or the first plan was triggered.
    #[default]
    NotDue,
    /// The first tasking came before any ownship state: the first plan waits for one until
    /// `until` (wall clock), to tell a restart mid-mission from a take-off
    /// (`triggers.first_plan_wait_ms`). Once an ownship state is here or `until` is past,
    /// it is [`Due`](FirstPlan::Due).
    WaitingForOwnship { until: Duration },
    /// Triggered at the next pass (a rendezvous's once the lead's route is here).
    Due,
    /// The first plan failed: tried again with the same inputs at `at` (wall clock); a new
    /// tasking or route makes it due at once.
    RetryAfterFailure { at: Duration },
}

impl FirstPlan {
    /// A first plan waits (for its inputs, an ownship state or its retry).
    pub(super) fn awaited(&self) -> bool {
        !matches!(self, FirstPlan::NotDue)
    }

    /// No retry waits at `now` (wall clock).
    pub(super) fn retry_passed(&self, now: Duration) -> bool {
        match self {
            FirstPlan::RetryAfterFailure { at } => now >= *at,
            _ => true,
        }
    }

    /// The end of the wait for an ownship state, if the first plan is in it.
    pub(super) fn ownship_wait_until(&self) -> Option<Duration> {
        match self {
            FirstPlan::WaitingForOwnship { until } => Some(*until),
            _ => None,
        }
    }

    /// New inputs before a first plan: it is due now (a retry's wait ends; a wait for an
    /// ownship state goes on).
    pub(super) fn make_due(&mut self) {
        if !matches!(self, FirstPlan::WaitingForOwnship { .. }) {
            *self = FirstPlan::Due;
        }
    }

    /// A retry waiting for its time is due now; any other state stays.
    pub(super) fn end_retry_wait(&mut self) {
        if matches!(self, FirstPlan::RetryAfterFailure { .. }) {
            *self = FirstPlan::Due;
        }
    }
}
