//! Reading and writing articulation state: joint positions and velocities, drives, link poses.

use nalgebra::{DVector, Vector3};
use rapier3d::dynamics::{JointAxesMask, JointAxis, MotorModel, Multibody};

use crate::articulation::{ArticulationId, DriveParams, JointInfo};
use crate::error::{check_finite, check_len, check_pose_finite, PhysicsError, Result};
use crate::math::{pose_from_na, vec_from_na, Pose3};
use crate::shape::VisualShape;
use crate::world::{BodyId, World};

impl World {
    /// Every articulation id, in creation order.
    pub fn articulations(&self) -> impl Iterator<Item = ArticulationId> + '_ {
        (0..self.articulations.len() as u32).map(ArticulationId)
    }

    /// The articulation's name (the URDF `<robot name>`).
    pub fn articulation_name(&self, art: ArticulationId) -> Result<&str> {
        Ok(&self.articulation_ref(art)?.name)
    }

    /// Number of degrees of freedom (movable joints).
    pub fn dof(&self, art: ArticulationId) -> Result<usize> {
        Ok(self.articulation_ref(art)?.dofs.len())
    }

    /// Names of the movable joints, in dof (qpos) order.
    pub fn joint_names(&self, art: ArticulationId) -> Result<Vec<&str>> {
        let a = self.articulation_ref(art)?;
        Ok(a.dofs
            .iter()
            .map(|d| a.joints[d.joint].name.as_str())
            .collect())
    }

    /// Facts about the movable joints, in dof order.
    pub fn joint_infos(&self, art: ArticulationId) -> Result<Vec<&JointInfo>> {
        let a = self.articulation_ref(art)?;
        Ok(a.dofs.iter().map(|d| &a.joints[d.joint]).collect())
    }

    /// Facts about every joint (fixed ones included), in the description's order.
    pub fn all_joint_infos(&self, art: ArticulationId) -> Result<&[JointInfo]> {
        Ok(&self.articulation_ref(art)?.joints)
    }

    /// Position limits `[lower, upper]` of the movable joints, in dof order (rad or m).
    pub fn joint_limits(&self, art: ArticulationId) -> Result<Vec<[f32; 2]>> {
        Ok(self.joint_infos(art)?.iter().map(|j| j.limits).collect())
    }

    /// The dof index of a movable joint.
    pub fn dof_index(&self, art: ArticulationId, joint: &str) -> Result<usize> {
        let a = self.articulation_ref(art)?;
        a.dofs
            .iter()
            .position(|d| a.joints[d.joint].name == joint)
            .ok_or_else(|| PhysicsError::UnknownName {
                articulation: a.name.clone(),
                kind: "movable joint",
                name: joint.into(),
            })
    }

    /// Names of the links, in the description's order.
    pub fn link_names(&self, art: ArticulationId) -> Result<Vec<&str>> {
        let a = self.articulation_ref(art)?;
        Ok(a.links.iter().map(|l| l.name.as_str()).collect())
    }

    /// Index of a link by name.
    pub fn link_index(&self, art: ArticulationId, link: &str) -> Result<usize> {
        let a = self.articulation_ref(art)?;
        a.links
            .iter()
            .position(|l| l.name == link)
            .ok_or_else(|| PhysicsError::UnknownName {
                articulation: a.name.clone(),
                kind: "link",
                name: link.into(),
            })
    }

    fn link_checked(
        &self,
        art: ArticulationId,
        link: usize,
    ) -> Result<&crate::articulation::ArtLink> {
        let a = self.articulation_ref(art)?;
        a.links.get(link).ok_or_else(|| PhysicsError::UnknownName {
            articulation: a.name.clone(),
            kind: "link",
            name: format!("#{link}"),
        })
    }

    /// Index (in [`World::all_joint_infos`]) of the joint whose child is this link; `None` for
    /// the root link.
    pub fn link_parent_joint(&self, art: ArticulationId, link: usize) -> Result<Option<usize>> {
        Ok(self.link_checked(art, link)?.parent_joint)
    }

    /// The rigid body carrying a link (links merged by fixed joints share a body).
    pub fn link_body(&self, art: ArticulationId, link: usize) -> Result<BodyId> {
        Ok(self.link_checked(art, link)?.body)
    }

    /// The distinct rigid bodies of the articulation (root first).
    pub fn articulation_bodies(&self, art: ArticulationId) -> Result<&[BodyId]> {
        Ok(&self.articulation_ref(art)?.bodies)
    }

    /// Pose of the link frame in the body frame of [`World::link_body`].
    pub fn link_pose_in_body(&self, art: ArticulationId, link: usize) -> Result<Pose3> {
        Ok(self.link_checked(art, link)?.pose_body_from_link)
    }

    /// Pose of a link frame in the world.
    pub fn link_pose(&self, art: ArticulationId, link: usize) -> Result<Pose3> {
        let l = self.link_checked(art, link)?;
        Ok(self.body_pose(l.body)? * l.pose_body_from_link)
    }

    /// Poses of every link frame in the world, in link order.
    pub fn link_poses(&self, art: ArticulationId) -> Result<Vec<Pose3>> {
        let a = self.articulation_ref(art)?;
        a.links
            .iter()
            .map(|l| Ok(self.body_pose(l.body)? * l.pose_body_from_link))
            .collect()
    }

    /// Velocity of a link: (linear velocity of the link frame's origin in m/s, angular velocity
    /// in rad/s), world frame.
    pub fn link_velocity(
        &self,
        art: ArticulationId,
        link: usize,
    ) -> Result<(Vector3<f32>, Vector3<f32>)> {
        let l = self.link_checked(art, link)?;
        let origin = self.link_pose(art, link)?.translation.vector;
        Ok((
            self.body_point_velocity(l.body, origin.into())?,
            self.body_angular_velocity(l.body)?,
        ))
    }

    /// Visual shapes of a link, in the link frame.
    pub fn link_visuals(&self, art: ArticulationId, link: usize) -> Result<&[VisualShape]> {
        Ok(&self.link_checked(art, link)?.visuals)
    }

    /// Pose of the root link in the world.
    pub fn root_pose(&self, art: ArticulationId) -> Result<Pose3> {
        let a = self.articulation_ref(art)?;
        self.body_pose(a.bodies[0])
    }

    fn multibody(&self, art: ArticulationId) -> Result<&Multibody> {
        let a = self.articulation_ref(art)?;
        Ok(self
            .sim
            .multibody_joints
            .get_multibody(a.multibody)
            .expect("articulation multibody exists"))
    }

    /// Joint positions (rad or m), dof order.
    pub fn qpos(&self, art: ArticulationId) -> Result<Vec<f32>> {
        let a = self.articulation_ref(art)?;
        let mb = self.multibody(art)?;
        Ok(a.dofs
            .iter()
            .map(|d| mb.link(d.mb_link).expect("link").joint.coords()[d.axis as usize])
            .collect())
    }

    /// Joint velocities (rad/s or m/s), dof order.
    pub fn qvel(&self, art: ArticulationId) -> Result<Vec<f32>> {
        let a = self.articulation_ref(art)?;
        let mb = self.multibody(art)?;
        let v = mb.generalized_velocity();
        Ok(a.dofs
            .iter()
            .map(|d| v[mb.link(d.mb_link).expect("link").assembly_id()])
            .collect())
    }

    /// Sets the joint positions (teleport; velocities are kept). Exact: `qpos()` returns the
    /// same bits.
    pub fn set_qpos(&mut self, art: ArticulationId, qpos: &[f32]) -> Result<()> {
        let a = self.articulation_ref(art)?;
        check_joint_values(&a.name, "qpos", a.dofs.len(), qpos)?;
        let (dofs, mbi) = (a.dofs.clone(), a.multibody);
        let mb = self
            .sim
            .multibody_joints
            .get_multibody_mut(mbi)
            .expect("multibody");
        for (d, &q) in dofs.iter().zip(qpos) {
            let joint = &mut mb.link_mut(d.mb_link).expect("link").joint;
            let current = joint.coords()[d.axis as usize];
            // x + (-x) = 0 and 0 + q = q exactly: the coordinate ends up with q's bits.
            joint.apply_displacement(&[-current]);
            joint.apply_displacement(&[q]);
        }
        mb.forward_kinematics(&self.sim.bodies, true);
        mb.update_rigid_bodies(&mut self.sim.bodies, true);
        self.sync_link_velocities(art);
        Ok(())
    }

    /// Sets the joint velocities (rad/s or m/s, dof order).
    pub fn set_qvel(&mut self, art: ArticulationId, qvel: &[f32]) -> Result<()> {
        let a = self.articulation_ref(art)?;
        check_joint_values(&a.name, "qvel", a.dofs.len(), qvel)?;
        let (dofs, mbi) = (a.dofs.clone(), a.multibody);
        let mb = self
            .sim
            .multibody_joints
            .get_multibody_mut(mbi)
            .expect("multibody");
        for (d, &v) in dofs.iter().zip(qvel) {
            let i = mb.link(d.mb_link).expect("link").assembly_id();
            mb.generalized_velocity_mut()[i] = v;
        }
        self.sync_link_velocities(art);
        Ok(())
    }

    /// Recomputes the link bodies' velocities from the joint velocities (body Jacobians).
    fn sync_link_velocities(&mut self, art: ArticulationId) {
        let mbi = self.articulations[art.index()].multibody;
        let mb = self
            .sim
            .multibody_joints
            .get_multibody(mbi)
            .expect("multibody");
        let v = DVector::from_column_slice(mb.generalized_velocity().as_slice());
        let mut updates = Vec::with_capacity(mb.num_links());
        for (i, link) in mb.links().enumerate() {
            let j = mb.body_jacobian(i);
            if j.ncols() != v.len() {
                continue;
            }
            let vel = j * &v;
            updates.push((
                link.rigid_body_handle(),
                Vector3::new(vel[0], vel[1], vel[2]),
                Vector3::new(vel[3], vel[4], vel[5]),
            ));
        }
        for (h, lin, ang) in updates {
            if let Some(rb) = self.sim.bodies.get_mut(h) {
                if rb.is_dynamic() {
                    rb.set_linvel(vec_from_na(&lin), false);
                    rb.set_angvel(vec_from_na(&ang), false);
                }
            }
        }
    }

    /// Moves the (fixed) root link to a new world pose, carrying the whole articulation.
    pub fn set_root_pose(&mut self, art: ArticulationId, pose: &Pose3) -> Result<()> {
        let a = self.articulation_ref(art)?;
        let (root, mbi) = (a.bodies[0], a.multibody);
        check_pose_finite(|| "root pose".into(), pose)?;
        let h = self.table[root.index()].handle;
        self.sim.bodies[h].set_position(pose_from_na(pose), true);
        let mb = self
            .sim
            .multibody_joints
            .get_multibody_mut(mbi)
            .expect("multibody");
        mb.forward_kinematics(&self.sim.bodies, true);
        mb.update_rigid_bodies(&mut self.sim.bodies, true);
        Ok(())
    }

    /// Sets the PD drive of one degree of freedom (keeps its targets). Changing gains is a
    /// configuration change for [`World::set_state`]; writing the same gains is a no-op.
    pub fn set_drive(&mut self, art: ArticulationId, dof: usize, drive: DriveParams) -> Result<()> {
        drive.validate()?;
        let a = self.articulation_ref(art)?;
        let d = *a.dofs.get(dof).ok_or_else(|| bad_dof(dof))?;
        let mbi = a.multibody;
        let mb = self
            .sim
            .multibody_joints
            .get_multibody_mut(mbi)
            .expect("multibody");
        let data = &mut mb.link_mut(d.mb_link).expect("link").joint.data;
        let m = &mut data.motors[d.axis as usize];
        if m.stiffness == drive.stiffness
            && m.damping == drive.damping
            && m.max_force == drive.force_limit
            && m.model == MotorModel::ForceBased
        {
            // Unchanged: not a configuration change, exact snapshots stay valid.
            return Ok(());
        }
        m.stiffness = drive.stiffness;
        m.damping = drive.damping;
        m.max_force = drive.force_limit;
        m.model = MotorModel::ForceBased;
        enable_motor_if_driven(data, d.axis);
        self.generation += 1;
        Ok(())
    }

    /// Sets the same PD drive on every degree of freedom.
    pub fn set_drives(&mut self, art: ArticulationId, drive: DriveParams) -> Result<()> {
        for i in 0..self.dof(art)? {
            self.set_drive(art, i, drive)?;
        }
        Ok(())
    }

    /// The PD drive of one degree of freedom (zero gains if never set).
    pub fn drive(&self, art: ArticulationId, dof: usize) -> Result<DriveParams> {
        let a = self.articulation_ref(art)?;
        let d = *a.dofs.get(dof).ok_or_else(|| bad_dof(dof))?;
        let mb = self.multibody(art)?;
        let data = &mb.link(d.mb_link).expect("link").joint.data;
        let m = &data.motors[d.axis as usize];
        Ok(DriveParams {
            stiffness: m.stiffness,
            damping: m.damping,
            force_limit: m.max_force,
        })
    }

    /// Writes position or velocity targets of `dofs` (all dofs in order when `None`).
    fn write_targets(
        &mut self,
        art: ArticulationId,
        dofs: Option<&[usize]>,
        values: &[f32],
        what: &str,
        velocity: bool,
    ) -> Result<()> {
        let a = self.articulation_ref(art)?;
        let n = a.dofs.len();
        check_joint_values(&a.name, what, dofs.map_or(n, <[usize]>::len), values)?;
        if let Some(&bad) = dofs.and_then(|d| d.iter().find(|&&i| i >= n)) {
            return Err(bad_dof(bad));
        }
        let all: Vec<usize>;
        let indices = match dofs {
            Some(d) => d,
            None => {
                all = (0..n).collect();
                &all
            }
        };
        let (art_dofs, mbi) = (a.dofs.clone(), a.multibody);
        let mb = self
            .sim
            .multibody_joints
            .get_multibody_mut(mbi)
            .expect("multibody");
        for (&i, &v) in indices.iter().zip(values) {
            let d = art_dofs[i];
            let data = &mut mb.link_mut(d.mb_link).expect("link").joint.data;
            // Stored whether or not the drive is on (see `enable_motor_if_driven`).
            let m = &mut data.motors[d.axis as usize];
            if velocity {
                m.target_vel = v;
            } else {
                m.target_pos = v;
            }
        }
        Ok(())
    }

    /// Sets the position targets (rad or m) of the listed degrees of freedom only.
    pub fn set_drive_targets_of(
        &mut self,
        art: ArticulationId,
        dofs: &[usize],
        qpos_target: &[f32],
    ) -> Result<()> {
        self.write_targets(
            art,
            Some(dofs),
            qpos_target,
            "drive position targets",
            false,
        )
    }

    /// Sets the velocity targets (rad/s or m/s) of the listed degrees of freedom only.
    pub fn set_drive_velocity_targets_of(
        &mut self,
        art: ArticulationId,
        dofs: &[usize],
        qvel_target: &[f32],
    ) -> Result<()> {
        self.write_targets(art, Some(dofs), qvel_target, "drive velocity targets", true)
    }

    /// Sets the drives' position targets (rad or m, dof order).
    pub fn set_drive_targets(&mut self, art: ArticulationId, qpos_target: &[f32]) -> Result<()> {
        self.write_targets(art, None, qpos_target, "drive position targets", false)
    }

    /// Sets the drives' velocity targets (rad/s or m/s, dof order).
    pub fn set_drive_velocity_targets(
        &mut self,
        art: ArticulationId,
        qvel_target: &[f32],
    ) -> Result<()> {
        self.write_targets(art, None, qvel_target, "drive velocity targets", true)
    }

    fn read_targets(&self, art: ArticulationId, velocity: bool) -> Result<Vec<f32>> {
        let a = self.articulation_ref(art)?;
        let mb = self.multibody(art)?;
        Ok(a.dofs
            .iter()
            .map(|d| {
                let m = &mb.link(d.mb_link).expect("link").joint.data.motors[d.axis as usize];
                if velocity {
                    m.target_vel
                } else {
                    m.target_pos
                }
            })
            .collect())
    }

    /// The drives' position targets (dof order).
    pub fn drive_targets(&self, art: ArticulationId) -> Result<Vec<f32>> {
        self.read_targets(art, false)
    }

    /// The drives' velocity targets (dof order).
    pub fn drive_velocity_targets(&self, art: ArticulationId) -> Result<Vec<f32>> {
        self.read_targets(art, true)
    }
}

/// Turns the rapier motor of `axis` on only if its drive has a stiffness or a damping.
///
/// The drive's gains and targets always live in `data.motors`; rapier solves a motor whose gains
/// are both zero as a rigid velocity constraint (up to its force limit), which would lock an
/// undriven joint (e.g. a faucet handle whose targets a state restore wrote), whereas a PD drive
/// without gains exerts no force.
fn enable_motor_if_driven(data: &mut rapier3d::dynamics::GenericJoint, axis: JointAxis) {
    let m = &data.motors[axis as usize];
    let bit = JointAxesMask::from(axis);
    if m.stiffness != 0.0 || m.damping != 0.0 {
        data.motor_axes |= bit;
    } else {
        data.motor_axes &= !bit;
    }
}

/// Checks that `values` (the `what` of articulation `articulation`, e.g. its qpos) has `expected`
/// entries, all finite.
fn check_joint_values(
    articulation: &str,
    what: &str,
    expected: usize,
    values: &[f32],
) -> Result<()> {
    check_len(
        || format!("{what} of \"{articulation}\""),
        expected,
        values.len(),
    )?;
    check_finite(|| format!("{what} of \"{articulation}\""), values)
}

/// The error for a dof index past the articulation's dof count.
fn bad_dof(dof: usize) -> PhysicsError {
    PhysicsError::InvalidParameter {
        name: "dof",
        value: dof.to_string(),
        expected: "an index below the articulation's dof count",
    }
}
