//! Renders a small tabletop scene from ManiSkill2's `base_camera` viewpoint and writes
//! `rgb.png`, `depth.png` and `segmentation.png` into the directory given as the first argument
//! (default: the current directory).
//!
//! `cargo run --release -p ms2-render --example render_demo -- /tmp/ms2-render-demo`

use ms2_render::*;
use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};
use std::path::PathBuf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out_dir = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| ".".into()));
    std::fs::create_dir_all(&out_dir)?;
    let renderer = Renderer::new(RendererConfig::default())?;
    println!("adapter: {:?}", renderer.adapter());

    let ground = renderer.add_mesh(&MeshData::plane(1.0, 1.0))?;
    let cube = renderer.add_mesh(&MeshData::cuboid([0.02, 0.02, 0.02]))?;
    let sphere = renderer.add_mesh(&MeshData::sphere(0.04, 32, 16))?;
    let capsule = renderer.add_mesh(&MeshData::capsule(0.02, 0.05, 24, 8))?;
    let cylinder = renderer.add_mesh(&MeshData::cylinder(0.03, 0.06, 24))?;
    let checker: Vec<u8> = (0..64 * 64)
        .flat_map(|i| {
            let (x, y) = (i % 64 / 8, i / 64 / 8);
            if (x + y) % 2 == 0 {
                [200, 200, 200, 255]
            } else {
                [90, 90, 90, 255]
            }
        })
        .collect();
    let checker = renderer.add_texture(&TextureData {
        width: 64,
        height: 64,
        rgba8_srgb: checker,
    })?;

    let mut scene = Scene::new();
    // The sun casts shadows over the 1 m around the origin.
    scene.lighting.shadow = Some(Shadow::default());
    let ids = |k| SegmentationIds { actor: k, link: k };
    scene.add_instance(Instance::new(
        ground,
        Material {
            base_color: [1.0, 1.0, 1.0, 1.0],
            texture: Some(checker),
        },
        Isometry3::identity(),
        ids(1),
    ));
    scene.add_instance(Instance::new(
        cube,
        Material::color(0.8, 0.1, 0.1),
        Isometry3::from_parts(
            Vector3::new(0.0, 0.0, 0.02).into(),
            UnitQuaternion::from_euler_angles(0.0, 0.0, 0.5),
        ),
        ids(2),
    ));
    scene.add_instance(Instance::new(
        sphere,
        Material::color(0.1, 0.6, 0.1),
        Isometry3::translation(-0.15, 0.12, 0.04),
        ids(3),
    ));
    scene.add_instance(Instance::new(
        capsule,
        Material::color(0.1, 0.2, 0.8),
        Isometry3::from_parts(
            Vector3::new(-0.1, -0.12, 0.02).into(),
            UnitQuaternion::from_euler_angles(std::f32::consts::FRAC_PI_2, 0.0, 0.3),
        ),
        ids(4),
    ));
    scene.add_instance(Instance::new(
        cylinder,
        Material::color(0.9, 0.7, 0.1),
        Isometry3::translation(-0.3, 0.0, 0.06),
        ids(5),
    ));
    let camera = Camera::new(256, 256, std::f32::consts::FRAC_PI_2, 0.01, 10.0).looking_at(
        Point3::new(0.3, 0.0, 0.6),
        Point3::new(-0.1, 0.0, 0.1),
        Vector3::z(),
    );
    let out = renderer.render(&[(&scene, &[camera][..])])?;
    let image = &out[0];
    image.save_rgb_png(&out_dir.join("rgb.png"))?;
    image.save_depth_png(&out_dir.join("depth.png"), 1.5)?;
    image.save_segmentation_png(&out_dir.join("segmentation.png"))?;
    println!(
        "{} triangles; wrote rgb.png, depth.png, segmentation.png to {}",
        scene.triangle_count(&renderer),
        out_dir.display()
    );
    Ok(())
}
