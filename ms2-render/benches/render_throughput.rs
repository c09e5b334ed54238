//! Camera images per second at 128×128: one camera per submission versus 2 cameras × 16 scenes
//! batched in one submission, for a light (~2 k triangles) and a heavy (~70 k triangles) scene.
//! Also pipelined batches (submit the next batch before collecting the previous one), as an
//! environment does when it steps physics while the previous step's images render.
//! Then a soft-body scene: the light tabletop plus a clay bed of ~4,000 particles (Excavate-v0's
//! size), drawn as one particle set (one instanced draw of exact spheres, two triangles each)
//! versus one icosphere instance (one draw) per particle; per frame the particle set's positions
//! are re-set, as an env does after each step.
//!
//! `cargo bench -p ms2-render` (prints a table; set `MS2_RENDER_BACKEND=gl` for the GL backend,
//! `MS2_RENDER_BENCH_SECONDS` to change the time per measurement, default 3).

use ms2_render::*;
use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};
use std::time::{Duration, Instant};

/// A tabletop: ground, a cube and `spheres` spheres of `segments` × `segments / 2` quads
/// (a stand-in for robot link meshes).
fn tabletop(renderer: &Renderer, spheres: usize, segments: u32) -> Scene {
    let ground = renderer.add_mesh(&MeshData::plane(1.0, 1.0)).unwrap();
    let cube = renderer
        .add_mesh(&MeshData::cuboid([0.02, 0.02, 0.02]))
        .unwrap();
    let sphere = renderer
        .add_mesh(&MeshData::sphere(0.03, segments, segments / 2))
        .unwrap();
    let mut scene = Scene::new();
    let ids = |k| SegmentationIds { actor: k, link: k };
    scene.add_instance(Instance::new(
        ground,
        Material::color(0.6, 0.6, 0.6),
        Isometry3::identity(),
        ids(1),
    ));
    scene.add_instance(Instance::new(
        cube,
        Material::color(0.8, 0.1, 0.1),
        Isometry3::translation(0.0, 0.0, 0.02),
        ids(2),
    ));
    for k in 0..spheres {
        let angle = k as f32 * 0.7;
        scene.add_instance(Instance::new(
            sphere,
            Material::color(0.2, 0.3, 0.8),
            Isometry3::from_parts(
                Vector3::new(
                    -0.4 + 0.2 * angle.cos(),
                    0.2 * angle.sin(),
                    0.05 + 0.04 * k as f32,
                )
                .into(),
                UnitQuaternion::identity(),
            ),
            ids(3 + k as u32),
        ));
    }
    scene
}

fn cameras() -> [Camera; 2] {
    let camera = Camera::new(128, 128, std::f32::consts::FRAC_PI_2, 0.01, 10.0);
    [
        camera.looking_at(
            Point3::new(0.3, 0.0, 0.6),
            Point3::new(-0.1, 0.0, 0.1),
            Vector3::z(),
        ),
        camera.looking_at(
            Point3::new(-0.2, 0.5, 0.4),
            Point3::new(-0.1, 0.0, 0.1),
            Vector3::z(),
        ),
    ]
}

/// Runs `step` for about `budget`; returns (steps done, seconds taken).
fn run(budget: Duration, step: &mut dyn FnMut()) -> (usize, f64) {
    let start = Instant::now();
    let mut steps = 0;
    while start.elapsed() < budget || steps < 2 {
        step();
        steps += 1;
    }
    (steps, start.elapsed().as_secs_f64())
}

/// A benchmarked way of rendering: its label, images per step, and the step.
type Mode<'a> = (&'static str, usize, Box<dyn FnMut() + 'a>);

/// Measures all modes side by side: `rounds` rounds, each running every mode for `budget` in
/// turn, so that other load on the machine hits all modes alike; returns images/s per mode
/// over all its rounds.
fn measure_side_by_side(rounds: usize, budget: Duration, modes: &mut [Mode<'_>]) -> Vec<f64> {
    for (_, _, step) in modes.iter_mut() {
        step(); // warm-up: allocates pooled buffers
    }
    let mut totals = vec![(0usize, 0.0f64); modes.len()];
    for _ in 0..rounds {
        for (k, (_, images, step)) in modes.iter_mut().enumerate() {
            let (steps, seconds) = run(budget, step.as_mut());
            totals[k].0 += steps * *images;
            totals[k].1 += seconds;
        }
    }
    totals
        .iter()
        .map(|&(images, seconds)| images as f64 / seconds)
        .collect()
}

fn main() {
    // `cargo bench` passes `--bench`; nothing else is parsed.
    let seconds: f64 = std::env::var("MS2_RENDER_BENCH_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3.0);
    let rounds = 5;
    let budget = Duration::from_secs_f64(seconds / rounds as f64);
    let renderer = Renderer::new(RendererConfig::default()).expect("a render adapter");
    let a = renderer.adapter();
    println!(
        "adapter: {} ({}, {}), {}",
        a.name, a.backend, a.device_type, a.driver
    );
    println!("128x128 images; {rounds} interleaved rounds, {seconds} s per mode in all");
    println!(
        "{:<8} {:>10}  {:<46} {:>9} {:>7}",
        "scene", "triangles", "mode", "images/s", "ratio"
    );
    let [cam0, cam1] = cameras();
    let cams = [cam0, cam1];
    for (label, spheres, segments) in [("light", 8, 16), ("heavy", 12, 96)] {
        let template = tabletop(&renderer, spheres, segments);
        let triangles = template.triangle_count(&renderer);
        let scenes: Vec<Scene> = (0..16).map(|_| template.clone()).collect();
        let views: Vec<(&Scene, &[Camera])> = scenes.iter().map(|s| (s, &cams[..])).collect();
        let mut modes: Vec<Mode<'_>> = vec![
            (
                "1 camera per submission",
                1,
                Box::new(|| {
                    renderer.render(&[(&template, &[cam0][..])]).unwrap();
                }),
            ),
            (
                "2 cameras x 16 scenes, one submission",
                32,
                Box::new(|| {
                    renderer.render(&views).unwrap();
                }),
            ),
            (
                "same, 4 batches pipelined (submit k+1, wait k)",
                4 * 32,
                Box::new(|| {
                    let mut pending = renderer.submit(&views).unwrap();
                    for _ in 1..4 {
                        let next = renderer.submit(&views).unwrap();
                        pending.wait().unwrap();
                        pending = next;
                    }
                    pending.wait().unwrap();
                }),
            ),
            (
                "ray cast (CPU), 1 camera",
                1,
                Box::new(|| {
                    renderer
                        .render_raycast(&[(&template, &[cam0][..])])
                        .unwrap();
                }),
            ),
            (
                "ray cast (CPU), 2 cameras x 16 scenes",
                32,
                Box::new(|| {
                    renderer.render_raycast(&views).unwrap();
                }),
            ),
        ];
        let rates = measure_side_by_side(rounds, budget, &mut modes);
        for ((name, _, _), rate) in modes.iter().zip(&rates) {
            println!(
                "{label:<8} {triangles:>10}  {name:<46} {rate:>9.0} {:>7.2}",
                rate / rates[0]
            );
        }
    }
    particle_rows(&renderer, rounds, budget, &cams);
}

/// Particle centres of a 12 × 12 × 3.5 cm clay bed at 5 mm spacing (4,225 particles).
fn clay_bed() -> Vec<[f32; 3]> {
    let mut out = Vec::new();
    for k in 0..7 {
        for j in 0..25 {
            for i in 0..25 {
                let p = |n: i32| -0.06 + 0.005 * n as f32;
                out.push([p(i) - 0.1, p(j), 0.0025 + 0.005 * k as f32]);
            }
        }
    }
    out
}

/// The particle rows: the light tabletop plus [`clay_bed`], drawn as a particle set (exact
/// spheres, two triangles per particle) and as one icosphere instance per particle.
fn particle_rows(renderer: &Renderer, rounds: usize, budget: Duration, cams: &[Camera]) {
    let bed = clay_bed();
    let ids = SegmentationIds {
        actor: 99,
        link: 99,
    };
    let clay = Material::color(0.55, 0.35, 0.2);
    let radius = 0.00375;
    let mut set_scene = tabletop(renderer, 8, 16);
    let set = set_scene.add_particle_set(ParticleSet::new(clay, radius, ids));
    set_scene
        .set_particle_positions(set, bed.iter().copied())
        .unwrap();
    let mut scenes = vec![(
        "particle set (2 tri/particle)".to_owned(),
        set_scene,
        Some(set),
    )];
    for subdivisions in [0, 1] {
        let mesh = renderer
            .add_mesh(&MeshData::icosphere(1.0, subdivisions))
            .unwrap();
        let mut scene = tabletop(renderer, 8, 16);
        for p in &bed {
            scene.add_instance(
                Instance::new(mesh, clay, Isometry3::translation(p[0], p[1], p[2]), ids)
                    .with_scale(Vector3::repeat(radius)),
            );
        }
        let label = format!("instance per particle ({} tri)", 20 << (2 * subdivisions));
        scenes.push((label, scene, None));
    }
    let triangles: Vec<usize> = scenes
        .iter()
        .map(|(_, s, _)| s.triangle_count(renderer))
        .collect();
    let mut modes: Vec<Mode<'_>> = scenes
        .iter_mut()
        .map(|(name, scene, set)| {
            let label: &'static str = Box::leak(name.clone().into_boxed_str());
            let bed = &bed;
            let step = move || {
                if let Some(set) = *set {
                    scene
                        .set_particle_positions(set, bed.iter().copied())
                        .unwrap();
                }
                renderer.render(&[(&*scene, cams)]).unwrap();
            };
            (label, cams.len(), Box::new(step) as Box<dyn FnMut() + '_>)
        })
        .collect();
    let rates = measure_side_by_side(rounds, budget, &mut modes);
    for (((name, _, _), rate), triangles) in modes.iter().zip(&rates).zip(&triangles) {
        println!(
            "{:<8} {triangles:>10}  {name:<46} {rate:>9.0} {:>7.2}",
            "clay",
            rate / rates[0]
        );
    }
}
