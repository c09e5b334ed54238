//! A second rigid engine behind ms2-tasks' rigid-world port: a kinematic world (every joint
//! follows its drive target exactly, actors stay where they are put, nothing collides). It is
//! small, but complete enough that the unchanged runtime builds PickCube on it, resets it with
//! the task's seeded distribution and produces its observations, which match the rapier
//! engine's to float precision: the port is the only way the runtime reaches an engine.

use std::collections::HashMap;
use std::sync::Arc;

use ms2_physics::{
    ActorDesc, ActorKind, ArticulationDesc, ArticulationId, ArticulationOptions, BodyId, BodyKind,
    DriveParams, JointInfo, JointType, PhysicsError, Pose3, ShapeSpec, VisualShape, WorldConfig,
};
use ms2_tasks::rigid_world::{PortResult, RigidEngine, RigidWorld};
use ms2_tasks::{make_env, Env, EnvConfig, ObsValue};
use nalgebra::{Point3, Translation3, UnitQuaternion, Vector3};

/// One body: an actor, or one link of an articulation.
#[derive(Debug, Clone)]
struct Body {
    name: String,
    kind: BodyKind,
    pose: Pose3,
    linear: Vector3<f32>,
    angular: Vector3<f32>,
    shapes: Vec<ShapeSpec>,
    visuals: Vec<VisualShape>,
}

/// One articulation: its links' bodies, movable joints in dof order, joint state and drives.
#[derive(Debug, Clone)]
struct Articulation {
    link_names: Vec<String>,
    bodies: Vec<BodyId>,
    joints: Vec<JointInfo>,
    /// Link indices in parent-before-child order.
    order: Vec<usize>,
    parent_joint: Vec<Option<usize>>,
    root: Pose3,
    qpos: Vec<f32>,
    qvel: Vec<f32>,
    targets: Vec<f32>,
    velocity_targets: Vec<f32>,
    drives: Vec<DriveParams>,
}

/// The kinematic world.
#[derive(Debug, Clone)]
struct KinematicWorld {
    timestep: f32,
    bodies: Vec<Body>,
    articulations: Vec<Articulation>,
    ground: Option<BodyId>,
}

fn no_body(body: BodyId) -> PhysicsError {
    PhysicsError::UnknownId {
        kind: "body",
        id: body.index(),
    }
}

fn no_articulation(art: ArticulationId) -> PhysicsError {
    PhysicsError::UnknownId {
        kind: "articulation",
        id: art.index(),
    }
}

fn no_name(kind: &'static str, name: &str) -> PhysicsError {
    PhysicsError::UnknownName {
        articulation: "kinematic articulation".to_owned(),
        kind,
        name: name.to_owned(),
    }
}

impl KinematicWorld {
    fn body(&self, body: BodyId) -> PortResult<&Body> {
        self.bodies.get(body.index()).ok_or_else(|| no_body(body))
    }

    fn body_mut(&mut self, body: BodyId) -> PortResult<&mut Body> {
        self.bodies
            .get_mut(body.index())
            .ok_or_else(|| no_body(body))
    }

    fn art(&self, art: ArticulationId) -> PortResult<&Articulation> {
        self.articulations
            .get(art.index())
            .ok_or_else(|| no_articulation(art))
    }

    fn art_mut(&mut self, art: ArticulationId) -> PortResult<&mut Articulation> {
        self.articulations
            .get_mut(art.index())
            .ok_or_else(|| no_articulation(art))
    }

    /// Forward kinematics: every link body of `art` at the articulation's qpos.
    fn update_links(&mut self, art: ArticulationId) {
        let a = &self.articulations[art.index()];
        let mut poses = vec![a.root; a.link_names.len()];
        for &link in &a.order {
            if let Some(j) = a.parent_joint[link] {
                let joint = &a.joints[j];
                let q = joint.dof.map_or(0.0, |d| a.qpos[d]);
                let motion = match joint.joint_type {
                    JointType::Revolute | JointType::Continuous => Pose3::from_parts(
                        Translation3::identity(),
                        UnitQuaternion::from_scaled_axis(joint.axis * q),
                    ),
                    JointType::Prismatic => {
                        Pose3::translation(joint.axis.x * q, joint.axis.y * q, joint.axis.z * q)
                    }
                    JointType::Fixed => Pose3::identity(),
                };
                poses[link] = poses[joint.parent_link] * joint.pose_parent_from_joint * motion;
            }
        }
        let bodies = a.bodies.clone();
        for (body, pose) in bodies.into_iter().zip(poses) {
            self.bodies[body.index()].pose = pose;
        }
    }

    fn dof_values(&self, art: ArticulationId, values: &[f32]) -> PortResult<()> {
        let expected = self.art(art)?.qpos.len();
        if values.len() != expected {
            return Err(PhysicsError::WrongLength {
                what: "joint values".to_owned(),
                expected,
                got: values.len(),
            });
        }
        Ok(())
    }
}

impl RigidWorld for KinematicWorld {
    fn engine_name(&self) -> &'static str {
        "kinematic (test)"
    }

    fn timestep(&self) -> f32 {
        self.timestep
    }

    fn step(&mut self) {
        for i in 0..self.articulations.len() {
            let a = &mut self.articulations[i];
            for d in 0..a.qpos.len() {
                a.qvel[d] = (a.targets[d] - a.qpos[d]) / self.timestep;
                a.qpos[d] = a.targets[d];
            }
            self.update_links(ArticulationId::from_index(i));
        }
    }

    fn state_len(&self) -> usize {
        self.get_state().len()
    }

    fn get_state(&self) -> Vec<f32> {
        let mut out = Vec::new();
        for b in &self.bodies {
            out.extend(b.pose.translation.vector.iter());
            out.extend(b.pose.rotation.coords.iter());
        }
        for a in &self.articulations {
            out.extend(&a.qpos);
            out.extend(&a.qvel);
            out.extend(&a.targets);
        }
        out
    }

    fn set_state(&mut self, state: &[f32]) -> PortResult<()> {
        if state.len() != self.state_len() {
            return Err(PhysicsError::WrongLength {
                what: "kinematic world state".to_owned(),
                expected: self.state_len(),
                got: state.len(),
            });
        }
        let mut it = state.iter().copied();
        for b in &mut self.bodies {
            let c: Vec<f32> = (0..7).map(|_| it.next().unwrap_or(0.0)).collect();
            let rotation = nalgebra::Quaternion::new(c[6], c[3], c[4], c[5]);
            b.pose = Pose3::from_parts(
                Translation3::new(c[0], c[1], c[2]),
                UnitQuaternion::new_unchecked(rotation),
            );
        }
        for a in &mut self.articulations {
            for v in a
                .qpos
                .iter_mut()
                .chain(a.qvel.iter_mut())
                .chain(a.targets.iter_mut())
            {
                *v = it.next().unwrap_or(0.0);
            }
        }
        for i in 0..self.articulations.len() {
            self.update_links(ArticulationId::from_index(i));
        }
        Ok(())
    }

    fn forget_solver_history(&mut self) -> PortResult<()> {
        Ok(())
    }

    fn add_actor(&mut self, desc: ActorDesc) -> PortResult<BodyId> {
        let id = BodyId::from_index(self.bodies.len());
        self.bodies.push(Body {
            name: desc.name,
            kind: match desc.kind {
                ActorKind::Static => BodyKind::Static,
                ActorKind::Dynamic => BodyKind::Dynamic,
                ActorKind::Kinematic => BodyKind::Kinematic,
            },
            pose: desc.pose,
            linear: Vector3::zeros(),
            angular: Vector3::zeros(),
            shapes: desc.shapes,
            visuals: desc.visuals,
        });
        Ok(id)
    }

    fn ground(&self) -> Option<BodyId> {
        self.ground
    }

    fn bodies(&self) -> Vec<BodyId> {
        (0..self.bodies.len()).map(BodyId::from_index).collect()
    }

    fn body_name(&self, body: BodyId) -> PortResult<&str> {
        Ok(&self.body(body)?.name)
    }

    fn body_kind(&self, body: BodyId) -> PortResult<BodyKind> {
        Ok(self.body(body)?.kind)
    }

    fn body_pose(&self, body: BodyId) -> PortResult<Pose3> {
        Ok(self.body(body)?.pose)
    }

    fn set_body_pose(&mut self, body: BodyId, pose: &Pose3) -> PortResult<()> {
        self.body_mut(body)?.pose = *pose;
        Ok(())
    }

    fn body_linear_velocity(&self, body: BodyId) -> PortResult<Vector3<f32>> {
        Ok(self.body(body)?.linear)
    }

    fn body_angular_velocity(&self, body: BodyId) -> PortResult<Vector3<f32>> {
        Ok(self.body(body)?.angular)
    }

    fn set_body_velocity(
        &mut self,
        body: BodyId,
        linear: &Vector3<f32>,
        angular: &Vector3<f32>,
    ) -> PortResult<()> {
        let b = self.body_mut(body)?;
        (b.linear, b.angular) = (*linear, *angular);
        Ok(())
    }

    fn body_center_of_mass(&self, body: BodyId) -> PortResult<Point3<f32>> {
        Ok(Point3::from(self.body(body)?.pose.translation.vector))
    }

    fn body_shapes(&self, body: BodyId) -> PortResult<&[ShapeSpec]> {
        Ok(&self.body(body)?.shapes)
    }

    fn body_visuals(&self, body: BodyId) -> PortResult<&[VisualShape]> {
        Ok(&self.body(body)?.visuals)
    }

    fn apply_force(&mut self, body: BodyId, _force: &Vector3<f32>) -> PortResult<()> {
        self.body(body).map(|_| ())
    }

    fn apply_torque(&mut self, body: BodyId, _torque: &Vector3<f32>) -> PortResult<()> {
        self.body(body).map(|_| ())
    }

    fn contact_impulse_between(&self, _a: BodyId, _b: BodyId) -> Vector3<f32> {
        Vector3::zeros()
    }

    fn add_articulation(
        &mut self,
        desc: &ArticulationDesc,
        options: &ArticulationOptions,
    ) -> PortResult<ArticulationId> {
        let id = ArticulationId::from_index(self.articulations.len());
        let link_index: HashMap<&str, usize> = desc
            .links
            .iter()
            .enumerate()
            .map(|(i, l)| (l.name.as_str(), i))
            .collect();
        let link = |name: &str| {
            link_index
                .get(name)
                .copied()
                .ok_or_else(|| no_name("link", name))
        };
        // Depth-first from the root (the link no joint has as child), children in joint order.
        let mut parent_joint = vec![None; desc.links.len()];
        for (j, joint) in desc.joints.iter().enumerate() {
            parent_joint[link(&joint.child)?] = Some(j);
        }
        let root = (0..desc.links.len())
            .find(|&l| parent_joint[l].is_none())
            .ok_or_else(|| PhysicsError::InvalidShape("no root link".to_owned()))?;
        let (mut order, mut stack) = (Vec::new(), vec![root]);
        while let Some(l) = stack.pop() {
            order.push(l);
            let children: Vec<usize> = desc
                .joints
                .iter()
                .filter(|j| j.parent == desc.links[l].name)
                .map(|j| link(&j.child))
                .collect::<PortResult<_>>()?;
            stack.extend(children.into_iter().rev());
        }
        let mut joints = Vec::new();
        let mut dofs = 0;
        let mut joint_of = vec![None; desc.links.len()];
        for &l in &order {
            let Some(j) = parent_joint[l] else { continue };
            let d = &desc.joints[j];
            let dof = d.joint_type.is_movable().then(|| {
                dofs += 1;
                dofs - 1
            });
            joint_of[l] = Some(joints.len());
            joints.push(JointInfo {
                name: d.name.clone(),
                joint_type: d.joint_type,
                parent_link: link(&d.parent)?,
                child_link: l,
                limits: d.limits.unwrap_or([f32::NEG_INFINITY, f32::INFINITY]),
                axis: d.axis.normalize(),
                pose_parent_from_joint: d.pose_parent_from_joint,
                effort_limit: d.effort_limit,
                velocity_limit: d.velocity_limit,
                mimic: d.mimic.clone(),
                dof,
            });
        }
        let bodies: Vec<BodyId> = desc
            .links
            .iter()
            .map(|l| {
                let b = BodyId::from_index(self.bodies.len());
                self.bodies.push(Body {
                    name: l.name.clone(),
                    kind: BodyKind::Link(id),
                    pose: options.root_pose,
                    linear: Vector3::zeros(),
                    angular: Vector3::zeros(),
                    shapes: l.collisions.clone(),
                    visuals: l.visuals.clone(),
                });
                b
            })
            .collect();
        let qpos = options.initial_qpos.clone().unwrap_or(vec![0.0; dofs]);
        self.articulations.push(Articulation {
            link_names: desc.links.iter().map(|l| l.name.clone()).collect(),
            bodies,
            joints,
            order,
            parent_joint: joint_of,
            root: options.root_pose,
            qvel: vec![0.0; dofs],
            targets: qpos.clone(),
            velocity_targets: vec![0.0; dofs],
            drives: vec![DriveParams::MANISKILL2_ARM; dofs],
            qpos,
        });
        self.update_links(id);
        Ok(id)
    }

    fn dof(&self, art: ArticulationId) -> PortResult<usize> {
        Ok(self.art(art)?.qpos.len())
    }

    fn joint_infos(&self, art: ArticulationId) -> PortResult<Vec<&JointInfo>> {
        Ok(self
            .art(art)?
            .joints
            .iter()
            .filter(|j| j.dof.is_some())
            .collect())
    }

    fn joint_names(&self, art: ArticulationId) -> PortResult<Vec<&str>> {
        Ok(self
            .joint_infos(art)?
            .into_iter()
            .map(|j| j.name.as_str())
            .collect())
    }

    fn dof_index(&self, art: ArticulationId, joint: &str) -> PortResult<usize> {
        self.joint_infos(art)?
            .iter()
            .find(|j| j.name == joint)
            .and_then(|j| j.dof)
            .ok_or_else(|| no_name("joint", joint))
    }

    fn link_names(&self, art: ArticulationId) -> PortResult<Vec<&str>> {
        Ok(self
            .art(art)?
            .link_names
            .iter()
            .map(String::as_str)
            .collect())
    }

    fn link_index(&self, art: ArticulationId, link: &str) -> PortResult<usize> {
        self.art(art)?
            .link_names
            .iter()
            .position(|l| l == link)
            .ok_or_else(|| no_name("link", link))
    }

    fn link_body(&self, art: ArticulationId, link: usize) -> PortResult<BodyId> {
        self.art(art)?
            .bodies
            .get(link)
            .copied()
            .ok_or_else(|| no_name("link", &link.to_string()))
    }

    fn link_pose(&self, art: ArticulationId, link: usize) -> PortResult<Pose3> {
        self.body_pose(self.link_body(art, link)?)
    }

    fn link_visuals(&self, art: ArticulationId, link: usize) -> PortResult<&[VisualShape]> {
        self.body_visuals(self.link_body(art, link)?)
    }

    fn set_root_pose(&mut self, art: ArticulationId, pose: &Pose3) -> PortResult<()> {
        self.art_mut(art)?.root = *pose;
        self.update_links(art);
        Ok(())
    }

    fn qpos(&self, art: ArticulationId) -> PortResult<Vec<f32>> {
        Ok(self.art(art)?.qpos.clone())
    }

    fn qvel(&self, art: ArticulationId) -> PortResult<Vec<f32>> {
        Ok(self.art(art)?.qvel.clone())
    }

    fn set_qpos(&mut self, art: ArticulationId, qpos: &[f32]) -> PortResult<()> {
        self.dof_values(art, qpos)?;
        self.art_mut(art)?.qpos = qpos.to_vec();
        self.update_links(art);
        Ok(())
    }

    fn set_qvel(&mut self, art: ArticulationId, qvel: &[f32]) -> PortResult<()> {
        self.dof_values(art, qvel)?;
        self.art_mut(art)?.qvel = qvel.to_vec();
        Ok(())
    }

    fn drive(&self, art: ArticulationId, dof: usize) -> PortResult<DriveParams> {
        self.art(art)?
            .drives
            .get(dof)
            .copied()
            .ok_or_else(|| no_name("dof", &dof.to_string()))
    }

    fn set_drive(&mut self, art: ArticulationId, dof: usize, drive: DriveParams) -> PortResult<()> {
        let slot = self
            .art_mut(art)?
            .drives
            .get_mut(dof)
            .ok_or_else(|| no_name("dof", &dof.to_string()))?;
        *slot = drive;
        Ok(())
    }

    fn drive_targets(&self, art: ArticulationId) -> PortResult<Vec<f32>> {
        Ok(self.art(art)?.targets.clone())
    }

    fn set_drive_targets(&mut self, art: ArticulationId, targets: &[f32]) -> PortResult<()> {
        self.dof_values(art, targets)?;
        self.art_mut(art)?.targets = targets.to_vec();
        Ok(())
    }

    fn drive_velocity_targets(&self, art: ArticulationId) -> PortResult<Vec<f32>> {
        Ok(self.art(art)?.velocity_targets.clone())
    }

    fn set_drive_velocity_targets(
        &mut self,
        art: ArticulationId,
        targets: &[f32],
    ) -> PortResult<()> {
        self.dof_values(art, targets)?;
        self.art_mut(art)?.velocity_targets = targets.to_vec();
        Ok(())
    }
}

/// Makes kinematic worlds with a static ground body.
#[derive(Debug)]
struct KinematicEngine;

impl RigidEngine for KinematicEngine {
    fn name(&self) -> &'static str {
        "kinematic (test)"
    }

    fn new_world(&self, config: &WorldConfig) -> PortResult<Box<dyn RigidWorld>> {
        let mut world = KinematicWorld {
            timestep: config.timestep,
            bodies: Vec::new(),
            articulations: Vec::new(),
            ground: None,
        };
        let ground = world.add_actor(ActorDesc::new("ground", ActorKind::Static))?;
        world.ground = Some(ground);
        Ok(Box::new(world))
    }
}

fn kinematic_env(cfg: &EnvConfig) -> Env {
    Env::with_engine(cfg, Arc::new(KinematicEngine)).expect("PickCube on the kinematic engine")
}

fn vector(obs: &ObsValue, key: &str) -> Vec<f32> {
    obs.get(key)
        .and_then(ObsValue::as_f32)
        .unwrap_or_else(|| panic!("{key} missing"))
        .to_vec()
}

fn assert_close(a: &[f32], b: &[f32], tol: f32, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: lengths");
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        assert!((x - y).abs() <= tol, "{what}[{i}]: {x} vs {y}");
    }
}

#[test]
fn pick_cube_resets_and_observes_on_a_second_engine() {
    let cfg = EnvConfig::new("PickCube-v0");
    let mut kinematic = kinematic_env(&cfg);
    let mut rapier = make_env(&cfg).unwrap();
    assert_eq!(
        kinematic.task_scene().unwrap().world.engine_name(),
        "kinematic (test)"
    );
    for seed in [0, 7, 42] {
        let (obs_k, _) = kinematic.reset(Some(seed), false).unwrap();
        let (obs_r, _) = rapier.reset(Some(seed), false).unwrap();
        // The same observation layout, and the same episode: the seeded cube, goal and joint
        // noise, and the TCP pose through each engine's own forward kinematics.
        assert_eq!(
            kinematic.observation_space(),
            rapier.observation_space(),
            "observation spaces"
        );
        for key in ["agent/qpos", "extra/goal_pos", "extra/obj_pose"] {
            assert_close(&vector(&obs_k, key), &vector(&obs_r, key), 1e-6, key);
        }
        assert_close(
            &vector(&obs_k, "extra/tcp_pose"),
            &vector(&obs_r, "extra/tcp_pose"),
            2e-4,
            "extra/tcp_pose",
        );
        assert!(vector(&obs_k, "agent/qvel").iter().all(|v| *v == 0.0));
    }
}

#[test]
fn the_kinematic_panda_follows_its_joint_targets() {
    let cfg = EnvConfig {
        control_mode: Some("pd_joint_pos".to_owned()),
        obs_mode: "state_dict".to_owned(),
        ..EnvConfig::new("PickCube-v0")
    };
    let mut env = kinematic_env(&cfg);
    let (obs, _) = env.reset(Some(3), false).unwrap();
    let mut target = vector(&obs, "agent/qpos")[..8].to_vec();
    target[0] += 0.3;
    target[3] -= 0.2;
    let out = env.step(&target).unwrap();
    let qpos = vector(&out.obs, "agent/qpos");
    assert_close(&qpos[..7], &target[..7], 1e-5, "arm qpos after one step");
    // The TCP moved with the joints (forward kinematics through the port).
    let before = vector(&obs, "extra/tcp_pose");
    let after = vector(&out.obs, "extra/tcp_pose");
    assert!((before[0] - after[0]).abs() + (before[1] - after[1]).abs() > 0.01);
    // State round trip through the port.
    let state = env.get_state();
    env.step(&vector(&obs, "agent/qpos")[..8]).unwrap();
    env.set_state(&state).unwrap();
    assert_eq!(env.get_state(), state);
}
