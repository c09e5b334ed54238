//! [`OrbitCamera`]: the viewer's free camera, orbiting a target point (world frame, z up).

use ms2_render::Camera;
use nalgebra::{Point3, Vector3};

/// Smallest orbit distance (m); zooming in stops there.
pub const MIN_DISTANCE_M: f32 = 0.05;
/// Largest orbit distance (m); zooming out stops there.
pub const MAX_DISTANCE_M: f32 = 50.0;
/// Pitch is kept within ±this (rad) so the view never flips over the pole.
const MAX_PITCH_RAD: f32 = 1.55;
/// Orbit angle per pixel of mouse drag (rad).
const RAD_PER_PIXEL: f32 = 0.005;
/// Distance factor per wheel line (zoom in = multiply by this).
const ZOOM_PER_LINE: f32 = 0.9;

/// A camera looking at `target` from `distance_m` away, at azimuth `yaw` (rad, from +x towards
/// +y) and elevation `pitch` (rad, positive = above the target). World frame, z up, metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrbitCamera {
    /// The point looked at (m, world).
    pub target: Point3<f32>,
    /// Eye-to-target distance (m).
    pub distance_m: f32,
    /// Azimuth of the eye around the target (rad, 0 = on +x, π/2 = on +y).
    pub yaw: f32,
    /// Elevation of the eye above the target (rad).
    pub pitch: f32,
    /// Vertical field of view (rad).
    pub fov_y: f32,
}

impl OrbitCamera {
    /// The orbit camera whose eye is at `eye` looking at `target` (m, world); `fov_y` in rad.
    pub fn looking_at(eye: Point3<f32>, target: Point3<f32>, fov_y: f32) -> OrbitCamera {
        let d = eye - target;
        let distance_m = d.norm().clamp(MIN_DISTANCE_M, MAX_DISTANCE_M);
        let horizontal = (d.x * d.x + d.y * d.y).sqrt();
        OrbitCamera {
            target,
            distance_m,
            yaw: d.y.atan2(d.x),
            pitch: d.z.atan2(horizontal).clamp(-MAX_PITCH_RAD, MAX_PITCH_RAD),
            fov_y,
        }
    }

    /// The orbit camera seeing what `camera` sees (same eye, direction and field of view),
    /// orbiting the point of its optical axis nearest the world origin (at least 0.3 m and at
    /// most 5 m ahead).
    pub fn from_camera(camera: &Camera) -> OrbitCamera {
        let pose = camera.pose_world_from_camera_gl;
        let eye = Point3::from(pose.translation.vector);
        let forward = pose.rotation * -Vector3::z();
        let ahead = (-eye.coords.dot(&forward)).clamp(0.3, 5.0);
        OrbitCamera::looking_at(eye, eye + ahead * forward, camera.fov_y)
    }

    /// The eye position (m, world).
    pub fn eye(&self) -> Point3<f32> {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        self.target + self.distance_m * Vector3::new(cp * cy, cp * sy, sp)
    }

    /// Rotates the view by a mouse drag of (`dx`, `dy`) pixels (right / down positive).
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        self.yaw -= dx * RAD_PER_PIXEL;
        self.pitch = (self.pitch + dy * RAD_PER_PIXEL).clamp(-MAX_PITCH_RAD, MAX_PITCH_RAD);
    }

    /// Moves the target (and eye) in the view plane by a drag of (`dx`, `dy`) pixels in a
    /// window `height_px` tall, so the point under the cursor follows it.
    pub fn pan(&mut self, dx: f32, dy: f32, height_px: f32) {
        let metres_per_pixel =
            2.0 * self.distance_m * (self.fov_y / 2.0).tan() / height_px.max(1.0);
        let forward = (self.target - self.eye()).normalize();
        let right = forward.cross(&Vector3::z()).normalize();
        let up = right.cross(&forward);
        self.target += (-dx * right + dy * up) * metres_per_pixel;
    }

    /// Zooms by `lines` wheel lines (positive = closer).
    pub fn zoom(&mut self, lines: f32) {
        self.distance_m =
            (self.distance_m * ZOOM_PER_LINE.powf(lines)).clamp(MIN_DISTANCE_M, MAX_DISTANCE_M);
    }

    /// The render camera of this view for a `width`×`height` image (near 0.01 m, far 100 m).
    pub fn camera(&self, width: u32, height: u32) -> Camera {
        Camera::new(width, height, self.fov_y, 0.01, 100.0).looking_at(
            self.eye(),
            self.target,
            Vector3::z(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn looking_at_round_trips_the_eye() {
        let eye = Point3::new(1.0, 1.0, 0.8);
        let target = Point3::new(0.0, 0.0, 0.35);
        let cam = OrbitCamera::looking_at(eye, target, 1.0);
        assert_relative_eq!(cam.eye(), eye, epsilon = 1e-5);
    }

    #[test]
    fn from_camera_sees_the_same_view() {
        let eye = Point3::new(1.0, 1.0, 0.8);
        let target = Point3::new(0.0, 0.0, 0.35);
        let cam = Camera::new(64, 64, 1.0, 0.01, 10.0).looking_at(eye, target, Vector3::z());
        let orbit = OrbitCamera::from_camera(&cam);
        assert_relative_eq!(orbit.eye(), eye, epsilon = 1e-4);
        let dir = (orbit.target - orbit.eye()).normalize();
        assert_relative_eq!(dir, (target - eye).normalize(), epsilon = 1e-4);
        assert_eq!(orbit.fov_y, 1.0);
    }

    #[test]
    fn orbit_keeps_distance_and_target() {
        let mut cam = OrbitCamera::looking_at(Point3::new(2.0, 0.0, 1.0), Point3::origin(), 1.0);
        let d = cam.distance_m;
        cam.orbit(100.0, -40.0);
        assert_relative_eq!((cam.eye() - cam.target).norm(), d, epsilon = 1e-5);
        assert_eq!(cam.target, Point3::origin());
        assert!(
            cam.yaw < 0.0,
            "dragging right turns the eye clockwise seen from above"
        );
        cam.orbit(0.0, 1e6);
        assert!(cam.pitch <= MAX_PITCH_RAD);
    }

    #[test]
    fn pan_moves_target_across_the_view_and_zoom_changes_distance() {
        let mut cam = OrbitCamera::looking_at(Point3::new(2.0, 0.0, 0.0), Point3::origin(), 1.0);
        cam.pan(100.0, 0.0, 500.0);
        // Looking along -x with z up, the view's right is +y; dragging right carries the scene
        // right, so the target moves left (-y).
        assert!(cam.target.y < 0.0 && cam.target.x.abs() < 1e-6 && cam.target.z.abs() < 1e-6);
        let before = cam.distance_m;
        cam.zoom(2.0);
        assert_relative_eq!(cam.distance_m, before * 0.81, epsilon = 1e-5);
        cam.zoom(-1000.0);
        assert_eq!(cam.distance_m, MAX_DISTANCE_M);
    }
}
