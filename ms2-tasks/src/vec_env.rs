//! [`VecEnv`]: several envs stepped in parallel (rigid state steps on a pool whose idle workers
//! spin briefly, `vec_pool`; the rest on rayon's), their cameras rendered in one batch.

use rayon::prelude::*;

use crate::config::EnvConfig;
use crate::env::{Env, StepOutput};
use crate::error::EnvError;
use crate::info::Info;
use crate::obs::ObsValue;
#[cfg(feature = "render")]
use crate::sensors::batch::{submit_batch, BatchItem, PendingBatch};
#[cfg(feature = "render")]
use crate::sensors::{visual_obs, CameraFrame, VisualLayout};

/// What one env does during [`VecEnv::run`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EnvCommand<'a> {
    /// Step with this action (`action_dim` floats).
    Step(&'a [f32]),
    /// Start a new episode (`seed = None` draws the next seed from the env's RNG).
    Reset {
        /// Episode seed.
        seed: Option<u64>,
    },
    /// Leave the env as it is (it reports nothing).
    Keep,
}

/// Most envs one [`VecEnv`] holds (each rigid-task env takes a few MB; more envs than this
/// only queue on the CPU cores).
pub const MAX_NUM_ENVS: usize = 4096;

/// `num_envs` copies of one env config, reset and stepped in parallel (no autoreset: the Python
/// layer implements gymnasium's).
///
/// In visual obs modes (feature `render`) a vector step has three phases: physics (and the
/// poses of every env's render scene and cameras) in parallel; batched rendering of every
/// camera (one GPU submission and one readback per half of the envs, pipelined with the other
/// half's physics: `sensors::batch::submit_batch`); then observation assembly (point-cloud
/// fusion, robot masks) in parallel. The images equal those of stepping each env alone.
///
/// ```
/// # #[cfg(feature = "rapier")] {
/// use ms2_tasks::{EnvConfig, VecEnv};
/// let mut venv = VecEnv::new(&EnvConfig::new("Dummy-v0"), 2).unwrap();
/// venv.reset(&[Some(0), Some(1)]).unwrap();
/// let dim = venv.envs()[0].action_space().size();
/// let outs = venv.step(&vec![0.0; 2 * dim]).unwrap();
/// assert_eq!(outs.len(), 2);
/// # }
/// ```
#[derive(Debug)]
pub struct VecEnv {
    envs: Vec<Env>,
    action_dim: usize,
    /// Whether visual steps render in two pipelined halves (see [`VecEnv::run`]).
    #[cfg_attr(not(feature = "render"), allow(dead_code))]
    pipelined: bool,
    /// Whether state steps of these (rigid) envs run on `vec_pool`'s spinning pool rather than
    /// rayon's (always false for soft-body envs, whose MPM step uses rayon's pool itself).
    spinning_pool: bool,
}

impl VecEnv {
    /// Makes `num_envs` envs (1..=[`MAX_NUM_ENVS`]) from `cfg`.
    pub fn new(cfg: &EnvConfig, num_envs: usize) -> Result<VecEnv, EnvError> {
        if !(1..=MAX_NUM_ENVS).contains(&num_envs) {
            return Err(EnvError::InvalidConfig(format!(
                "num_envs must be in 1..={MAX_NUM_ENVS}, got {num_envs}"
            )));
        }
        cfg.check_bounds()?;
        let spinning = crate::vec_pool::spinning_by_default()?;
        let envs = (0..num_envs)
            .into_par_iter()
            .map(|_| Env::new(cfg))
            .collect::<Result<Vec<_>, _>>()?;
        let action_dim = envs[0].action_space().size();
        let spinning_pool = spinning && !has_soft_bodies(&envs[0]);
        Ok(VecEnv {
            envs,
            action_dim,
            pipelined: true,
            spinning_pool,
        })
    }

    /// Number of envs.
    pub fn num_envs(&self) -> usize {
        self.envs.len()
    }

    /// The envs.
    pub fn envs(&self) -> &[Env] {
        &self.envs
    }

    /// The envs, mutably (e.g. to reset one after its episode ended).
    pub fn envs_mut(&mut self) -> &mut [Env] {
        &mut self.envs
    }

    /// Turns the two-half render pipeline of visual steps on (the default) or off (all envs'
    /// physics, then one batch of all cameras). The outputs are the same either way; this is
    /// for measuring the overlap. Without the `render` feature there are no visual steps and
    /// this changes nothing.
    pub fn set_pipelined_rendering(&mut self, pipelined: bool) {
        self.pipelined = pipelined;
    }

    /// Steps rigid envs in state modes on a pool whose idle workers spin about half a
    /// millisecond before sleeping, the calling thread stepping envs too (the default), or on
    /// rayon's pool (`false`), whose workers are woken for every vector step. The outputs are the
    /// same either way. The default is the spinning pool unless the environment variable
    /// `MS2_VEC_POOL` is `rayon` (for machines whose cores are busy with other work, where a
    /// spinning worker slows the step down). Soft-body envs and visual steps always use rayon's
    /// pool.
    pub fn set_spinning_pool(&mut self, spinning: bool) {
        self.spinning_pool = spinning && !has_soft_bodies(&self.envs[0]);
    }

    /// Resets every env; `seeds` has one entry per env (`None` = draw from that env's RNG).
    pub fn reset(&mut self, seeds: &[Option<u64>]) -> Result<Vec<(ObsValue, Info)>, EnvError> {
        if seeds.len() != self.envs.len() {
            return Err(EnvError::SeedCount {
                expected: self.envs.len(),
                got: seeds.len(),
            });
        }
        let commands: Vec<EnvCommand<'_>> = seeds
            .iter()
            .map(|&seed| EnvCommand::Reset { seed })
            .collect();
        Ok(self
            .run(&commands)?
            .into_iter()
            .flatten()
            .map(|out| (out.obs, out.info))
            .collect())
    }

    /// Steps every env; `actions` holds `num_envs * action_dim` floats, row-major (env-major).
    pub fn step(&mut self, actions: &[f32]) -> Result<Vec<StepOutput>, EnvError> {
        let expected = self.envs.len() * self.action_dim;
        if actions.len() != expected {
            return Err(EnvError::ActionShape {
                control_mode: self.envs[0].control_mode().to_owned(),
                expected,
                got: actions.len(),
            });
        }
        let commands: Vec<EnvCommand<'_>> = if self.action_dim == 0 {
            vec![EnvCommand::Step(&[]); self.envs.len()]
        } else {
            actions
                .chunks(self.action_dim)
                .map(EnvCommand::Step)
                .collect()
        };
        Ok(self.run(&commands)?.into_iter().flatten().collect())
    }

    /// Runs one command per env in parallel and returns, per env, its step output (`None` for
    /// [`EnvCommand::Keep`]). A reset reports its first observation and info with reward 0
    /// and both flags false (gymnasium's "next step" autoreset convention).
    ///
    /// In visual modes the envs run as two halves in a pipeline: the first half's physics,
    /// then its cameras are submitted in one batch; the second half's physics runs while the
    /// first half renders, then its batch is submitted; observations are assembled as each
    /// batch arrives.
    pub fn run(
        &mut self,
        commands: &[EnvCommand<'_>],
    ) -> Result<Vec<Option<StepOutput>>, EnvError> {
        if commands.len() != self.envs.len() {
            return Err(EnvError::InvalidConfig(format!(
                "expected one command per env ({}), got {}",
                self.envs.len(),
                commands.len()
            )));
        }
        #[cfg(feature = "render")]
        if let Some((layout, robot_seg)) = self.envs[0].visual_layout() {
            return self.run_visual(commands, layout, robot_seg);
        }
        let pool = if self.spinning_pool && self.envs.len() > 1 {
            Pool::Spinning
        } else {
            Pool::Rayon
        };
        let stepped = simulate(&mut self.envs, commands, pool, |_| Ok(()))?;
        Ok(stepped.into_iter().map(|s| s.map(|(out, _)| out)).collect())
    }

    /// [`VecEnv::run`] in a visual obs mode: physics, batched rendering and assembly in two
    /// pipelined halves.
    #[cfg(feature = "render")]
    fn run_visual(
        &mut self,
        commands: &[EnvCommand<'_>],
        layout: VisualLayout,
        robot_seg: bool,
    ) -> Result<Vec<Option<StepOutput>>, EnvError> {
        let n = self.envs.len();
        let split = if n >= 2 && self.pipelined {
            n.div_ceil(2)
        } else {
            n
        };
        let (first_envs, second_envs) = self.envs.split_at_mut(split);
        let (first_commands, second_commands) = commands.split_at(split);
        let first = simulate(
            first_envs,
            first_commands,
            Pool::Rayon,
            Env::prepare_cameras,
        )?;
        let first_batch = submit(first_envs, &first)?;
        let second = simulate(
            second_envs,
            second_commands,
            Pool::Rayon,
            Env::prepare_cameras,
        )?;
        let second_batch = submit(second_envs, &second)?;
        let keys = self.envs[0].spec().non_privileged_extra_keys;
        let mut outs = assemble(first, first_batch.wait()?, keys, layout, robot_seg);
        outs.extend(assemble(
            second,
            second_batch.wait()?,
            keys,
            layout,
            robot_seg,
        ));
        Ok(outs)
    }
}

/// An env's step output before its images, and its cameras posed for rendering (`None` for
/// [`EnvCommand::Keep`]).
#[cfg(feature = "render")]
type Simulated = Option<(StepOutput, Vec<ms2_render::Camera>)>;

/// Whether an env steps MPM particles (its task has a soft-body component).
fn has_soft_bodies(env: &Env) -> bool {
    env.task().is_some_and(|task| task.soft().is_some())
}

/// The thread pool a vector step's physics runs on.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Pool {
    /// rayon's global pool.
    Rayon,
    /// `vec_pool`'s: the caller helps, idle workers spin before sleeping.
    Spinning,
}

/// One env's output of [`simulate`].
type Simulation<C> = Result<Option<(StepOutput, C)>, EnvError>;

/// Runs the commands' physics in parallel on `pool`, then `prepare` on each env that ran a
/// command (in visual modes: pose its render scene and cameras); `None` for
/// [`EnvCommand::Keep`].
fn simulate<C: Send>(
    envs: &mut [Env],
    commands: &[EnvCommand<'_>],
    pool: Pool,
    prepare: impl Fn(&mut Env) -> Result<C, EnvError> + Sync,
) -> Result<Vec<Option<(StepOutput, C)>>, EnvError> {
    let run = |env: &mut Env, command: &EnvCommand<'_>| -> Simulation<C> {
        let out = match *command {
            EnvCommand::Keep => return Ok(None),
            EnvCommand::Step(action) => env.step_deferred(action)?,
            EnvCommand::Reset { seed } => {
                let (obs, info) = env.reset_deferred(seed)?;
                StepOutput {
                    obs,
                    reward: 0.0,
                    terminated: false,
                    truncated: false,
                    info,
                }
            }
        };
        let prepared = prepare(env)?;
        Ok(Some((out, prepared)))
    };
    match pool {
        Pool::Rayon => envs
            .par_iter_mut()
            .zip(commands.par_iter())
            .map(|(env, command)| run(env, command))
            .collect(),
        Pool::Spinning => {
            let mut jobs: Vec<(&mut Env, &EnvCommand<'_>, Option<Simulation<C>>)> = envs
                .iter_mut()
                .zip(commands)
                .map(|(env, command)| (env, command, None))
                .collect();
            crate::vec_pool::for_each(&mut jobs, &|(env, command, out)| {
                *out = Some(run(env, command));
            });
            jobs.into_iter()
                .map(|(_, _, out)| {
                    // `vec_pool::for_each` runs every job; never report a skipped env as kept.
                    out.unwrap_or_else(|| {
                        Err(EnvError::InvalidConfig(
                            "an env of the vector step was not stepped".to_owned(),
                        ))
                    })
                })
                .collect()
        }
    }
}

/// Submits every camera of the simulated envs in one batch.
#[cfg(feature = "render")]
fn submit(envs: &mut [Env], simulated: &[Simulated]) -> Result<PendingBatch, EnvError> {
    let items: Vec<BatchItem<'_>> = envs
        .iter_mut()
        .zip(simulated)
        .filter_map(|(env, s)| {
            s.as_ref()
                .map(|(_, cameras)| env.sensors().map(|sensors| (sensors, &cameras[..])))
        })
        .collect::<Result<_, EnvError>>()?;
    submit_batch(&items)
}

/// The visual observations (image copies, fused point clouds, masks), in parallel.
#[cfg(feature = "render")]
fn assemble(
    simulated: Vec<Simulated>,
    frames: Vec<CameraFrame>,
    keys: &[&str],
    layout: VisualLayout,
    robot_seg: bool,
) -> Vec<Option<StepOutput>> {
    let mut frames = frames.into_iter();
    let frames: Vec<Option<CameraFrame>> = simulated
        .iter()
        .map(|s| s.as_ref().and_then(|_| frames.next()))
        .collect();
    simulated
        .into_par_iter()
        .zip(frames)
        .map(|(s, frame)| {
            let (mut out, _) = s?;
            let state_dict = std::mem::replace(&mut out.obs, ObsValue::Dict(Vec::new()));
            out.obs = visual_obs::assemble(state_dict, keys, frame?, layout, robot_seg);
            Some(out)
        })
        .collect()
}
