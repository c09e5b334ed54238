//! [`CameraCfgUpdates`]: changes to an env's cameras in the shape of ManiSkill2's `camera_cfgs`
//! keyword (`{"width": 64, "base_camera": {"fov": 1.2}}`).

use nalgebra::{Quaternion, Translation3, UnitQuaternion};

use super::camera::{CameraConfig, CameraMount};
use crate::error::EnvError;

/// The camera fields a `camera_cfgs` entry may set (ManiSkill2's `CameraConfig` names).
pub const CAMERA_UPDATE_KEYS: [&str; 8] = [
    "width",
    "height",
    "fov",
    "near",
    "far",
    "p",
    "q",
    "add_segmentation",
];

/// New values for some fields of a camera; `None` keeps the current value.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CameraUpdate {
    /// Image width in pixels.
    pub width: Option<u32>,
    /// Image height in pixels.
    pub height: Option<u32>,
    /// Vertical field of view (radians; ManiSkill2's `fov`).
    pub fov: Option<f32>,
    /// Near clipping distance (m).
    pub near: Option<f32>,
    /// Far clipping distance (m).
    pub far: Option<f32>,
    /// Position (m) of the camera in its mount's frame (the world, or the link it rides on).
    pub p: Option<[f32; 3]>,
    /// Orientation (quaternion w, x, y, z; normalised here) in its mount's frame, robotics
    /// convention (x forward, z up).
    pub q: Option<[f32; 4]>,
    /// Adds (`true`) or removes the camera's `Segmentation` image in the `image` / `rgbd`
    /// observations (ManiSkill2's `add_segmentation`).
    pub add_segmentation: Option<bool>,
}

impl CameraUpdate {
    /// Applies the set fields to `camera` (which is validated afterwards by the env).
    fn apply(&self, camera: &mut CameraConfig) -> Result<(), EnvError> {
        if let Some(w) = self.width {
            camera.width = w;
        }
        if let Some(h) = self.height {
            camera.height = h;
        }
        if let Some(fov) = self.fov {
            camera.fov_y = fov;
        }
        if let Some(near) = self.near {
            camera.near = near;
        }
        if let Some(far) = self.far {
            camera.far = far;
        }
        if let Some(seg) = self.add_segmentation {
            camera.segmentation = seg;
        }
        if self.p.is_none() && self.q.is_none() {
            return Ok(());
        }
        let pose = match &mut camera.mount {
            CameraMount::World {
                pose_world_from_camera,
            } => pose_world_from_camera,
            CameraMount::RobotLink {
                pose_link_from_camera,
                ..
            } => pose_link_from_camera,
        };
        if let Some(p) = self.p {
            if p.iter().any(|v| !v.is_finite()) {
                return Err(bad(
                    &camera.uid,
                    format!("p must be 3 finite metres, got {p:?}"),
                ));
            }
            pose.translation = Translation3::new(p[0], p[1], p[2]);
        }
        if let Some(q) = self.q {
            let quat = Quaternion::new(q[0], q[1], q[2], q[3]);
            let norm = quat.norm();
            if !(norm.is_finite() && norm > 1e-6) {
                return Err(bad(
                    &camera.uid,
                    format!("q must be a non-zero finite quaternion (w, x, y, z), got {q:?}"),
                ));
            }
            pose.rotation = UnitQuaternion::from_quaternion(quat);
        }
        Ok(())
    }
}

fn bad(uid: &str, what: String) -> EnvError {
    EnvError::InvalidConfig(format!("camera_cfgs for camera {uid:?}: {what}"))
}

/// ManiSkill2's `camera_cfgs`: an update for every camera, then updates of named cameras
/// (applied after, so they win).
///
/// ```
/// use ms2_tasks::sensors::{CameraCfgUpdates, CameraConfig, CameraUpdate};
/// let updates = CameraCfgUpdates {
///     all: CameraUpdate { width: Some(64), height: Some(64), ..Default::default() },
///     per_camera: vec![("hand_camera".into(), CameraUpdate { fov: Some(1.0), ..Default::default() })],
/// };
/// let cams = updates.applied_to(CameraConfig::panda_defaults()).unwrap();
/// assert_eq!((cams[0].width, cams[1].width, cams[1].fov_y), (64, 64, 1.0));
/// assert!(CameraCfgUpdates { per_camera: vec![("nope".into(), CameraUpdate::default())],
///     ..Default::default() }.applied_to(CameraConfig::panda_defaults()).is_err());
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CameraCfgUpdates {
    /// Applied to every camera.
    pub all: CameraUpdate,
    /// Applied to the camera with that uid.
    pub per_camera: Vec<(String, CameraUpdate)>,
}

impl CameraCfgUpdates {
    /// `cameras` with the updates applied and checked ([`CameraConfig::validate`]). A uid that
    /// names no camera is an error listing the cameras.
    pub fn applied_to(
        &self,
        mut cameras: Vec<CameraConfig>,
    ) -> Result<Vec<CameraConfig>, EnvError> {
        for camera in &mut cameras {
            self.all.apply(camera)?;
        }
        for (uid, update) in &self.per_camera {
            let uids: Vec<String> = cameras.iter().map(|c| c.uid.clone()).collect();
            let camera = cameras.iter_mut().find(|c| &c.uid == uid).ok_or_else(|| {
                EnvError::InvalidConfig(format!(
                    "camera_cfgs names camera {uid:?}, but the env's cameras are {uids:?}"
                ))
            })?;
            update.apply(camera)?;
        }
        for camera in &cameras {
            camera.validate()?;
        }
        Ok(cameras)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn per_camera_updates_win_and_poses_move_within_the_mount() {
        let updates = CameraCfgUpdates {
            all: CameraUpdate {
                fov: Some(1.0),
                ..Default::default()
            },
            per_camera: vec![(
                "base_camera".to_owned(),
                CameraUpdate {
                    fov: Some(0.5),
                    p: Some([1.0, 2.0, 3.0]),
                    q: Some([2.0, 0.0, 0.0, 0.0]),
                    ..Default::default()
                },
            )],
        };
        let cams = updates.applied_to(CameraConfig::panda_defaults()).unwrap();
        assert_eq!(cams[0].fov_y, 0.5);
        assert_eq!(cams[1].fov_y, 1.0);
        let CameraMount::World {
            pose_world_from_camera,
        } = &cams[0].mount
        else {
            panic!("base camera is world-mounted");
        };
        assert_eq!(pose_world_from_camera.translation.vector.z, 3.0);
        assert!((pose_world_from_camera.rotation.w - 1.0).abs() < 1e-6);
        assert_eq!(cams[1].mount, CameraConfig::hand_camera().mount);
    }

    #[test]
    fn bad_values_name_the_camera_and_field() {
        let zero_width = CameraCfgUpdates {
            all: CameraUpdate {
                width: Some(0),
                ..Default::default()
            },
            ..Default::default()
        };
        let err = zero_width
            .applied_to(CameraConfig::panda_defaults())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("base_camera") && err.contains("width"),
            "{err}"
        );
        let zero_q = CameraCfgUpdates {
            per_camera: vec![(
                "hand_camera".to_owned(),
                CameraUpdate {
                    q: Some([0.0; 4]),
                    ..Default::default()
                },
            )],
            ..Default::default()
        };
        let err = zero_q
            .applied_to(CameraConfig::panda_defaults())
            .unwrap_err()
            .to_string();
        assert!(err.contains("hand_camera") && err.contains('q'), "{err}");
    }
}
