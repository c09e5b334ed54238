//! Helpers of ms2's cross-crate simulated tests: a Panda in a physics world driven by an
//! ms2-control controller, stepped at 500 Hz.

use ms2_control::{ControlMode, ControlTiming};
use ms2_physics::{World, WorldConfig};
use ms2_tasks::agents::{build_panda_from_urdf, Agent, PandaAgent};
use ms2_tasks::geometry::Pose3;
use ms2_tasks::seeding::episode_rng;

/// The Panda alone on the ground, with the controller of one control mode.
pub struct Rig {
    /// The world.
    pub world: World,
    /// The robot and its controller.
    pub agent: PandaAgent,
    /// Physics substeps per control step.
    pub substeps: usize,
}

impl Rig {
    /// A Panda at ManiSkill2's base pose and rest qpos (noise from `seed`), controlled in `mode`
    /// at 20 Hz with 500 Hz physics.
    pub fn new(mode: ControlMode, seed: u64) -> Rig {
        let mut world = World::new(WorldConfig::default()).expect("world");
        let timing = ControlTiming::MANISKILL2;
        let mut agent =
            build_panda_from_urdf(&mut world, mode, timing, ms2_assets::PANDA_URDF)
                .expect("agent");
        agent
            .initialize(&mut world, &mut episode_rng(seed))
            .expect("initialize");
        Rig {
            world,
            agent,
            substeps: timing.substeps(),
        }
    }

    /// Sends one action to the controller (no stepping).
    pub fn command(&mut self, action: &[f32]) {
        self.agent
            .set_action(&mut self.world, action)
            .expect("valid action");
    }

    /// Runs `control_steps` control periods (each `substeps` physics steps) without new actions.
    pub fn run(&mut self, control_steps: usize) {
        for _ in 0..control_steps * self.substeps {
            self.agent.before_substep(&mut self.world);
            self.world.step();
        }
    }

    /// One control step: command then run one period.
    pub fn step(&mut self, action: &[f32]) {
        self.command(action);
        self.run(1);
    }

    /// TCP pose in the world.
    pub fn tcp(&self) -> Pose3 {
        self.agent.tcp_pose(&self.world)
    }

    /// Joint positions.
    pub fn qpos(&self) -> Vec<f32> {
        self.agent.qpos(&self.world)
    }

    /// Drive position targets.
    pub fn drive_targets(&self) -> Vec<f32> {
        self.world
            .drive_targets(self.agent.articulation())
            .expect("articulation")
    }
}
