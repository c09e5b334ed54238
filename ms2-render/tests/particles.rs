//! Particle sets: one instanced draw of exact spheres (soft bodies' particles).

use ms2_render::*;
use nalgebra::{Isometry3, Point3, Vector3};
use std::sync::OnceLock;

fn renderer() -> &'static Renderer {
    static RENDERER: OnceLock<Renderer> = OnceLock::new();
    RENDERER.get_or_init(|| Renderer::new(RendererConfig::default()).expect("a render adapter"))
}

const CLAY: SegmentationIds = SegmentationIds { actor: 7, link: 5 };
const RADIUS: f32 = 0.004;
const SPACING: f32 = 0.005;

/// A fine sphere mesh of radius 1 (for comparing with per-particle instances).
fn sphere_mesh() -> MeshHandle {
    static MESH: OnceLock<MeshHandle> = OnceLock::new();
    *MESH.get_or_init(|| renderer().add_mesh(&MeshData::icosphere(1.0, 3)).unwrap())
}

/// A slab of particles on a lattice: x, y ∈ [−w, w], z from `SPACING / 2` up to `top`.
fn slab(half_width: f32, top: f32) -> Vec<[f32; 3]> {
    let n = (2.0 * half_width / SPACING).round() as i32;
    let layers = (top / SPACING).round() as i32;
    let mut out = Vec::new();
    for k in 0..layers {
        for j in 0..=n {
            for i in 0..=n {
                out.push([
                    -half_width + i as f32 * SPACING,
                    -half_width + j as f32 * SPACING,
                    SPACING / 2.0 + k as f32 * SPACING,
                ]);
            }
        }
    }
    out
}

/// A ground plane (ids 1, 1) and an empty particle set (ids [`CLAY`]).
fn scene_with_particles() -> (Scene, ParticleSetId) {
    let r = renderer();
    let ground = r.add_mesh(&MeshData::plane(1.0, 1.0)).unwrap();
    let mut scene = Scene::new();
    scene.add_instance(Instance::new(
        ground,
        Material::color(0.5, 0.5, 0.5),
        Isometry3::identity(),
        SegmentationIds { actor: 1, link: 1 },
    ));
    let id = scene.add_particle_set(ParticleSet::new(
        Material::color(0.6, 0.4, 0.2),
        RADIUS,
        CLAY,
    ));
    (scene, id)
}

/// Looks straight down from `height` m above the origin.
fn top_camera(size: u32, height: f32) -> Camera {
    Camera::new(size, size, 0.6, 0.01, 10.0).looking_at(
        Point3::new(0.0, 0.0, height),
        Point3::origin(),
        Vector3::y(),
    )
}

fn oblique_camera(size: u32) -> Camera {
    Camera::new(size, size, 1.0, 0.01, 10.0).looking_at(
        Point3::new(0.25, -0.2, 0.2),
        Point3::new(0.0, 0.0, 0.01),
        Vector3::z(),
    )
}

fn clay_pixels(out: &CameraOutput) -> usize {
    out.segmentation_link
        .iter()
        .zip(&out.segmentation_actor)
        .filter(|&(&link, &actor)| link == CLAY.link && actor == CLAY.actor)
        .count()
}

#[test]
fn particles_are_seen_at_their_depth_with_their_ids() {
    let (mut scene, clay) = scene_with_particles();
    let top = 0.02;
    let positions = slab(0.04, top);
    scene
        .set_particle_positions(clay, positions.iter().copied())
        .unwrap();
    let height = 0.3;
    let camera = top_camera(96, height);
    let out = &renderer().render(&[(&scene, &[camera][..])]).unwrap()[0];
    // The slab's highest particle centres are at top − spacing / 2; their spheres reach r above.
    let highest = positions.iter().map(|p| p[2]).fold(f32::MIN, f32::max);
    let surface_depth = height - (highest + RADIUS);
    let cloud = out.point_cloud_world();
    let mut inside = 0;
    for (k, p) in cloud.iter().enumerate() {
        // Pixels well inside the slab's footprint see clay, nearly at the top of its spheres.
        if p[0].abs() < 0.035 && p[1].abs() < 0.035 && out.depth_m[k] > 0.0 {
            inside += 1;
            assert_eq!(out.segmentation_link[k], CLAY.link, "pixel {k} at {p:?}");
            assert_eq!(out.segmentation_actor[k], CLAY.actor, "pixel {k} at {p:?}");
            let d = out.depth_m[k];
            assert!(
                (surface_depth - 0.001..=surface_depth + RADIUS).contains(&d),
                "pixel {k}: depth {d} m, slab surface at {surface_depth} m"
            );
        }
        // Outside the footprint (with a radius of margin) only the ground is seen.
        if (p[0].abs() > 0.04 + RADIUS + 0.002 || p[1].abs() > 0.04 + RADIUS + 0.002)
            && out.depth_m[k] > 0.0
        {
            assert_eq!(out.segmentation_link[k], 1, "pixel {k} at {p:?}");
        }
    }
    assert!(inside > 500, "only {inside} pixels inside the footprint");
    // The clay's colour (brown: red above blue) where it is seen.
    let k = out
        .segmentation_link
        .iter()
        .position(|&l| l == CLAY.link)
        .unwrap();
    assert!(
        out.rgb[3 * k] > out.rgb[3 * k + 2] + 20,
        "{:?}",
        &out.rgb[3 * k..3 * k + 3]
    );
}

/// The particles' spheres are exact: they look like fine sphere meshes (1,280 triangles each)
/// drawn one instance per particle.
#[test]
fn particle_set_draws_like_one_sphere_mesh_per_particle() {
    let (mut scene, clay) = scene_with_particles();
    let positions = slab(0.03, 0.015);
    scene
        .set_particle_positions(clay, positions.iter().copied())
        .unwrap();
    let (mut instanced, _) = scene_with_particles();
    for p in &positions {
        instanced.add_instance(
            Instance::new(
                sphere_mesh(),
                Material::color(0.6, 0.4, 0.2),
                Isometry3::translation(p[0], p[1], p[2]),
                CLAY,
            )
            .with_scale(Vector3::repeat(RADIUS)),
        );
    }
    let cameras = [oblique_camera(64), top_camera(48, 0.25)];
    let r = renderer();
    let a = r.render(&[(&scene, &cameras[..])]).unwrap();
    let b = r.render(&[(&instanced, &cameras[..])]).unwrap();
    for (x, y) in a.iter().zip(&b) {
        let (clay_x, clay_y) = (clay_pixels(x), clay_pixels(y));
        assert!(clay_x > 50, "{clay_x} clay pixels");
        assert!(
            clay_x.abs_diff(clay_y) * 50 <= clay_x,
            "{clay_x} vs {clay_y} clay pixels"
        );
        let n = x.depth_m.len();
        let differ = (0..n)
            .filter(|&i| x.segmentation_link[i] != y.segmentation_link[i])
            .count();
        assert!(
            differ * 50 <= clay_x,
            "{differ} of {clay_x} clay pixels differ"
        );
        let worst = (0..n)
            .filter(|&i| x.segmentation_link[i] == CLAY.link && y.segmentation_link[i] == CLAY.link)
            .map(|i| (x.depth_m[i] - y.depth_m[i]).abs())
            .fold(0.0f32, f32::max);
        // The mesh's facets lie up to 0.3 % of the radius inside the sphere.
        assert!(worst < 0.1 * RADIUS, "depths differ by up to {worst} m");
    }
    assert_eq!(
        scene.triangle_count(r),
        positions.len() * 2 + 2,
        "2 triangles per particle plus the ground's two"
    );
}

#[test]
fn particle_count_may_change_between_frames() {
    let (mut scene, clay) = scene_with_particles();
    let camera = oblique_camera(64);
    let r = renderer();
    let mut seen = Vec::new();
    for half_width in [0.01, 0.04, 0.0, 0.02] {
        let positions = if half_width > 0.0 {
            slab(half_width, 0.01)
        } else {
            Vec::new()
        };
        scene.set_particle_positions(clay, positions).unwrap();
        let out = &r.render(&[(&scene, &[camera][..])]).unwrap()[0];
        seen.push(clay_pixels(out));
    }
    assert!(seen[0] > 0 && seen[1] > 4 * seen[0], "{seen:?}");
    assert_eq!(seen[2], 0, "an empty set draws nothing");
    assert!(seen[3] > seen[0] && seen[3] < seen[1], "{seen:?}");
    // A hidden set draws nothing either.
    scene.particle_set_mut(clay).unwrap().visible = false;
    let out = &r.render(&[(&scene, &[camera][..])]).unwrap()[0];
    assert_eq!(clay_pixels(out), 0);
}

#[test]
fn bad_particles_give_typed_errors() {
    let (mut scene, clay) = scene_with_particles();
    let camera = oblique_camera(8);
    let r = renderer();
    scene
        .set_particle_positions(clay, [[0.0, 0.0, 0.01], [f32::NAN, 0.0, 0.0]])
        .unwrap();
    let err = r.render(&[(&scene, &[camera][..])]).unwrap_err();
    assert!(
        matches!(&err, RenderError::InvalidScene(m) if m.contains("particle 1")),
        "{err}"
    );
    scene
        .set_particle_positions(clay, [[0.0, 0.0, 0.01]])
        .unwrap();
    scene.particle_set_mut(clay).unwrap().radius_m = 0.0;
    assert!(matches!(
        r.render(&[(&scene, &[camera][..])]),
        Err(RenderError::InvalidScene(_))
    ));
    assert!(scene
        .set_particle_positions(ParticleSetId(3), [[0.0; 3]])
        .is_err());
    let mut textured = Scene::new();
    let texture = r
        .add_texture(&TextureData {
            width: 1,
            height: 1,
            rgba8_srgb: vec![255; 4],
        })
        .unwrap();
    let mut set = ParticleSet::new(
        Material {
            base_color: [1.0; 4],
            texture: Some(texture),
        },
        0.01,
        CLAY,
    );
    set.positions_world.push([0.0; 3]);
    textured.add_particle_set(set);
    let err = r.render(&[(&textured, &[camera][..])]).unwrap_err();
    assert!(
        matches!(&err, RenderError::InvalidScene(m) if m.contains("untextured")),
        "{err}"
    );
}

/// With shadows on, a floating slab of particles shades the ground under it (the particle
/// shadow pass draws disks facing the light), and its spheres are lit from above.
#[test]
fn particles_cast_shadows_when_enabled() {
    let (mut scene, clay) = scene_with_particles();
    scene.lighting = Lighting {
        ambient: [0.2; 3],
        directional: vec![DirectionalLight {
            direction_world: Vector3::new(0.0, 0.0, -1.0),
            color: [0.8; 3],
        }],
        background: [0.0; 3],
        shadow: None,
    };
    // A 6 × 6 cm slab, one particle thick, 0.2 m above the ground at x = −0.1.
    let slab: Vec<[f32; 3]> = slab(0.03, SPACING)
        .into_iter()
        .map(|p| [p[0] - 0.1, p[1], 0.2])
        .collect();
    scene.set_particle_positions(clay, slab).unwrap();
    let camera = Camera::new(96, 96, 1.2, 0.01, 10.0).looking_at(
        Point3::new(0.4, 0.0, 0.15),
        Point3::new(-0.05, 0.0, 0.0),
        Vector3::z(),
    );
    let r = renderer();
    let ground_brightness = |out: &CameraOutput, world: Point3<f32>| {
        let uv = out.intrinsic_cv() * (out.extrinsic_cv() * world.to_homogeneous());
        let i = (uv.y / uv.z).round() as usize * 96 + (uv.x / uv.z).round() as usize;
        assert_eq!(out.segmentation_link[i], 1, "expected ground at {world:?}");
        out.rgb[3 * i] as i32
    };
    let (under, beside) = (Point3::new(-0.1, 0.0, 0.0), Point3::new(0.1, 0.0, 0.0));
    let lit = &r.render(&[(&scene, &[camera][..])]).unwrap()[0];
    assert!((ground_brightness(lit, under) - ground_brightness(lit, beside)).abs() <= 2);
    scene.lighting.shadow = Some(Shadow {
        center_world: Vector3::zeros(),
        radius_m: 0.5,
        resolution: 256,
    });
    let shadowed = &r.render(&[(&scene, &[camera][..])]).unwrap()[0];
    let (dark, bright) = (
        ground_brightness(shadowed, under),
        ground_brightness(shadowed, beside),
    );
    assert!(
        dark + 40 < bright,
        "under the slab {dark}, beside it {bright}"
    );
    assert!(clay_pixels(shadowed) > 20, "the slab is seen");
}
