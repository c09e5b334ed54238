//! The rapier engine ([`ms2_physics::World`]) behind the rigid-world port.

use ms2_physics::{
    ActorDesc, ArticulationDesc, ArticulationId, ArticulationOptions, BodyId, BodyKind,
    DriveParams, JointInfo, Pose3, ShapeSpec, VisualShape, World, WorldConfig,
};
use nalgebra::{Point3, Vector3};

use super::{PortResult, RigidEngine, RigidWorld};

/// Makes [`ms2_physics::World`]s (rapier 3D, multibody articulations).
#[derive(Debug, Clone, Copy, Default)]
pub struct RapierEngine;

impl RigidEngine for RapierEngine {
    fn name(&self) -> &'static str {
        "rapier"
    }

    fn new_world(&self, config: &WorldConfig) -> PortResult<Box<dyn RigidWorld>> {
        Ok(Box::new(World::new(config.clone())?))
    }
}

impl RigidWorld for World {
    fn engine_name(&self) -> &'static str {
        "rapier"
    }

    fn timestep(&self) -> f32 {
        World::timestep(self)
    }

    fn step(&mut self) {
        World::step(self)
    }

    fn step_reusing_mass_matrices(&mut self, max_displacement: f32) {
        World::step_reusing_mass_matrices(self, max_displacement)
    }

    fn state_len(&self) -> usize {
        World::state_len(self)
    }

    fn get_state(&self) -> Vec<f32> {
        World::get_state(self)
    }

    fn set_state(&mut self, state: &[f32]) -> PortResult<()> {
        World::set_state(self, state)
    }

    fn state_layout(&self) -> Option<Vec<ms2_physics::StateField>> {
        Some(World::state_layout(self))
    }

    fn forget_solver_history(&mut self) -> PortResult<()> {
        World::forget_solver_history(self)
    }

    fn add_actor(&mut self, desc: ActorDesc) -> PortResult<BodyId> {
        World::add_actor(self, desc)
    }

    fn ground(&self) -> Option<BodyId> {
        World::ground(self)
    }

    fn bodies(&self) -> Vec<BodyId> {
        World::bodies(self).collect()
    }

    fn body_name(&self, body: BodyId) -> PortResult<&str> {
        World::body_name(self, body)
    }

    fn body_kind(&self, body: BodyId) -> PortResult<BodyKind> {
        World::body_kind(self, body)
    }

    fn body_pose(&self, body: BodyId) -> PortResult<Pose3> {
        World::body_pose(self, body)
    }

    fn set_body_pose(&mut self, body: BodyId, pose: &Pose3) -> PortResult<()> {
        World::set_body_pose(self, body, pose)
    }

    fn body_linear_velocity(&self, body: BodyId) -> PortResult<Vector3<f32>> {
        World::body_linear_velocity(self, body)
    }

    fn body_angular_velocity(&self, body: BodyId) -> PortResult<Vector3<f32>> {
        World::body_angular_velocity(self, body)
    }

    fn set_body_velocity(
        &mut self,
        body: BodyId,
        linear: &Vector3<f32>,
        angular: &Vector3<f32>,
    ) -> PortResult<()> {
        World::set_body_velocity(self, body, linear, angular)
    }

    fn body_center_of_mass(&self, body: BodyId) -> PortResult<Point3<f32>> {
        World::body_center_of_mass(self, body)
    }

    fn body_shapes(&self, body: BodyId) -> PortResult<&[ShapeSpec]> {
        World::body_shapes(self, body)
    }

    fn body_visuals(&self, body: BodyId) -> PortResult<&[VisualShape]> {
        World::body_visuals(self, body)
    }

    fn apply_force(&mut self, body: BodyId, force: &Vector3<f32>) -> PortResult<()> {
        World::apply_force(self, body, force)
    }

    fn apply_torque(&mut self, body: BodyId, torque: &Vector3<f32>) -> PortResult<()> {
        World::apply_torque(self, body, torque)
    }

    fn contact_impulse_between(&self, a: BodyId, b: BodyId) -> Vector3<f32> {
        World::contact_impulse_between(self, a, b)
    }

    fn add_articulation(
        &mut self,
        desc: &ArticulationDesc,
        options: &ArticulationOptions,
    ) -> PortResult<ArticulationId> {
        World::add_articulation(self, desc, options)
    }

    fn dof(&self, art: ArticulationId) -> PortResult<usize> {
        World::dof(self, art)
    }

    fn joint_infos(&self, art: ArticulationId) -> PortResult<Vec<&JointInfo>> {
        World::joint_infos(self, art)
    }

    fn joint_names(&self, art: ArticulationId) -> PortResult<Vec<&str>> {
        World::joint_names(self, art)
    }

    fn dof_index(&self, art: ArticulationId, joint: &str) -> PortResult<usize> {
        World::dof_index(self, art, joint)
    }

    fn link_names(&self, art: ArticulationId) -> PortResult<Vec<&str>> {
        World::link_names(self, art)
    }

    fn link_index(&self, art: ArticulationId, link: &str) -> PortResult<usize> {
        World::link_index(self, art, link)
    }

    fn link_body(&self, art: ArticulationId, link: usize) -> PortResult<BodyId> {
        World::link_body(self, art, link)
    }

    fn link_pose(&self, art: ArticulationId, link: usize) -> PortResult<Pose3> {
        World::link_pose(self, art, link)
    }

    fn link_visuals(&self, art: ArticulationId, link: usize) -> PortResult<&[VisualShape]> {
        World::link_visuals(self, art, link)
    }

    fn set_root_pose(&mut self, art: ArticulationId, pose: &Pose3) -> PortResult<()> {
        World::set_root_pose(self, art, pose)
    }

    fn qpos(&self, art: ArticulationId) -> PortResult<Vec<f32>> {
        World::qpos(self, art)
    }

    fn qvel(&self, art: ArticulationId) -> PortResult<Vec<f32>> {
        World::qvel(self, art)
    }

    fn set_qpos(&mut self, art: ArticulationId, qpos: &[f32]) -> PortResult<()> {
        World::set_qpos(self, art, qpos)
    }

    fn set_qvel(&mut self, art: ArticulationId, qvel: &[f32]) -> PortResult<()> {
        World::set_qvel(self, art, qvel)
    }

    fn drive(&self, art: ArticulationId, dof: usize) -> PortResult<DriveParams> {
        World::drive(self, art, dof)
    }

    fn set_drive(&mut self, art: ArticulationId, dof: usize, drive: DriveParams) -> PortResult<()> {
        World::set_drive(self, art, dof, drive)
    }

    fn drive_targets(&self, art: ArticulationId) -> PortResult<Vec<f32>> {
        World::drive_targets(self, art)
    }

    fn set_drive_targets(&mut self, art: ArticulationId, targets: &[f32]) -> PortResult<()> {
        World::set_drive_targets(self, art, targets)
    }

    fn drive_velocity_targets(&self, art: ArticulationId) -> PortResult<Vec<f32>> {
        World::drive_velocity_targets(self, art)
    }

    fn set_drive_velocity_targets(
        &mut self,
        art: ArticulationId,
        targets: &[f32],
    ) -> PortResult<()> {
        World::set_drive_velocity_targets(self, art, targets)
    }
}
