//! The lead's datalink: the tasking (at start and at every `targets` / `final` event), the
//! lead's route (at start and at every `lead-route` event) and its periodic state along
//! the route it flies — the route announced, or after a `lead-off-route` event one it
//! never announced. Pure: it says what to send at a mission time; the mission sends it.

use wingman_interfaces::{LeadRoute, LeadState, MAX_ROUTE_POINTS, MAX_TARGETS, Tasking, Wire};
use wingman_planning::lead::{LeadError, LeadPath, LeadPoint};
use wingman_planning::scenario::{EventKind, Scenario, messages};

/// A scenario whose tasking or route does not fit the messages.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DatalinkError {
    #[error("{0} targets: a tasking holds at most {MAX_TARGETS}")]
    TooManyTargets(usize),
    #[error("lead route of {0} points: a route holds 2 to {MAX_ROUTE_POINTS}")]
    RoutePoints(usize),
    #[error("lead route: {0}")]
    Lead(#[from] LeadError),
}

impl From<messages::TooManyTargets> for DatalinkError {
    fn from(e: messages::TooManyTargets) -> Self {
        DatalinkError::TooManyTargets(e.0)
    }
}

/// One tasking revision and the mission time it is sent at.
#[derive(Debug, Clone, Copy)]
pub struct TaskingRevision {
    pub at_s: f64,
    pub tasking: Tasking,
}

/// One lead route and the mission time from which the lead flies it.
#[derive(Debug, Clone, Copy)]
pub struct RouteRevision {
    pub at_s: f64,
    pub path: LeadPath,
    pub message: LeadRoute,
}

/// The datalink of one mission.
#[derive(Debug, Clone)]
pub struct Datalink {
    taskings: Vec<TaskingRevision>,
    /// The routes announced (each one sent).
    routes: Vec<RouteRevision>,
    /// The routes the lead flies, announced or not, in time order.
    flown: Vec<RouteRevision>,
    taskings_sent: usize,
    routes_sent: usize,
}

impl Datalink {
    /// Every tasking and route revision of `sc`, in time order.
    pub fn new(sc: &Scenario) -> Result<Datalink, DatalinkError> {
        let first = messages::tasking(sc, 1, &sc.targets, sc.final_point.as_ref())?;
        let mut taskings = vec![TaskingRevision {
            at_s: sc.start.time_s,
            tasking: first,
        }];
        let mut routes = Vec::new();
        let mut flown = Vec::new();
        if let Some(lead) = &sc.lead {
            routes.push(route(1, sc.start.time_s, &lead.route_m, lead.speed_mps)?);
            flown.push(routes[0]);
        }
        let mut events: Vec<_> = sc.events.iter().collect();
        events.sort_by(|a, b| a.at_s.total_cmp(&b.at_s));
        for e in events {
            match &e.kind {
                EventKind::LeadRoute { route_m, speed_mps } => {
                    let revision = routes.len() as u32 + 1;
                    routes.push(route(revision, e.at_s, route_m, *speed_mps)?);
                    flown.extend(routes.last());
                }
                EventKind::LeadOffRoute { route_m, speed_mps } => {
                    // The lead still reports the revision it announced last.
                    let revision = routes.len() as u32;
                    flown.push(route(revision, e.at_s, route_m, *speed_mps)?);
                }
                EventKind::Targets { targets_m } => {
                    let prev = taskings.last().map(|r| r.tasking).unwrap_or(first);
                    let mut t = messages::tasking(sc, prev.revision + 1, targets_m, None)?;
                    t.final_state = prev.final_state;
                    t.final_time_s = prev.final_time_s;
                    taskings.push(TaskingRevision {
                        at_s: e.at_s,
                        tasking: t,
                    });
                }
                EventKind::Final(f) => {
                    let prev = taskings.last().map(|r| r.tasking).unwrap_or(first);
                    let mut t = prev;
                    t.revision = prev.revision + 1;
                    t.final_state = f.state(sc.model);
                    t.final_time_s = f.time_s.unwrap_or(0.0);
                    taskings.push(TaskingRevision {
                        at_s: e.at_s,
                        tasking: t,
                    });
                }
            }
        }
        Ok(Datalink {
            taskings,
            routes,
            flown,
            taskings_sent: 0,
            routes_sent: 0,
        })
    }

    /// Tasking revisions due by `t` and not sent yet.
    pub fn taskings_due(&mut self, t: f64) -> &[TaskingRevision] {
        let from = self.taskings_sent;
        while self.taskings_sent < self.taskings.len()
            && self.taskings[self.taskings_sent].at_s <= t + 1e-9
        {
            self.taskings_sent += 1;
        }
        &self.taskings[from..self.taskings_sent]
    }

    /// Route revisions due by `t` and not sent yet.
    pub fn routes_due(&mut self, t: f64) -> &[RouteRevision] {
        let from = self.routes_sent;
        while self.routes_sent < self.routes.len() && self.routes[self.routes_sent].at_s <= t + 1e-9
        {
            self.routes_sent += 1;
        }
        &self.routes[from..self.routes_sent]
    }

    /// Whether the mission has a lead (a rendezvous).
    pub fn has_lead(&self) -> bool {
        !self.routes.is_empty()
    }

    /// Every tasking revision.
    pub fn taskings(&self) -> &[TaskingRevision] {
        &self.taskings
    }

    /// Every route revision.
    pub fn routes(&self) -> &[RouteRevision] {
        &self.routes
    }

    /// The route announced for `t` (the newest whose time has come).
    pub fn route_at(&self, t: f64) -> Option<&RouteRevision> {
        newest_at(&self.routes, t)
    }

    /// The route the lead flies at `t`, announced or not.
    pub fn flown_route_at(&self, t: f64) -> Option<&RouteRevision> {
        newest_at(&self.flown, t)
    }

    /// Every route the lead flies, announced or not, in time order.
    pub fn flown_routes(&self) -> &[RouteRevision] {
        &self.flown
    }

    /// The lead's true state at `t`.
    pub fn lead_at(&self, t: f64) -> Option<LeadPoint> {
        self.flown_route_at(t).map(|r| r.path.at(t))
    }

    /// The `LeadState` message at `t` (header left for the sender): the lead's true state
    /// and the revision of the route it announced last.
    pub fn lead_state(&self, t: f64) -> Option<LeadState> {
        let r = self.flown_route_at(t)?;
        let p = r.path.at(t);
        let mut m = LeadState::zeroed();
        m.time_s = t;
        m.position_m = p.position;
        m.heading_rad = p.heading;
        m.gamma_rad = p.gamma;
        m.speed_mps = r.path.speed();
        m.route_revision = r.message.revision;
        Some(m)
    }
}

/// The newest of `routes` whose time has come by `t` (the first before any).
fn newest_at(routes: &[RouteRevision], t: f64) -> Option<&RouteRevision> {
    routes
        .iter()
        .rev()
        .find(|r| r.at_s <= t + 1e-9)
        .or(routes.first())
}

fn route(
    revision: u32,
    at_s: f64,
    points: &[[f64; 3]],
    speed: f64,
) -> Result<RouteRevision, DatalinkError> {
    if !(2..=MAX_ROUTE_POINTS).contains(&points.len()) {
        return Err(DatalinkError::RoutePoints(points.len()));
    }
    let path = LeadPath::new(points, speed, at_s)?;
    let mut m = LeadRoute::zeroed();
    m.revision = revision;
    m.point_count = points.len() as u32;
    m.start_time_s = at_s;
    m.speed_mps = speed;
    m.points_m[..points.len()].copy_from_slice(points);
    Ok(RouteRevision {
        at_s,
        path,
        message: m,
    })
}
