//! What one camera produces: images, camera parameters and point clouds.

use crate::{Camera, RenderError};
use nalgebra::{Matrix3, Matrix3x4, Matrix4, Point3};
use std::path::Path;

/// The images of one camera, row-major from the top-left pixel, `width * height` pixels.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraOutput {
    /// The camera that took the images (pose, size, field of view).
    pub camera: Camera,
    /// Shaded colour, sRGB, 3 bytes per pixel.
    pub rgb: Vec<u8>,
    /// Distance along the optical axis (OpenCV z) in metres; 0 where nothing was hit
    /// (background, or beyond the far plane).
    pub depth_m: Vec<f32>,
    /// Actor id ([`crate::SegmentationIds::actor`]) of the surface seen; 0 for background.
    pub segmentation_actor: Vec<u32>,
    /// Link id ([`crate::SegmentationIds::link`]) of the surface seen; 0 for background.
    pub segmentation_link: Vec<u32>,
}

impl CameraOutput {
    /// Image width in pixels.
    pub fn width(&self) -> u32 {
        self.camera.width
    }

    /// Image height in pixels.
    pub fn height(&self) -> u32 {
        self.camera.height
    }

    /// Whether pixel `index` (row-major) saw a surface (as opposed to background).
    pub fn is_valid(&self, index: usize) -> bool {
        self.depth_m[index] > 0.0
    }

    /// Intrinsic matrix, OpenCV convention (see [`Camera::intrinsic_cv`]).
    pub fn intrinsic_cv(&self) -> Matrix3<f32> {
        self.camera.intrinsic_cv()
    }

    /// World-to-camera extrinsic `[R | t]`, OpenCV convention.
    pub fn extrinsic_cv(&self) -> Matrix3x4<f32> {
        self.camera.extrinsic_cv()
    }

    /// Camera-to-world transform, OpenGL convention.
    pub fn cam2world_gl(&self) -> Matrix4<f32> {
        self.camera.cam2world_gl()
    }

    /// Per-pixel points in the camera frame, OpenCV convention (x right, y down, z forward),
    /// metres, as `[x, y, z, w]` with w = 1 for valid pixels and all zeros for background.
    pub fn point_cloud_camera_cv(&self) -> Vec<[f32; 4]> {
        let k = self.intrinsic_cv();
        let (f, cx, cy) = (k[(0, 0)], k[(0, 2)], k[(1, 2)]);
        let w = self.width() as usize;
        self.depth_m
            .iter()
            .enumerate()
            .map(|(i, &z)| {
                if z > 0.0 {
                    let (u, v) = ((i % w) as f32, (i / w) as f32);
                    [(u - cx) / f * z, (v - cy) / f * z, z, 1.0]
                } else {
                    [0.0; 4]
                }
            })
            .collect()
    }

    /// Per-pixel points in the world frame (metres) as `[x, y, z, w]` with w = 1 for valid
    /// pixels and all zeros for background — ManiSkill2's `xyzw` layout.
    pub fn point_cloud_world(&self) -> Vec<[f32; 4]> {
        let pose = self.camera.pose_world_from_camera_cv();
        self.point_cloud_camera_cv()
            .into_iter()
            .map(|p| {
                if p[3] > 0.0 {
                    let q = pose * Point3::new(p[0], p[1], p[2]);
                    [q.x, q.y, q.z, 1.0]
                } else {
                    [0.0; 4]
                }
            })
            .collect()
    }

    /// Writes the colour image as a PNG (through a temporary file renamed into place).
    pub fn save_rgb_png(&self, path: &Path) -> Result<(), RenderError> {
        save_png(
            path,
            self.width(),
            self.height(),
            image::ColorType::Rgb8,
            &self.rgb,
        )
    }

    /// Writes the depth image as an 8-bit grey PNG, near = white, `max_depth_m` and background
    /// = black (for looking at, not for measuring).
    pub fn save_depth_png(&self, path: &Path, max_depth_m: f32) -> Result<(), RenderError> {
        let grey: Vec<u8> = self
            .depth_m
            .iter()
            .map(|&d| {
                if d > 0.0 {
                    (255.0 * (1.0 - (d / max_depth_m).clamp(0.0, 1.0))) as u8
                } else {
                    0
                }
            })
            .collect();
        save_png(
            path,
            self.width(),
            self.height(),
            image::ColorType::L8,
            &grey,
        )
    }

    /// Writes the link segmentation as a PNG with one arbitrary bright colour per id
    /// (background black).
    pub fn save_segmentation_png(&self, path: &Path) -> Result<(), RenderError> {
        let rgb: Vec<u8> = self
            .segmentation_link
            .iter()
            .flat_map(|&id| segmentation_color(id))
            .collect();
        save_png(
            path,
            self.width(),
            self.height(),
            image::ColorType::Rgb8,
            &rgb,
        )
    }
}

/// A distinct, bright RGB colour per segmentation id, for showing segmentation images to people
/// (id 0, the background, is black). The same id always gets the same colour.
///
/// ```
/// assert_eq!(ms2_render::segmentation_color(0), [0, 0, 0]);
/// assert_eq!(ms2_render::segmentation_color(7), ms2_render::segmentation_color(7));
/// assert_ne!(ms2_render::segmentation_color(1), ms2_render::segmentation_color(2));
/// ```
pub fn segmentation_color(id: u32) -> [u8; 3] {
    if id == 0 {
        return [0, 0, 0];
    }
    let h = id.wrapping_mul(2_654_435_761);
    [
        (h >> 24) as u8 | 0x40,
        (h >> 16) as u8 | 0x40,
        (h >> 8) as u8 | 0x40,
    ]
}

/// Encodes `data` as PNG into `path` via a temporary sibling file and a rename.
pub(crate) fn save_png(
    path: &Path,
    width: u32,
    height: u32,
    color: image::ColorType,
    data: &[u8],
) -> Result<(), RenderError> {
    let err = |reason: String| RenderError::ImageWrite {
        path: path.to_path_buf(),
        reason,
    };
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = std::path::PathBuf::from(tmp);
    image::save_buffer_with_format(&tmp, data, width, height, color, image::ImageFormat::Png)
        .map_err(|e| err(e.to_string()))?;
    std::fs::rename(&tmp, path).map_err(|e| err(e.to_string()))
}

/// Point clouds of several cameras fused in the world frame (ManiSkill2's `pointcloud`
/// observation): all pixels of all cameras, in camera order then row-major.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FusedPointCloud {
    /// World-frame points, metres, `[x, y, z, w]` with w = 1 for valid points and all zeros
    /// for background pixels.
    pub xyzw: Vec<[f32; 4]>,
    /// Colour of each point, sRGB.
    pub rgb: Vec<[u8; 3]>,
    /// Actor id of each point (0 = background).
    pub segmentation_actor: Vec<u32>,
    /// Link id of each point (0 = background).
    pub segmentation_link: Vec<u32>,
}

impl FusedPointCloud {
    /// Concatenates the world-frame point clouds of `outputs`.
    pub fn from_cameras(outputs: &[CameraOutput]) -> FusedPointCloud {
        let mut fused = FusedPointCloud::default();
        for out in outputs {
            fused.xyzw.extend(out.point_cloud_world());
            fused
                .rgb
                .extend(out.rgb.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
            fused
                .segmentation_actor
                .extend_from_slice(&out.segmentation_actor);
            fused
                .segmentation_link
                .extend_from_slice(&out.segmentation_link);
        }
        fused
    }

    /// Number of points (valid or not).
    pub fn len(&self) -> usize {
        self.xyzw.len()
    }

    /// Whether there are no points at all.
    pub fn is_empty(&self) -> bool {
        self.xyzw.is_empty()
    }
}
