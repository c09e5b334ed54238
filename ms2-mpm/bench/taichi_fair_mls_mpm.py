"""A fair Taichi baseline for ms2-mpm: the clay substep of `taichi_mls_mpm.py` (same scene,
grid, dx, dt, material model, boundary and particle count), written the way a Taichi expert
would write it for a CPU:

- particle-to-grid scatters without atomics: each particle adds its contributions with
  plain loads and stores to the private grid of the thread running it
  (`ti.global_thread_idx()`, the CPU worker's index), and a parallel pass over the nodes adds
  the copies (and zeroes them for the next substep);
- the grid passes (reduction, grid update) visit only the particles' bounding box of nodes
  (stencil included), tracked per thread at the end of grid-to-particle;
- the grids are stored in dense 4x4x4-node blocks (`ti.root.dense(...).dense(...)`), each
  node a vec4 (momentum or velocity xyz, mass w);
- the stress comes either from `ti.svd` with the original port's von Mises return mapping
  (`--eigen svd`), or from a port of ms2-mpm's own algorithm (`--eigen jacobi`): cyclic Jacobi
  on F·Fᵀ for the left rotation and stretches (sweeps stop at a relative off-diagonal size
  of 1e-6, at most four), the stretch-ratio test that skips the logarithms inside the yield
  surface, the projection F <- U·diag(s_new/s)·Uᵀ·F, and `ti.svd` only for inverted or
  collapsed states (as ms2-mpm's `CompiledMaterial::project_and_stress_left`).

Prints one line of key=value pairs (read by compare_taichi.sh).

Usage: python taichi_fair_mls_mpm.py PARTICLES THREADS SUBSTEPS [--eigen svd|jacobi]
"""

import argparse

import taichi as ti

from mls_scene import (
    BLOCK_ORIGIN,
    BOUND,
    DT,
    DX,
    ELASTIC_RATIO,
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
    ap = argparse.ArgumentParser()
    ap.add_argument("particles", type=int)
    ap.add_argument("threads", type=int)
    ap.add_argument("substeps", type=int)
    ap.add_argument("--eigen", choices=["svd", "jacobi"], default="svd")
    args = ap.parse_args()
    n_part, n_thr, substeps = args.particles, args.threads, args.substeps
    layers = check_particles(n_part)
    if n_thr <= 0:
        raise SystemExit(f"threads must be >= 1, got {n_thr}")
    jacobi = args.eigen == "jacobi"
    ti.init(
        arch=ti.cpu, cpu_max_num_threads=n_thr, default_fp=ti.f32, log_level=ti.WARN
    )

    n_grid, dx, dt, inv_dx = N_GRID, DX, DT, INV_DX
    spacing, p_vol, p_mass = SPACING, P_VOL, P_MASS
    mu, lam, yield_strain = MU, LAM, YIELD_STRAIN
    elastic_ratio = ELASTIC_RATIO
    min_stretch = 0.05
    jac_tol2, jac_sweeps = 1e-6 * 1e-6, 4
    bound, friction = BOUND, FRICTION
    gravity = ti.Vector(GRAVITY)
    lo_clamp, hi_clamp = LO_CLAMP, HI_CLAMP
    block = 4

    x = ti.Vector.field(3, ti.f32, n_part)
    v = ti.Vector.field(3, ti.f32, n_part)
    c_aff = ti.Matrix.field(3, 3, ti.f32, n_part)
    f_def = ti.Matrix.field(3, 3, ti.f32, n_part)
    # Shared grid (velocity xyz, mass w) and one private grid per thread, in 4^3-node blocks.
    grid = ti.Vector.field(4, ti.f32)
    ti.root.dense(ti.ijk, n_grid // block).dense(ti.ijk, block).place(grid)
    priv = ti.Vector.field(4, ti.f32)
    ti.root.dense(ti.i, n_thr).dense(ti.jkl, n_grid // block).dense(
        ti.jkl, block
    ).place(priv)
    # Per thread, the range of stencil base nodes of the particles it moved; union in `box`.
    thread_lo = ti.Vector.field(3, ti.i32, n_thr)
    thread_hi = ti.Vector.field(3, ti.i32, n_thr)
    box = ti.Vector.field(3, ti.i32, 2)

    @ti.func
    def base_node(xp):
        return ti.cast(ti.floor(xp * inv_dx - 0.5), ti.i32)

    @ti.kernel
    def init():
        for p in x:
            i, j, k = p // (32 * layers), (p // layers) % 32, p % layers
            x[p] = ti.Vector(BLOCK_ORIGIN) + (ti.Vector([i, j, k]) + 0.5) * spacing
            v[p] = ti.Vector.zero(ti.f32, 3)
            c_aff[p] = ti.Matrix.zero(ti.f32, 3, 3)
            f_def[p] = ti.Matrix.identity(ti.f32, 3)
        for t in range(n_thr):
            thread_lo[t] = ti.Vector([0, 0, 0])
            thread_hi[t] = ti.Vector([n_grid - 3, n_grid - 3, n_grid - 3])

    @ti.func
    def corotated(u, s):
        d = 2.0 * mu * (s - 1.0) * s
        j_det = s[0] * s[1] * s[2]
        us = ti.Matrix.cols([u[:, 0] * d[0], u[:, 1] * d[1], u[:, 2] * d[2]])
        return us @ u.transpose() + ti.Matrix.identity(ti.f32, 3) * (
            lam * (j_det - 1.0) * j_det
        )

    @ti.func
    def stress_svd(f_new):
        """The original port: SVD, clamp, return mapping on the Hencky strain."""
        u, sig, vv = ti.svd(f_new)
        s = ti.Vector(
            [
                ti.max(sig[0, 0], min_stretch),
                ti.max(sig[1, 1], min_stretch),
                ti.max(sig[2, 2], min_stretch),
            ]
        )
        eps = ti.log(s)
        dev = eps - eps.sum() / 3.0
        dev_norm = dev.norm()
        excess = dev_norm - yield_strain
        if excess > 0.0:
            eps -= dev * (excess / dev_norm)
            s = ti.exp(eps)
        f_out = (
            u @ ti.Matrix([[s[0], 0, 0], [0, s[1], 0], [0, 0, s[2]]]) @ vv.transpose()
        )
        return f_out, corotated(u, s)

    @ti.func
    def left_stretch(f):
        """ms2-mpm's left stretch: cyclic Jacobi on F·Fᵀ (eigenvalues = stretches²), the
        rotation angle in the form with two square roots and one division, sorted by
        decreasing stretch with det U = +1."""
        a = f @ f.transpose()
        u = ti.Matrix.identity(ti.f32, 3)
        for _ in range(jac_sweeps):
            off = a[0, 1] ** 2 + a[0, 2] ** 2 + a[1, 2] ** 2
            diag = a[0, 0] ** 2 + a[1, 1] ** 2 + a[2, 2] ** 2
            if off <= jac_tol2 * diag:
                break
            for p, q, r in ti.static(((0, 1, 2), (0, 2, 1), (1, 2, 0))):
                beta = 2.0 * a[p, q]
                tau = a[q, q] - a[p, p]
                rr = ti.sqrt(tau * tau + beta * beta)
                d = ti.abs(tau) + rr
                prod = 2.0 * rr * d
                c, s = 1.0, 0.0
                if prod >= 1.1754944e-38:
                    inv = 1.0 / ti.sqrt(prod)
                    sgn = 1.0 if tau >= 0.0 else -1.0
                    c, s = d * inv, -(sgn * beta * inv)
                pp, qq, pq = a[p, p], a[q, q], a[p, q]
                cs = c * s
                a[p, p] = c * c * pp + 2.0 * cs * pq + s * s * qq
                a[q, q] = s * s * pp - 2.0 * cs * pq + c * c * qq
                a[p, q] = cs * (qq - pp) + (c * c - s * s) * pq
                a[q, p] = a[p, q]
                pr, qr = a[p, r], a[q, r]
                a[p, r] = c * pr + s * qr
                a[r, p] = a[p, r]
                a[q, r] = c * qr - s * pr
                a[r, q] = a[q, r]
                up, uq = u[:, p], u[:, q]
                u_p, u_q = c * up + s * uq, c * uq - s * up
                for k in ti.static(range(3)):
                    u[k, p], u[k, q] = u_p[k], u_q[k]
        lam2 = ti.Vector([a[0, 0], a[1, 1], a[2, 2]])
        for i, j in ti.static(((0, 1), (0, 2), (1, 2))):
            if lam2[i] < lam2[j]:
                ui, uj = u[:, i], u[:, j]
                for k in ti.static(range(3)):
                    u[k, i], u[k, j] = uj[k], -ui[k]
                lam2[i], lam2[j] = lam2[j], lam2[i]
        return u, ti.sqrt(ti.max(lam2, 0.0))

    @ti.func
    def stress_jacobi(f_new):
        """ms2-mpm's clay path (see `CompiledMaterial::project_and_stress_left`)."""
        f_out, tau = f_new, ti.Matrix.zero(ti.f32, 3, 3)
        u, s = left_stretch(f_new)
        if s[2] < min_stretch or f_new.determinant() <= 0.0:
            f_out, tau = stress_svd(f_new)
        elif s[0] <= elastic_ratio * s[2]:
            tau = corotated(u, s)
        else:
            eps = ti.log(s)
            dev = eps - eps.sum() / 3.0
            dev_norm = dev.norm()
            excess = dev_norm - yield_strain
            if excess <= 0.0:
                tau = corotated(u, s)
            else:
                s_new = ti.exp(eps - dev * (excess / dev_norm))
                r = s_new / s
                ur = ti.Matrix.cols([u[:, 0] * r[0], u[:, 1] * r[1], u[:, 2] * r[2]])
                f_out = ur @ u.transpose() @ f_new
                tau = corotated(u, s_new)
        return f_out, tau

    @ti.func
    def weights(fx):
        return [0.5 * (1.5 - fx) ** 2, 0.75 - (fx - 1.0) ** 2, 0.5 * (fx - 0.5) ** 2]

    @ti.kernel
    def p2g():
        for p in range(n_part):
            t = ti.global_thread_idx()
            base = base_node(x[p])
            fx = x[p] * inv_dx - base
            w = weights(fx)
            f_new = (ti.Matrix.identity(ti.f32, 3) + dt * c_aff[p]) @ f_def[p]
            f_out, tau = ti.Matrix.zero(ti.f32, 3, 3), ti.Matrix.zero(ti.f32, 3, 3)
            if ti.static(jacobi):
                f_out, tau = stress_jacobi(f_new)
            else:
                f_out, tau = stress_svd(f_new)
            f_def[p] = f_out
            affine = (-dt * p_vol * 4.0 * inv_dx * inv_dx) * tau + p_mass * c_aff[p]
            mv = p_mass * v[p]
            for i, j, k in ti.static(ti.ndrange(3, 3, 3)):
                offset = ti.Vector([i, j, k])
                dpos = (offset - fx) * dx
                weight = w[i][0] * w[j][1] * w[k][2]
                mom = weight * (mv + affine @ dpos)
                node = base + offset
                # Plain load and store: this grid belongs to this thread alone.
                priv[t, node] = priv[t, node] + ti.Vector(
                    [mom[0], mom[1], mom[2], weight * p_mass]
                )

    @ti.kernel
    def reduce_and_update():
        for _ in range(1):  # serial: the nodes the particles' stencils reach
            lo = ti.Vector([n_grid, n_grid, n_grid])
            hi = ti.Vector([-1, -1, -1])
            for t in range(n_thr):
                lo, hi = ti.min(lo, thread_lo[t]), ti.max(hi, thread_hi[t])
            box[0], box[1] = lo, hi + 3
        for i, j, k in ti.ndrange(
            (box[0][0], box[1][0]), (box[0][1], box[1][1]), (box[0][2], box[1][2])
        ):
            acc = ti.Vector.zero(ti.f32, 4)
            for t in range(n_thr):
                acc += priv[t, i, j, k]
                priv[t, i, j, k] = ti.Vector.zero(ti.f32, 4)
            m = acc[3]
            vel = ti.Vector.zero(ti.f32, 3)
            if m > 0.0:
                vel = ti.Vector([acc[0], acc[1], acc[2]]) / m + dt * gravity
                node = ti.Vector([i, j, k])
                for a in ti.static(range(3)):
                    outward = 0.0
                    if node[a] < bound:
                        outward = -1.0
                    elif node[a] >= n_grid - bound:
                        outward = 1.0
                    vn = vel[a] * outward
                    if vn > 0.0:
                        vel[a] = 0.0
                        vt = vel.norm()
                        if vt > 0.0:
                            vel *= ti.max(1.0 - friction * vn / vt, 0.0)
            grid[i, j, k] = ti.Vector([vel[0], vel[1], vel[2], m])

    @ti.kernel
    def g2p():
        for t in range(n_thr):
            thread_lo[t] = ti.Vector([n_grid, n_grid, n_grid])
            thread_hi[t] = ti.Vector([-1, -1, -1])
        for p in range(n_part):
            t = ti.global_thread_idx()
            base = base_node(x[p])
            fx = x[p] * inv_dx - base
            w = weights(fx)
            new_v = ti.Vector.zero(ti.f32, 3)
            new_c = ti.Matrix.zero(ti.f32, 3, 3)
            for i, j, k in ti.static(ti.ndrange(3, 3, 3)):
                offset = ti.Vector([i, j, k])
                dpos = (offset - fx) * dx
                weight = w[i][0] * w[j][1] * w[k][2]
                g4 = grid[base + offset]
                g = ti.Vector([g4[0], g4[1], g4[2]])
                new_v += weight * g
                new_c += 4.0 * inv_dx * inv_dx * weight * g.outer_product(dpos)
            v[p] = new_v
            c_aff[p] = new_c
            xn = ti.math.clamp(x[p] + dt * new_v, lo_clamp, hi_clamp)
            x[p] = xn
            b = base_node(xn)
            # Plain load and store: this box belongs to this thread alone.
            thread_lo[t] = ti.min(thread_lo[t], b)
            thread_hi[t] = ti.max(thread_hi[t], b)

    def substep():
        p2g()
        reduce_and_update()
        g2p()

    max_tid = ti.field(ti.i32, ())

    @ti.kernel
    def highest_thread_index():
        for p in range(n_part):
            ti.atomic_max(max_tid[None], ti.global_thread_idx())

    highest_thread_index()
    if max_tid[None] >= n_thr:
        raise SystemExit(
            f"ti.global_thread_idx() reached {max_tid[None]}, expected < {n_thr} threads"
        )
    init()
    secs = timed_substeps(ti, substep, substeps)
    report(ti, f"-fair-{args.eigen}", x.to_numpy(), n_thr, substeps, secs)


if __name__ == "__main__":
    main()
