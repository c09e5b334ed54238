"""The clay-block scene both Taichi baselines run (`taichi_mls_mpm.py`, `taichi_fair_mls_mpm.py`),
matching `ms2_mpm::scenes::clay_block` and the ms2-mpm substep, and their shared timing and
report line (read by compare_taichi.sh).

Units: metres, seconds, kilograms, pascals; z up.
"""

import math
import time

#: Grid nodes per axis, cell size (m), substep (s).
N_GRID, DX, DT = 64, 0.01, 5e-4
INV_DX = 1.0 / DX
#: Particle lattice spacing (m), rest volume (m^3) and mass (kg, clay of 1000 kg/m^3).
SPACING = 0.005
P_VOL = SPACING**3
P_MASS = 1000.0 * P_VOL
#: Young's modulus (Pa), Poisson ratio, von Mises yield stress (Pa), and the Lamé parameters.
E_MODULUS, NU, YIELD_STRESS = 1e4, 0.3, 2e3
MU = E_MODULUS / (2 * (1 + NU))
LAM = E_MODULUS * NU / ((1 + NU) * (1 - 2 * NU))
YIELD_STRAIN = YIELD_STRESS / (2 * MU)
#: Below this ratio of largest to smallest stretch nothing yields (ms2-mpm's shortcut).
ELASTIC_RATIO = math.exp(YIELD_STRAIN * 1.5**0.5)
#: Slip walls `BOUND` nodes thick, Coulomb friction on them; gravity (m/s^2).
BOUND, FRICTION = 3, 0.5
GRAVITY = (0.0, 0.0, -9.81)
LO_CLAMP, HI_CLAMP = BOUND * DX, (N_GRID - BOUND) * DX
#: Lower corner (m) of the block: 32 x 32 particles per layer, `particles // 1024` layers.
BLOCK_ORIGIN = (0.24, 0.24, 0.04)
#: Substeps run (and compiled) before the timed ones.
WARM_UP_SUBSTEPS = 50


def check_particles(particles: int) -> int:
    """The layer count of a block of `particles` (a positive multiple of 1024), else exit."""
    if particles <= 0 or particles % 1024:
        raise SystemExit(
            f"particles must be a positive multiple of 1024, got {particles}"
        )
    return particles // 1024


def timed_substeps(ti, substep, substeps: int) -> float:
    """Seconds for `substeps` calls of the kernel `substep` after the warm-up (JIT included)."""
    for _ in range(WARM_UP_SUBSTEPS):
        substep()
    ti.sync()
    start = time.perf_counter()
    for _ in range(substeps):
        substep()
    ti.sync()
    return time.perf_counter() - start


def report(
    ti, variant: str, positions, threads: int, substeps: int, secs: float
) -> None:
    """Prints the key=value line compare_taichi.sh reads; `positions` is the (N, 3) array."""
    particles = positions.shape[0]
    top = float(positions[:, 2].max())
    version = ".".join(str(part) for part in ti.__version__)
    print(
        f"engine=taichi-{version}{variant} particles={particles} threads={threads} "
        f"substeps={substeps} seconds={secs:.3f} "
        f"particle_substeps_per_s={particles * substeps / secs:.4e} top_z={top:.4f}"
    )
