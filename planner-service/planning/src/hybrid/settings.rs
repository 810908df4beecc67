//! The planner's settings: each stage's, with their deployment defaults (why each default
//! is what it is: `docs/decisions/`), and their check before a plan starts.

use crate::basins::StartRanking;
use crate::collocation::{ExportSettings, NlpSettings, RefineSettings, TranscriptionSettings};
use crate::seeding::SeedSettings;
use crate::swarm::{self, SwarmSettings};

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
            points: 6,
            interval_s: 25.0,
            min_intervals: 2,
        }
    }
}

/// Settings of the whole planner.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannerSettings {
    pub swarm: SwarmSettings,
    pub mesh: MeshSettings,
    pub transcription: TranscriptionSettings,
    pub nlp: NlpSettings,
    /// The NLP settings of the ranking solves on the coarse mesh (they only have to tell
    /// the basins apart: looser tolerances).
    pub ranking_nlp: NlpSettings,
    /// The NLP settings of the finalists' solves on the working mesh.
    pub finalist_nlp: NlpSettings,
    /// The NLP settings of the floor's solve under a short budget (`nlp_stage::floor`).
    pub floor_nlp: NlpSettings,
    pub refine: RefineSettings,
    /// Refinement rounds after the first NLP solve.
    pub refine_rounds: usize,
    pub export: ExportSettings,
    /// Largest share of the deadline the swarm may use.
    pub swarm_share: f64,
    /// NLP starts from distinct basins: the swarm's best and the best seeds that pass some
    /// threat on another side (see `basins`).
    pub starts: usize,
    /// A 2-D plan from scratch may solve starts up to this many in all: after its global
    /// search, while its work and time allow, the next `starts` of them at a time (a
    /// wave, `hybrid::waves`); `starts` or fewer: no waves.
    pub wave_starts: usize,
    /// The same in 3-D.
    pub wave_starts_3d: usize,
    /// A wave of a 2-D plan starts only if the plan's NLP work so far and the last
    /// stage's again stay within this many units (a solve's iterations times its mesh's
    /// intervals: counted, so the same on any computer); `None`: no limit but the clock.
    pub wave_work: Option<usize>,
    /// The same in 3-D.
    pub wave_work_3d: Option<usize>,
    /// The seeds the waves' starts are drawn from (built by the first wave).
    pub wave_seeds: SeedSettings,
    /// How the waves' starts are ranked (a fixed-time plan's; see `basins::candidates`):
    /// the starts of the global search are left out.
    pub wave_ranking: StartRanking,
    /// A wave's start is a finalist only if its ranked cost is at most the best ranked so
    /// far by this (relative).
    pub wave_gap_tol: f64,
    /// The share of a 2-D plan's budget (from its start) within which waves run.
    pub wave_share: f64,
    /// The same in 3-D.
    pub wave_share_3d: f64,
    /// How a fixed-time plan's seeds are ranked as starts (see `basins::candidates`).
    pub start_ranking: StartRanking,
    /// Threads solving the starts' NLPs side by side.
    pub threads: usize,
    /// The coarser mesh on which all starts are first ranked (2-D).
    pub ranking_mesh: MeshSettings,
    /// The ranking mesh of 3-D plans.
    pub ranking_mesh_3d: MeshSettings,
    /// The first barrier parameter of the 3-D ranking solves (`None`: `ranking_nlp`'s).
    pub ranking_mu_init_3d: Option<f64>,
    /// Largest scaled constraint violation of a ranking solve that still ranks.
    pub ranking_feasibility_tol: f64,
    /// How many of the best-ranked starts are solved again on the working mesh (at most).
    pub finalists: usize,
    /// A ranked start whose dense cost is within this of a finalist's (relative), on a path
    /// not distinct from it ([`basins::separation`] under [`basins::MIN_SEPARATION_M`]),
    /// reached the same basin: it is not solved again.
    pub finalist_duplicate_tol: f64,
    /// A ranked start whose dense cost is above the best's by more than this (relative)
    /// is out of the race: it is not solved again.
    pub finalist_gap_tol: f64,
    /// Start the solves on the working and the refined meshes primal-dual from the
    /// previous mesh's solution (multipliers carried over, see `collocation::warm`).
    pub warm_mesh_changes: bool,
    /// The starts from the global search's seeds (of distinct basins) that a warm re-plan
    /// adds when a new threat lies across the plan in flight (2-D).
    pub warm_seed_starts: usize,
    /// The same in 3-D.
    pub warm_seed_starts_3d: usize,
    /// Split a finalist's working-mesh intervals where its ranked path crosses a threat's
    /// edge (the exposure along an interval varying by more than this; phases before the
    /// last; see [`split_crossings`]); `None`: no split.
    pub crossing_split: Option<f64>,
}

/// The deployment defaults. Why each is what it is, with what was measured, is in
/// `docs/decisions/` (the record named beside it).
impl Default for PlannerSettings {
    fn default() -> Self {
        // A refined solve or a polish follows; feasible as the refined ones (0022).
        let finalist_nlp = NlpSettings::default()
            .with_feral_static_pivoting(true)
            .with_tol(1e-5)
            .with_acceptable_tol(1e-4)
            .with_acceptable_constr_viol_tol(Some(1e-7))
            .with_constr_viol_tol(Some(1e-7));
        PlannerSettings {
            swarm: SwarmSettings::default(),
            mesh: MeshSettings::default(),
            transcription: TranscriptionSettings::default(),
            // The winner's refined solve: tol 1e-6 (0026), no second-order test (0013).
            nlp: NlpSettings::default()
                .with_feral_static_pivoting(true)
                .with_tol(1e-6)
                .with_second_order_check(false),
            // Ranking only tells basins apart: stop at the first acceptable iterate
            // (0008), no second-order test (0013) or corrections (0027).
            ranking_nlp: NlpSettings::default()
                .with_feral_static_pivoting(true)
                .with_tol(1e-4)
                .with_acceptable_tol(1e-3)
                .with_acceptable_iter(1)
                .with_acceptable_constr_viol_tol(Some(1e-3))
                .with_second_order_check(false)
                .with_second_order_corrections(false),
            // The floor: as feasible as a finalist, with no second-order corrections, as the
            // ranking solves on the same coarse mesh (0027): with them a 3-D rendezvous
            // floor wandered for 49 iterations and was cut at 150 ms (0035).
            floor_nlp: finalist_nlp.clone().with_second_order_corrections(false),
            finalist_nlp,
            refine: RefineSettings::default(),
            refine_rounds: 1, // more moved no cost, took 20-30 % of the plan (0011)
            export: ExportSettings::default(),
            swarm_share: 0.3,
            starts: 5, // six's worst cost, a 16 % shorter ranking; four lose basins (0021)
            start_ranking: StartRanking::OnTimeFirst,
            // 2-D: waves while 40 000 units of work hold them, which fit the take-off
            // budget at half the usual speed, so that the work, not the clock, decides
            // how many run (0048). 3-D: one wave, within half the budget (0040); a 3-D
            // unit takes 2-4 times as long, and a cap that fits leaves no wave.
            wave_starts: 25,
            wave_starts_3d: 10,
            wave_work: Some(40_000),
            wave_work_3d: None,
            // The yardstick's wider bulges and random curves (0040).
            wave_seeds: SeedSettings::default()
                .with_bulge_ratios(&[0.15, 0.3, 0.5, 0.8, 1.2])
                .with_random_seeds(64)
                .with_random_bulge_max(1.0)
                .with_max_seeds(512),
            wave_ranking: StartRanking::Both,
            wave_gap_tol: 0.5, // 0.1 and 0.3 found no more (0040)
            wave_share: 1.0,
            // A 3-D take-off's whole 2.5 s on two threads fills the duty-cycle window.
            wave_share_3d: 0.5,
            threads: 2, // the NLP tasks on two threads (0023)
            // Coarser meshes lose basins; four points only in 3-D (0012).
            ranking_mesh: MeshSettings {
                points: 5,
                interval_s: 35.0,
                min_intervals: 2,
            },
            ranking_mesh_3d: MeshSettings {
                points: 4,
                interval_s: 35.0,
                min_intervals: 2,
            },
            ranking_mu_init_3d: Some(1e-3), // 3-D starts are whole paths (0018)
            ranking_feasibility_tol: 1e-3,  // as loose as the ranking's stop (0008)
            // Two distinct finalists within 10 % of the best (0020).
            finalists: 2,
            finalist_duplicate_tol: 1e-3,
            finalist_gap_tol: 0.1,
            warm_mesh_changes: true, // 9-28 -> 3-11 iterations per mesh change (0006)
            crossing_split: Some(0.3), // a crossing steps the exposure by ~1 (0029)
            // 2-D pop-ups at 50 ms: 9-10 -> 16-17 of 18 within 0.5 %; 3-D ranking them
            // took the warm path past 150 ms (0035).
            warm_seed_starts: 3,
            warm_seed_starts_3d: 0,
        }
    }
}

/// Planner settings that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlannerSettingsError {
    #[error("swarm: {0}")]
    Swarm(#[from] swarm::SwarmError),
    #[error("`{stage}`: {source}")]
    Nlp {
        stage: &'static str,
        source: crate::collocation::NlpSettingsError,
    },
    #[error("`{setting}`: {problem}")]
    OutOfRange {
        setting: &'static str,
        problem: &'static str,
    },
}

impl PlannerSettings {
    /// Checks every stage's settings (the swarm's, the three NLP settings) and the
    /// planner's own, so that a bad setting is refused before a plan starts.
    pub fn validate(&self) -> Result<(), PlannerSettingsError> {
        self.swarm.validate()?;
        self.wave_seeds
            .validate()
            .map_err(swarm::SwarmError::from)?;
        for (stage, nlp) in [
            ("nlp", &self.nlp),
            ("ranking_nlp", &self.ranking_nlp),
            ("finalist_nlp", &self.finalist_nlp),
            ("floor_nlp", &self.floor_nlp),
        ] {
            nlp.validate()
                .map_err(|source| PlannerSettingsError::Nlp { stage, source })?;
        }
        let out = |setting: &'static str, problem: &'static str| {
            Err(PlannerSettingsError::OutOfRange { setting, problem })
        };
        let fraction = |x: f64| x.is_finite() && x > 0.0 && x <= 1.0;
        let non_negative = |x: f64| x.is_finite() && x >= 0.0;
        if !fraction(self.swarm_share) {
            return out("swarm_share", "must be in (0, 1]");
        }
        if !(1..=200).contains(&self.starts) {
            // A start's index names its solves' deadline cuts in 8 bits (`cuts::Work`).
            return out("starts", "must be in 1..=200");
        }
        for (setting, value) in [
            ("wave_starts", self.wave_starts),
            ("wave_starts_3d", self.wave_starts_3d),
        ] {
            if value > 200 {
                // Each wave names its cuts' part in 8 bits (`cuts::Part::Wave`).
                return out(setting, "must be at most 200");
            }
        }
        for (setting, value) in [
            ("wave_share", self.wave_share),
            ("wave_share_3d", self.wave_share_3d),
        ] {
            if !fraction(value) {
                return out(setting, "must be in (0, 1]");
            }
        }
        if !(1..=64).contains(&self.threads) {
            return out("threads", "must be in 1..=64");
        }
        if self.finalists == 0 {
            return out("finalists", "must be at least 1");
        }
        if self.refine_rounds > 16 {
            return out("refine_rounds", "must be at most 16");
        }
        for (setting, value) in [
            ("warm_seed_starts", self.warm_seed_starts),
            ("warm_seed_starts_3d", self.warm_seed_starts_3d),
        ] {
            if value > 16 {
                return out(setting, "must be at most 16");
            }
        }
        for (setting, value) in [
            ("ranking_feasibility_tol", self.ranking_feasibility_tol),
            ("finalist_duplicate_tol", self.finalist_duplicate_tol),
            ("finalist_gap_tol", self.finalist_gap_tol),
            ("wave_gap_tol", self.wave_gap_tol),
        ] {
            if !non_negative(value) {
                return out(setting, "must be finite and non-negative");
            }
        }
        if self
            .ranking_mu_init_3d
            .is_some_and(|v| !(v.is_finite() && v > 0.0))
        {
            return out("ranking_mu_init_3d", "must be finite and positive when set");
        }
        if self
            .crossing_split
            .is_some_and(|v| !(v.is_finite() && v > 0.0))
        {
            return out("crossing_split", "must be finite and positive when set");
        }
        Ok(())
    }
}
