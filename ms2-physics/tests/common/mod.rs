//! Shared helpers for the Panda tests: the PickCube-like scene and a small numerical IK.

#![allow(dead_code)]

use ms2_physics::{
    add_panda, ActorDesc, ActorKind, ArticulationId, BodyId, MassSpec, Material, PandaOptions,
    Pose3, ShapeDesc, ShapeSpec, World, WorldConfig,
};
use nalgebra::{DMatrix, DVector, UnitQuaternion, Vector3};

/// Panda at (-0.615, 0, 0) and, if `cube_at` is given, a 4 cm cube (1000 kg/m³) there.
pub fn panda_scene(
    config: WorldConfig,
    cube_at: Option<Vector3<f32>>,
) -> (World, ArticulationId, Option<BodyId>) {
    let mut world = World::new(config).unwrap();
    let panda = add_panda(&mut world, &PandaOptions::default()).unwrap();
    let cube = cube_at.map(|p| {
        world
            .add_actor(
                ActorDesc::new("cube", ActorKind::Dynamic)
                    .with_pose(Pose3::translation(p.x, p.y, p.z))
                    .with_shape(
                        ShapeSpec::new(ShapeDesc::cuboid(0.04, 0.04, 0.04))
                            .with_material(Material::default())
                            .with_mass(MassSpec::Density(1000.0)),
                    ),
            )
            .unwrap()
    });
    (world, panda, cube)
}

/// Forward kinematics of the TCP through a scratch world (no stepping).
pub struct TcpKinematics {
    world: World,
    panda: ArticulationId,
    tcp: usize,
}

impl TcpKinematics {
    pub fn new() -> Self {
        let config = WorldConfig {
            ground: None,
            ..WorldConfig::default()
        };
        let mut world = World::new(config).unwrap();
        let panda = add_panda(&mut world, &PandaOptions::default()).unwrap();
        let tcp = world.link_index(panda, ms2_assets::PANDA_TCP_LINK).unwrap();
        TcpKinematics { world, panda, tcp }
    }

    pub fn tcp_pose(&mut self, q_arm: &[f32]) -> Pose3 {
        let mut q = self.world.qpos(self.panda).unwrap();
        q[..7].copy_from_slice(q_arm);
        self.world.set_qpos(self.panda, &q).unwrap();
        self.world.link_pose(self.panda, self.tcp).unwrap()
    }

    /// Damped-least-squares IK for the 7 arm joints, from `q0`, to a TCP position and rotation.
    pub fn solve(
        &mut self,
        q0: &[f32],
        position: Vector3<f32>,
        rotation: UnitQuaternion<f32>,
    ) -> Vec<f32> {
        let mut q: Vec<f32> = q0[..7].to_vec();
        let error = |pose: &Pose3| -> DVector<f64> {
            let dp = position - pose.translation.vector;
            let dr = (rotation * pose.rotation.inverse()).scaled_axis();
            DVector::from_iterator(6, dp.iter().chain(dr.iter()).map(|v| *v as f64))
        };
        for _ in 0..100 {
            let pose = self.tcp_pose(&q);
            let e = error(&pose);
            if e.norm() < 1e-5 {
                break;
            }
            let mut jac = DMatrix::<f64>::zeros(6, 7);
            let eps = 1e-3f32;
            for j in 0..7 {
                let mut qp = q.clone();
                qp[j] += eps;
                let ep = error(&self.tcp_pose(&qp));
                let col = (&e - ep) / eps as f64;
                jac.set_column(j, &col);
            }
            let lambda = 1e-4;
            let jjt = &jac * jac.transpose() + DMatrix::<f64>::identity(6, 6) * lambda;
            let dq = jac.transpose() * jjt.lu().solve(&e).unwrap();
            for j in 0..7 {
                q[j] += dq[j] as f32;
            }
        }
        q
    }
}

/// Largest linear speed of any body (m/s) and whether every pose/velocity is finite.
pub fn max_speed(world: &World) -> (f32, bool) {
    let mut max = 0.0f32;
    let mut finite = true;
    for b in world.bodies() {
        let v = world.body_linear_velocity(b).unwrap();
        let p = world.body_pose(b).unwrap();
        finite &= v.iter().all(|x| x.is_finite())
            && p.translation.vector.iter().all(|x| x.is_finite())
            && p.rotation.coords.iter().all(|x| x.is_finite());
        max = max.max(v.norm());
    }
    (max, finite)
}
