//! The mobile Panda's camera rig (three overhead cameras on `mobile_base`): the fused
//! `pointcloud` observation matches a CPU ray cast of the cameras' pixels against the ground
//! plane within 1 mm, wherever a camera sees the ground.

use ms2_tasks::agents::mobile_panda::mobile_panda_cameras;
use ms2_tasks::sensors::CameraMount;
use ms2_tasks::{make_env, ArrayData, EnvConfig, ObsValue};
use nalgebra::{Point3, Quaternion, UnitQuaternion, Vector3};

fn f32s<'a>(obs: &'a ObsValue, path: &str) -> &'a [f32] {
    match obs.get(path) {
        Some(ObsValue::Array(a)) => match &a.data {
            ArrayData::F32(v) => v,
            other => panic!("{path}: {other:?}"),
        },
        other => panic!("{path}: {other:?}"),
    }
}

#[test]
fn fused_point_cloud_matches_a_ray_cast_of_the_ground() {
    let mut env = make_env(&EnvConfig {
        obs_mode: "pointcloud".to_owned(),
        ..EnvConfig::new("OpenCabinetDrawer-v1")
    })
    .unwrap();
    let (obs, _) = env.reset(Some(2), false).unwrap();
    let base = f32s(&obs, "agent/base_pose");
    let pose_world_from_base = nalgebra::Isometry3::from_parts(
        Vector3::new(base[0], base[1], base[2]).into(),
        UnitQuaternion::from_quaternion(Quaternion::new(base[3], base[4], base[5], base[6])),
    );
    let xyzw = f32s(&obs, "pointcloud/xyzw");
    let cams = mobile_panda_cameras();
    let pixels: usize = cams.iter().map(|c| (c.width * c.height) as usize).sum();
    assert_eq!(xyzw.len(), 4 * pixels, "three 400×160 cameras fused");
    let (mut checked, mut worst, mut offset) = (0usize, 0.0_f32, 0usize);
    for cam in &cams {
        let CameraMount::RobotLink {
            pose_link_from_camera,
            ..
        } = &cam.mount
        else {
            panic!("mounted on the base");
        };
        let pose = pose_world_from_base * pose_link_from_camera;
        let (w, h) = (cam.width as usize, cam.height as usize);
        let f = (h as f32 / 2.0) / (cam.fov_y / 2.0).tan();
        for v in 0..h {
            for u in 0..w {
                let p = &xyzw[4 * (offset + v * w + u)..][..4];
                // Ground points only: the cabinet and the robot stand above it (a point of an
                // object's side within 0.5 mm of the ground is as good as never sampled).
                if p[3] != 1.0 || p[2].abs() > 5e-4 {
                    continue;
                }
                // Robotics camera frame: x forward, y left, z up.
                let dir = pose.rotation
                    * Vector3::new(
                        1.0,
                        -((u as f32 + 0.5) - w as f32 / 2.0) / f,
                        -((v as f32 + 0.5) - h as f32 / 2.0) / f,
                    );
                let origin = pose.translation.vector;
                assert!(dir.z < 0.0, "a ground pixel looks down");
                let hit = Point3::from(origin + dir * (-origin.z / dir.z));
                let err = (Point3::new(p[0], p[1], p[2]) - hit).norm();
                worst = worst.max(err);
                checked += 1;
            }
        }
        offset += w * h;
    }
    assert!(
        checked > pixels / 4,
        "only {checked} of {pixels} points on the ground"
    );
    assert!(
        worst <= 1e-3,
        "a ground point is {worst} m off the ray cast"
    );
}
