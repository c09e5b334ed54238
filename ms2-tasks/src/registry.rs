//! The task registry: every env id, its [`TaskSpec`], how to build it, and its scripted policy
//! and motion-planning solution.
//!
//! Tasks live in family folders (`src/families/<family>/`); each family registers its tasks with
//! one call ([`crate::families`]), and nothing else in the crate dispatches on an env id. A crate
//! or test of its own adds a family at run time with [`register_family`].
//!
//! ```
//! let spec = ms2_tasks::task_spec("PickCube-v0").unwrap();
//! assert_eq!(spec.max_episode_steps, 200);
//! assert_eq!(spec.default_robot(), "panda");
//! ```

use std::sync::{OnceLock, RwLock};

use crate::backend::EnvBackend;
use crate::config::EnvConfig;
use crate::env::Env;
use crate::error::EnvError;
use crate::scripted::ScriptedPolicy;
use crate::spec::TaskSpec;
use crate::task::Task;

/// Builds a task's hooks for a config (the runtime builds its world and robot).
pub type MakeTask = fn(&EnvConfig) -> Result<Box<dyn Task>, EnvError>;

/// Builds the scripted (oracle) policy of an env of the task in its control mode.
pub type MakeScriptedPolicy = fn(&Env) -> Result<Box<dyn ScriptedPolicy>, EnvError>;

/// Builds a whole simulation backend (the physics-free `Dummy-v0`).
pub(crate) type MakeBackend = fn(&EnvConfig, u32) -> Result<Box<dyn EnvBackend>, EnvError>;

/// How a registered task is simulated.
#[derive(Clone, Copy)]
pub(crate) enum Simulation {
    /// A [`Task`] on the shared robot runtime.
    Task(MakeTask),
    /// A backend of its own.
    Backend(MakeBackend),
}

/// A registered task: its spec, how to build it, its scripted policy and (with the `demos`
/// feature) its motion-planning solution.
#[derive(Clone, Copy)]
pub struct TaskRegistration {
    /// The task's static facts.
    pub spec: TaskSpec,
    pub(crate) simulation: Simulation,
    /// Its scripted policy, if it has one.
    pub scripted_policy: Option<MakeScriptedPolicy>,
    /// Its motion-planning solution, if it has one.
    #[cfg(feature = "demos")]
    pub solution: Option<&'static dyn crate::demos::solutions::Solution>,
    /// Whether the task is listed ([`env_ids`], [`task_specs`], gymnasium, `ms2 envs`); test
    /// envs such as `Dummy-v0` are not, but can still be made by id.
    pub public: bool,
}

impl std::fmt::Debug for TaskRegistration {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TaskRegistration")
            .field("spec", &self.spec)
            .field("scripted_policy", &self.scripted_policy.is_some())
            .finish_non_exhaustive()
    }
}

impl TaskRegistration {
    /// A task built by `make` on the shared robot runtime.
    pub fn new(spec: TaskSpec, make: MakeTask) -> Self {
        Self {
            spec,
            simulation: Simulation::Task(make),
            scripted_policy: None,
            #[cfg(feature = "demos")]
            solution: None,
            public: true,
        }
    }

    /// The same registration as a test env: makeable by id, but left out of [`env_ids`],
    /// [`task_specs`] and hence the gymnasium registry and `ms2 envs`.
    pub fn test_only(self) -> Self {
        Self {
            public: false,
            ..self
        }
    }

    /// A task simulated by a backend of its own.
    pub(crate) fn with_backend(spec: TaskSpec, make: MakeBackend) -> Self {
        Self {
            simulation: Simulation::Backend(make),
            ..Self::new(spec, |_| {
                unreachable!("a backend registration builds no task")
            })
        }
    }

    /// The same registration with a scripted policy.
    pub fn scripted(self, policy: MakeScriptedPolicy) -> Self {
        Self {
            scripted_policy: Some(policy),
            ..self
        }
    }

    /// The same registration with a motion-planning solution.
    #[cfg(feature = "demos")]
    pub fn solution(self, solution: &'static dyn crate::demos::solutions::Solution) -> Self {
        Self {
            solution: Some(solution),
            ..self
        }
    }
}

/// Collects the registrations of one family (see [`crate::families`]).
#[derive(Debug, Default)]
pub struct Registrar {
    tasks: Vec<TaskRegistration>,
}

impl Registrar {
    /// Registers one task.
    pub fn add(&mut self, registration: TaskRegistration) {
        self.tasks.push(registration);
    }
}

fn registry() -> &'static RwLock<Vec<TaskRegistration>> {
    static REGISTRY: OnceLock<RwLock<Vec<TaskRegistration>>> = OnceLock::new();
    REGISTRY.get_or_init(|| {
        let mut r = Registrar::default();
        crate::families::register_builtin(&mut r);
        RwLock::new(r.tasks)
    })
}

fn read<R>(f: impl FnOnce(&[TaskRegistration]) -> R) -> R {
    let guard = registry().read().unwrap_or_else(|e| e.into_inner());
    f(&guard)
}

/// Adds a family of tasks at run time (a crate or test of one's own; the built-in families are
/// registered on first use). Nothing is added when any of its ids is already registered.
///
/// ```
/// use ms2_tasks::registry::{register_family, Registrar};
/// fn none(_: &mut Registrar) {}
/// register_family(none).unwrap();
/// ```
pub fn register_family(register: fn(&mut Registrar)) -> Result<(), EnvError> {
    let mut family = Registrar::default();
    register(&mut family);
    let mut guard = registry().write().unwrap_or_else(|e| e.into_inner());
    for (i, new) in family.tasks.iter().enumerate() {
        let id = new.spec.env_id;
        let taken = guard
            .iter()
            .chain(&family.tasks[..i])
            .any(|r| r.spec.env_id == id);
        if taken {
            return Err(EnvError::InvalidConfig(format!(
                "env id {id:?} is already registered"
            )));
        }
    }
    guard.extend(family.tasks);
    Ok(())
}

/// Public environment ids, in registration order (test envs registered with
/// [`TaskRegistration::test_only`], such as `Dummy-v0`, are left out but can be made by id).
///
/// ```
/// assert!(ms2_tasks::env_ids().contains(&"PickCube-v0"));
/// assert!(!ms2_tasks::env_ids().contains(&"Dummy-v0"));
/// assert!(ms2_tasks::task_spec("Dummy-v0").is_ok());
/// ```
pub fn env_ids() -> Vec<&'static str> {
    read(|r| {
        r.iter()
            .filter(|t| t.public)
            .map(|t| t.spec.env_id)
            .collect()
    })
}

/// Every public task's spec, in registration order.
pub fn task_specs() -> Vec<TaskSpec> {
    read(|r| r.iter().filter(|t| t.public).map(|t| t.spec).collect())
}

/// The registration of `env_id`; an error lists the registered ids.
pub fn registration(env_id: &str) -> Result<TaskRegistration, EnvError> {
    read(|r| r.iter().find(|t| t.spec.env_id == env_id).copied()).ok_or_else(|| {
        EnvError::UnknownEnvId {
            got: env_id.to_owned(),
            valid: env_ids().into_iter().map(str::to_owned).collect(),
        }
    })
}

/// The spec of `env_id`; an error lists the registered ids.
pub fn task_spec(env_id: &str) -> Result<TaskSpec, EnvError> {
    registration(env_id).map(|r| r.spec)
}

/// Every registration, in registration order.
pub fn task_registrations() -> Vec<TaskRegistration> {
    read(<[TaskRegistration]>::to_vec)
}
