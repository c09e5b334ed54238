//! The CPU ray-cast sensor path against the wgpu rasterizer on the same scenes: depth within
//! 1 mm and equal segmentation away from silhouette edges, colours close.

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

/// A tabletop: ground, a rotated box, a scaled unit box, a fine sphere, a non-uniformly
/// scaled capsule, a rod through the sphere in the sphere's frame, a textured quad and a small
/// particle slab.
fn table_scene() -> Scene {
    let r = renderer();
    let ground = r.add_mesh(&MeshData::plane(3.0, 3.0)).unwrap();
    let cube = r.add_mesh(&MeshData::cuboid([0.05, 0.08, 0.03])).unwrap();
    let unit_box = r.add_mesh(&MeshData::cuboid([0.5, 0.5, 0.5])).unwrap();
    let sphere = r.add_mesh(&MeshData::icosphere(0.06, 4)).unwrap();
    let capsule = r.add_mesh(&MeshData::capsule(0.03, 0.06, 24, 8)).unwrap();
    let rod = r.add_mesh(&MeshData::cylinder(0.015, 0.11, 16)).unwrap();
    let quad = r.add_mesh(&MeshData::cuboid([0.06, 0.06, 0.005])).unwrap();
    let texture = r
        .add_texture(&TextureData {
            width: 2,
            height: 2,
            rgba8_srgb: vec![
                255, 0, 0, 255, 0, 255, 0, 255, //
                0, 0, 255, 255, 255, 255, 255, 255,
            ],
        })
        .unwrap();
    let mut scene = Scene::new();
    scene.add_instance(Instance::new(
        cube,
        Material::color(0.8, 0.1, 0.1),
        Isometry3::from_parts(
            Vector3::new(0.0, 0.05, 0.03).into(),
            UnitQuaternion::from_euler_angles(0.0, 0.0, 0.4),
        ),
        ids(2, 20),
    ));
    scene.add_instance(
        Instance::new(
            unit_box,
            Material::color(0.1, 0.1, 0.8),
            Isometry3::translation(-0.15, -0.15, 0.03),
            ids(3, 30),
        )
        .with_scale(Vector3::new(0.06, 0.06, 0.06)),
    );
    let sphere_pose = Isometry3::from_parts(
        Vector3::new(-0.2, 0.15, 0.06).into(),
        UnitQuaternion::from_euler_angles(0.0, 1.5, 0.3),
    );
    scene.add_instance(Instance::new(
        sphere,
        Material::color(0.2, 0.7, 0.2),
        sphere_pose,
        ids(4, 40),
    ));
    // A rod through the sphere in the same frame (as two material parts of one robot link):
    // the ray caster merges them into one mesh, keeping each part's colour and ids.
    scene.add_instance(Instance::new(
        rod,
        Material::color(0.9, 0.8, 0.1),
        sphere_pose,
        ids(8, 80),
    ));
    scene.add_instance(
        Instance::new(
            capsule,
            Material::color(0.9, 0.9, 0.9),
            Isometry3::from_parts(
                Vector3::new(0.05, -0.2, 0.15).into(),
                UnitQuaternion::from_euler_angles(0.5, 0.3, 0.0),
            ),
            ids(5, 50),
        )
        .with_scale(Vector3::new(1.5, 1.0, 1.0)),
    );
    let mut textured = Material::color(1.0, 1.0, 1.0);
    textured.texture = Some(texture);
    scene.add_instance(Instance::new(
        quad,
        textured,
        Isometry3::translation(-0.3, -0.05, 0.005),
        ids(6, 60),
    ));
    let mut slab = ParticleSet::new(Material::color(0.6, 0.4, 0.2), 0.006, ids(7, 70));
    for i in 0..8 {
        for j in 0..8 {
            slab.positions_world
                .push([0.15 + 0.01 * i as f32, 0.1 + 0.01 * j as f32, 0.006]);
        }
    }
    scene.add_particle_set(slab);
    scene.add_instance(Instance::new(
        ground,
        Material::color(0.5, 0.5, 0.5),
        Isometry3::identity(),
        ids(1, 1),
    ));
    scene
}

fn cameras() -> Vec<Camera> {
    vec![
        Camera::new(128, 128, FRAC_PI_2, 0.01, 10.0).looking_at(
            Point3::new(0.3, 0.0, 0.6),
            Point3::new(-0.1, 0.0, 0.1),
            Vector3::z(),
        ),
        Camera::new(96, 64, 1.0, 0.01, 10.0).looking_at(
            Point3::new(-0.2, 0.55, 0.3),
            Point3::new(0.0, 0.0, 0.03),
            Vector3::z(),
        ),
        // Close enough that the near plane cuts the sphere.
        Camera::new(64, 64, 1.2, 0.05, 10.0).looking_at(
            Point3::new(-0.2, 0.15, 0.16),
            Point3::new(-0.2, 0.15, 0.0),
            Vector3::y(),
        ),
    ]
}

/// Pixels whose 3×3 neighbourhood holds one link id in both images (not on an edge).
fn interior(a: &CameraOutput, b: &CameraOutput, x: usize, y: usize) -> bool {
    let (w, h) = (a.width() as usize, a.height() as usize);
    if x == 0 || y == 0 || x + 1 >= w || y + 1 >= h {
        return false;
    }
    let id = a.segmentation_link[y * w + x];
    (y - 1..=y + 1).all(|yy| {
        (x - 1..=x + 1).all(|xx| {
            a.segmentation_link[yy * w + xx] == id && b.segmentation_link[yy * w + xx] == id
        })
    })
}

#[test]
fn raycast_agrees_with_the_rasterizer() {
    let r = renderer();
    let scene = table_scene();
    let cams = cameras();
    let raster = r.render(&[(&scene, &cams[..])]).unwrap();
    let rays = r.render_raycast(&[(&scene, &cams[..])]).unwrap();
    assert_eq!(raster.len(), rays.len());
    for (k, (a, b)) in raster.iter().zip(&rays).enumerate() {
        let (w, h) = (a.width() as usize, a.height() as usize);
        assert_eq!((b.width(), b.height()), (a.width(), a.height()));
        let mut compared = 0;
        let mut ids_seen = std::collections::BTreeSet::new();
        let mut edge_mismatch = 0;
        let mut colour_error = 0.0f64;
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                if !interior(a, b, x, y) {
                    if a.segmentation_link[i] != b.segmentation_link[i] {
                        edge_mismatch += 1;
                    }
                    continue;
                }
                compared += 1;
                ids_seen.insert(a.segmentation_link[i]);
                assert_eq!(
                    a.segmentation_actor[i], b.segmentation_actor[i],
                    "camera {k} ({x}, {y})"
                );
                let (da, db) = (a.depth_m[i], b.depth_m[i]);
                assert_eq!(da > 0.0, db > 0.0, "camera {k} ({x}, {y}): {da} vs {db}");
                assert!(
                    (da - db).abs() < 1e-3,
                    "camera {k} ({x}, {y}): depth {da} vs {db}"
                );
                for c in 0..3 {
                    colour_error += (a.rgb[3 * i + c] as f64 - b.rgb[3 * i + c] as f64).abs();
                }
            }
        }
        // Most pixels are away from edges, and the few edge pixels may differ.
        assert!(
            compared > w * h * 3 / 4,
            "camera {k}: only {compared} interior pixels"
        );
        assert!(
            edge_mismatch < w * h / 20,
            "camera {k}: {edge_mismatch} edge pixels differ"
        );
        assert!(ids_seen.len() >= 2, "camera {k} sees {ids_seen:?}");
        // Same lighting: mean colour difference of a few levels out of 255 (interpolation of
        // normals and texture coordinates differs slightly between the paths).
        let mean = colour_error / (3 * compared) as f64;
        assert!(mean < 3.0, "camera {k}: mean colour difference {mean}");
    }
    // The base camera sees every object of the scene.
    let seen: std::collections::BTreeSet<u32> = rays[0].segmentation_link.iter().copied().collect();
    for id in [1, 20, 30, 40, 50, 60, 70, 80] {
        assert!(seen.contains(&id), "object {id} missing from {seen:?}");
    }
}

#[test]
fn raycast_shadows_and_background_match_the_rasterizer() {
    let r = renderer();
    let mut scene = table_scene();
    scene.lighting.shadow = Some(Shadow::default());
    scene.lighting.background = [0.2, 0.3, 0.4];
    // Looking up past the horizon: background pixels.
    let cam = Camera::new(64, 64, 1.2, 0.01, 10.0).looking_at(
        Point3::new(0.6, 0.0, 0.3),
        Point3::new(-0.4, 0.0, 0.2),
        Vector3::z(),
    );
    let a = &r.render(&[(&scene, &[cam][..])]).unwrap()[0];
    let b = &r.render_raycast(&[(&scene, &[cam][..])]).unwrap()[0];
    let background = (0..a.depth_m.len())
        .filter(|&i| b.depth_m[i] == 0.0)
        .count();
    assert!(background > 200, "{background} background pixels");
    for i in 0..a.depth_m.len() {
        if b.depth_m[i] == 0.0 && a.depth_m[i] == 0.0 {
            assert_eq!(&a.rgb[3 * i..3 * i + 3], &b.rgb[3 * i..3 * i + 3]);
            assert_eq!(b.segmentation_link[i], 0);
        }
    }
    // Shadowed ground is darker than lit ground in both paths by about the same amount.
    let ground_levels = |out: &CameraOutput| {
        let mut levels: Vec<u8> = (0..out.depth_m.len())
            .filter(|&i| out.segmentation_link[i] == 1)
            .map(|i| out.rgb[3 * i])
            .collect();
        levels.sort_unstable();
        (levels[levels.len() / 50], levels[levels.len() / 2])
    };
    let (dark_a, lit_a) = ground_levels(a);
    let (dark_b, lit_b) = ground_levels(b);
    assert!(
        dark_b + 20 < lit_b,
        "ray cast: shadow {dark_b}, lit {lit_b}"
    );
    assert!(
        (dark_a as i32 - dark_b as i32).abs() < 10,
        "{dark_a} vs {dark_b}"
    );
    assert!(
        (lit_a as i32 - lit_b as i32).abs() < 4,
        "{lit_a} vs {lit_b}"
    );
}

#[test]
fn sensor_backend_follows_the_configuration() {
    let cpu = Renderer::new(RendererConfig {
        sensor_backend: SensorBackend::Raycast,
        ..Default::default()
    })
    .unwrap();
    assert_eq!(cpu.sensor_backend(), SensorBackend::Raycast);
    let mesh = cpu.add_mesh(&MeshData::cuboid([0.1, 0.1, 0.1])).unwrap();
    let mut scene = Scene::new();
    scene.add_instance(Instance::new(
        mesh,
        Material::color(1.0, 0.0, 0.0),
        Isometry3::identity(),
        ids(1, 2),
    ));
    let cam = Camera::new(16, 16, 1.0, 0.01, 10.0).looking_at(
        Point3::new(0.0, 0.0, 1.0),
        Point3::origin(),
        Vector3::y(),
    );
    let out = cpu.render_sensors(&[(&scene, &[cam][..])]).unwrap();
    assert_eq!(out.len(), 1);
    // The box's top face is 0.9 m from the camera.
    assert!((out[0].depth_m[8 * 16 + 8] - 0.9).abs() < 1e-5);
    assert_eq!(out[0].segmentation_link[8 * 16 + 8], 2);
    let raster = Renderer::new(RendererConfig {
        sensor_backend: SensorBackend::Raster,
        ..Default::default()
    })
    .unwrap();
    assert_eq!(raster.sensor_backend(), SensorBackend::Raster);
    // Unknown meshes and bad cameras are typed errors on the ray-cast path too.
    let mut bad = Scene::new();
    bad.add_instance(Instance::new(
        MeshHandle::from_raw(999),
        Material::color(1.0, 0.0, 0.0),
        Isometry3::identity(),
        ids(1, 1),
    ));
    assert!(matches!(
        cpu.render_raycast(&[(&bad, &[cam][..])]),
        Err(RenderError::UnknownMesh(999, _))
    ));
    let mut wide = cam;
    wide.fov_y = 4.0;
    assert!(matches!(
        cpu.render_raycast(&[(&scene, &[wide][..])]),
        Err(RenderError::InvalidCamera(_))
    ));
}
