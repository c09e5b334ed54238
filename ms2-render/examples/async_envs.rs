//! The asynchronous rendering pattern for vectorised environments: 16 environments (scenes)
//! share one renderer; each step submits this step's images, advances "physics" (here: moving
//! the cubes, plus a busy-wait standing in for a physics step) while they render, then
//! collects them. Prints steps/s with and without the overlap.
//!
//! `cargo run --release -p ms2-render --example async_envs`

use ms2_render::*;
use nalgebra::{Isometry3, Point3, Vector3};
use std::time::{Duration, Instant};

const ENVS: usize = 16;
const STEPS: usize = 20;

/// Stand-in for one physics step of all environments: `cost` of CPU work, then cube moves.
fn step_physics(scenes: &mut [Scene], cube: InstanceId, t: usize, cost: Duration) {
    let start = Instant::now();
    while start.elapsed() < cost {
        std::hint::spin_loop();
    }
    for (k, scene) in scenes.iter_mut().enumerate() {
        let x = 0.1 * ((t + k) as f32 * 0.3).sin();
        scene
            .set_pose(cube, Isometry3::translation(x, 0.0, 0.02))
            .expect("cube id is valid");
    }
}

fn main() -> Result<(), RenderError> {
    let renderer = Renderer::new(RendererConfig::default())?;
    let ground = renderer.add_mesh(&MeshData::plane(1.0, 1.0))?;
    let cube_mesh = renderer.add_mesh(&MeshData::cuboid([0.02, 0.02, 0.02]))?;
    let mut template = Scene::new();
    template.add_instance(Instance::new(
        ground,
        Material::color(0.6, 0.6, 0.6),
        Isometry3::identity(),
        SegmentationIds { actor: 1, link: 1 },
    ));
    let cube = template.add_instance(Instance::new(
        cube_mesh,
        Material::color(0.8, 0.1, 0.1),
        Isometry3::translation(0.0, 0.0, 0.02),
        SegmentationIds { actor: 2, link: 2 },
    ));
    let camera = Camera::new(128, 128, std::f32::consts::FRAC_PI_2, 0.01, 10.0).looking_at(
        Point3::new(0.3, 0.0, 0.6),
        Point3::new(-0.1, 0.0, 0.1),
        Vector3::z(),
    );
    let cameras = [camera];
    let mut scenes = vec![template; ENVS];
    let physics_cost = Duration::from_millis(10);

    // Warm-up: the first batch of a shape allocates its pooled GPU objects.
    let views: Vec<(&Scene, &[Camera])> = scenes.iter().map(|s| (s, &cameras[..])).collect();
    renderer.render(&views)?;

    // Sequential: render, then step physics.
    let start = Instant::now();
    for t in 0..STEPS {
        let views: Vec<(&Scene, &[Camera])> = scenes.iter().map(|s| (s, &cameras[..])).collect();
        let images = renderer.render(&views)?;
        assert_eq!(images.len(), ENVS);
        step_physics(&mut scenes, cube, t, physics_cost);
    }
    let sequential = STEPS as f64 / start.elapsed().as_secs_f64();

    // Overlapped: submit, step physics while rendering, then collect.
    let start = Instant::now();
    for t in 0..STEPS {
        let views: Vec<(&Scene, &[Camera])> = scenes.iter().map(|s| (s, &cameras[..])).collect();
        let pending = renderer.submit(&views)?;
        // Scenes are plain CPU data: the submitted batch already holds its own copy of the poses.
        step_physics(&mut scenes, cube, t, physics_cost);
        let images = pending.wait()?;
        assert_eq!(images.len(), ENVS);
    }
    let overlapped = STEPS as f64 / start.elapsed().as_secs_f64();
    println!(
        "{ENVS} envs x 1 camera 128x128, {} ms physics per step: sequential {sequential:.1} \
         steps/s, overlapped {overlapped:.1} steps/s ({:.2}x)",
        physics_cost.as_millis(),
        overlapped / sequential
    );
    Ok(())
}
