//! The hybrid planner (FORMULATION.md §7, dissertation chapter IV): deterministic spline
//! seeds and a particle swarm find the basin; the swarm's best, lifted to the full model,
//! starts the LGR collocation NLP, which makes it locally optimal and dynamically
//! feasible; h-refinement rounds make the mesh fine where the plan needs it; the result is
//! flown with the tracking law and exported densely.
//!
//! It is *anytime* under one deadline: the time left flows from the swarm to the NLP and
//! its refinement rounds. At the deadline it returns the best it has, flagged:
//! `Optimal` (the NLP converged), `Feasible` (the NLP stopped early with its constraints
//! within tolerance), `SwarmOnly` (the swarm's lifted path).

use std::time::Duration;

use wingman_interfaces::Quality;

use crate::clock::Deadline;
use crate::collocation::{
    ExportSettings, Mesh, NlpSettings, NlpStatus, PrimalDual, RefineSettings, Transcription,
    TranscriptionSettings, export, interval_errors, refine, solve,
};
use crate::problem::Problem;
use crate::swarm::{self, SwarmOutcome, SwarmSettings, SwarmWorkspace};
use crate::trajectory::Trajectory;

/// How each phase's first mesh is cut.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshSettings {
    /// LGR points per interval.
    pub points: usize,
    /// Target length of an interval of the first mesh.
    pub interval_s: f64,
    /// Fewest intervals in a phase.
    pub min_intervals: usize,
}

impl Default for MeshSettings {
    fn default() -> Self {
        MeshSettings {
            points: 8,
            interval_s: 40.0,
            min_intervals: 2,
        }
    }
}

/// Settings of the whole planner.
#[derive(Debug, Clone)]
pub struct PlannerSettings {
    pub swarm: SwarmSettings,
    pub mesh: MeshSettings,
    pub transcription: TranscriptionSettings,
    pub nlp: NlpSettings,
    pub refine: RefineSettings,
    /// Refinement rounds after the first NLP solve.
    pub refine_rounds: usize,
    pub export: ExportSettings,
    /// Largest share of the deadline the swarm may use.
    pub swarm_share: f64,
}

impl Default for PlannerSettings {
    fn default() -> Self {
        PlannerSettings {
            swarm: SwarmSettings::default(),
            mesh: MeshSettings::default(),
            transcription: TranscriptionSettings::default(),
            nlp: NlpSettings {
                feral_static_pivoting: true,
                ..NlpSettings::default()
            },
            refine: RefineSettings::default(),
            refine_rounds: 3,
            export: ExportSettings::default(),
            swarm_share: 0.3,
        }
    }
}

/// Bad input: the planner cannot start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    #[error("invalid problem: {0}")]
    Problem(#[from] crate::problem::ProblemError),
    #[error("swarm: {0}")]
    Swarm(#[from] swarm::SwarmError),
    #[error("NLP settings: {0}")]
    Nlp(#[from] crate::collocation::solve::OptionError),
    #[error("the planner produced a non-finite trajectory")]
    NonFinite,
}

/// Time spent in each stage.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StageTimes {
    pub swarm: Duration,
    pub nlp: Duration,
    pub export: Duration,
    pub total: Duration,
}

/// What the NLP stage did.
#[derive(Debug, Clone, PartialEq)]
pub struct NlpReport {
    /// Status of the last solve.
    pub status: Option<NlpStatus>,
    /// Iterations of each solve (first mesh, then each refinement round).
    pub iterations: Vec<usize>,
    /// Intervals per phase of the final mesh.
    pub intervals: Vec<usize>,
    /// Objective of the last accepted solve (its own quadrature).
    pub objective: f64,
}

/// The planner's answer.
#[derive(Debug, Clone)]
pub struct PlanOutcome {
    pub quality: Quality,
    /// The plan: dense samples of the flown path with its controls and phase end times.
    pub trajectory: Trajectory,
    /// The objective of `trajectory` re-evaluated on its samples (Simpson).
    pub cost: f64,
    /// The swarm's best path (lifted), for reports and plots.
    pub swarm_best: Trajectory,
    pub swarm_cost: f64,
    pub swarm_iterations: usize,
    pub nlp: NlpReport,
    pub times: StageTimes,
}

/// The planner with its reusable workspace.
pub struct Planner {
    swarm: SwarmWorkspace,
}

impl Planner {
    pub fn new(settings: &PlannerSettings) -> Planner {
        Planner {
            swarm: SwarmWorkspace::new(&settings.swarm),
        }
    }

    /// The seeds of the last plan (for plots).
    pub fn swarm_workspace(&self) -> &SwarmWorkspace {
        &self.swarm
    }

    /// Plans `problem` by `deadline`. Never fails on a valid problem: at worst the swarm's
    /// path comes back flagged `SwarmOnly`.
    pub fn plan(
        &mut self,
        problem: &Problem,
        settings: &PlannerSettings,
        deadline: Deadline<'static>,
    ) -> Result<PlanOutcome, PlanError> {
        problem.validate()?;
        let clock = deadline.clock();
        let started = clock.now();
        let mut times = StageTimes::default();

        let swarm_deadline = deadline.share(settings.swarm_share);
        let sw: SwarmOutcome =
            swarm::run(problem, &settings.swarm, &mut self.swarm, swarm_deadline)?;
        times.swarm = sw.elapsed;
        if !sw.best.is_valid() {
            return Err(PlanError::NonFinite);
        }
        let swarm_cost = trajectory_cost(problem, &sw.best);

        let nlp_started = clock.now();
        let mut report = NlpReport {
            status: None,
            iterations: Vec::new(),
            intervals: Vec::new(),
            objective: f64::NAN,
        };
        // The accepted NLP result so far: transcription, solution, quality.
        let mut accepted: Option<(Transcription, Vec<f64>, Quality)> = None;
        let durations = phase_durations(problem.t0, &sw.best);
        let mut mesh = Mesh::uniform(
            settings.mesh.points,
            &durations,
            settings.mesh.interval_s,
            settings.mesh.min_intervals,
        );
        let mut guess = sw.best.clone();
        for round in 0..=settings.refine_rounds {
            if deadline.expired() {
                break;
            }
            let mut tr = Transcription::new(problem, &mesh, &guess, &settings.transcription);
            let mut x = vec![0.0; tr.n_vars()];
            tr.initial_point(&guess, &mut x);
            let j0 = tr.objective(&x);
            tr.obj_scale = 1.0 / j0.abs().max(1e-3);
            let mut nlp = settings.nlp.clone();
            if round > 0 {
                // A refined mesh starts from the previous solution: a small barrier keeps it.
                nlp.mu_init = Some(settings.nlp.refine_mu_init);
            }
            let (tr, out) = solve(
                tr,
                PrimalDual {
                    x,
                    ..PrimalDual::default()
                },
                false,
                &nlp,
                deadline,
            )?;
            report.iterations.push(out.iterations);
            report.status = Some(out.status);
            let quality = match (out.status, out.feasible) {
                (NlpStatus::Converged, true) => Some(Quality::Optimal),
                (_, true) => Some(Quality::Feasible),
                _ => None,
            };
            let Some(quality) = quality else { break };
            report.objective = out.objective;
            report.intervals = mesh.phases.iter().map(Vec::len).collect();
            let converged = quality == Quality::Optimal;
            accepted = Some((tr, out.x, quality));
            if !converged || round == settings.refine_rounds {
                break;
            }
            let (tr, x, _) = accepted.as_ref().expect("just accepted");
            let mut errors = Vec::new();
            interval_errors(tr, x, &mut errors);
            let Some(next) = refine(&mesh, &errors, &settings.refine) else {
                break;
            };
            let reference = ExportSettings {
                closed_loop: false,
                max_step_s: settings.export.max_step_s / 2.0,
                ..settings.export
            };
            export(tr, x, &reference, &mut guess);
            mesh = next;
        }
        times.nlp = clock.now().saturating_sub(nlp_started);

        let export_started = clock.now();
        let (quality, trajectory) = match &accepted {
            Some((tr, x, quality)) => {
                let mut flown = Trajectory::default();
                export(tr, x, &settings.export, &mut flown);
                (*quality, flown)
            }
            None => (Quality::SwarmOnly, sw.best.clone()),
        };
        if !trajectory.is_valid() {
            return Err(PlanError::NonFinite);
        }
        times.export = clock.now().saturating_sub(export_started);
        times.total = clock.now().saturating_sub(started);
        Ok(PlanOutcome {
            quality,
            cost: trajectory_cost(problem, &trajectory),
            trajectory,
            swarm_best: sw.best,
            swarm_cost,
            swarm_iterations: sw.iterations,
            nlp: report,
            times,
        })
    }
}

/// Phase durations of a trajectory (at least one second each).
fn phase_durations(t0: f64, tr: &Trajectory) -> Vec<f64> {
    let mut prev = t0;
    tr.phase_ends
        .iter()
        .map(|&e| {
            let d = (e - prev).max(1.0);
            prev = e;
            d
        })
        .collect()
}

/// The objective (FORMULATION.md §4) of a sampled trajectory: `|u|²` integrated exactly
/// for controls linear between samples, `E` by composite Simpson on the samples.
pub fn trajectory_cost(problem: &Problem, tr: &Trajectory) -> f64 {
    use wingman_interfaces::Objective;
    let n = tr.len();
    if n < 2 {
        return f64::INFINITY;
    }
    let nu = problem.nu();
    let mut effort = 0.0;
    for k in 0..n - 1 {
        let dt = tr.times[k + 1] - tr.times[k];
        for e in 0..nu {
            let (a, b) = (tr.controls[k][e], tr.controls[k + 1][e]);
            effort += dt * (a * a + a * b + b * b) / 3.0;
        }
    }
    let exposure = crate::metrics::simpson_by(&tr.times, |k| {
        let s = &tr.states[k];
        problem.exposure(
            &[s[0], s[1], if problem.dim() == 3 { s[2] } else { 0.0 }],
            tr.times[k],
        )
    });
    let w = &problem.weights;
    let run = (1.0 - w.beta) * effort + w.beta * exposure;
    match problem.objective {
        Objective::FixedTime => run,
        _ => w.alpha * tr.times[n - 1] + (1.0 - w.alpha) * run,
    }
}
