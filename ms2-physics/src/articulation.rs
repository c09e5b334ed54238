//! Articulations built from an [`ArticulationDesc`] as rapier
//! reduced-coordinate multibodies.
//!
//! Links joined by fixed joints are merged into one rigid body (as PhysX does): the body frame is
//! the frame of the group's first link, and every merged link keeps its own frame through
//! `pose_body_from_link`. Every movable joint (revolute, continuous, prismatic) is one degree of
//! freedom; the order of the degrees of freedom is a depth-first walk of the kinematic tree from
//! the root link, children in the order their joints appear in the description (for the Panda:
//! `panda_joint1..7`, then the two finger joints).

use std::collections::HashMap;

use nalgebra::{Matrix3, Vector3};
use rapier3d::dynamics::{
    GenericJointBuilder, JointAxesMask, JointAxis, MassProperties, MultibodyIndex, RigidBodyBuilder,
};
use rapier3d::math::{Pose, Rotation};

use crate::description::{invalid, validate_tree};
pub use crate::description::{
    ArticulationDesc, ArticulationOptions, DriveParams, Inertial, JointDesc, JointInfo, JointType,
    LinkDesc, Mimic, SelfCollision,
};
use crate::error::{PhysicsError, Result};
pub use crate::ids::ArticulationId;
use crate::ids::{BodyId, BodyKind};
use crate::math::{pose_from_na, vec_from_na, Pose3};
use crate::shape::{MassSpec, ShapeSpec, VisualShape};
use crate::world::{BodyEntry, World};

/// One link of a built articulation.
#[derive(Clone, Debug)]
pub(crate) struct ArtLink {
    pub(crate) name: String,
    pub(crate) body: BodyId,
    pub(crate) pose_body_from_link: Pose3,
    pub(crate) parent_joint: Option<usize>,
    pub(crate) visuals: Vec<VisualShape>,
}

/// One degree of freedom of a built articulation.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Dof {
    pub(crate) joint: usize,
    /// Link id (inside the rapier multibody) of the body this dof moves.
    pub(crate) mb_link: usize,
    pub(crate) axis: JointAxis,
}

/// A built articulation.
#[derive(Clone, Debug)]
pub(crate) struct Articulation {
    pub(crate) name: String,
    pub(crate) links: Vec<ArtLink>,
    pub(crate) joints: Vec<JointInfo>,
    pub(crate) dofs: Vec<Dof>,
    pub(crate) bodies: Vec<BodyId>,
    pub(crate) multibody: MultibodyIndex,
}

fn mat3_from_na(m: &Matrix3<f32>) -> rapier3d::math::Matrix {
    rapier3d::math::Matrix::from_cols_slice(m.as_slice())
}

impl World {
    /// Adds an articulation from a description; returns its id.
    ///
    /// Builds one rapier multibody with a fixed root at `options.root_pose`. Drives start with
    /// zero gains: set them with [`World::set_drive`] / [`World::set_drives`].
    pub fn add_articulation(
        &mut self,
        desc: &ArticulationDesc,
        options: &ArticulationOptions,
    ) -> Result<ArticulationId> {
        self.add_articulation_from(desc, options, "<description>")
    }

    pub(crate) fn add_articulation_from(
        &mut self,
        desc: &ArticulationDesc,
        options: &ArticulationOptions,
        file: &str,
    ) -> Result<ArticulationId> {
        let tree = validate_tree(desc, file)?;
        if !crate::math::pose_is_finite(&options.root_pose) {
            return Err(PhysicsError::InvalidParameter {
                name: "root_pose",
                value: format!("{:?}", options.root_pose),
                expected: "a finite pose",
            });
        }
        options.default_material.validate()?;
        for (name, m) in &options.link_materials {
            m.validate()?;
            if !desc.links.iter().any(|l| &l.name == name) {
                return Err(PhysicsError::UnknownName {
                    articulation: desc.name.clone(),
                    kind: "link",
                    name: name.clone(),
                });
            }
        }
        let art_id = ArticulationId(self.articulations.len() as u32);
        let n = desc.links.len();

        // Group links into bodies and compute the zero-configuration world poses.
        let mut body_of_link = vec![usize::MAX; n]; // index of the group's first link
        let mut pose_body_from_link = vec![Pose3::identity(); n];
        let mut world_from_link = vec![Pose3::identity(); n];
        for &l in &tree.order {
            match tree.parent_joint[l] {
                None => {
                    body_of_link[l] = l;
                    world_from_link[l] = options.root_pose;
                }
                Some(j) => {
                    let joint = &desc.joints[j];
                    let p = desc
                        .links
                        .iter()
                        .position(|x| x.name == joint.parent)
                        .expect("validated");
                    world_from_link[l] = world_from_link[p] * joint.pose_parent_from_joint;
                    if joint.joint_type.is_movable() {
                        body_of_link[l] = l;
                    } else {
                        body_of_link[l] = body_of_link[p];
                        pose_body_from_link[l] =
                            pose_body_from_link[p] * joint.pose_parent_from_joint;
                    }
                }
            }
        }

        // Create one rapier body per group, in depth-first order.
        let mut body_id_of_group: HashMap<usize, BodyId> = HashMap::new();
        let mut art_bodies = Vec::new();
        let root = tree.order[0];
        for &l in &tree.order {
            if body_of_link[l] != l {
                continue;
            }
            let members: Vec<usize> = tree
                .order
                .iter()
                .copied()
                .filter(|&m| body_of_link[m] == l)
                .collect();
            let mut mprops = MassProperties::default();
            let mut total_mass = 0.0;
            for &m in &members {
                if let Some(inertial) = &desc.links[m].inertial {
                    let local = MassProperties::with_inertia_matrix(
                        rapier3d::math::Vector::ZERO,
                        inertial.mass,
                        mat3_from_na(&inertial.inertia),
                    );
                    let pose = pose_body_from_link[m] * inertial.pose_link_from_inertial;
                    mprops += local.transform_by(&pose_from_na(&pose));
                    total_mass += inertial.mass;
                }
            }
            let is_root = l == root;
            if !is_root && total_mass <= 0.0 {
                // A massless moving body would make the multibody's mass matrix singular.
                mprops = MassProperties::new(
                    rapier3d::math::Vector::ZERO,
                    1e-3,
                    rapier3d::math::Vector::splat(1e-7),
                );
            }
            let rb = if is_root {
                RigidBodyBuilder::fixed()
            } else {
                RigidBodyBuilder::dynamic()
                    .can_sleep(false)
                    .gravity_scale(if options.gravity_compensation {
                        0.0
                    } else {
                        1.0
                    })
                    .additional_mass_properties(mprops)
            }
            .pose(pose_from_na(&world_from_link[l]));
            let handle = self.sim.bodies.insert(rb);
            let id = BodyId(self.table.len() as u32);
            let mut shapes = Vec::new();
            let mut visuals = Vec::new();
            let mut colliders = Vec::new();
            for &m in &members {
                let link = &desc.links[m];
                let material = options
                    .link_materials
                    .iter()
                    .find(|(name, _)| name == &link.name)
                    .map(|(_, mat)| *mat)
                    .unwrap_or(options.default_material);
                for c in &link.collisions {
                    let spec = ShapeSpec {
                        shape: c.shape.clone(),
                        pose_body_from_shape: pose_body_from_link[m] * c.pose_body_from_shape,
                        material,
                        mass: MassSpec::Massless,
                    };
                    let collider = spec
                        .to_collider()
                        .map_err(|e| {
                            invalid(
                                file,
                                format!("<link name=\"{}\"> <collision>", link.name),
                                e.to_string(),
                            )
                        })?
                        .user_data(id.0 as u128)
                        .build();
                    let collider = self.sim.colliders.insert_with_parent(
                        collider,
                        handle,
                        &mut self.sim.bodies,
                    );
                    self.register_patch_collider(collider, material.torsional_patch_radius_m);
                    colliders.push(collider);
                    shapes.push(spec);
                }
                for v in &link.visuals {
                    visuals.push(VisualShape {
                        shape: v.shape.clone(),
                        pose_body_from_shape: pose_body_from_link[m] * v.pose_body_from_shape,
                        rgba: v.rgba,
                    });
                }
            }
            self.table.push(BodyEntry {
                name: desc.links[l].name.clone(),
                kind: BodyKind::Link(art_id),
                handle,
                colliders,
                shapes,
                visuals,
            });
            body_id_of_group.insert(l, id);
            art_bodies.push(id);
        }

        // Joints: one multibody joint per movable joint, in depth-first order.
        let link_index: HashMap<&str, usize> = desc
            .links
            .iter()
            .enumerate()
            .map(|(i, l)| (l.name.as_str(), i))
            .collect();
        let mut joint_order: Vec<usize> = Vec::new();
        for &l in &tree.order {
            if let Some(j) = tree.parent_joint[l] {
                joint_order.push(j);
            }
        }
        let mut joints_info: Vec<Option<JointInfo>> = vec![None; desc.joints.len()];
        let mut dof_joints: Vec<(usize, BodyId, JointAxis)> = Vec::new();
        for &j in &joint_order {
            let joint = &desc.joints[j];
            let p = link_index[joint.parent.as_str()];
            let c = link_index[joint.child.as_str()];
            let axis = if joint.joint_type.is_movable() {
                joint.axis.normalize()
            } else {
                Vector3::z()
            };
            let limits = match joint.joint_type {
                JointType::Fixed => [0.0, 0.0],
                JointType::Continuous => [f32::NEG_INFINITY, f32::INFINITY],
                _ => joint.limits.unwrap_or([f32::NEG_INFINITY, f32::INFINITY]),
            };
            let dof = if joint.joint_type.is_movable() {
                Some(dof_joints.len())
            } else {
                None
            };
            joints_info[j] = Some(JointInfo {
                name: joint.name.clone(),
                joint_type: joint.joint_type,
                parent_link: p,
                child_link: c,
                limits,
                axis,
                pose_parent_from_joint: joint.pose_parent_from_joint,
                effort_limit: joint.effort_limit,
                velocity_limit: joint.velocity_limit,
                mimic: joint.mimic.clone(),
                dof,
            });
            if !joint.joint_type.is_movable() {
                continue;
            }
            let parent_body = body_id_of_group[&body_of_link[p]];
            let child_body = body_id_of_group[&c];
            let rot = Rotation::from_rotation_arc(rapier3d::math::Vector::X, vec_from_na(&axis));
            let frame1 = pose_from_na(&(pose_body_from_link[p] * joint.pose_parent_from_joint))
                * Pose::from_rotation(rot);
            let frame2 = Pose::from_rotation(rot);
            let (mask, rapier_axis) = match joint.joint_type {
                JointType::Prismatic => (JointAxesMask::LOCKED_PRISMATIC_AXES, JointAxis::LinX),
                _ => (JointAxesMask::LOCKED_REVOLUTE_AXES, JointAxis::AngX),
            };
            let mut builder = GenericJointBuilder::new(mask)
                .local_frame1(frame1)
                .local_frame2(frame2)
                .contacts_enabled(false);
            if limits[0].is_finite() || limits[1].is_finite() {
                builder = builder.limits(rapier_axis, limits);
            }
            let ph = self.table[parent_body.index()].handle;
            let ch = self.table[child_body.index()].handle;
            self.sim
                .multibody_joints
                .insert(ph, ch, builder.build(), true)
                .ok_or_else(|| {
                    invalid(
                        file,
                        format!("<joint name=\"{}\">", joint.name),
                        "rapier refused the joint (it would close a loop)".into(),
                    )
                })?;
            dof_joints.push((j, child_body, rapier_axis));
        }
        let joints_info: Vec<JointInfo> =
            joints_info.into_iter().map(|j| j.expect("set")).collect();

        // Resolve multibody link ids now that the multibody is complete.
        let root_handle = self.table[body_id_of_group[&root].index()].handle;
        let multibody = match self.sim.multibody_joints.rigid_body_link(root_handle) {
            Some(link) => link.multibody,
            None => {
                return Err(invalid(
                    file,
                    "<robot>".into(),
                    "no movable joint: use a static actor for a rigid object".into(),
                ))
            }
        };
        let mut dofs = Vec::with_capacity(dof_joints.len());
        for (j, body, axis) in &dof_joints {
            let h = self.table[body.index()].handle;
            let link = self
                .sim
                .multibody_joints
                .rigid_body_link(h)
                .expect("inserted link");
            dofs.push(Dof {
                joint: *j,
                mb_link: link.id,
                axis: *axis,
            });
        }

        // Joint damping and friction from the description (rapier's default damping is replaced).
        {
            let mb = self
                .sim
                .multibody_joints
                .get_multibody_mut(multibody)
                .expect("multibody exists");
            mb.damping_mut().fill(0.0);
            for d in &dofs {
                let a = mb.link(d.mb_link).expect("link").assembly_id();
                mb.damping_mut()[a] = desc.joints[d.joint].damping;
                mb.frictions_mut()[a] = desc.joints[d.joint].friction;
            }
            if options.self_collision == SelfCollision::Disabled {
                mb.set_self_contacts_enabled(false);
            }
        }

        let links: Vec<ArtLink> = (0..n)
            .map(|l| ArtLink {
                name: desc.links[l].name.clone(),
                body: body_id_of_group[&body_of_link[l]],
                pose_body_from_link: pose_body_from_link[l],
                parent_joint: tree.parent_joint[l],
                visuals: desc.links[l].visuals.clone(),
            })
            .collect();
        self.articulations.push(Articulation {
            name: desc.name.clone(),
            links,
            joints: joints_info,
            dofs,
            bodies: art_bodies.clone(),
            multibody,
        });
        self.generation += 1;

        if let Some(q) = &options.initial_qpos {
            self.set_qpos(art_id, q)?;
        } else {
            let q: Vec<f32> = self.articulations[art_id.index()]
                .dofs
                .iter()
                .map(|d| {
                    let [lo, hi] = self.articulations[art_id.index()].joints[d.joint].limits;
                    0.0f32.clamp(lo, hi)
                })
                .collect();
            self.set_qpos(art_id, &q)?;
        }
        if options.self_collision == SelfCollision::NonAdjacent {
            self.exclude_touching_links(&art_bodies, 1e-3);
        }
        Ok(art_id)
    }

    /// Excludes contacts between bodies of `bodies` whose shapes are closer than `margin` (m).
    fn exclude_touching_links(&mut self, bodies: &[BodyId], margin: f32) {
        use rapier3d::parry::query;
        for (i, &a) in bodies.iter().enumerate() {
            for &b in &bodies[i + 1..] {
                let mut touching = false;
                'outer: for &ca in &self.table[a.index()].colliders {
                    for &cb in &self.table[b.index()].colliders {
                        let (c1, c2) = (&self.sim.colliders[ca], &self.sim.colliders[cb]);
                        if let Ok(d) =
                            query::distance(c1.position(), c1.shape(), c2.position(), c2.shape())
                        {
                            if d.distance < margin {
                                touching = true;
                                break 'outer;
                            }
                        }
                    }
                }
                if touching {
                    self.hooks.exclude(a, b);
                    for id in [a, b] {
                        for &c in &self.table[id.index()].colliders {
                            let co = &mut self.sim.colliders[c];
                            co.set_active_hooks(
                                co.active_hooks()
                                    | rapier3d::prelude::ActiveHooks::FILTER_CONTACT_PAIRS,
                            );
                        }
                    }
                }
            }
        }
    }
}
