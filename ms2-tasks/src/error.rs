//! Typed errors of the environment runtime.

/// Everything that can go wrong when making, resetting or stepping an environment.
///
/// Messages name the bad value and list what was expected.
#[derive(Debug, thiserror::Error)]
pub enum EnvError {
    /// `env_id` is not registered.
    #[error("unknown env id {got:?}; registered ids: {valid:?}")]
    UnknownEnvId {
        /// The id that was asked for.
        got: String,
        /// The registered ids.
        valid: Vec<String>,
    },
    /// `obs_mode` is not supported by this environment.
    #[error("unknown obs_mode {got:?}; valid obs modes: {valid:?}")]
    UnknownObsMode {
        /// The mode that was asked for.
        got: String,
        /// The supported modes.
        valid: Vec<String>,
    },
    /// `robot` is not supported by this environment (or not registered).
    #[error("unknown robot {got:?}; valid robots: {valid:?}")]
    UnknownRobot {
        /// The robot that was asked for.
        got: String,
        /// The supported robots.
        valid: Vec<String>,
    },
    /// `control_mode` is not supported by this environment's robot.
    #[error("unknown control_mode {got:?}; valid control modes: {valid:?}")]
    UnknownControlMode {
        /// The mode that was asked for.
        got: String,
        /// The supported modes.
        valid: Vec<String>,
    },
    /// `reward_mode` is not supported.
    #[error("unknown reward_mode {got:?}; valid reward modes: {valid:?}")]
    UnknownRewardMode {
        /// The mode that was asked for.
        got: String,
        /// The supported modes.
        valid: Vec<String>,
    },
    /// `render_mode` is not supported.
    #[error("unknown render_mode {got:?}; valid render modes: {valid:?}")]
    UnknownRenderMode {
        /// The mode that was asked for.
        got: String,
        /// The supported modes.
        valid: Vec<String>,
    },
    /// The action has the wrong number of elements for the control mode.
    #[error("action for control_mode {control_mode:?} must have {expected} elements, got {got}")]
    ActionShape {
        /// The env's control mode.
        control_mode: String,
        /// Expected number of elements.
        expected: usize,
        /// Number of elements given.
        got: usize,
    },
    /// The action contains NaN or an infinity.
    #[error(
        "action for control_mode {control_mode:?} has non-finite element {value} at index {index}"
    )]
    NonFiniteAction {
        /// The env's control mode.
        control_mode: String,
        /// Index of the first non-finite element.
        index: usize,
        /// Its value.
        value: f32,
    },
    /// A state vector given to `set_state` has the wrong length.
    #[error("state vector must have {expected} elements, got {got}")]
    StateShape {
        /// Expected number of elements.
        expected: usize,
        /// Number of elements given.
        got: usize,
    },
    /// A state vector given to `set_state` contains NaN or an infinity.
    #[error("state vector has non-finite element {value} at index {index}")]
    NonFiniteState {
        /// Index of the first non-finite element.
        index: usize,
        /// Its value.
        value: f32,
    },
    /// A state vector given to `set_state` holds a finite but impossible value (outside joint
    /// limits, too fast, too far from the scene, a non-unit quaternion): see
    /// [`crate::state_check`] for the bounds.
    #[error("state[{index}] = {value} ({meaning}) is outside {expected}")]
    StateOutOfBounds {
        /// Index of the first out-of-bounds element.
        index: usize,
        /// Its value.
        value: f32,
        /// What the element is (e.g. `"qpos of panda_joint1"`).
        meaning: String,
        /// The accepted range, with its unit.
        expected: String,
    },
    /// The simulation produced NaN or an infinity (an internal failure, not bad input): the
    /// step is refused and the next `reset` rebuilds the scene.
    #[error(
        "the simulation became non-finite: {what} = {value} after step {step}; \
         the env rebuilds its scene at the next reset"
    )]
    NonFiniteSimulation {
        /// What went non-finite (an observation key and index, or the reward).
        what: String,
        /// The value.
        value: f64,
        /// The episode step at which it happened.
        step: u32,
    },
    /// `VecEnv::reset` got a seed list of the wrong length.
    #[error("expected one seed entry per env ({expected}), got {got}")]
    SeedCount {
        /// Number of envs.
        expected: usize,
        /// Number of seeds given.
        got: usize,
    },
    /// The configuration is inconsistent (message says what and why).
    #[error("invalid env config: {0}")]
    InvalidConfig(String),
    /// The rigid engine refused an input or failed.
    #[error("physics error: {0}")]
    Physics(#[from] ms2_physics::PhysicsError),
    /// A robot or object description (URDF) could not be read.
    #[error("description error: {0}")]
    Urdf(#[from] ms2_physics::UrdfError),
    /// A soft-body scene failed.
    #[cfg(feature = "soft")]
    #[error("soft body: {0}")]
    Soft(#[from] crate::soft::SoftSceneError),
    /// The crate was built without a rigid engine (feature `rapier`): pass one to
    /// [`crate::Env::with_engine`].
    #[error("no rigid engine: ms2-tasks was built without the `rapier` feature; pass an engine to Env::with_engine")]
    NoRigidEngine,
    /// The request needs a cargo feature this build of ms2-tasks lacks.
    #[error("{what} needs ms2-tasks' `{feature}` feature, which this build lacks")]
    FeatureDisabled {
        /// What was asked for.
        what: String,
        /// The missing feature.
        feature: &'static str,
    },
    /// A fetched asset (e.g. the real Panda's description) is present but unusable: a file
    /// is missing, truncated or has a wrong checksum (the message names the file).
    #[error("asset error: {0}")]
    Asset(String),
    /// The controller failed (the control crate's error is the source).
    #[error("controller error: {0}")]
    Controller(#[from] ms2_control::ControlError),
    /// Rendering failed (message from the render crate), or the scene holds something that
    /// cannot be drawn.
    #[error("render error: {0}")]
    Render(String),
    /// The obs mode or render call needs cameras, but this env has no renderable scene.
    #[error("env {env_id:?} cannot render ({reason})")]
    NotRenderable {
        /// The env id.
        env_id: String,
        /// Why not.
        reason: String,
    },
    /// No scripted policy exists for this env / control mode.
    #[error("no scripted policy for env {env_id:?} with control_mode {control_mode:?}: {reason}")]
    NoScriptedPolicy {
        /// The env id.
        env_id: String,
        /// The env's control mode.
        control_mode: String,
        /// Why not.
        reason: String,
    },
}

/// Two errors are equal when they are the same variant with the same message (sources such as
/// [`ms2_physics::PhysicsError`] are compared through their messages, which name every value).
impl PartialEq for EnvError {
    fn eq(&self, other: &Self) -> bool {
        std::mem::discriminant(self) == std::mem::discriminant(other)
            && self.to_string() == other.to_string()
    }
}
