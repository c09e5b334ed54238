//! Camera configurations: ManiSkill2's `base_camera`, `hand_camera` and human render camera.
//! Plain data in every build; [`CameraConfig::camera_at`] (a posed `ms2_render::Camera`) needs
//! the `render` feature.

#[cfg(feature = "render")]
use ms2_physics::ArticulationId;
use ms2_physics::Pose3;
#[cfg(feature = "render")]
use ms2_render::Camera;
use nalgebra::{Point3, Quaternion, Translation3, UnitQuaternion, Vector3};

use crate::error::EnvError;
#[cfg(feature = "render")]
use crate::rigid_world::RigidWorld;

/// Where a camera is: fixed in the world, or riding on a link of the robot.
///
/// Poses are in the robotics (SAPIEN / ManiSkill2 mount) convention: camera x forward,
/// y left, z up.
#[derive(Debug, Clone, PartialEq)]
pub enum CameraMount {
    /// Fixed in the world.
    World {
        /// Pose of the camera (robotics convention) in the world frame, metres.
        pose_world_from_camera: Pose3,
    },
    /// Attached to a link of the robot, moving with it.
    RobotLink {
        /// Link name, e.g. `"panda_hand"`.
        link: String,
        /// Pose of the camera (robotics convention) in the link frame, metres.
        pose_link_from_camera: Pose3,
    },
}

/// One camera: name, image size, field of view, clipping distances and mount.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraConfig {
    /// Name used as the observation key, e.g. `"base_camera"`.
    pub uid: String,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Vertical field of view (radians).
    pub fov_y: f32,
    /// Near clipping distance (m).
    pub near: f32,
    /// Far clipping distance (m); depth beyond it reads 0.
    pub far: f32,
    /// Where the camera is.
    pub mount: CameraMount,
    /// Whether the `image` / `rgbd` observations of this camera include its `Segmentation`
    /// image (u32 [H, W, 4]; ManiSkill2's `camera_cfgs={"add_segmentation": True}`). Off by
    /// default, as in ManiSkill2.
    pub segmentation: bool,
}

/// Pose (robotics convention: x forward, z up) of a camera at `eye` looking at `target`.
pub fn look_at_robotics(eye: [f32; 3], target: [f32; 3]) -> Pose3 {
    let eye = Point3::from(eye);
    let forward = (Point3::from(target) - eye).normalize();
    let left = Vector3::z().cross(&forward);
    let left = if left.norm() < 1e-6 {
        Vector3::y()
    } else {
        left.normalize()
    };
    let up = forward.cross(&left);
    let rot = nalgebra::Rotation3::from_matrix_unchecked(nalgebra::Matrix3::from_columns(&[
        forward, left, up,
    ]));
    Pose3::from_parts(
        Translation3::from(eye.coords),
        UnitQuaternion::from_rotation_matrix(&rot),
    )
}

/// `cameras` with those named in `views` — `(uid, eye, target)`, metres, world frame — fixed
/// in the world looking from `eye` at `target` (ManiSkill2's tasks place `base_camera` and
/// `render_camera` this way); other cameras unchanged.
///
/// ```
/// use ms2_tasks::sensors::{with_views, CameraConfig, CameraMount};
/// let cams = with_views(CameraConfig::panda_defaults(), &[("base_camera", [0.0, -0.3, 0.2], [0.0, 0.0, 0.1])]);
/// assert!(matches!(cams[0].mount, CameraMount::World { .. }));
/// assert_eq!(cams[1], CameraConfig::hand_camera());
/// ```
pub fn with_views(
    mut cameras: Vec<CameraConfig>,
    views: &[(&str, [f32; 3], [f32; 3])],
) -> Vec<CameraConfig> {
    for cam in &mut cameras {
        if let Some((_, eye, target)) = views.iter().find(|(uid, ..)| *uid == cam.uid) {
            cam.mount = CameraMount::World {
                pose_world_from_camera: look_at_robotics(*eye, *target),
            };
        }
    }
    cameras
}

impl CameraConfig {
    /// A camera fixed in the world: `width`×`height` pixels, vertical field of view `fov_y`
    /// (radians), clipping planes `near`..`far` (metres), at `pose_world_from_camera` (robotics
    /// convention: x forward, y left, z up, as ManiSkill2's camera poses).
    ///
    /// ```
    /// use ms2_tasks::sensors::{look_at_robotics, CameraConfig};
    /// let cam = CameraConfig::in_world("base_camera", 128, 128, 1.57, 0.01, 10.0,
    ///     look_at_robotics([0.3, 0.0, 0.6], [-0.1, 0.0, 0.1]));
    /// assert!(cam.validate().is_ok());
    /// ```
    pub fn in_world(
        uid: &str,
        width: u32,
        height: u32,
        fov_y: f32,
        near: f32,
        far: f32,
        pose_world_from_camera: Pose3,
    ) -> CameraConfig {
        CameraConfig {
            uid: uid.to_owned(),
            width,
            height,
            fov_y,
            near,
            far,
            mount: CameraMount::World {
                pose_world_from_camera,
            },
            segmentation: false,
        }
    }

    /// ManiSkill2's `base_camera`: 128×128, fov π/2, near 0.01, far 10, at (0.3, 0, 0.6) looking
    /// at (-0.1, 0, 0.1).
    pub fn base_camera() -> CameraConfig {
        CameraConfig {
            uid: "base_camera".to_owned(),
            width: 128,
            height: 128,
            fov_y: std::f32::consts::FRAC_PI_2,
            near: 0.01,
            far: 10.0,
            mount: CameraMount::World {
                pose_world_from_camera: look_at_robotics([0.3, 0.0, 0.6], [-0.1, 0.0, 0.1]),
            },
            segmentation: false,
        }
    }

    /// ManiSkill2's `hand_camera`: 128×128, fov 1.57, near 0.01, far 10, on `panda_hand` at
    /// p = (0.0465, -0.0200, 0.0360), q (wxyz) = (0, 0.7071, 0, 0.7071).
    pub fn hand_camera() -> CameraConfig {
        CameraConfig {
            uid: "hand_camera".to_owned(),
            width: 128,
            height: 128,
            fov_y: 1.57,
            near: 0.01,
            far: 10.0,
            mount: CameraMount::RobotLink {
                link: "panda_hand".to_owned(),
                pose_link_from_camera: Pose3::from_parts(
                    Translation3::new(0.046_498_2, -0.020_001_1, 0.036_001_1),
                    UnitQuaternion::from_quaternion(Quaternion::new(
                        0.0,
                        std::f32::consts::FRAC_1_SQRT_2,
                        0.0,
                        std::f32::consts::FRAC_1_SQRT_2,
                    )),
                ),
            },
            segmentation: false,
        }
    }

    /// The camera of `render_mode = "rgb_array"` (ManiSkill2 0.5.3's `render_camera` of its
    /// Panda pick-and-place tasks): 512×512, fov 1 rad, near 0.01 m, far 10 m, at
    /// (0.4, 0.4, 0.8) looking at (0, 0, 0.4).
    pub fn render_camera() -> CameraConfig {
        CameraConfig {
            uid: "render_camera".to_owned(),
            width: 512,
            height: 512,
            fov_y: 1.0,
            near: 0.01,
            far: 10.0,
            mount: CameraMount::World {
                pose_world_from_camera: look_at_robotics([0.4, 0.4, 0.8], [0.0, 0.0, 0.4]),
            },
            segmentation: false,
        }
    }

    /// The observation cameras of the Panda tasks: `base_camera`, `hand_camera`.
    pub fn panda_defaults() -> Vec<CameraConfig> {
        vec![Self::base_camera(), Self::hand_camera()]
    }

    /// The observation cameras of `xmate3_robotiq` (ManiSkill2's, mounted on the robot):
    /// `base_camera` on `camera_base_link` (fixed in front of the robot, looking back down at
    /// it) and `hand_camera` on `camera_hand_link` (the wrist), both 128×128, fov 1.5707,
    /// near 0.01, far 10, at the link frame.
    pub fn xmate3_defaults() -> Vec<CameraConfig> {
        let on_link = |uid: &str, link: &str| CameraConfig {
            uid: uid.to_owned(),
            width: 128,
            height: 128,
            fov_y: 1.5707,
            near: 0.01,
            far: 10.0,
            mount: CameraMount::RobotLink {
                link: link.to_owned(),
                pose_link_from_camera: Pose3::identity(),
            },
            segmentation: false,
        };
        vec![
            on_link("base_camera", "camera_base_link"),
            on_link("hand_camera", "camera_hand_link"),
        ]
    }

    /// The human render camera of the `xmate3_robotiq` tasks: as [`Self::render_camera`] but
    /// at (0.5, 0.5, 1.0) looking at (0, 0, 0.5) (ManiSkill2's, for the taller robot).
    pub fn xmate3_render_camera() -> CameraConfig {
        CameraConfig {
            mount: CameraMount::World {
                pose_world_from_camera: look_at_robotics([0.5, 0.5, 1.0], [0.0, 0.0, 0.5]),
            },
            ..Self::render_camera()
        }
    }

    /// The observation cameras of `PandaAvoidObstacles-v0` (ManiSkill2's): `base_camera` at
    /// (-0.25, 0, 1.2) looking at (0.6, 0, 0.6) (128×128, fov π/2), and the Panda's
    /// `hand_camera`.
    pub fn avoid_obstacles_defaults() -> Vec<CameraConfig> {
        let base = CameraConfig {
            mount: CameraMount::World {
                pose_world_from_camera: look_at_robotics([-0.25, 0.0, 1.2], [0.6, 0.0, 0.6]),
            },
            ..Self::base_camera()
        };
        vec![base, Self::hand_camera()]
    }

    /// The human render camera of `PandaAvoidObstacles-v0`: at (1.5, 0, 1.5) looking at
    /// (0, 0, 0.5), facing the robot over the wall.
    pub fn avoid_obstacles_render_camera() -> CameraConfig {
        CameraConfig {
            mount: CameraMount::World {
                pose_world_from_camera: look_at_robotics([1.5, 0.0, 1.5], [0.0, 0.0, 0.5]),
            },
            ..Self::render_camera()
        }
    }

    /// Checks the size, field of view and clipping distances (the mount is checked when the
    /// camera is attached to a scene).
    pub fn validate(&self) -> Result<(), EnvError> {
        let bad = |what: String| {
            Err(EnvError::InvalidConfig(format!(
                "camera {:?}: {what}",
                self.uid
            )))
        };
        if self.uid.is_empty() {
            return bad("uid must not be empty".to_owned());
        }
        if !(1..=4096).contains(&self.width) || !(1..=4096).contains(&self.height) {
            return bad(format!(
                "width and height must be in 1..=4096 pixels, got {}×{}",
                self.width, self.height
            ));
        }
        if !(self.fov_y.is_finite() && self.fov_y > 0.0 && self.fov_y < std::f32::consts::PI) {
            return bad(format!("fov_y must be in (0, π) rad, got {}", self.fov_y));
        }
        if !(self.near.is_finite()
            && self.far.is_finite()
            && self.near > 0.0
            && self.far > self.near)
        {
            return bad(format!(
                "need 0 < near < far (m), got near {} and far {}",
                self.near, self.far
            ));
        }
        Ok(())
    }

    /// The render camera at the current pose of its mount (`robot` = the robot carrying
    /// link-mounted cameras). Feature `render`.
    #[cfg(feature = "render")]
    pub fn camera_at(
        &self,
        world: &dyn RigidWorld,
        robot: Option<ArticulationId>,
    ) -> Result<Camera, EnvError> {
        let pose_world_from_camera = match &self.mount {
            CameraMount::World {
                pose_world_from_camera,
            } => *pose_world_from_camera,
            CameraMount::RobotLink {
                link,
                pose_link_from_camera,
            } => {
                let art = robot.ok_or_else(|| {
                    EnvError::InvalidConfig(format!(
                        "camera {:?} is mounted on link {link:?} but the env has no robot",
                        self.uid
                    ))
                })?;
                let link_pose = world
                    .link_index(art, link)
                    .and_then(|i| world.link_pose(art, i))
                    .map_err(|e| {
                        EnvError::InvalidConfig(format!(
                            "camera {:?} mount link {link:?}: {e}",
                            self.uid
                        ))
                    })?;
                link_pose * pose_link_from_camera
            }
        };
        Ok(
            Camera::new(self.width, self.height, self.fov_y, self.near, self.far)
                .with_pose_robotics(pose_world_from_camera),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_points_x_forward_at_target() {
        let pose = look_at_robotics([0.3, 0.0, 0.6], [-0.1, 0.0, 0.1]);
        let forward = pose.rotation * Vector3::x();
        let expected = Vector3::new(-0.4, 0.0, -0.5).normalize();
        assert!((forward - expected).norm() < 1e-5, "{forward:?}");
        assert!(
            (pose.rotation * Vector3::z()).z > 0.0,
            "camera up points up"
        );
    }

    #[test]
    fn bad_camera_configs_are_rejected() {
        let mut cam = CameraConfig::base_camera();
        assert!(cam.validate().is_ok());
        cam.fov_y = f32::NAN;
        let err = cam.validate().unwrap_err().to_string();
        assert!(
            err.contains("base_camera") && err.contains("fov_y"),
            "{err}"
        );
        let mut cam = CameraConfig::hand_camera();
        cam.far = 0.001;
        assert!(cam.validate().is_err());
        cam = CameraConfig::render_camera();
        cam.width = 0;
        assert!(cam.validate().is_err());
    }
}
