"""``Ms2Env``: one ms2 environment as a ``gymnasium.Env``.

Made by ``gymnasium.make("PickCube-v0", obs_mode=..., control_mode=...)`` after ``import ms2``, or
directly as ``Ms2Env("PickCube-v0", ...)``. Observations are (nested dicts of) numpy arrays made
in Rust; actions are converted once to a contiguous float32 array and stepped with the GIL
released.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import gymnasium as gym
import numpy as np

from . import _native
from . import assets as _assets
from .spaces import to_gym_space
from .visualization import camera_images_to_tiles, tile_images

#: Native episode limit used when gymnasium's ``TimeLimit`` wrapper enforces the limit instead
#: (``gymnasium.make`` applies one with the registered or the given ``max_episode_steps``).
UNLIMITED_EPISODE_STEPS = 2**31 - 1

#: Physics substeps that share one articulation mass matrix in the rigid tasks unless
#: ``mass_matrix_substeps`` says otherwise (the native ``DEFAULT_MASS_MATRIX_SUBSTEPS``; a test
#: checks they agree). The soft-body tasks rebuild it every substep.
DEFAULT_MASS_MATRIX_SUBSTEPS = 3


#: Fraction of the solver's prediction distance a contact-free pair of robot links (or of a
#: robot link and the ground) may drift before the narrow phase looks at it again, unless
#: ``filtered_pair_recycling`` says otherwise (the native default; a test checks they agree).
DEFAULT_FILTERED_PAIR_RECYCLING = 1.0


def default_mass_matrix_substeps(soft_bodies: bool) -> int:
    """A task's default ``mass_matrix_substeps``: 1 with soft bodies, else
    ``DEFAULT_MASS_MATRIX_SUBSTEPS``."""
    return 1 if soft_bodies else DEFAULT_MASS_MATRIX_SUBSTEPS


def adopt_config(env: Any, config: dict[str, Any]) -> None:
    """Sets ``env_id``, ``obs_mode``, ``control_mode``, ``reward_mode``, ``render_mode``,
    ``sim_freq``, ``control_freq``, ``mpm_freq`` (``None`` without soft bodies) and
    ``exact_restore``, ``mass_matrix_substeps`` and ``filtered_pair_recycling`` on ``env``
    from a native env's resolved ``config()`` (task defaults filled in)."""
    for key in (
        "env_id",
        "obs_mode",
        "robot",
        "control_mode",
        "reward_mode",
        "render_mode",
        "sim_freq",
        "control_freq",
        "mpm_freq",
        "exact_restore",
        "mass_matrix_substeps",
        "filtered_pair_recycling",
    ):
        setattr(env, key, config[key])


#: Largest accepted seed: seeds are unsigned 64-bit integers, ``0 <= seed <= 2**64 - 1``
#: (ManiSkill2's own seeds, drawn by ``np.random.RandomState``, are below ``2**32``).
MAX_SEED = 2**64 - 1


def check_seed(seed: Any, name: str = "seed") -> int | None:
    """``seed`` as an int in ``[0, MAX_SEED]`` (``None`` passes): ``TypeError`` for a non-int
    (``bool`` and floats included), ``ValueError`` naming the range otherwise."""
    if seed is None:
        return None
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)):
        raise TypeError(f"{name} must be an int or None, got {type(seed).__name__} {seed!r}")
    if not 0 <= int(seed) <= MAX_SEED:
        raise ValueError(f"{name} must be in [0, 2**64 - 1], got {seed}")
    return int(seed)


def check_options(options: Any, valid: tuple[str, ...]) -> dict[str, Any]:
    """``reset``'s ``options`` as a dict (``None`` = empty): ``TypeError`` for a non-mapping,
    ``ValueError`` for an unknown key (naming the valid ones)."""
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise TypeError(f"options must be a dict or None, got {type(options).__name__} {options!r}")
    unknown = [k for k in options if k not in valid]
    if unknown:
        raise ValueError(f"unknown reset option(s) {unknown}; valid options: {list(valid)}")
    return dict(options)


def real_array(value: Any, what: str) -> np.ndarray:
    """``value`` as a contiguous float32 array; ``ValueError`` for complex, string, bytes or
    object data (which a float32 cast would silently mangle or fail on obscurely)."""
    array = np.asarray(value)
    if array.dtype == np.float32:  # no cast (the common case; errstate costs ~0.6 µs a call)
        return np.ascontiguousarray(array)
    if array.dtype.kind not in "biuf":
        raise ValueError(f"{what} must hold real numbers, got dtype {array.dtype}")
    with np.errstate(over="ignore"):  # values beyond float32 become inf, refused natively
        return np.ascontiguousarray(array, dtype=np.float32)


class _Closed:
    """Stands in for the native env after ``close()``: every use raises a clear error."""

    def __init__(self, what: str) -> None:
        self._what = what

    def __getattr__(self, name: str) -> Any:
        raise ValueError(f"this {self._what} is closed; make a new one")


def _seed_from(rng: np.random.Generator) -> int:
    """A 63-bit seed drawn from ``rng``."""
    return int(rng.integers(0, 2**63 - 1))


class Ms2Env(gym.Env):
    """An ms2 task (``PickCube-v0``, ``LiftCube-v0``, ``StackCube-v0``, ...) as a gymnasium env.

    Args:
        env_id: registered task id (``ms2.env_ids()`` lists them).
        obs_mode: ``"state"`` (default, ManiSkill2's: one flat float32 array), ``"state_dict"``
            (nested dict of arrays), ``"none"`` (an empty dict), ``"image"`` (raw camera
            textures ``Color`` / ``Position``), ``"rgbd"``, ``"pointcloud"``,
            ``"rgbd_robot_seg"``, ``"pointcloud_robot_seg"``, and ``"particles"`` on the
            soft-body tasks; ``supported_obs_modes`` lists an env's.
        robot: robot uid, ManiSkill2's keyword (``"panda"``); ``None`` = the task's default.
            A robot the task does not support raises ``ValueError`` listing the valid ones.
        control_mode: e.g. ``"pd_ee_delta_pose"``; ``None`` = ``"pd_joint_delta_pos"``.
        reward_mode: ``"sparse"``, ``"dense"`` or ``"normalized_dense"`` (``None``).
        render_mode: ``None``, ``"rgb_array"`` (the render camera's 512×512 view),
            ``"cameras"`` (that view tiled with every observation camera's images: RGB, depth
            and, with ``add_segmentation``, the two segmentation channels, as ManiSkill2) or
            ``"human"`` (``render()`` opens and updates a viewer window: mouse orbit / pan /
            zoom, ``space`` pause, ``n`` single step, ``c`` sensor views, ``m`` segmentation;
            see docs/viewer.md). ``"human"`` needs a display: without one ``render()`` raises
            ``RuntimeError`` naming ``DISPLAY`` / ``WAYLAND_DISPLAY``.
        sim_freq: physics frequency in Hz (500 by default).
        control_freq: env step frequency in Hz (20 by default); ``sim_freq`` must be a multiple.
        max_episode_steps: episode limit in env steps after which ``truncated`` is set;
            ``None`` = the task's default (200).
        camera_cfgs: changes to the observation cameras of the visual obs modes, as ManiSkill2's
            keyword: ``{"width": 64, "height": 64, "fov": 1.2}`` sets fields of every camera,
            ``{"base_camera": {"p": [..], "q": [..]}}`` of one camera (fields: ``width``,
            ``height``, ``fov`` (vertical, radians), ``near``, ``far`` (m), ``p``, ``q`` (pose
            in the mount's frame, quaternion wxyz), ``add_segmentation`` (adds
            ``Segmentation`` u32 [H, W, 4] to the ``image`` / ``rgbd`` observations)). Unknown
            keys or bad values raise ``ValueError``.
        mpm_freq: MPM substep frequency in Hz of the soft-body tasks (``Excavate-v0``,
            ``Fill-v0``); ``None`` = the task's default (2000, as ManiSkill2). Must be a
            whole multiple of ``sim_freq``; ``ValueError`` on envs without soft bodies.
        enable_shadow: whether the first directional light casts shadows in every image
            (ManiSkill2's keyword; off by default).
        render_camera_cfgs: changes to the camera of ``render()``, as ``camera_cfgs``
            (``{"width": 256, "height": 256, "fov": 1.2, "p": [..], "q": [..]}``, also under
            the key ``"render_camera"``).
        bg_name: ManiSkill2's visual background; only ``None`` (ms2 ships no background
            scenes: any name raises ``ValueError``).
        exact_restore: when ``True``, every step starts from the flat state alone (rapier's
            warm-start history is dropped first, as at a reset), so ``set_state`` into *any*
            env of the same build continues bit for bit like the recorded run; costs about
            20 % of the state step rate. Off by default (then a restore into the same env,
            or of an episode's first state, is still exact; see docs/trajectory_format.md).
        mass_matrix_substeps: how many consecutive 2 ms physics substeps share one joint-space
            mass matrix of each robot or articulated object; ``None`` = the task's default (3
            for the rigid tasks: rebuilt at substeps 0, 3, ..., 24 of each env step, saving
            about a sixth of the CPU time of a rigid env step; 1 for the soft-body tasks). 1
            rebuilds it every substep, as upstream rapier. ms2's own keyword; an int in
            ``[1, 1000]``, else ``TypeError`` / ``ValueError``.
        filtered_pair_recycling: how far (a fraction of the 2 mm prediction distance) a pair of
            robot links, or a robot link and the ground, without contacts may drift before the
            narrow phase looks at it again (a pair farther apart: its separation less 2 mm);
            ``None`` = the default, 1. 0 looks at every pair at
            every substep, as upstream rapier (with ``mass_matrix_substeps=1``: the dynamics of
            trajectories recorded before 2026-11-29). Pairs in contact and pairs with the
            task's objects are always updated. ms2's own keyword; a number in ``[0, 1]``, else
            ``TypeError`` / ``ValueError``.
        model_ids: the object models episodes draw from in the object-variation tasks
            (``PickSingleYCB-v0``, ``PickSingleEGAD-v0``; ``PickClutterYCB-v0``'s procedural
            clutters), ManiSkill2's keyword: one id or a list; ``None`` = every model of the
            task's info json. An unknown id raises
            ``ValueError`` naming it; other tasks refuse the keyword.

    Unknown ids or modes raise ``ValueError`` listing the valid ones.
    """

    metadata = {"render_modes": ["rgb_array", "cameras", "human"], "render_fps": 20}

    def __init__(
        self,
        env_id: str = "PickCube-v0",
        obs_mode: str = "state",
        robot: str | None = None,
        control_mode: str | None = None,
        reward_mode: str | None = None,
        render_mode: str | None = None,
        sim_freq: float = 500.0,
        control_freq: float = 20.0,
        max_episode_steps: int | None = None,
        camera_cfgs: dict[str, Any] | None = None,
        mpm_freq: float | None = None,
        enable_shadow: bool = False,
        render_camera_cfgs: dict[str, Any] | None = None,
        bg_name: str | None = None,
        exact_restore: bool = False,
        mass_matrix_substeps: int | None = None,
        filtered_pair_recycling: float | None = None,
        model_ids: str | list[str] | None = None,
    ) -> None:
        _assets.register_installed_packages()
        self._native = _native.NativeEnv(
            env_id,
            obs_mode=obs_mode,
            robot=robot,
            control_mode=control_mode,
            reward_mode=reward_mode,
            render_mode=render_mode,
            sim_freq=sim_freq,
            control_freq=control_freq,
            max_episode_steps=max_episode_steps,
            camera_cfgs=camera_cfgs,
            mpm_freq=mpm_freq,
            enable_shadow=enable_shadow,
            render_camera_cfgs=render_camera_cfgs,
            bg_name=bg_name,
            exact_restore=exact_restore,
            mass_matrix_substeps=mass_matrix_substeps,
            filtered_pair_recycling=filtered_pair_recycling,
            model_ids=model_ids,
        )
        adopt_config(self, self._native.config())
        _assets.warn_if_primitive_panda()
        self.observation_space = to_gym_space(self._native.observation_space())
        self.action_space = to_gym_space(self._native.action_space())
        self.metadata = {**self.metadata, "render_fps": self.control_freq}
        self._seeded = False
        self._viewer: Any = None

    # --- gymnasium API -------------------------------------------------------------------------

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        """Starts an episode. ``seed`` makes it reproducible; ``seed=None`` continues the env's
        random sequence (seeded from OS entropy on the first reset). ``options={"reconfigure":
        True}`` rebuilds the scene (ManiSkill2's option)."""
        seed = check_seed(seed)
        options = check_options(options, ("reconfigure",))
        reconfigure = options.get("reconfigure", False)
        if not isinstance(reconfigure, (bool, np.bool_)):
            raise TypeError(f"options['reconfigure'] must be a bool, got {reconfigure!r}")
        native_reset = self._native.reset  # a closed env raises here
        super().reset(seed=seed)
        if seed is None and not self._seeded:
            seed = _seed_from(self.np_random)
        if seed is not None:
            self._seeded = True
        reconfigure = bool(reconfigure)
        return native_reset(seed=seed, reconfigure=reconfigure)

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        """One control step (``sim_freq / control_freq`` physics steps). ``action`` must have the
        action space's shape and be finite (``ValueError`` otherwise)."""
        native_step = self._native.step  # a closed env raises here
        action = real_array(action, "action")
        if action.shape != self.action_space.shape:
            raise ValueError(
                f"action for control_mode {self.control_mode!r} must have shape "
                f"{self.action_space.shape}, got {action.shape}"
            )
        return native_step(action)

    def render(self) -> np.ndarray | None:
        """An RGB image (uint8 [H, W, 3]): with ``render_mode="rgb_array"`` the render
        camera's view (goal markers shown); with ``"cameras"`` that view tiled with every
        observation camera's RGB, depth and segmentation images (ManiSkill2's layout). With
        ``"human"`` it shows the scene in the viewer window (opened on the first call) and
        returns ``None`` (gymnasium's rule; :meth:`render_human` returns the viewer, as
        ManiSkill2's does, and :attr:`viewer` holds it)."""
        if self.render_mode is None:
            gym.logger.warn(
                "render() called without render_mode; make the env with render_mode='rgb_array'"
            )
            return None
        if self.render_mode == "human":
            self.render_human()
            return None
        view = self._native.render()
        if self.render_mode == "cameras":
            return tile_images([view, *camera_images_to_tiles(self._native.camera_images())])
        return view

    def get_obs(self) -> Any:
        """The observation of the current state in the env's obs mode, without stepping
        (ManiSkill2's ``env.get_obs()``)."""
        return self._native.get_obs()

    def render_human(self) -> Any:
        """Opens the viewer window on the first call (``RuntimeError`` without a display),
        handles its mouse and key events and draws the scene as it is now. While the viewer is
        paused (``space``) the call keeps the window live and returns only when the user
        resumes, single-steps (``n``) or closes the window, so a loop that calls ``render()``
        after each ``step()`` pauses with it. Returns the viewer (``ms2._native.NativeViewer``:
        ``take_keys()``, ``press_key()``, ``paused``, ``closed``, ``close()``, ...)."""
        if self._viewer is None:
            self._viewer = _native.NativeViewer(self._native, title=f"ms2 {self.env_id}")
        if not self._viewer.closed:
            self._viewer.show(self._native)
        return self._viewer

    @property
    def viewer(self) -> Any:
        """The viewer window of ``render_mode="human"`` (``None`` before the first render)."""
        return self._viewer

    def close(self) -> None:
        """Closes the viewer window, if any, and releases the native env; any later call
        raises ``ValueError`` (the env is closed)."""
        if self._viewer is not None:
            self._viewer.close()
            self._viewer = None
        self._native = _Closed("Ms2Env")  # type: ignore[assignment]

    # --- ManiSkill2-style extras ----------------------------------------------------------------

    def get_state(self) -> np.ndarray:
        """The full simulation state (float32 vector) to restore with :meth:`set_state`."""
        return self._native.get_state()

    def set_state(self, state: np.ndarray) -> None:
        """Restores a state from :meth:`get_state`. ``ValueError`` on a wrong length, NaN, or an
        impossible value (a joint outside its limits, a body too fast or too far away, a
        non-unit quaternion), naming the index and its meaning (bounds:
        ``docs/tasks.md``, "State bounds")."""
        state = real_array(state, "state")
        if state.ndim != 1:
            raise ValueError(f"state must be a 1-D array, got shape {state.shape}")
        self._native.set_state(state)

    def segmentation_ids(self) -> dict[str, int]:
        """Ids of the segmentation images' channel 1 (actor/link) by object name: ``"ground"``,
        each actor (e.g. ``"cube"``), each robot link (``"panda_hand"``, ...) and the soft-body
        tasks' particles (``"clay"``). ``obs["camera"]["Segmentation"][..., 1] == ids["clay"]``
        masks the clay."""
        return dict(self._native.segmentation_ids())

    @property
    def elapsed_steps(self) -> int:
        """Env steps taken in this episode."""
        return self._native.elapsed_steps()

    @property
    def episode_seed(self) -> int:
        """Seed of the current episode: ``reset(seed=env.episode_seed)`` replays it."""
        return self._native.episode_seed()

    @property
    def model_id(self) -> str:
        """The asset model of the current episode (ManiSkill2's ``env.model_id``) in the tasks
        that draw one per episode: PickSingleYCB/EGAD, TurnFaucet, OpenCabinetDrawer/Door.
        Other tasks raise ``AttributeError``, as ManiSkill2's envs without the attribute do."""
        model_id = self._native.model_id()
        if model_id is None:
            raise AttributeError(f"{self.env_id} has no model_id: it does not draw asset models")
        return model_id

    @property
    def model_scale(self) -> float:
        """The scale of the current episode's model (ManiSkill2's ``env.model_scale``) in
        PickSingleYCB/EGAD; ``AttributeError`` elsewhere."""
        scale = self._native.model_scale()
        if scale is None:
            raise AttributeError(f"{self.env_id} has no model_scale: it does not scale models")
        return scale

    @property
    def max_episode_steps(self) -> int:
        """The native episode limit in env steps."""
        return self._native.max_episode_steps()

    @property
    def supported_control_modes(self) -> list[str]:
        """Control modes of this env's robot."""
        return self._native.control_modes()

    @property
    def supported_obs_modes(self) -> list[str]:
        """Observation modes of this env."""
        return self._native.obs_modes()

    @property
    def supported_reward_modes(self) -> list[str]:
        """Reward modes of this env."""
        return self._native.reward_modes()


def make_registered(**kwargs: Any) -> Ms2Env:
    """Entry point of the ids registered with gymnasium: an :class:`Ms2Env` whose episode limit
    is left to the ``TimeLimit`` wrapper ``gymnasium.make`` adds (so ``gymnasium.make(id,
    max_episode_steps=N)`` works as for any gymnasium env)."""
    kwargs.setdefault("max_episode_steps", UNLIMITED_EPISODE_STEPS)
    return Ms2Env(**kwargs)


class ScriptedPolicy:
    """The runtime's scripted (oracle, privileged-state) policy for an env.

    ``policy = ScriptedPolicy(env)`` (a gymnasium env made from ms2, wrappers allowed); call
    :meth:`reset` after each ``env.reset`` and :meth:`act` for each step's action. ``ValueError``
    if the task has no scripted policy for the env's control mode.
    """

    def __init__(self, env: gym.Env) -> None:
        unwrapped = env.unwrapped
        if not isinstance(unwrapped, Ms2Env):
            raise TypeError(f"ScriptedPolicy needs an ms2 env, got {type(unwrapped).__name__}")
        self._native = _native.NativeScriptedPolicy(unwrapped._native)

    def reset(self) -> None:
        """Starts a new episode (call after ``env.reset``)."""
        self._native.reset()

    def act(self) -> np.ndarray:
        """The action for the env's current state (float32, the action space's shape)."""
        return self._native.act()
