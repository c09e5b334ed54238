//! Pinhole cameras: pose conventions, intrinsics and extrinsics.
//!
//! Three camera frame conventions appear in robotics code; this crate names each explicitly:
//! - **OpenGL** (`_gl`): x right, y up, the camera looks along −z. Used internally for rendering
//!   and by ManiSkill2's `cam2world_gl`.
//! - **OpenCV** (`_cv`): x right, y down, the camera looks along +z. Used by `intrinsic_cv` and
//!   `extrinsic_cv`.
//! - **Robotics / SAPIEN** (`_robotics`): x forward (the viewing direction), y left, z up. Used by
//!   ManiSkill2's camera mounts (e.g. the hand camera's mount offset).

use crate::RenderError;
use nalgebra::{
    Isometry3, Matrix3, Matrix3x4, Matrix4, Point3, Rotation3, UnitQuaternion, Vector3,
};

/// Rotation taking OpenGL camera axes to robotics axes: columns are the GL axes expressed in the
/// robotics frame (GL x right = −y_robotics, GL y up = z_robotics, GL z back = −x_robotics).
fn rotation_robotics_from_gl() -> Rotation3<f32> {
    Rotation3::from_matrix_unchecked(Matrix3::new(
        0.0, 0.0, -1.0, //
        -1.0, 0.0, 0.0, //
        0.0, 1.0, 0.0,
    ))
}

/// Rotation taking OpenCV camera axes to OpenGL camera axes (a half turn about x).
fn rotation_gl_from_cv() -> Rotation3<f32> {
    Rotation3::from_matrix_unchecked(Matrix3::new(
        1.0, 0.0, 0.0, //
        0.0, -1.0, 0.0, //
        0.0, 0.0, -1.0,
    ))
}

/// A pinhole camera: pose, image size, vertical field of view and clipping distances.
///
/// Pixels are square; the principal point is the image centre. Everything behind `near` or
/// beyond `far` (metres along the viewing axis) is background.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Pose of the camera in the world, OpenGL camera convention (x right, y up, looking along −z).
    pub pose_world_from_camera_gl: Isometry3<f32>,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Vertical field of view in radians, in (0, π).
    pub fov_y: f32,
    /// Near clipping distance in metres (> 0).
    pub near: f32,
    /// Far clipping distance in metres (> near).
    pub far: f32,
}

impl Camera {
    /// A camera at the world origin (OpenGL convention: looking along world −z, image-up along
    /// world +y); place it with [`Camera::with_pose_gl`], [`Camera::with_pose_robotics`] or
    /// [`Camera::looking_at`].
    pub fn new(width: u32, height: u32, fov_y: f32, near: f32, far: f32) -> Camera {
        Camera {
            pose_world_from_camera_gl: Isometry3::identity(),
            width,
            height,
            fov_y,
            near,
            far,
        }
    }

    /// This camera with the given pose, OpenGL camera convention.
    pub fn with_pose_gl(mut self, pose_world_from_camera_gl: Isometry3<f32>) -> Camera {
        self.pose_world_from_camera_gl = pose_world_from_camera_gl;
        self
    }

    /// This camera with a pose given in the robotics/SAPIEN convention (x forward, y left,
    /// z up), as ManiSkill2's camera mounts are.
    pub fn with_pose_robotics(self, pose_world_from_camera_robotics: Isometry3<f32>) -> Camera {
        let rot = UnitQuaternion::from_rotation_matrix(&rotation_robotics_from_gl());
        self.with_pose_gl(
            pose_world_from_camera_robotics * Isometry3::from_parts(Default::default(), rot),
        )
    }

    /// This camera placed at `eye`, looking at `target` (world frame, metres), with image-up
    /// roughly along `up`. If `up` is parallel to the viewing direction, world z (or y) is used.
    pub fn looking_at(self, eye: Point3<f32>, target: Point3<f32>, up: Vector3<f32>) -> Camera {
        let forward = (target - eye).normalize();
        let mut up = up;
        if forward.cross(&up).norm() < 1e-6 {
            up = if forward.z.abs() < 0.9 {
                Vector3::z()
            } else {
                Vector3::y()
            };
        }
        let z_gl = -forward;
        let x_gl = up.cross(&z_gl).normalize();
        let y_gl = z_gl.cross(&x_gl);
        let rot = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[x_gl, y_gl, z_gl]));
        self.with_pose_gl(Isometry3::from_parts(
            eye.coords.into(),
            UnitQuaternion::from_rotation_matrix(&rot),
        ))
    }

    /// Checks sizes, field of view and clipping distances.
    pub fn validate(&self) -> Result<(), RenderError> {
        if self.width == 0 || self.height == 0 || self.width > 8192 || self.height > 8192 {
            return Err(RenderError::InvalidCamera(format!(
                "image size {}x{} must be between 1 and 8192 pixels per side",
                self.width, self.height
            )));
        }
        if !(self.fov_y > 0.0 && self.fov_y < std::f32::consts::PI) {
            return Err(RenderError::InvalidCamera(format!(
                "fov_y {} rad must be in (0, π)",
                self.fov_y
            )));
        }
        if !(self.near > 0.0 && self.far > self.near && self.far.is_finite()) {
            return Err(RenderError::InvalidCamera(format!(
                "clipping distances near {} m, far {} m must satisfy 0 < near < far < ∞",
                self.near, self.far
            )));
        }
        let m = self.pose_world_from_camera_gl.to_homogeneous();
        if !m.iter().all(|v| v.is_finite()) {
            return Err(RenderError::InvalidCamera("pose must be finite".into()));
        }
        Ok(())
    }

    /// Focal length in pixels (the same along both axes).
    pub fn focal_length_px(&self) -> f32 {
        0.5 * self.height as f32 / (0.5 * self.fov_y).tan()
    }

    /// Intrinsic matrix K, OpenCV convention: pixel (u, v) = (column, row) with the centre of
    /// the top-left pixel at (0, 0); `[fx 0 cx; 0 fy cy; 0 0 1]` with cx = (width − 1)/2.
    pub fn intrinsic_cv(&self) -> Matrix3<f32> {
        let f = self.focal_length_px();
        let cx = 0.5 * (self.width as f32 - 1.0);
        let cy = 0.5 * (self.height as f32 - 1.0);
        Matrix3::new(f, 0.0, cx, 0.0, f, cy, 0.0, 0.0, 1.0)
    }

    /// Pose of the camera in the world, OpenCV camera convention.
    pub fn pose_world_from_camera_cv(&self) -> Isometry3<f32> {
        let rot = UnitQuaternion::from_rotation_matrix(&rotation_gl_from_cv());
        self.pose_world_from_camera_gl * Isometry3::from_parts(Default::default(), rot)
    }

    /// Extrinsic matrix `[R | t]` (3×4) mapping world points to OpenCV camera coordinates.
    pub fn extrinsic_cv(&self) -> Matrix3x4<f32> {
        let m = self.pose_world_from_camera_cv().inverse().to_homogeneous();
        m.fixed_view::<3, 4>(0, 0).into_owned()
    }

    /// Camera-to-world transform (4×4), OpenGL camera convention (ManiSkill2's `cam2world_gl`).
    pub fn cam2world_gl(&self) -> Matrix4<f32> {
        self.pose_world_from_camera_gl.to_homogeneous()
    }

    /// The world-to-clip matrix used for rasterisation (wgpu clip space: depth in [0, 1]).
    pub(crate) fn clip_from_world(&self) -> Matrix4<f32> {
        let aspect = self.width as f32 / self.height as f32;
        let t = 1.0 / (0.5 * self.fov_y).tan();
        let (n, f) = (self.near, self.far);
        #[rustfmt::skip]
        let proj = Matrix4::new(
            t / aspect, 0.0, 0.0, 0.0,
            0.0, t, 0.0, 0.0,
            0.0, 0.0, f / (n - f), n * f / (n - f),
            0.0, 0.0, -1.0, 0.0,
        );
        proj * self.pose_world_from_camera_gl.inverse().to_homogeneous()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn intrinsics_match_fov() {
        let cam = Camera::new(128, 96, std::f32::consts::FRAC_PI_2, 0.01, 10.0).looking_at(
            Point3::new(0.3, 0.0, 0.6),
            Point3::new(-0.1, 0.0, 0.1),
            Vector3::z(),
        );
        let k = cam.intrinsic_cv();
        // fov π/2: the top edge of the image is at 45°, half the height away from the centre.
        assert_relative_eq!(k[(1, 1)], 48.0, epsilon = 1e-4);
        assert_relative_eq!(k[(0, 0)], 48.0, epsilon = 1e-4);
        assert_relative_eq!(k[(0, 2)], 63.5);
        assert_relative_eq!(k[(1, 2)], 47.5);
        // The target projects to the image centre.
        let p = cam.extrinsic_cv() * Vector3::new(-0.1, 0.0, 0.1).push(1.0);
        let uv = k * p;
        assert_relative_eq!(uv.x / uv.z, 63.5, epsilon = 1e-3);
        assert_relative_eq!(uv.y / uv.z, 47.5, epsilon = 1e-3);
    }

    #[test]
    fn conventions_agree() {
        let eye = Point3::new(1.0, 2.0, 3.0);
        let cam = Camera::new(8, 8, 1.0, 0.1, 10.0).looking_at(
            eye,
            Point3::new(1.0, 2.0, 0.0),
            Vector3::x(),
        );
        // Looking straight down with image-up along world x: OpenCV +z (forward) is world −z,
        // OpenCV +y (image down) is world −x.
        let cv = cam.pose_world_from_camera_cv();
        assert_relative_eq!(cv * Vector3::z(), -Vector3::z(), epsilon = 1e-6);
        assert_relative_eq!(cv * Vector3::y(), -Vector3::x(), epsilon = 1e-6);
        // The robotics pose gives back the same camera.
        let robotics = cam.pose_world_from_camera_gl
            * Isometry3::from_parts(
                Default::default(),
                UnitQuaternion::from_rotation_matrix(&rotation_robotics_from_gl()).inverse(),
            );
        assert_relative_eq!(robotics * Vector3::x(), -Vector3::z(), epsilon = 1e-6);
        let again = Camera::new(8, 8, 1.0, 0.1, 10.0).with_pose_robotics(robotics);
        assert_relative_eq!(
            again.pose_world_from_camera_gl.to_homogeneous(),
            cam.pose_world_from_camera_gl.to_homogeneous(),
            epsilon = 1e-6
        );
    }

    #[test]
    fn invalid_cameras_are_rejected() {
        let mut cam = Camera::new(8, 8, 1.0, 0.1, 10.0).looking_at(
            Point3::origin(),
            Point3::new(1.0, 0.0, 0.0),
            Vector3::z(),
        );
        assert!(cam.validate().is_ok());
        cam.fov_y = f32::NAN;
        assert!(cam.validate().is_err());
        cam.fov_y = 1.0;
        cam.near = 0.0;
        assert!(cam.validate().is_err());
        cam.near = 0.1;
        cam.width = 0;
        assert!(cam.validate().is_err());
    }
}
