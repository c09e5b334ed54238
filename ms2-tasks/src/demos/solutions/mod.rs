//! Motion-planning solutions: sense–plan–act with privileged state, driving `pd_joint_pos`.
//!
//! Each solution reads the true object poses and goal after reset ([`scene`]), plans with
//! [ms2-plan](ms2_plan) (a top-down grasp from the cube's bounding box at the yaw closest to the
//! hand's, screw motions and RRT-Connect, TOPP-RA timing at the control frequency, the ground
//! and the other cubes as obstacles) and plays the planned joint targets as `pd_joint_pos`
//! actions, recording the episode ([`driver`]). A task registers its [`Solution`] with its
//! family (the cube tasks: `families/rigid/solutions.rs`).
//!
//! ```no_run
//! use ms2_tasks::demos::solutions::{solution_env_ids, solve_episode};
//! use ms2_tasks::EnvConfig;
//! assert!(solution_env_ids().contains(&"PickCube-v0"));
//! let episode = solve_episode(&EnvConfig::new("PickCube-v0"), 0).unwrap();
//! assert_eq!(episode.env_states.len(), episode.actions.len() + 1);
//! println!("success: {:?}", episode.success.last());
//! ```

pub mod driver;
pub mod planning_geometry;
pub mod quality;
pub mod scene;

use std::sync::OnceLock;
use std::time::Instant;

use ms2_plan::{KinematicRobot, PlanError, PlanningRobot};

use crate::agents::ARM_DOF;
use crate::config::{EnvConfig, ObsMode};
use crate::demos::{DemoEpisode, DemoError};
use crate::env::{make_env, Env};
use crate::error::EnvError;
use crate::registry;
pub use driver::{Gripper, JointTargetDriver, CONTROL_MODE};
pub use quality::Cleanliness;
pub use scene::{SensedCube, SensedState};

/// A task's motion-planning solution, registered with the task
/// ([`crate::registry::TaskRegistration::solution`]).
pub trait Solution: Sync {
    /// Runs the solution on `driver`'s freshly reset env (driving [`CONTROL_MODE`]); `panda`
    /// is the planning model of the robot, `seed` seeds the planners.
    ///
    /// # Errors
    /// [`SolveError::OutOfSteps`] when the episode limit ends the motion, planning and env
    /// errors otherwise.
    fn run(
        &self,
        driver: &mut JointTargetDriver<'_>,
        panda: &KinematicRobot,
        seed: u64,
        timings: &mut SolveTimings,
    ) -> Result<(), SolveError>;

    /// Whether [`DemoSolver::solve`] should plan an episode again from its reset, with other
    /// planner seeds (at most [`SINGLE_GRASP_PLANS`] plans in all), when the solution succeeded
    /// but not [cleanly](Cleanliness): by grasping again within the episode (its gripper
    /// closed more than once), or after an object moved before the grasp. It keeps the first
    /// plan of the best rank. Such events are chaotic: a demonstration that contains one is
    /// replayed faithfully but converts poorly to other control modes (the converted grasp may
    /// hold where the source's slipped, or close on another part of a nudged object).
    /// Default: `false`.
    fn prefers_single_grasp(&self) -> bool {
        false
    }
}

/// One episode solved by [`DemoSolver::solve_ranked`].
#[derive(Debug, Clone)]
pub struct SolvedEpisode {
    /// The kept plan's episode (successful or not).
    pub episode: DemoEpisode,
    /// Time spent on every plan made for it.
    pub timings: SolveTimings,
    /// The kept plan's rank, for successful episodes of solutions that
    /// [prefer clean grasps](Solution::prefers_single_grasp); `None` otherwise.
    pub cleanliness: Option<Cleanliness>,
}

/// Plans per episode when a solution [prefers clean grasps](Solution::prefers_single_grasp).
pub const SINGLE_GRASP_PLANS: u64 = 3;

/// How many times `episode`'s gripper action turns from opening to closing (its last action
/// component: > 0 opens, < 0 closes), a closing first action included.
pub fn gripper_closings(episode: &DemoEpisode) -> usize {
    let closed: Vec<bool> = episode
        .actions
        .iter()
        .map(|a| a.last().is_some_and(|&g| g < 0.0))
        .collect();
    closed.windows(2).filter(|w| !w[0] && w[1]).count() + usize::from(closed.first() == Some(&true))
}

/// Why a solution stopped early (internal; mapped to [`DemoError`] or a failed episode).
#[derive(Debug, thiserror::Error)]
pub enum SolveError {
    /// The privileged state lacks something the solution reads.
    #[error("sensing failed: {0}")]
    Sensing(String),
    /// A planning query failed.
    #[error("{phase} planning failed: {source}")]
    Plan {
        /// The phase whose query failed (`grasp`, `reach`, `descend`, `lift`, `carry`, ...).
        phase: &'static str,
        /// The planner's error.
        source: PlanError,
    },
    /// The env failed while stepping or resetting.
    #[error(transparent)]
    Demo(#[from] DemoError),
    /// The episode limit was reached before the motion ended.
    #[error("the episode limit was reached")]
    OutOfSteps,
}

/// Where the time of one solved episode went (wall-clock seconds).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SolveTimings {
    /// Time spent in planning queries (grasp search, screw motions, RRT-Connect, timing).
    pub planning_seconds: f64,
    /// Number of planning queries.
    pub planning_queries: u32,
    /// Total time of the episode, env reset and simulation included.
    pub total_seconds: f64,
}

impl SolveTimings {
    /// Adds `other`'s times and queries (an episode planned again).
    pub fn accumulate(&mut self, other: &SolveTimings) {
        self.planning_seconds += other.planning_seconds;
        self.planning_queries += other.planning_queries;
        self.total_seconds += other.total_seconds;
    }
}

/// Env ids that have a motion-planning solution.
pub fn solution_env_ids() -> Vec<&'static str> {
    registry::task_registrations()
        .into_iter()
        .filter(|r| r.solution.is_some())
        .map(|r| r.spec.env_id)
        .collect()
}

/// ms2's Panda for planning with the simulated Panda's collision shapes
/// ([`planning_geometry`]), built once.
pub fn planning_panda() -> Result<&'static KinematicRobot, PlanError> {
    static PANDA: OnceLock<Result<KinematicRobot, PlanError>> = OnceLock::new();
    PANDA
        .get_or_init(planning_geometry::planning_panda_for_simulated_robot)
        .as_ref()
        .map_err(Clone::clone)
}

/// Solves episodes of one env, reusing the env between seeds.
pub struct DemoSolver {
    env: Env,
    solution: &'static dyn Solution,
    panda: &'static KinematicRobot,
}

impl DemoSolver {
    /// A solver for `cfg.env_id`. `cfg.control_mode` must be `None` or `"pd_joint_pos"`; the
    /// solver's env always observes `state` (the solution reads privileged state directly, so
    /// `obs_mode` does not matter and images are never rendered).
    ///
    /// # Errors
    /// [`DemoError::NoSolution`] for an env without a solution, [`DemoError::Env`] for a bad
    /// config, [`DemoError::Planning`] if the planning robot cannot be built.
    pub fn new(cfg: &EnvConfig) -> Result<Self, DemoError> {
        let no_solution = || DemoError::NoSolution {
            env_id: cfg.env_id.clone(),
            valid: solution_env_ids().into_iter().map(str::to_owned).collect(),
        };
        let solution = registry::registration(&cfg.env_id)
            .ok()
            .and_then(|r| r.solution)
            .ok_or_else(no_solution)?;
        Self::with_solution(cfg, solution)
    }

    /// A solver running `solution` (e.g. one wrapping a registered solution) in an env made
    /// from `cfg`; errors as [`DemoSolver::new`] except [`DemoError::NoSolution`].
    pub fn with_solution(
        cfg: &EnvConfig,
        solution: &'static dyn Solution,
    ) -> Result<Self, DemoError> {
        if let Some(mode) = cfg.control_mode.as_deref() {
            if mode != CONTROL_MODE {
                return Err(DemoError::Env(EnvError::InvalidConfig(format!(
                    "motion-planning solutions drive {CONTROL_MODE}, got control_mode {mode:?} \
                     (convert the episodes afterwards by replay)"
                ))));
            }
        }
        let env_cfg = EnvConfig {
            control_mode: Some(CONTROL_MODE.to_owned()),
            obs_mode: ObsMode::State.as_str().to_owned(),
            ..cfg.clone()
        };
        let env = make_env(&env_cfg)?;
        let panda = planning_panda().map_err(|e| DemoError::Planning {
            seed: 0,
            reason: format!("planning robot: {e}"),
        })?;
        check_joint_order(&env, panda)?;
        Ok(Self {
            env,
            solution,
            panda,
        })
    }

    /// Runs the solution for episode `seed`. Returns the episode whether it succeeded or not
    /// (it succeeded if `episode.success.last() == Some(&true)`).
    ///
    /// # Errors
    /// [`DemoError::Planning`] if a planning query fails, [`DemoError::Env`] if the env fails.
    pub fn solve(&mut self, seed: u64) -> Result<(DemoEpisode, SolveTimings), DemoError> {
        self.solve_ranked(seed).map(|s| (s.episode, s.timings))
    }

    /// [`DemoSolver::solve`], also returning the kept plan's [`Cleanliness`] (for solutions
    /// that [prefer clean grasps](Solution::prefers_single_grasp) and succeeded).
    ///
    /// # Errors
    /// As [`DemoSolver::solve`].
    pub fn solve_ranked(&mut self, seed: u64) -> Result<SolvedEpisode, DemoError> {
        let (first, first_timings) = self.solve_with(seed, seed)?;
        if !self.solution.prefers_single_grasp() || !first.succeeded() {
            return Ok(SolvedEpisode {
                episode: first,
                timings: first_timings,
                cleanliness: None,
            });
        }
        let mut rank = Cleanliness::of(&mut self.env, &first)?;
        let (mut best, mut timings) = (first, first_timings);
        for k in 1..SINGLE_GRASP_PLANS {
            if rank == Cleanliness::Clean {
                break;
            }
            // Another planner stream for the same scene (the episode seed is unchanged).
            let planning_seed = seed ^ (k << 56);
            let Ok((episode, t)) = self.solve_with(seed, planning_seed) else {
                continue;
            };
            timings.accumulate(&t);
            if !episode.succeeded() {
                continue;
            }
            let r = Cleanliness::of(&mut self.env, &episode)?;
            if r > rank {
                (best, rank) = (episode, r);
            }
        }
        Ok(SolvedEpisode {
            episode: best,
            timings,
            cleanliness: Some(rank),
        })
    }

    /// One plan of episode `seed` with the planners seeded by `planning_seed`.
    fn solve_with(
        &mut self,
        seed: u64,
        planning_seed: u64,
    ) -> Result<(DemoEpisode, SolveTimings), DemoError> {
        let t0 = Instant::now();
        let mut timings = SolveTimings::default();
        let mut driver =
            JointTargetDriver::start(&mut self.env, seed).map_err(|e| to_demo(e, seed))?;
        match self
            .solution
            .run(&mut driver, self.panda, planning_seed, &mut timings)
        {
            Ok(()) | Err(SolveError::OutOfSteps) => {}
            Err(e) => return Err(to_demo(e, seed)),
        }
        timings.total_seconds = t0.elapsed().as_secs_f64();
        Ok((driver.finish(), timings))
    }
}

/// Runs the motion-planning solution of `cfg.env_id` for episode `seed` in `pd_joint_pos`
/// (`cfg.control_mode` must be `None` or `"pd_joint_pos"`; `obs_mode` is irrelevant).
/// Returns the episode whether it succeeded or not; the caller keeps successes
/// (`episode.success.last() == Some(&true)`).
///
/// # Errors
/// As [`DemoSolver::new`] and [`DemoSolver::solve`].
pub fn solve_episode(cfg: &EnvConfig, seed: u64) -> Result<DemoEpisode, DemoError> {
    Ok(DemoSolver::new(cfg)?.solve(seed)?.0)
}

fn to_demo(e: SolveError, seed: u64) -> DemoError {
    match e {
        SolveError::Demo(e) => e,
        other => DemoError::Planning {
            seed,
            reason: other.to_string(),
        },
    }
}

/// The planned joints must be the env robot's first joints, in order (the `pd_joint_pos`
/// action order).
fn check_joint_order(env: &Env, panda: &KinematicRobot) -> Result<(), DemoError> {
    let planned = panda.planned_joint_names();
    let scene = env.task_scene().ok_or_else(|| DemoError::Planning {
        seed: 0,
        reason: "the env has no robot".to_owned(),
    })?;
    let names = scene
        .world
        .joint_names(scene.agent.articulation())
        .map_err(|e| DemoError::Env(EnvError::from(e)))?;
    if planned.len() != ARM_DOF || names.len() < ARM_DOF || planned[..] != names[..ARM_DOF] {
        return Err(DemoError::Planning {
            seed: 0,
            reason: format!(
                "planned joints {planned:?} are not the robot's first {ARM_DOF} joints {names:?}"
            ),
        });
    }
    debug_assert_eq!(panda.dof(), ARM_DOF);
    Ok(())
}
