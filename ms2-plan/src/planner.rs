//! The planner facade: [`MotionPlanner`] turns queries into joint trajectories sampled at the
//! control frequency.

use nalgebra::Isometry3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::checker::{CheckerOptions, CollisionChecker};
use crate::error::check_positive;
use crate::robot::{JointLimits, PlanningRobot};
use crate::rrt::{check_query_configuration, plan_rrt_connect, RrtConfig};
use crate::scene::CollisionScene;
use crate::screw::{plan_screw_path, ScrewConfig};
use crate::shortcut::shortcut_path;
use crate::spline::CubicSplinePath;
use crate::time_parameterization::{parameterize, JointTrajectory};
use crate::PlanError;

/// Settings of a [`MotionPlanner`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlannerConfig {
    /// Sampling-planner settings.
    pub rrt: RrtConfig,
    /// Random shortcut attempts after RRT-Connect.
    pub shortcut_iterations: usize,
    /// Cartesian (screw) motion settings.
    pub screw: ScrewConfig,
    /// Collision-checker settings (safety margin, self-collision).
    pub checker: CheckerOptions,
    /// Control frequency (Hz) at which trajectories are sampled; ms2's default is 20.
    pub control_frequency: f64,
    /// Fraction (0, 1] of each joint's velocity limit the trajectory may use.
    pub velocity_scale: f64,
    /// Fraction (0, 1] of each joint's acceleration limit the trajectory may use.
    pub acceleration_scale: f64,
    /// Path-parameter spacing (rad or m) of the time-parameterization grid.
    pub time_grid_resolution: f64,
    /// Random IK restarts for [`MotionPlanner::plan_to_pose`] when the seeded IK fails.
    pub ik_attempts: usize,
    /// Seed of the planner's random number generator (ChaCha8): same seed, same plans.
    pub seed: u64,
}

impl Default for PlannerConfig {
    fn default() -> Self {
        Self {
            rrt: RrtConfig::default(),
            shortcut_iterations: 100,
            screw: ScrewConfig::default(),
            checker: CheckerOptions::default(),
            control_frequency: 20.0,
            velocity_scale: 1.0,
            acceleration_scale: 1.0,
            time_grid_resolution: 0.005,
            ik_attempts: 20,
            seed: 0,
        }
    }
}

/// A planned motion: geometric waypoints and the timed trajectory through them.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedMotion {
    /// Joint-space waypoints (rad or m), first = start, last = goal.
    pub waypoints: Vec<Vec<f64>>,
    /// Joint targets at the control frequency.
    pub trajectory: JointTrajectory,
    /// Whether the trajectory follows a smooth spline through the waypoints (`true`) or, because
    /// the spline was not collision-free, stops at every waypoint (`false`).
    pub smoothed: bool,
}

/// Plans collision-free joint trajectories for one robot.
///
/// Plans are reproducible: the random number generator is seeded from
/// [`PlannerConfig::seed`] and advanced by each query.
pub struct MotionPlanner<'r, R: PlanningRobot + ?Sized> {
    robot: &'r R,
    config: PlannerConfig,
    rng: ChaCha8Rng,
}

impl<'r, R: PlanningRobot + ?Sized> MotionPlanner<'r, R> {
    /// A planner for `robot`.
    ///
    /// # Errors
    /// [`PlanError::InvalidParameter`] for unusable settings; robot limits that are not
    /// positive.
    pub fn new(robot: &'r R, config: PlannerConfig) -> Result<Self, PlanError> {
        check_positive("control_frequency", config.control_frequency)?;
        check_positive("time_grid_resolution", config.time_grid_resolution)?;
        for (name, scale) in [
            ("velocity_scale", config.velocity_scale),
            ("acceleration_scale", config.acceleration_scale),
        ] {
            if !(scale > 0.0 && scale <= 1.0) {
                return Err(PlanError::InvalidParameter {
                    name,
                    value: scale,
                    expected: "a fraction in (0, 1]",
                });
            }
        }
        for l in robot.joint_limits() {
            check_positive("joint max_velocity", l.max_velocity)?;
            check_positive("joint max_acceleration", l.max_acceleration)?;
            if !(l.lower.is_finite() && l.upper.is_finite() && l.lower <= l.upper) {
                return Err(PlanError::InvalidParameter {
                    name: "joint position limits",
                    value: l.lower,
                    expected: "finite limits with lower <= upper",
                });
            }
        }
        Ok(Self {
            robot,
            config,
            rng: ChaCha8Rng::seed_from_u64(config.seed),
        })
    }

    /// The settings.
    pub fn config(&self) -> &PlannerConfig {
        &self.config
    }

    /// The robot.
    pub fn robot(&self) -> &'r R {
        self.robot
    }

    /// A collision checker for `scene` with the planner's checker settings.
    ///
    /// # Errors
    /// As [`CollisionChecker::new`].
    pub fn checker(&self, scene: &CollisionScene) -> Result<CollisionChecker<'r, R>, PlanError> {
        CollisionChecker::new(self.robot, scene, self.config.checker)
    }

    /// Plans from `start` to `goal` (joint configurations) with RRT-Connect, shortcutting and
    /// time parameterization.
    ///
    /// # Errors
    /// Invalid or colliding start/goal, [`PlanError::NoPathFound`], or a time-parameterization
    /// failure.
    pub fn plan_to_configuration(
        &mut self,
        scene: &CollisionScene,
        start: &[f64],
        goal: &[f64],
    ) -> Result<PlannedMotion, PlanError> {
        let checker = self.checker(scene)?;
        let path = plan_rrt_connect(&checker, start, goal, &self.config.rrt, &mut self.rng)?;
        let path = shortcut_path(
            &checker,
            &path,
            self.config.shortcut_iterations,
            self.config.rrt.collision_resolution,
            &mut self.rng,
        );
        self.timed(&checker, path)
    }

    /// Plans from `start` to a TCP pose (base frame): IK (seeded with `start`, then with random
    /// configurations) gives a collision-free goal configuration, then as
    /// [`MotionPlanner::plan_to_configuration`].
    ///
    /// # Errors
    /// [`PlanError::IkFailed`] if no collision-free IK solution is found; otherwise as
    /// [`MotionPlanner::plan_to_configuration`].
    pub fn plan_to_pose(
        &mut self,
        scene: &CollisionScene,
        start: &[f64],
        pose_base_from_tcp: &Isometry3<f64>,
    ) -> Result<PlannedMotion, PlanError> {
        let checker = self.checker(scene)?;
        check_query_configuration(&checker, "start configuration", start)?;
        let goal = self.collision_free_ik(&checker, pose_base_from_tcp, start)?;
        self.plan_to_configuration(scene, start, &goal)
    }

    /// Moves the TCP from its pose at `start` to `pose_base_from_tcp` along a screw (straight
    /// line with uniformly turning orientation) through IK.
    ///
    /// # Errors
    /// [`PlanError::ScrewMotionFailed`] if IK, a joint jump or a collision stops the motion.
    pub fn plan_screw(
        &mut self,
        scene: &CollisionScene,
        start: &[f64],
        pose_base_from_tcp: &Isometry3<f64>,
    ) -> Result<PlannedMotion, PlanError> {
        let checker = self.checker(scene)?;
        let path = plan_screw_path(&checker, start, pose_base_from_tcp, &self.config.screw)?;
        self.timed(&checker, path)
    }

    /// Time-parameterizes collision-free `waypoints` (checked against `checker`'s scene):
    /// a smooth spline if it stays collision-free and within limits, else straight segments
    /// that stop at each waypoint.
    ///
    /// # Errors
    /// [`PlanError::TimeParameterization`] if no velocity profile exists.
    pub fn time_parameterize(
        &self,
        checker: &CollisionChecker<'_, R>,
        waypoints: &[Vec<f64>],
    ) -> Result<(JointTrajectory, bool), PlanError> {
        let limits = self.scaled_limits();
        let timestep = 1.0 / self.config.control_frequency;
        let resolution = self.config.time_grid_resolution;
        let spline = CubicSplinePath::new(waypoints)?;
        if waypoints.len() > 2 && self.spline_is_valid(checker, &spline) {
            return Ok((parameterize(&spline, &limits, timestep, resolution)?, true));
        }
        let mut trajectory = JointTrajectory {
            timestep,
            positions: Vec::new(),
            velocities: Vec::new(),
        };
        for w in waypoints.windows(2) {
            let segment = CubicSplinePath::new(w)?;
            trajectory.append(&parameterize(&segment, &limits, timestep, resolution)?);
        }
        if trajectory.is_empty() {
            let single = CubicSplinePath::new(&waypoints[..1])?;
            trajectory = parameterize(&single, &limits, timestep, resolution)?;
        }
        Ok((trajectory, false))
    }

    fn timed(
        &self,
        checker: &CollisionChecker<'_, R>,
        waypoints: Vec<Vec<f64>>,
    ) -> Result<PlannedMotion, PlanError> {
        let (trajectory, smoothed) = self.time_parameterize(checker, &waypoints)?;
        Ok(PlannedMotion {
            waypoints,
            trajectory,
            smoothed,
        })
    }

    fn scaled_limits(&self) -> Vec<JointLimits> {
        self.robot
            .joint_limits()
            .iter()
            .map(|l| JointLimits {
                max_velocity: l.max_velocity * self.config.velocity_scale,
                max_acceleration: l.max_acceleration * self.config.acceleration_scale,
                ..*l
            })
            .collect()
    }

    /// Checks the spline densely: consecutive checked points are at most the collision
    /// resolution apart per joint (the spline's speed `|dq/ds|` is bounded by sampling finely).
    fn spline_is_valid(&self, checker: &CollisionChecker<'_, R>, spline: &CubicSplinePath) -> bool {
        let resolution = self.config.rrt.collision_resolution;
        let mut s = 0.0;
        let mut previous = spline.position(0.0);
        let length = spline.length();
        let mut step = resolution;
        while s < length {
            let next_s = (s + step).min(length);
            let q = spline.position(next_s);
            let largest = q
                .iter()
                .zip(&previous)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            if largest > resolution && step > 1e-6 {
                step *= 0.5;
                continue;
            }
            if !checker.is_valid(&q) {
                return false;
            }
            previous = q;
            s = next_s;
            step = resolution;
        }
        true
    }

    fn collision_free_ik(
        &mut self,
        checker: &CollisionChecker<'_, R>,
        pose_base_from_tcp: &Isometry3<f64>,
        start: &[f64],
    ) -> Result<Vec<f64>, PlanError> {
        let mut last_error = String::from("no attempt made");
        for attempt in 0..=self.config.ik_attempts {
            let seed: Vec<f64> = if attempt == 0 {
                start.to_vec()
            } else {
                self.robot
                    .joint_limits()
                    .iter()
                    .map(|l| self.rng.random_range(l.lower..=l.upper))
                    .collect()
            };
            match self.robot.inverse_kinematics(pose_base_from_tcp, &seed) {
                Ok(q) if checker.is_valid(&q) => return Ok(q),
                Ok(q) => {
                    last_error = checker.first_contact(&q).ok().flatten().map_or_else(
                        || "solution outside joint limits".into(),
                        |c| format!("solution in collision: {c}"),
                    );
                }
                Err(e) => last_error = e.to_string(),
            }
        }
        Err(PlanError::IkFailed(format!(
            "no collision-free solution after {} attempts; last: {last_error}",
            self.config.ik_attempts + 1
        )))
    }
}
