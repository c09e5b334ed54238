//! ManiSkill2's visual observation layouts (`rgbd`, `pointcloud`, `*_robot_seg`) assembled from
//! camera outputs.
//!
//! - `rgbd`: `{"agent", "extra", "camera_param": {cam: {"extrinsic_cv" [3,4],
//!   "cam2world_gl" [4,4], "intrinsic_cv" [3,3]}}, "image": {cam: {"rgb" u8 [H,W,3],
//!   "depth" f32 [H,W,1] (metres, 0 = nothing seen)}}}`; `rgbd_robot_seg` adds
//!   `image[cam]["robot_seg"]` bool `[H,W,1]`; a camera with `add_segmentation` adds
//!   `image[cam]["Segmentation"]` u32 `[H,W,4]`.
//! - `image` (ManiSkill2's raw textures, from which its `rgbd` and `pointcloud` are derived):
//!   as `rgbd` but `image[cam]` = `{"Color" f32 [H,W,4] (RGBA in [0, 1], alpha 1),
//!   "Position" f32 [H,W,4] (x, y, z in the camera's OpenGL frame: x right, y up, looking
//!   down -z, metres; w = depth / far in [0, 1) on surfaces, all (0, 0, 0, 1) where nothing is
//!   seen, so `-Position[..., 2]` is the depth and `Position[..., 3] < 1` the valid mask)}`,
//!   plus `"Segmentation"` with `add_segmentation`.
//! - `pointcloud`: `{"agent", "extra", "pointcloud": {"xyzw" f32 [N,4] (world frame; w = 1 for
//!   points on a surface, all zeros for background), "rgb" u8 [N,3], "Segmentation" u32 [N,4]}}`,
//!   N = the sum of H·W over cameras (camera order, then row-major); `pointcloud_robot_seg`
//!   adds `pointcloud["robot_seg"]` bool `[N,1]`.
//! - `Segmentation` channels: 0 = visual-shape id, 1 = actor/link id (see
//!   [`crate::adapters::render_scene`]), 2 and 3 = 0 (as in ManiSkill2).
//! - [`VisualLayout`] is plain data (every build); [`CameraFrame`] and [`assemble`] need the
//!   `render` feature.
//! - `extra` keeps only what a real robot would know: the task spec's
//!   `non_privileged_extra_keys` ([`crate::spec::TaskSpec`]).

#[cfg(feature = "render")]
use ms2_render::CameraOutput;

#[cfg(feature = "render")]
use crate::obs::{non_privileged_state, Array, ArrayData, ObsValue};

/// A visual observation layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum VisualLayout {
    /// Per-camera images and camera parameters.
    Rgbd,
    /// One world-frame point cloud fused over the cameras.
    PointCloud,
    /// Raw per-camera textures (`Color`, `Position`) plus camera parameters.
    Image,
}

/// One frame of an env's observation cameras (feature `render`).
#[cfg(feature = "render")]
#[derive(Debug, Clone)]
pub struct CameraFrame {
    /// Camera uids, in config order.
    pub uids: Vec<String>,
    /// One output per camera, same order.
    pub outputs: Vec<CameraOutput>,
    /// Channel-1 (actor/link) ids of the robot's links.
    pub robot_ids: Vec<u32>,
    /// Per camera (same order): whether its `Segmentation` image is observed.
    pub segmentation: Vec<bool>,
}

#[cfg(feature = "render")]
fn array(shape: Vec<usize>, data: ArrayData) -> ObsValue {
    ObsValue::Array(Array { shape, data })
}

#[cfg(feature = "render")]
fn matrix_rows<const R: usize, const C: usize>(m: &nalgebra::SMatrix<f32, R, C>) -> ObsValue {
    let data = (0..R)
        .flat_map(|r| (0..C).map(move |c| m[(r, c)]))
        .collect();
    array(vec![R, C], ArrayData::F32(data))
}

/// ManiSkill2's `Segmentation` texture of one camera: per pixel (visual-shape id, actor/link
/// id, 0, 0).
#[cfg(feature = "render")]
fn segmentation_image(out: &CameraOutput) -> Vec<u32> {
    out.segmentation_actor
        .iter()
        .zip(&out.segmentation_link)
        .flat_map(|(&visual, &link)| [visual, link, 0, 0])
        .collect()
}

/// ManiSkill2's raw `Color` and `Position` textures of one camera (see the module docs).
#[cfg(feature = "render")]
fn raw_textures(out: CameraOutput) -> Vec<(String, ObsValue)> {
    let (h, w) = (out.height() as usize, out.width() as usize);
    let color = out
        .rgb
        .chunks_exact(3)
        .flat_map(|p| {
            [p[0], p[1], p[2]]
                .map(|c| f32::from(c) / 255.0)
                .into_iter()
                .chain([1.0])
        })
        .collect();
    let far = out.camera.far.max(f32::MIN_POSITIVE);
    let position = out
        .point_cloud_camera_cv()
        .into_iter()
        .flat_map(|p| {
            if p[3] > 0.0 {
                [p[0], -p[1], -p[2], (p[2] / far).min(1.0 - f32::EPSILON)]
            } else {
                [0.0, 0.0, 0.0, 1.0]
            }
        })
        .collect();
    vec![
        (
            "Color".to_owned(),
            array(vec![h, w, 4], ArrayData::F32(color)),
        ),
        (
            "Position".to_owned(),
            array(vec![h, w, 4], ArrayData::F32(position)),
        ),
    ]
}

/// The full visual observation: `state_dict`'s non-privileged part (`extra` filtered to
/// `non_privileged_extra_keys`) plus the camera data in `layout`, with a robot mask when
/// `robot_seg`. Takes the frame by value: its images move into the observation without copies.
/// Feature `render`.
#[cfg(feature = "render")]
pub fn assemble(
    state_dict: ObsValue,
    non_privileged_extra_keys: &[&str],
    frame: CameraFrame,
    layout: VisualLayout,
    robot_seg: bool,
) -> ObsValue {
    let mut root = non_privileged_state(state_dict, non_privileged_extra_keys);
    let is_robot = |link_id: &u32| frame.robot_ids.contains(link_id);
    match layout {
        VisualLayout::Rgbd | VisualLayout::Image => {
            let mut params = Vec::with_capacity(frame.outputs.len());
            let mut images = Vec::with_capacity(frame.outputs.len());
            let seg_flags = frame
                .segmentation
                .iter()
                .copied()
                .chain(std::iter::repeat(false));
            for ((uid, out), with_seg) in frame.uids.iter().zip(frame.outputs).zip(seg_flags) {
                let (h, w) = (out.height() as usize, out.width() as usize);
                params.push((
                    uid.clone(),
                    ObsValue::Dict(vec![
                        ("extrinsic_cv".to_owned(), matrix_rows(&out.extrinsic_cv())),
                        ("cam2world_gl".to_owned(), matrix_rows(&out.cam2world_gl())),
                        ("intrinsic_cv".to_owned(), matrix_rows(&out.intrinsic_cv())),
                    ]),
                ));
                let mask = robot_seg.then(|| out.segmentation_link.iter().map(is_robot).collect());
                let segmentation = with_seg.then(|| segmentation_image(&out));
                let mut image = match layout {
                    VisualLayout::Image => raw_textures(out),
                    _ => vec![
                        (
                            "rgb".to_owned(),
                            array(vec![h, w, 3], ArrayData::U8(out.rgb)),
                        ),
                        (
                            "depth".to_owned(),
                            array(vec![h, w, 1], ArrayData::F32(out.depth_m)),
                        ),
                    ],
                };
                if let Some(seg) = segmentation {
                    image.push((
                        "Segmentation".to_owned(),
                        array(vec![h, w, 4], ArrayData::U32(seg)),
                    ));
                }
                if let Some(mask) = mask {
                    image.push((
                        "robot_seg".to_owned(),
                        array(vec![h, w, 1], ArrayData::Bool(mask)),
                    ));
                }
                images.push((uid.clone(), ObsValue::Dict(image)));
            }
            root.push(("camera_param".to_owned(), ObsValue::Dict(params)));
            root.push(("image".to_owned(), ObsValue::Dict(images)));
        }
        VisualLayout::PointCloud => {
            // Cameras fused in order straight into the flat arrays (no intermediate cloud).
            let n: usize = frame.outputs.iter().map(|o| o.depth_m.len()).sum();
            let mut xyzw = Vec::with_capacity(4 * n);
            let mut rgb = Vec::with_capacity(3 * n);
            let mut seg = Vec::with_capacity(4 * n);
            let mut mask = Vec::with_capacity(if robot_seg { n } else { 0 });
            for out in &frame.outputs {
                for point in out.point_cloud_world() {
                    xyzw.extend_from_slice(&point);
                }
                rgb.extend_from_slice(&out.rgb);
                for (&visual, &link) in out.segmentation_actor.iter().zip(&out.segmentation_link) {
                    seg.extend_from_slice(&[visual, link, 0, 0]);
                }
                if robot_seg {
                    mask.extend(out.segmentation_link.iter().map(is_robot));
                }
            }
            let mut cloud = vec![
                ("xyzw".to_owned(), array(vec![n, 4], ArrayData::F32(xyzw))),
                ("rgb".to_owned(), array(vec![n, 3], ArrayData::U8(rgb))),
                (
                    "Segmentation".to_owned(),
                    array(vec![n, 4], ArrayData::U32(seg)),
                ),
            ];
            if robot_seg {
                cloud.push((
                    "robot_seg".to_owned(),
                    array(vec![n, 1], ArrayData::Bool(mask)),
                ));
            }
            root.push(("pointcloud".to_owned(), ObsValue::Dict(cloud)));
        }
    }
    ObsValue::Dict(root)
}
