"""Reference: the same MLS-MPM clay substep as ms2-mpm, written with Taichi's CPU backend.

Scene and step match `ms2_mpm::scenes::clay_block` and the ms2-mpm substep: a 64^3 grid of
1 cm cells, 5 mm particle spacing (volume 1.25e-7 m^3), clay of density 1000 kg/m^3, E 1e4 Pa,
Poisson 0.3, yield stress 2e3 Pa (fixed-corotated elasticity, von Mises return mapping on the
Hencky strain), slip walls 3 nodes thick with friction 0.5, gravity -9.81 m/s^2 on z, substeps
of 0.5 ms. Prints one line of key=value pairs (read by compare_taichi.sh).

Usage: python taichi_mls_mpm.py PARTICLES THREADS SUBSTEPS
"""

import sys

import taichi as ti

from mls_scene import (
    BLOCK_ORIGIN,
    BOUND,
    DT,
    DX,
    FRICTION,
    GRAVITY,
    HI_CLAMP,
    INV_DX,
    LAM,
    LO_CLAMP,
    MU,
    N_GRID,
    P_MASS,
    P_VOL,
    SPACING,
    YIELD_STRAIN,
    check_particles,
    report,
    timed_substeps,
)


def main() -> None:
    particles, threads, substeps = (int(a) for a in sys.argv[1:4])
    layers = check_particles(particles)
    ti.init(
        arch=ti.cpu, cpu_max_num_threads=threads, default_fp=ti.f32, log_level=ti.WARN
    )

    n_grid, dx, dt, inv_dx = N_GRID, DX, DT, INV_DX
    spacing, p_vol, p_mass = SPACING, P_VOL, P_MASS
    mu, lam, yield_strain = MU, LAM, YIELD_STRAIN
    bound, friction = BOUND, FRICTION
    gravity = ti.Vector(GRAVITY)
    lo_clamp, hi_clamp = LO_CLAMP, HI_CLAMP

    x = ti.Vector.field(3, ti.f32, particles)
    v = ti.Vector.field(3, ti.f32, particles)
    c_aff = ti.Matrix.field(3, 3, ti.f32, particles)
    f_def = ti.Matrix.field(3, 3, ti.f32, particles)
    grid_v = ti.Vector.field(3, ti.f32, (n_grid, n_grid, n_grid))
    grid_m = ti.field(ti.f32, (n_grid, n_grid, n_grid))

    @ti.kernel
    def init():
        for p in x:
            i, j, k = p // (32 * layers), (p // layers) % 32, p % layers
            x[p] = ti.Vector(BLOCK_ORIGIN) + (ti.Vector([i, j, k]) + 0.5) * spacing
            v[p] = ti.Vector.zero(ti.f32, 3)
            c_aff[p] = ti.Matrix.zero(ti.f32, 3, 3)
            f_def[p] = ti.Matrix.identity(ti.f32, 3)

    @ti.kernel
    def substep():
        for I in ti.grouped(grid_m):
            grid_v[I] = ti.Vector.zero(ti.f32, 3)
            grid_m[I] = 0.0
        for p in x:
            xg = x[p] * inv_dx
            base = ti.cast(ti.floor(xg - 0.5), ti.i32)
            fx = xg - base
            w = [0.5 * (1.5 - fx) ** 2, 0.75 - (fx - 1.0) ** 2, 0.5 * (fx - 0.5) ** 2]
            f_new = (ti.Matrix.identity(ti.f32, 3) + dt * c_aff[p]) @ f_def[p]
            u, sig, vv = ti.svd(f_new)
            s = ti.Vector(
                [
                    ti.max(sig[0, 0], 0.05),
                    ti.max(sig[1, 1], 0.05),
                    ti.max(sig[2, 2], 0.05),
                ]
            )
            eps = ti.log(s)
            dev = eps - eps.sum() / 3.0
            dev_norm = dev.norm()
            excess = dev_norm - yield_strain
            if excess > 0.0:
                eps -= dev * (excess / dev_norm)
                s = ti.exp(eps)
            f_def[p] = (
                u
                @ ti.Matrix([[s[0], 0, 0], [0, s[1], 0], [0, 0, s[2]]])
                @ vv.transpose()
            )
            j_det = s[0] * s[1] * s[2]
            d = 2.0 * mu * (s - 1.0) * s
            tau = (
                u
                @ ti.Matrix([[d[0], 0, 0], [0, d[1], 0], [0, 0, d[2]]])
                @ u.transpose()
            )
            tau += ti.Matrix.identity(ti.f32, 3) * (lam * (j_det - 1.0) * j_det)
            affine = (-dt * p_vol * 4.0 * inv_dx * inv_dx) * tau + p_mass * c_aff[p]
            for i, j, k in ti.static(ti.ndrange(3, 3, 3)):
                offset = ti.Vector([i, j, k])
                dpos = (offset - fx) * dx
                weight = w[i][0] * w[j][1] * w[k][2]
                grid_v[base + offset] += weight * (p_mass * v[p] + affine @ dpos)
                grid_m[base + offset] += weight * p_mass
        for I in ti.grouped(grid_m):
            m = grid_m[I]
            if m > 0.0:
                vel = grid_v[I] / m + dt * gravity
                for a in ti.static(range(3)):
                    outward = 0.0
                    if I[a] < bound:
                        outward = -1.0
                    elif I[a] >= n_grid - bound:
                        outward = 1.0
                    vn = vel[a] * outward
                    if vn > 0.0:
                        vel[a] = 0.0
                        vt = vel.norm()
                        if vt > 0.0:
                            vel *= ti.max(1.0 - friction * vn / vt, 0.0)
                grid_v[I] = vel
        for p in x:
            xg = x[p] * inv_dx
            base = ti.cast(ti.floor(xg - 0.5), ti.i32)
            fx = xg - base
            w = [0.5 * (1.5 - fx) ** 2, 0.75 - (fx - 1.0) ** 2, 0.5 * (fx - 0.5) ** 2]
            new_v = ti.Vector.zero(ti.f32, 3)
            new_c = ti.Matrix.zero(ti.f32, 3, 3)
            for i, j, k in ti.static(ti.ndrange(3, 3, 3)):
                offset = ti.Vector([i, j, k])
                dpos = (offset - fx) * dx
                weight = w[i][0] * w[j][1] * w[k][2]
                g = grid_v[base + offset]
                new_v += weight * g
                new_c += 4.0 * inv_dx * inv_dx * weight * g.outer_product(dpos)
            v[p] = new_v
            c_aff[p] = new_c
            x[p] = ti.math.clamp(x[p] + dt * new_v, lo_clamp, hi_clamp)

    init()
    secs = timed_substeps(ti, substep, substeps)
    report(ti, "", x.to_numpy(), threads, substeps, secs)


if __name__ == "__main__":
    main()
