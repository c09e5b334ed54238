"""ManiSkill2 0.5.3's env-state vectors mapped into ms2's, so that trajectory files ManiSkill2
wrote (its released demonstrations) replay and convert in ms2.

ManiSkill2's state of a rigid-body task (``BaseEnv.get_state``): every actor of the scene in
creation order (the ground and kinematic markers included) as pose p (3), q (wxyz, 4), linear
and angular velocity (3 + 3); then each articulation as root pose (7), root velocity (6),
``qpos`` (n) and ``qvel`` (n); then the task's own entries (PickCube / LiftCube: ``goal_pos``).

ms2's state (``docs/tasks.md``): the dynamic actors (pose 7, velocities 3 + 3), the robot's
root pose (7) and, per joint, position, velocity, drive position target and drive velocity
target; then the controller state of target-accumulating control modes; then the task state.

The mapping copies the actors' and joints' values; ManiSkill2 keeps no drive targets, so they
are set to hold the recorded joint positions at rest (the next action sets them anew), and the
controller state (empty in the non-target modes ManiSkill2's demos use) is taken from the ms2
env. A state ms2 cannot map raises :class:`UnmappableStateError`, naming the file, the env and
the lengths.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Floats per actor in both layouts: pose (7) and linear + angular velocity (6).
ACTOR_LEN = 13
#: Floats of ManiSkill2's articulation header: root pose (7) and root velocity (6).
MS2_ROOT_LEN = 7
MANISKILL2_ROOT_LEN = 13


@dataclass(frozen=True)
class ManiSkill2Layout:
    """What ManiSkill2 0.5.3 stores for one task.

    Attributes:
        actors: the scene's actors in ManiSkill2's order (``None`` = not simulated in ms2:
            the ground, goal markers), else the index of the matching dynamic actor in ms2.
        dof: the robot's joint count (Panda: 7 arm + 2 fingers).
        task_len: floats of the task's own state after the robot (the same entries in ms2).
    """

    actors: tuple[int | None, ...]
    dof: int
    task_len: int

    @property
    def length(self) -> int:
        """Length of ManiSkill2's state vector."""
        return ACTOR_LEN * len(self.actors) + MANISKILL2_ROOT_LEN + 2 * self.dof + self.task_len

    @property
    def ms2_actor_count(self) -> int:
        return sum(a is not None for a in self.actors)


#: ManiSkill2 0.5.3's layouts of the tasks ms2 has (actors: ground, objects, goal marker).
LAYOUTS: dict[str, ManiSkill2Layout] = {
    "PickCube-v0": ManiSkill2Layout(actors=(None, 0, None), dof=9, task_len=3),
    "LiftCube-v0": ManiSkill2Layout(actors=(None, 0, None), dof=9, task_len=3),
    "StackCube-v0": ManiSkill2Layout(actors=(None, 0, 1), dof=9, task_len=0),
}


class UnmappableStateError(ValueError):
    """A trajectory's env states match neither ms2's layout nor a known ManiSkill2 one."""


def _unmappable(source: str, env_id: str, got: int, ms2_len: int, why: str) -> UnmappableStateError:
    known = LAYOUTS.get(env_id)
    expected = f"ms2's {ms2_len}" + (f" or ManiSkill2 0.5.3's {known.length}" if known else "")
    return UnmappableStateError(
        f"{source}: env states of {env_id} have {got} floats; expected {expected} ({why})"
    )


def map_states(
    states: np.ndarray, env_id: str, template: np.ndarray, source: str = "trajectory"
) -> np.ndarray:
    """ManiSkill2 0.5.3 states ``[T, S_ms2]`` (or one ``[S]``) of ``env_id`` as ms2 states.

    ``template`` is a state of the ms2 env that will take them (same control mode): its
    controller-state part is kept. ``source`` names the file in errors. States already of ms2's
    length are returned unchanged. Raises :class:`UnmappableStateError` when the length matches
    neither layout."""
    states = np.asarray(states, dtype=np.float32)
    template = np.asarray(template, dtype=np.float32)
    single = states.ndim == 1
    rows = states[None] if single else states
    if rows.shape[1] == template.size:
        return states
    layout = LAYOUTS.get(env_id)
    if layout is None:
        raise _unmappable(
            source, env_id, rows.shape[1], template.size, "no ManiSkill2 layout is known for it"
        )
    if rows.shape[1] != layout.length:
        raise _unmappable(
            source, env_id, rows.shape[1], template.size, "not ManiSkill2 0.5.3's layout either"
        )
    world_len = ACTOR_LEN * layout.ms2_actor_count + MS2_ROOT_LEN + 4 * layout.dof
    ctrl_len = template.size - world_len - layout.task_len
    if ctrl_len < 0:
        raise _unmappable(
            source, env_id, rows.shape[1], template.size, "ms2's scene has other objects"
        )
    out = np.repeat(template[None], rows.shape[0], axis=0)
    for ms_index, ms2_index in enumerate(layout.actors):
        if ms2_index is not None:
            src = slice(ACTOR_LEN * ms_index, ACTOR_LEN * (ms_index + 1))
            out[:, ACTOR_LEN * ms2_index : ACTOR_LEN * (ms2_index + 1)] = rows[:, src]
    robot_src = ACTOR_LEN * len(layout.actors)
    robot_dst = ACTOR_LEN * layout.ms2_actor_count
    out[:, robot_dst : robot_dst + MS2_ROOT_LEN] = rows[:, robot_src : robot_src + MS2_ROOT_LEN]
    qpos_at = robot_src + MANISKILL2_ROOT_LEN
    qpos = rows[:, qpos_at : qpos_at + layout.dof]
    qvel = rows[:, qpos_at + layout.dof : qpos_at + 2 * layout.dof]
    joints = np.stack([qpos, qvel, qpos, np.zeros_like(qpos)], axis=-1)  # [T, dof, 4]
    joints_at = robot_dst + MS2_ROOT_LEN
    out[:, joints_at : joints_at + 4 * layout.dof] = joints.reshape(rows.shape[0], -1)
    if layout.task_len:
        out[:, template.size - layout.task_len :] = rows[:, -layout.task_len :]
    return out[0] if single else out


__all__ = ["LAYOUTS", "ManiSkill2Layout", "UnmappableStateError", "map_states"]
