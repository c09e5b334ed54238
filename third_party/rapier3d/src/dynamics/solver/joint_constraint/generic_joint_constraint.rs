use super::LinkOrBodyRef;
use crate::dynamics::solver::joint_constraint::joint_velocity_constraint::WritebackId;
use crate::dynamics::solver::joint_constraint::{JointConstraintHelper, JointSolverBody};
use crate::dynamics::solver::solver_body::SolverBodies;
use crate::dynamics::{GenericJoint, IntegrationParameters, JointGraphEdge, JointIndex};
use crate::math::{DIM, DVector, Real, SPATIAL_DIM};
use parry::math::Pose;

#[derive(Debug, Copy, Clone)]
pub struct GenericJointConstraint {
    pub is_rigid_body1: bool,
    pub is_rigid_body2: bool,
    pub solver_vel1: u32,
    pub solver_vel2: u32,

    pub ndofs1: usize,
    pub j_id1: usize,
    pub ndofs2: usize,
    pub j_id2: usize,
    /// `u32::MAX`, or the index `i` if the side-2 Jacobian (at `j_id2`) is the unit vector
    /// `e_i` and there is no side 1 (`ndofs1 == 0`): a motor, limit or friction constraint
    /// on one generalized coordinate of a multibody. Its `J · v` is then read as `v[i]`.
    pub unit_jacobian2: u32,

    pub joint_id: JointIndex,

    pub impulse: Real,
    pub impulse_bounds: [Real; 2],
    pub inv_lhs: Real,
    pub rhs: Real,
    pub rhs_wo_bias: Real,
    pub cfm_coeff: Real,
    pub cfm_gain: Real,

    pub writeback_id: WritebackId,
}

impl Default for GenericJointConstraint {
    fn default() -> Self {
        GenericJointConstraint::invalid()
    }
}

impl GenericJointConstraint {
    pub fn invalid() -> Self {
        Self {
            is_rigid_body1: false,
            is_rigid_body2: false,
            solver_vel1: u32::MAX,
            solver_vel2: u32::MAX,
            ndofs1: usize::MAX,
            j_id1: usize::MAX,
            ndofs2: usize::MAX,
            j_id2: usize::MAX,
            unit_jacobian2: u32::MAX,
            joint_id: usize::MAX,
            impulse: 0.0,
            impulse_bounds: [-Real::MAX, Real::MAX],
            inv_lhs: Real::MAX,
            rhs: Real::MAX,
            rhs_wo_bias: Real::MAX,
            cfm_coeff: Real::MAX,
            cfm_gain: Real::MAX,
            writeback_id: WritebackId::Dof(0),
        }
    }

    pub fn lock_axes(
        params: &IntegrationParameters,
        joint_id: JointIndex,
        body1: &JointSolverBody<Real, 1>,
        body2: &JointSolverBody<Real, 1>,
        mb1: LinkOrBodyRef,
        mb2: LinkOrBodyRef,
        frame1: &Pose,
        frame2: &Pose,
        joint: &GenericJoint,
        jacobians: &mut DVector,
        j_id: &mut usize,
        out: &mut [Self],
    ) -> usize {
        let mut len = 0;
        let locked_axes = joint.locked_axes.bits();
        let motor_axes = joint.motor_axes.bits();
        let limit_axes = joint.limit_axes.bits();

        let builder = JointConstraintHelper::<Real>::new(
            frame1,
            frame2,
            &body1.world_com,
            &body2.world_com,
            locked_axes,
        );

        let start = len;
        for i in DIM..SPATIAL_DIM {
            if motor_axes & (1 << i) != 0 {
                out[len] = builder.motor_angular_generic(
                    jacobians,
                    j_id,
                    joint_id,
                    body1,
                    body2,
                    mb1,
                    mb2,
                    i - DIM,
                    &joint.motors[i].motor_params(params.dt),
                    WritebackId::Motor(i),
                );
                len += 1;
            }
        }
        for i in 0..DIM {
            if motor_axes & (1 << i) != 0 {
                out[len] = builder.motor_linear_generic(
                    jacobians,
                    j_id,
                    joint_id,
                    body1,
                    body2,
                    mb1,
                    mb2,
                    // locked_ang_axes,
                    i,
                    &joint.motors[i].motor_params(params.dt),
                    WritebackId::Motor(i),
                );
                len += 1;
            }
        }
        JointConstraintHelper::finalize_generic_constraints(jacobians, &mut out[start..len]);

        let start = len;
        for i in DIM..SPATIAL_DIM {
            if locked_axes & (1 << i) != 0 {
                out[len] = builder.lock_angular_generic(
                    params,
                    jacobians,
                    j_id,
                    joint_id,
                    body1,
                    body2,
                    mb1,
                    mb2,
                    i - DIM,
                    joint.softness,
                    WritebackId::Dof(i),
                );
                len += 1;
            }
        }
        for i in 0..DIM {
            if locked_axes & (1 << i) != 0 {
                out[len] = builder.lock_linear_generic(
                    params,
                    jacobians,
                    j_id,
                    joint_id,
                    body1,
                    body2,
                    mb1,
                    mb2,
                    i,
                    joint.softness,
                    WritebackId::Dof(i),
                );
                len += 1;
            }
        }

        for i in DIM..SPATIAL_DIM {
            if limit_axes & (1 << i) != 0 {
                out[len] = builder.limit_angular_generic(
                    params,
                    jacobians,
                    j_id,
                    joint_id,
                    body1,
                    body2,
                    mb1,
                    mb2,
                    i - DIM,
                    [joint.limits[i].min, joint.limits[i].max],
                    joint.softness,
                    WritebackId::Limit(i),
                );
                len += 1;
            }
        }
        for i in 0..DIM {
            if limit_axes & (1 << i) != 0 {
                out[len] = builder.limit_linear_generic(
                    params,
                    jacobians,
                    j_id,
                    joint_id,
                    body1,
                    body2,
                    mb1,
                    mb2,
                    i,
                    [joint.limits[i].min, joint.limits[i].max],
                    joint.softness,
                    WritebackId::Limit(i),
                );
                len += 1;
            }
        }

        JointConstraintHelper::finalize_generic_constraints(jacobians, &mut out[start..len]);
        len
    }

    fn solver_vel1<'a>(
        &self,
        solver_vels: &'a SolverBodies,
        generic_solver_vels: &'a DVector,
    ) -> &'a [Real] {
        solver_vel_slice(
            self.solver_vel1,
            self.is_rigid_body1,
            self.ndofs1,
            solver_vels,
            generic_solver_vels,
        )
    }

    fn solver_vel1_mut<'a>(
        &self,
        solver_vels: &'a mut SolverBodies,
        generic_solver_vels: &'a mut DVector,
    ) -> &'a mut [Real] {
        solver_vel_slice_mut(
            self.solver_vel1,
            self.is_rigid_body1,
            self.ndofs1,
            solver_vels,
            generic_solver_vels,
        )
    }

    fn solver_vel2<'a>(
        &self,
        solver_vels: &'a SolverBodies,
        generic_solver_vels: &'a DVector,
    ) -> &'a [Real] {
        solver_vel_slice(
            self.solver_vel2,
            self.is_rigid_body2,
            self.ndofs2,
            solver_vels,
            generic_solver_vels,
        )
    }

    fn solver_vel2_mut<'a>(
        &self,
        solver_vels: &'a mut SolverBodies,
        generic_solver_vels: &'a mut DVector,
    ) -> &'a mut [Real] {
        solver_vel_slice_mut(
            self.solver_vel2,
            self.is_rigid_body2,
            self.ndofs2,
            solver_vels,
            generic_solver_vels,
        )
    }

    // PERF: on plain slices, with the arithmetic of nalgebra's `dot` and `axpy` (see
    //       `dot_in_nalgebra_order` and `axpy_in_nalgebra_order`), so the results are
    //       bit-identical to the `DVectorView` version this replaces, at a fraction of its
    //       instructions (no view construction, no stride handling).
    pub fn solve(
        &mut self,
        jacobians: &DVector,
        solver_vels: &mut SolverBodies,
        generic_solver_vels: &mut DVector,
    ) {
        let jacobians = jacobians.as_slice();

        if self.impulse_bounds == [0.0, 0.0] && self.impulse == 0.0 {
            // An inactive constraint (a joint limit away from its bounds): the impulse is
            // clamped to zero at every pass, so the velocities would only receive `±0 · w`.
            // (That leaves every finite velocity as it is, except that a `-0.0` would turn
            // into `+0.0`; nothing downstream depends on the sign of a zero velocity.)
            return;
        }
        if self.unit_jacobian2 != u32::MAX && self.ndofs1 == 0 && !self.is_rigid_body2 {
            // A constraint on one coordinate of a multibody (the common case): no side 1,
            // whose empty dot product would be `+0.0` and whose axpy would do nothing.
            let start = self.solver_vel2 as usize;
            let solver_vel2 = &mut generic_solver_vels.as_mut_slice()[start..start + self.ndofs2];
            let wj2 = &jacobians[self.j_id2 + self.ndofs2..self.j_id2 + 2 * self.ndofs2];
            let vel1: Real = 0.0;
            // `e_i · v` in nalgebra's order sums `+0.0`, `1 · v[i]` and products `0 · v[k]`
            // (`±0` for a finite `v[k]`): `v[i]`, except that `-0` comes out as `+0`, as
            // here. (An infinite or NaN velocity would make nalgebra's sum NaN.)
            let vel2 = solver_vel2[self.unit_jacobian2 as usize] + 0.0;
            let delta_impulse = self.update_impulse(vel2 - vel1);
            axpy_unless_no_change(solver_vel2, -delta_impulse, wj2);
            return;
        }

        // Each side's Jacobian (`ndofs` values at `j_id`) is followed by its weighted Jacobian.
        let (j1, wj1) = jacobians[self.j_id1..self.j_id1 + 2 * self.ndofs1].split_at(self.ndofs1);
        let (j2, wj2) = jacobians[self.j_id2..self.j_id2 + 2 * self.ndofs2].split_at(self.ndofs2);

        let vel1 = dot_in_nalgebra_order(j1, self.solver_vel1(solver_vels, generic_solver_vels));
        let vel2 = dot_in_nalgebra_order(j2, self.solver_vel2(solver_vels, generic_solver_vels));
        let delta_impulse = self.update_impulse(vel2 - vel1);

        axpy_unless_no_change(
            self.solver_vel1_mut(solver_vels, generic_solver_vels),
            delta_impulse,
            wj1,
        );
        axpy_unless_no_change(
            self.solver_vel2_mut(solver_vels, generic_solver_vels),
            -delta_impulse,
            wj2,
        );
    }

    /// The projected Gauss-Seidel update of the impulse, given the constraint velocity
    /// `J₂ v₂ − J₁ v₁`; returns the impulse change.
    #[inline(always)]
    fn update_impulse(&mut self, relative_vel: Real) -> Real {
        let dvel = self.rhs + relative_vel;
        let total_impulse = na::clamp(
            self.impulse + self.inv_lhs * (dvel - self.cfm_gain * self.impulse),
            self.impulse_bounds[0],
            self.impulse_bounds[1],
        );
        let delta_impulse = total_impulse - self.impulse;
        self.impulse = total_impulse;
        delta_impulse
    }

    pub fn writeback_impulses(&self, joints_all: &mut [JointGraphEdge]) {
        // TODO: we don’t support impulse writeback for internal constraints yet.
        if self.joint_id != JointIndex::MAX {
            let joint = &mut joints_all[self.joint_id].weight;
            match self.writeback_id {
                WritebackId::Dof(i) => joint.impulses[i] = self.impulse,
                WritebackId::Limit(i) => joint.data.limits[i].impulse = self.impulse,
                WritebackId::Motor(i) => joint.data.motors[i].impulse = self.impulse,
                // Writeback not supported yet for internal friction.
                WritebackId::Friction(_) => {}
            }
        }
    }

    pub fn remove_bias_from_rhs(&mut self) {
        self.rhs = self.rhs_wo_bias;
    }
}

/// The velocities a constraint side acts on: nothing (`solver_vel == u32::MAX`), a rigid
/// body's solver velocity (`SPATIAL_DIM` values), or `ndofs` generalized velocities of a
/// multibody starting at `solver_vel`.
fn solver_vel_slice<'a>(
    solver_vel: u32,
    is_rigid_body: bool,
    ndofs: usize,
    solver_vels: &'a SolverBodies,
    generic_solver_vels: &'a DVector,
) -> &'a [Real] {
    if solver_vel == u32::MAX {
        &[]
    } else if is_rigid_body {
        &solver_vels.vels[solver_vel as usize].as_slice()[..]
    } else {
        &generic_solver_vels.as_slice()[solver_vel as usize..solver_vel as usize + ndofs]
    }
}

/// Mutable version of [`solver_vel_slice`].
fn solver_vel_slice_mut<'a>(
    solver_vel: u32,
    is_rigid_body: bool,
    ndofs: usize,
    solver_vels: &'a mut SolverBodies,
    generic_solver_vels: &'a mut DVector,
) -> &'a mut [Real] {
    if solver_vel == u32::MAX {
        &mut []
    } else if is_rigid_body {
        &mut solver_vels.vels[solver_vel as usize].as_mut_slice()[..]
    } else {
        &mut generic_solver_vels.as_mut_slice()[solver_vel as usize..solver_vel as usize + ndofs]
    }
}

/// `a · b` with exactly the floating-point operations of nalgebra 0.35's `dot` on
/// dynamically-sized vectors: eight partial sums (starting from `+0.0`) over the blocks of
/// eight, combined as `((acc0 + acc4) + (acc1 + acc5)) + …`, then the remaining products
/// added one by one.
#[inline(always)]
pub(crate) fn dot_in_nalgebra_order(a: &[Real], b: &[Real]) -> Real {
    assert_eq!(
        a.len(),
        b.len(),
        "dot product of vectors of different lengths"
    );
    let blocks_a = a.chunks_exact(8);
    let blocks_b = b.chunks_exact(8);
    let (rest_a, rest_b) = (blocks_a.remainder(), blocks_b.remainder());
    let mut acc = [0.0 as Real; 8];
    for (x, y) in blocks_a.zip(blocks_b) {
        for k in 0..8 {
            acc[k] += x[k] * y[k];
        }
    }
    let mut res: Real = 0.0;
    res += acc[0] + acc[4];
    res += acc[1] + acc[5];
    res += acc[2] + acc[6];
    res += acc[3] + acc[7];
    for (x, y) in rest_a.iter().zip(rest_b) {
        res += *x * *y;
    }
    res
}

/// `y += alpha · x` with the floating-point operations of nalgebra 0.35's
/// `axpy(alpha, x, 1.0)` (`alpha · x · 1 + 1 · y`, where both multiplications by one are
/// exact).
#[inline(always)]
pub(crate) fn axpy_in_nalgebra_order(y: &mut [Real], alpha: Real, x: &[Real]) {
    assert_eq!(y.len(), x.len(), "axpy on vectors of different lengths");
    for (y, x) in y.iter_mut().zip(x) {
        *y += alpha * *x;
    }
}

/// [`axpy_in_nalgebra_order`], skipped when it cannot change `y`'s bits: when `alpha` is
/// `±0` (an impulse change of zero, e.g. every PGS pass of an inactive joint limit, whose
/// impulse bounds are both zero) and no entry of `y` is zero. For a finite `x`, `alpha · x` is
/// then `±0` and `y + (±0)` is `y` for every non-zero `y` (only a zero `y` can change:
/// `-0 + +0` is `+0`). (With an infinite or NaN `x`, the skipped axpy would have written NaN.)
#[inline(always)]
pub(crate) fn axpy_unless_no_change(y: &mut [Real], alpha: Real, x: &[Real]) {
    // No early exit: the scan is branch-free and vectorizes.
    if alpha == 0.0 && !y.iter().fold(false, |any_zero, v| any_zero | (*v == 0.0)) {
        return;
    }
    axpy_in_nalgebra_order(y, alpha, x);
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::vec::Vec;
    use na::{DVectorView, DVectorViewMut};

    /// A deterministic pseudo-random value in [-1, 1), with exact zeros of both signs now and
    /// then.
    fn value(seed: &mut u64) -> Real {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let v = ((*seed >> 40) as Real / (1u64 << 24) as Real) * 2.0 - 1.0;
        match (*seed >> 20) % 11 {
            0 => 0.0,
            1 => -0.0,
            _ => v,
        }
    }

    fn values(seed: &mut u64, n: usize) -> Vec<Real> {
        (0..n).map(|_| value(seed)).collect()
    }

    #[test]
    fn generic_joint_constraint_kernels_match_nalgebra_bit_for_bit() {
        let mut seed = 7;
        for n in 0..=20 {
            for _ in 0..50 {
                let a = values(&mut seed, n);
                let b = values(&mut seed, n);
                let expected = DVectorView::from_slice(&a, n).dot(&DVectorView::from_slice(&b, n));
                assert_eq!(
                    dot_in_nalgebra_order(&a, &b).to_bits(),
                    expected.to_bits(),
                    "dot, n = {n}"
                );

                let alpha = value(&mut seed);
                let mut y = values(&mut seed, n);
                let mut expected = y.clone();
                DVectorViewMut::from_slice(&mut expected, n).axpy(
                    alpha,
                    &DVectorView::from_slice(&a, n),
                    1.0,
                );
                axpy_in_nalgebra_order(&mut y, alpha, &a);
                let bits = |v: &[Real]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&y), bits(&expected), "axpy, n = {n}");
            }
        }
    }

    /// The zero-impulse shortcut writes exactly what the full axpy writes, for zero `alpha`s
    /// of both signs and `y`s with and without zeros of both signs.
    #[test]
    fn axpy_shortcut_matches_the_full_axpy_bit_for_bit() {
        let mut seed = 5;
        let bits = |v: &[Real]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let mut shortcuts = 0;
        for n in 0..=20 {
            for round in 0..200 {
                let x = values(&mut seed, n);
                let mut y: Vec<Real> = values(&mut seed, n);
                if round % 2 == 0 {
                    // No zeros in `y` half of the time, so the shortcut is taken.
                    y.iter_mut().filter(|v| **v == 0.0).for_each(|v| *v = 0.5);
                }
                let alpha = match round % 4 {
                    0 | 1 => 0.0,
                    2 => -0.0,
                    _ => value(&mut seed),
                };
                let mut expected = y.clone();
                axpy_in_nalgebra_order(&mut expected, alpha, &x);
                if alpha == 0.0 && !y.contains(&0.0) {
                    shortcuts += 1;
                }
                axpy_unless_no_change(&mut y, alpha, &x);
                assert_eq!(bits(&y), bits(&expected), "n = {n}, alpha = {alpha:?}");
            }
        }
        assert!(shortcuts > 1000, "the shortcut was taken {shortcuts} times");
    }

    /// What `solve` relies on for a unit-vector Jacobian `e_i`: nalgebra's `e_i · v` is
    /// `v[i] + 0.0` for finite `v`, zeros of either sign included.
    #[test]
    fn unit_jacobian_dot_is_the_coordinate_plus_zero() {
        let mut seed = 11;
        for n in 1..=20 {
            for i in 0..n {
                for _ in 0..20 {
                    let mut v = values(&mut seed, n);
                    if seed % 3 == 0 {
                        v[i] = if seed % 2 == 0 { -0.0 } else { 0.0 };
                    }
                    let mut e = alloc::vec![0.0; n];
                    e[i] = 1.0;
                    let expected =
                        DVectorView::from_slice(&e, n).dot(&DVectorView::from_slice(&v, n));
                    assert_eq!(
                        (v[i] + 0.0).to_bits(),
                        expected.to_bits(),
                        "n = {n}, i = {i}"
                    );
                }
            }
        }
    }

    /// ms2's round 6: an inactive constraint (impulse bounds both zero: a joint limit away from
    /// its bounds) returns before its PGS step. It writes exactly what that step would write
    /// (which clamps the impulse to zero and adds `±0 · w` to the velocities) whenever no
    /// velocity is an exact zero, and it leaves the velocities and its impulse untouched.
    #[test]
    fn an_inactive_constraint_changes_nothing() {
        let mut seed = 13;
        let n = 9;
        let mut compared = 0;
        for round in 0..400 {
            let i = round % n;
            let mut v = values(&mut seed, n);
            if round % 2 == 0 {
                v.iter_mut().filter(|x| **x == 0.0).for_each(|x| *x = 0.25);
            }
            let mut jacobians = DVector::zeros(2 * n);
            jacobians[i] = 1.0;
            for (k, w) in values(&mut seed, n).into_iter().enumerate() {
                jacobians[n + k] = w;
            }
            let mut constraint = GenericJointConstraint {
                ndofs1: 0,
                solver_vel2: 0,
                ndofs2: n,
                j_id2: 0,
                unit_jacobian2: i as u32,
                impulse: 0.0,
                impulse_bounds: [-0.0, 0.0],
                inv_lhs: 1.0 + value(&mut seed).abs(),
                rhs: value(&mut seed),
                cfm_gain: 0.01,
                ..GenericJointConstraint::invalid()
            };
            // The PGS step the shortcut skips.
            let mut expected = v.clone();
            let mut full = constraint;
            let delta = full.update_impulse(expected[i] + 0.0);
            axpy_unless_no_change(&mut expected, -delta, &jacobians.as_slice()[n..]);

            let mut generic = DVector::from_vec(v.clone());
            constraint.solve(&jacobians, &mut SolverBodies::default(), &mut generic);
            let bits = |v: &[Real]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(
                bits(generic.as_slice()),
                bits(&v),
                "round {round}: velocities"
            );
            assert_eq!(constraint.impulse, 0.0);
            assert_eq!(full.impulse, 0.0);
            if !v.contains(&0.0) {
                assert_eq!(bits(generic.as_slice()), bits(&expected), "round {round}");
                compared += 1;
            }
        }
        assert!(
            compared >= 200,
            "compared {compared} rounds with the full step"
        );
    }
}
