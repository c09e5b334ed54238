//! Rendering tests on whatever adapter the machine has (lavapipe / llvmpipe on CPU machines).
//! One renderer is shared by all tests of this binary.

use ms2_render::*;
use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};
use std::f32::consts::FRAC_PI_2;
use std::sync::OnceLock;

fn renderer() -> &'static Renderer {
    static RENDERER: OnceLock<Renderer> = OnceLock::new();
    RENDERER.get_or_init(|| Renderer::new(RendererConfig::default()).expect("a render adapter"))
}

fn ids(actor: u32, link: u32) -> SegmentationIds {
    SegmentationIds { actor, link }
}

/// A ground plane (actor 1) and two boxes (actors 2 and 3, links 20 and 30).
struct BoxScene {
    scene: Scene,
    box_a: InstanceId,
    half_extents_a: [f32; 3],
}

fn box_scene() -> BoxScene {
    let r = renderer();
    let ground = r.add_mesh(&MeshData::plane(2.0, 2.0)).unwrap();
    let half_extents_a = [0.05, 0.08, 0.03];
    let box_a = r.add_mesh(&MeshData::cuboid(half_extents_a)).unwrap();
    let unit_box = r.add_mesh(&MeshData::cuboid([0.5, 0.5, 0.5])).unwrap();
    let mut scene = Scene::new();
    scene.add_instance(Instance::new(
        ground,
        Material::color(0.5, 0.5, 0.5),
        Isometry3::identity(),
        ids(1, 1),
    ));
    let box_a_id = scene.add_instance(Instance::new(
        box_a,
        Material::color(0.8, 0.1, 0.1),
        Isometry3::from_parts(
            Vector3::new(0.0, 0.05, 0.03).into(),
            UnitQuaternion::from_euler_angles(0.0, 0.0, 0.4),
        ),
        ids(2, 20),
    ));
    // The second box reuses a unit cube mesh scaled to 6 cm.
    scene.add_instance(
        Instance::new(
            unit_box,
            Material::color(0.1, 0.1, 0.8),
            Isometry3::translation(-0.15, -0.15, 0.03),
            ids(3, 30),
        )
        .with_scale(Vector3::new(0.06, 0.06, 0.06)),
    );
    BoxScene {
        scene,
        box_a: box_a_id,
        half_extents_a,
    }
}

fn base_camera(size: u32) -> Camera {
    Camera::new(size, size, FRAC_PI_2, 0.01, 10.0).looking_at(
        Point3::new(0.3, 0.0, 0.6),
        Point3::new(-0.1, 0.0, 0.1),
        Vector3::z(),
    )
}

fn side_camera(size: u32) -> Camera {
    Camera::new(size, size, 1.0, 0.01, 10.0).looking_at(
        Point3::new(-0.2, 0.45, 0.25),
        Point3::new(0.0, 0.0, 0.03),
        Vector3::z(),
    )
}

#[test]
fn depth_of_a_plane_at_known_distance() {
    let r = renderer();
    let plane = r.add_mesh(&MeshData::plane(2.0, 2.0)).unwrap();
    let mut scene = Scene::new();
    // The camera looks along world −z from the origin; the plane faces it 0.7 m away.
    scene.add_instance(Instance::new(
        plane,
        Material::color(1.0, 1.0, 1.0),
        Isometry3::translation(0.0, 0.0, -0.7),
        ids(1, 1),
    ));
    let camera = Camera::new(64, 48, 1.0, 0.01, 10.0);
    let out = &r.render(&[(&scene, &[camera][..])]).unwrap()[0];
    assert_eq!(out.depth_m.len(), 64 * 48);
    let worst = out
        .depth_m
        .iter()
        .map(|d| (d - 0.7).abs())
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-3, "depth error up to {worst} m");
    // Beyond the far plane nothing is seen.
    let short = Camera { far: 0.5, ..camera };
    let out = &r.render(&[(&scene, &[short][..])]).unwrap()[0];
    assert!(out.depth_m.iter().all(|&d| d == 0.0));
    assert!(out.segmentation_actor.iter().all(|&id| id == 0));
}

#[test]
fn box_point_cloud_lies_on_its_surface() {
    let BoxScene {
        scene,
        box_a,
        half_extents_a,
    } = box_scene();
    let pose = scene.instances()[box_a.0 as usize].pose_world_from_mesh;
    let cameras = [base_camera(128), side_camera(128)];
    let outputs = renderer().render(&[(&scene, &cameras[..])]).unwrap();
    for out in &outputs {
        let cloud = out.point_cloud_world();
        let mut hits = 0;
        for (i, p) in cloud.iter().enumerate() {
            assert_eq!(p[3] == 1.0, out.is_valid(i));
            if out.segmentation_link[i] != 20 {
                continue;
            }
            hits += 1;
            let local = pose.inverse() * Point3::new(p[0], p[1], p[2]);
            // Distance to the box surface for points on or near it.
            let outside =
                Vector3::from_fn(|k, _| (local[k].abs() - half_extents_a[k]).max(0.0)).norm();
            let inside = (0..3)
                .map(|k| local[k].abs() - half_extents_a[k])
                .fold(f32::MIN, f32::max)
                .min(0.0);
            let distance = outside + inside.abs();
            assert!(
                distance < 2e-3,
                "pixel {i}: point {local:?} is {distance} m off the box surface"
            );
        }
        assert!(hits > 100, "the box covers only {hits} pixels");
    }
    // Fused over both cameras: every point keeps its pixel's colour and ids.
    let fused = FusedPointCloud::from_cameras(&outputs);
    assert_eq!(fused.len(), 2 * 128 * 128);
    let i = 128 * 128 + 77;
    assert_eq!(fused.xyzw[i], outputs[1].point_cloud_world()[77]);
    assert_eq!(fused.rgb[i][..], outputs[1].rgb[3 * 77..3 * 77 + 3]);
    assert_eq!(fused.segmentation_link[i], outputs[1].segmentation_link[77]);
}

#[test]
fn segmentation_ids_match_the_actors_hit() {
    let BoxScene { scene, .. } = box_scene();
    let camera = base_camera(128);
    let out = &renderer().render(&[(&scene, &[camera][..])]).unwrap()[0];
    let k = out.intrinsic_cv();
    let pixel_of = |world: Point3<f32>| {
        let p = out.extrinsic_cv() * world.to_homogeneous();
        let uv = k * p;
        let (u, v) = (
            (uv.x / uv.z).round() as usize,
            (uv.y / uv.z).round() as usize,
        );
        v * out.width() as usize + u
    };
    // Top-face centres of the boxes, and a ground point.
    let a = pixel_of(Point3::new(0.0, 0.05, 0.06));
    assert_eq!(
        (out.segmentation_actor[a], out.segmentation_link[a]),
        (2, 20)
    );
    let b = pixel_of(Point3::new(-0.15, -0.15, 0.06));
    assert_eq!(
        (out.segmentation_actor[b], out.segmentation_link[b]),
        (3, 30)
    );
    let g = pixel_of(Point3::new(0.1, -0.2, 0.0));
    assert_eq!(
        (out.segmentation_actor[g], out.segmentation_link[g]),
        (1, 1)
    );
    // The top row looks above the ground's far edge: background.
    assert_eq!(out.segmentation_actor[0], 0);
    assert!(!out.is_valid(0));
    // Every id present belongs to the scene.
    assert!(out
        .segmentation_link
        .iter()
        .all(|id| [0, 1, 20, 30].contains(id)));
    // Colours: the red box's top is red-dominant.
    let red = &out.rgb[3 * a..3 * a + 3];
    assert!(
        red[0] > 2 * red[1] && red[0] > 2 * red[2],
        "box pixel colour {red:?}"
    );
}

#[test]
fn same_scene_renders_identically_and_batches_match_single_renders() {
    let BoxScene {
        mut scene, box_a, ..
    } = box_scene();
    let r = renderer();
    let cameras = [base_camera(64), side_camera(48)];
    let first = r.render(&[(&scene, &cameras[..])]).unwrap();
    let second = r.render(&[(&scene, &cameras[..])]).unwrap();
    // Exact equality (no Debug dump of whole images on failure).
    assert!(
        first == second,
        "re-rendering the same scene changed the images"
    );

    // A moved copy of the scene, batched with the original through the asynchronous path.
    let original = scene.clone();
    scene
        .set_pose(box_a, Isometry3::translation(0.1, -0.1, 0.03))
        .unwrap();
    let pending = r
        .submit(&[(&original, &cameras[..]), (&scene, &cameras[..])])
        .unwrap();
    let batched = pending.wait().unwrap();
    assert_eq!(batched.len(), 4);
    let moved = r.render(&[(&scene, &cameras[..])]).unwrap();
    // Cameras sit at other places of the batch's atlas than when rendered alone, which may move
    // edges by rounding: compare with a small tolerance.
    for (batch, single) in batched.iter().zip(first.iter().chain(&moved)) {
        assert_nearly_equal(batch, single);
    }
    assert_ne!(moved[0].segmentation_link, first[0].segmentation_link);
}

/// Same camera; at most 0.5 % of pixels differ in segmentation; where both saw the same link,
/// depths agree within 0.1 mm; mean colour difference below one level.
fn assert_nearly_equal(a: &CameraOutput, b: &CameraOutput) {
    assert_eq!(a.camera, b.camera);
    let n = a.depth_m.len();
    let seg_mismatch = (0..n)
        .filter(|&i| a.segmentation_link[i] != b.segmentation_link[i])
        .count();
    assert!(
        seg_mismatch * 200 <= n,
        "{seg_mismatch} of {n} segmentation pixels differ"
    );
    let worst_depth = (0..n)
        .filter(|&i| a.segmentation_link[i] == b.segmentation_link[i])
        .map(|i| (a.depth_m[i] - b.depth_m[i]).abs())
        .fold(0.0f32, f32::max);
    assert!(worst_depth < 1e-4, "depths differ by up to {worst_depth} m");
    let colour: f64 = a
        .rgb
        .iter()
        .zip(&b.rgb)
        .map(|(x, y)| x.abs_diff(*y) as f64)
        .sum::<f64>()
        / a.rgb.len() as f64;
    assert!(colour < 1.0, "mean colour difference {colour}");
}

#[test]
fn textures_are_sampled_with_uvs_left_to_right() {
    let r = renderer();
    // 8×1 texture: left half red, right half blue.
    let texels: Vec<u8> = (0..8)
        .flat_map(|i| {
            if i < 4 {
                [255, 0, 0, 255]
            } else {
                [0, 0, 255, 255]
            }
        })
        .collect();
    let texture = r
        .add_texture(&TextureData {
            width: 8,
            height: 1,
            rgba8_srgb: texels,
        })
        .unwrap();
    let plane = r.add_mesh(&MeshData::plane(0.5, 0.5)).unwrap();
    let mut scene = Scene::new();
    scene.lighting = Lighting {
        ambient: [1.0; 3],
        directional: vec![],
        background: [0.0; 3],
        shadow: None,
    };
    scene.add_instance(Instance::new(
        plane,
        Material {
            base_color: [1.0; 4],
            texture: Some(texture),
        },
        Isometry3::translation(0.0, 0.0, -1.0),
        ids(1, 1),
    ));
    let out = &r
        .render(&[(&scene, &[Camera::new(32, 32, 0.5, 0.1, 10.0)][..])])
        .unwrap()[0];
    let px = |u: usize, v: usize| &out.rgb[3 * (v * 32 + u)..3 * (v * 32 + u) + 3];
    assert!(
        px(2, 16)[0] > 200 && px(2, 16)[2] < 50,
        "left {:?}",
        px(2, 16)
    );
    assert!(
        px(29, 16)[2] > 200 && px(29, 16)[0] < 50,
        "right {:?}",
        px(29, 16)
    );
}

#[test]
fn bad_input_gives_typed_errors() {
    let r = renderer();
    let mut scene = Scene::new();
    scene.add_instance(Instance::new(
        MeshHandle::from_raw(9999),
        Material::color(1.0, 1.0, 1.0),
        Isometry3::identity(),
        ids(1, 1),
    ));
    let camera = Camera::new(8, 8, 1.0, 0.1, 10.0);
    assert!(matches!(
        r.render(&[(&scene, &[camera][..])]),
        Err(RenderError::UnknownMesh(9999, _))
    ));
    let empty = Scene::new();
    let bad = Camera {
        near: -1.0,
        ..camera
    };
    assert!(matches!(
        r.render(&[(&empty, &[bad][..])]),
        Err(RenderError::InvalidCamera(_))
    ));
    assert!(r
        .add_texture(&TextureData {
            width: 2,
            height: 2,
            rgba8_srgb: vec![0; 3]
        })
        .is_err());
    assert!(matches!(
        BackendChoice::parse("metal"),
        Err(RenderError::UnknownBackend { .. })
    ));
    assert!(r.render(&[]).unwrap().is_empty());
}

/// Set this environment variable to rewrite the golden images instead of comparing with them.
const UPDATE_GOLDEN_ENV_VAR: &str = "MS2_RENDER_UPDATE_GOLDEN";

#[test]
fn golden_image_matches_within_rasterizer_tolerance() {
    let BoxScene { scene, .. } = box_scene();
    let out = &renderer()
        .render(&[(&scene, &[base_camera(64)][..])])
        .unwrap()[0];
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/box_scene_64.png");
    if std::env::var_os(UPDATE_GOLDEN_ENV_VAR).is_some() {
        out.save_rgb_png(&path).unwrap();
        eprintln!("rewrote {}", path.display());
        return;
    }
    let golden = image::open(&path)
        .unwrap_or_else(|e| {
            panic!(
                "{}: {e} (regenerate with {UPDATE_GOLDEN_ENV_VAR}=1)",
                path.display()
            )
        })
        .to_rgb8();
    assert_eq!((golden.width(), golden.height()), (64, 64));
    let diffs: Vec<u8> = golden
        .as_raw()
        .iter()
        .zip(&out.rgb)
        .map(|(a, b)| a.abs_diff(*b))
        .collect();
    let mean = diffs.iter().map(|&d| d as f64).sum::<f64>() / diffs.len() as f64;
    let large = diffs.iter().filter(|&&d| d > 24).count() as f64 / diffs.len() as f64;
    // Small differences between rasterizers (edge pixels, rounding) are allowed; a wrong
    // camera, colour or lighting changes far more than this.
    assert!(
        mean < 2.0 && large < 0.02,
        "mean channel difference {mean}, {large} of channels differ by more than 24"
    );
}

#[test]
fn environments_in_threads_share_one_renderer() {
    let BoxScene { scene, .. } = box_scene();
    let camera = base_camera(32);
    let alone = renderer().render(&[(&scene, &[camera][..])]).unwrap();
    let results: Vec<Vec<CameraOutput>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..3)
            .map(|_| {
                let (shared, scene) = (renderer().clone(), scene.clone());
                s.spawn(move || {
                    let mut last = Vec::new();
                    for _ in 0..3 {
                        last = shared.render(&[(&scene, &[camera][..])]).unwrap();
                    }
                    last
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for r in &results {
        assert!(r == &alone, "a render from another thread differs");
    }
}

#[test]
fn directional_light_casts_shadows_when_enabled() {
    let r = renderer();
    let ground = r.add_mesh(&MeshData::plane(1.0, 1.0)).unwrap();
    let plate = r.add_mesh(&MeshData::cuboid([0.1, 0.1, 0.005])).unwrap();
    let mut scene = Scene::new();
    scene.lighting = Lighting {
        ambient: [0.2; 3],
        directional: vec![DirectionalLight {
            direction_world: Vector3::new(0.0, 0.0, -1.0),
            color: [0.8; 3],
        }],
        background: [0.0; 3],
        shadow: None,
    };
    let white = Material::color(1.0, 1.0, 1.0);
    scene.add_instance(Instance::new(
        ground,
        white,
        Isometry3::identity(),
        ids(1, 1),
    ));
    // A plate floating 0.3 m above the ground at x = −0.2.
    scene.add_instance(Instance::new(
        plate,
        white,
        Isometry3::translation(-0.2, 0.0, 0.3),
        ids(2, 2),
    ));
    // Looking at the ground from the side, below the plate's height.
    let camera = Camera::new(96, 96, 1.2, 0.01, 10.0).looking_at(
        Point3::new(0.6, 0.0, 0.25),
        Point3::new(-0.1, 0.0, 0.0),
        Vector3::z(),
    );
    let brightness = |out: &CameraOutput, world: Point3<f32>| {
        let uv = out.intrinsic_cv() * (out.extrinsic_cv() * world.to_homogeneous());
        let i = (uv.y / uv.z).round() as usize * 96 + (uv.x / uv.z).round() as usize;
        assert_eq!(out.segmentation_link[i], 1, "expected ground at {world:?}");
        out.rgb[3 * i] as i32
    };
    let under = Point3::new(-0.2, 0.0, 0.0);
    let beside = Point3::new(0.1, 0.0, 0.0);
    let lit = &r.render(&[(&scene, &[camera][..])]).unwrap()[0];
    assert!((brightness(lit, under) - brightness(lit, beside)).abs() <= 2);
    scene.lighting.shadow = Some(Shadow {
        center_world: Vector3::zeros(),
        radius_m: 0.6,
        resolution: 256,
    });
    let shadowed = &r.render(&[(&scene, &[camera][..])]).unwrap()[0];
    let (dark, bright) = (brightness(shadowed, under), brightness(shadowed, beside));
    assert!(
        dark + 60 < bright,
        "shadowed ground {dark}, lit ground {bright}"
    );
    assert!(
        (bright - brightness(lit, beside)).abs() <= 2,
        "no self-shadowing on lit ground"
    );
    // Bad shadow settings are rejected.
    scene.lighting.shadow = Some(Shadow {
        center_world: Vector3::zeros(),
        radius_m: -1.0,
        resolution: 256,
    });
    assert!(matches!(
        r.render(&[(&scene, &[camera][..])]),
        Err(RenderError::InvalidScene(_))
    ));
}
