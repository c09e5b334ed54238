//! Scripted (oracle) policies of the bucket tasks: a bucket trajectory planned from the
//! privileged episode data at reset ([`BucketPlan`]), each bucket waypoint turned into a TCP
//! target ([`tcp_for_bucket`]) and then into an action of the env's control mode
//! ([`TcpOracle`]). One policy type, [`BucketPolicy`], serves both tasks.

use glam::Vec3;

use super::bucket_arm::tcp_for_bucket;
use super::excavate::Excavate;
use super::excavate_scene::{interpolate_waypoints, BucketPose, ScriptedScoop};
use super::fill::{Fill, MAX_EPISODE_STEPS};
use crate::env::Env;
use crate::error::EnvError;
use crate::scripted::oracle::{TcpOracle, GRIPPER_OPEN};
use crate::scripted::{tcp_oracle, ScriptedPolicy};
use crate::task::TaskScene;

/// Control steps the scoop gives the arm to bring the bucket from its rest pose to the bed's
/// near edge.
const APPROACH_STEPS: u32 = 14;

/// Pitch (rad) of the pour: the opening 75° down.
const POUR_PITCH: f32 = -75.0 * std::f32::consts::PI / 180.0;

/// Control steps of the pour's carry: lift, then turn the open front sideways while bringing
/// the lip over the beaker (the turn takes about 0.04 rad per step in `pd_ee_delta_pose`,
/// whose rotation is clipped at 0.1 rad per step and tracked about halfway each step).
const POUR_CARRY_STEPS: u32 = 36;

/// Distance (m) the pour's lip stops short of the pour point, back along the open front.
const POUR_LIP_BACK: f32 = 0.02;

/// Distance (m) the pour's lip stops below the pour point (2 cm above the beaker's rim).
const POUR_LIP_DROP: f32 = 0.02;

/// Control steps of the pour's tilt from 30 % to all of [`POUR_PITCH`].
const POUR_TILT_STEPS: u32 = 24;

/// A bucket trajectory planned once per episode.
pub trait BucketPlan: Send + Sized + 'static {
    /// Plans from the task at reset, the bucket starting level at `start`; `None` when the
    /// env is not this plan's task or has no episode yet.
    fn plan(env: &Env, scene: &TaskScene, start: BucketPose) -> Option<Self>;
    /// The bucket pose to reach at the end of control step `step` (0-based).
    fn command(&self, step: u32) -> BucketPose;
}

/// The scripted policy over plan `P` (see the [module docs](self)).
pub struct BucketPolicy<P> {
    oracle: TcpOracle,
    plan: Option<P>,
}

impl<P: BucketPlan> BucketPolicy<P> {
    /// The policy of `env` (an error when its control mode is not position-based).
    pub fn boxed(env: &Env) -> Result<Box<dyn ScriptedPolicy>, EnvError> {
        Ok(Box::new(Self {
            oracle: tcp_oracle(env)?,
            plan: None,
        }))
    }
}

impl<P: BucketPlan> ScriptedPolicy for BucketPolicy<P> {
    fn reset(&mut self, env: &Env) {
        self.plan = env.task_scene().and_then(|scene| {
            let arm_task = env.task()?;
            let arm = arm_task
                .downcast_ref::<Excavate>()
                .map(Excavate::arm)
                .or_else(|| arm_task.downcast_ref::<Fill>().map(Fill::arm))?;
            let mut start = arm.bucket_command_pose(scene.world.as_ref());
            start.pitch = 0.0;
            start.yaw = 0.0;
            P::plan(env, scene, start)
        });
    }

    fn act(&mut self, env: &Env) -> Vec<f32> {
        let Some(plan) = &self.plan else {
            return vec![0.0; env.action_space().size()];
        };
        let target = tcp_for_bucket(&plan.command(env.elapsed_steps()));
        self.oracle.action(env, &target, GRIPPER_OPEN)
    }
}

/// `Excavate-v0`'s scripted policy: the kinematic scene's scoop, planned from the bucket's
/// pose at reset.
pub type ExcavatePolicy = BucketPolicy<ScriptedScoop>;

impl BucketPlan for ScriptedScoop {
    fn plan(env: &Env, _scene: &TaskScene, start: BucketPose) -> Option<Self> {
        let bed = env.task()?.downcast_ref::<Excavate>()?.bed()?;
        Some(ScriptedScoop::plan_from(start, bed, APPROACH_STEPS))
    }

    fn command(&self, step: u32) -> BucketPose {
        ScriptedScoop::command(self, step)
    }
}

/// Bucket waypoints of the scripted pour: lift, turn the open front sideways (towards the
/// robot's centre line) while carrying the lip over the beaker, lower it, tilt the opening
/// down about the lip, hold. The lip stops `POUR_LIP_BACK` short of the pour point and
/// `POUR_LIP_DROP` below it: poured from the pour point itself at 2 kHz, a quarter of the
/// clay (flung along the open front) landed beyond the beaker's far wall.
///
/// The turn keeps the pour within the Panda's reach: the bucket hangs 20 cm below the hand,
/// so tilting it by `POUR_PITCH` swings the hand 19 cm along the open front. Tilted
/// forward (along world +x, the bucket's heading at rest) that put the hand beyond the
/// Panda's reach over the beaker; IK then failed and the bucket drifted back towards the
/// robot in `pd_ee_delta_pose`. Sideways the hand stays about 70 cm from the robot's base.
#[derive(Clone, Debug)]
pub struct PourPlan {
    waypoints: Vec<(u32, BucketPose)>,
}

impl PourPlan {
    /// Plans the pour from the bucket's pose `start` (its yaw taken as 0) to the pour point
    /// `pour` (m, world; [`Fill::pour_point`]).
    pub fn new(start: BucketPose, pour: Vec3) -> Self {
        let hx = super::excavate_scene::BUCKET_INNER_HALF[0];
        // Open front towards −y for a beaker left of the centre line (y > 0), else +y: the
        // tilt swings the hand towards the centre line.
        let yaw = -std::f32::consts::FRAC_PI_2.copysign(pour.y);
        let heading = glam::Quat::from_rotation_z(yaw);
        // The clay leaves the lip moving along the open front: aim the lip short of `pour`.
        let lip = pour - heading * Vec3::new(POUR_LIP_BACK, 0.0, POUR_LIP_DROP);
        // Plate centre that puts the lip at `lip` for a given pitch.
        let centre = |pitch: f32| BucketPose {
            position: lip - heading * Vec3::new(hx * pitch.cos(), 0.0, hx * pitch.sin()),
            pitch,
            yaw,
        };
        let lifted = BucketPose {
            position: start.position + Vec3::new(0.0, 0.0, 0.04),
            pitch: 0.0,
            yaw: 0.0,
        };
        let mut above = centre(0.0);
        above.position.z += 0.02;
        let t = POUR_CARRY_STEPS;
        Self {
            waypoints: vec![
                (0, BucketPose { yaw: 0.0, ..start }),
                (6, lifted),
                (t, above),
                (t + 4, centre(0.0)),
                (t + 8, centre(0.3 * POUR_PITCH)),
                (t + 8 + POUR_TILT_STEPS, centre(POUR_PITCH)),
                (MAX_EPISODE_STEPS, centre(POUR_PITCH)),
            ],
        }
    }
}

/// `Fill-v0`'s scripted policy: [`PourPlan`] to the beaker's pour point.
pub type FillPolicy = BucketPolicy<PourPlan>;

impl BucketPlan for PourPlan {
    fn plan(env: &Env, _scene: &TaskScene, start: BucketPose) -> Option<Self> {
        let fill = env.task()?.downcast_ref::<Fill>()?;
        Some(PourPlan::new(start, fill.pour_point()))
    }

    fn command(&self, step: u32) -> BucketPose {
        interpolate_waypoints(&self.waypoints, step)
    }
}
