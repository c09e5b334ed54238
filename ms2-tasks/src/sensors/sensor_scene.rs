//! [`Sensors`]: one env's render scene and cameras (feature `render`).

use std::sync::Arc;

use ms2_physics::ArticulationId;
use ms2_render::{
    Camera, CameraOutput, Instance, InstanceId, Material, ParticleSetId, Renderer, Scene,
    SegmentationIds,
};
use nalgebra::{Isometry3, Vector3};

use super::{particle_culling, CameraConfig, CameraFrame, GoalMarker, GOAL_MARKER_RADIUS_M};
use crate::adapters::render_scene::render_err;
use crate::adapters::{ParticleVisual, RenderContext, WorldRenderScene};
use crate::error::EnvError;
use crate::rigid_world::RigidWorld;

/// One env's cameras and render scene.
#[derive(Debug)]
pub struct Sensors {
    ctx: Arc<RenderContext>,
    scene: WorldRenderScene,
    cameras: Vec<CameraConfig>,
    render_camera: CameraConfig,
    robot: Option<ArticulationId>,
    robot_ids: Vec<u32>,
    goal_marker: InstanceId,
    particle_sets: Vec<SensorParticleSet>,
}

/// An env's scene as of now, for drawing it through cameras of one's own (a viewer window):
/// poses synchronised with the world, the goal marker shown as in human renders.
pub struct SceneView<'a> {
    /// The renderer the scene's meshes live in.
    pub renderer: &'a Renderer,
    /// The render scene.
    pub scene: &'a Scene,
    /// The observation cameras at their current poses, with their uids, in config order.
    pub cameras: Vec<(String, Camera)>,
    /// The camera of `render_mode = "rgb_array"` (a good initial view).
    pub render_camera: Camera,
}

impl std::fmt::Debug for SceneView<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SceneView")
            .field("cameras", &self.cameras)
            .field("render_camera", &self.render_camera)
            .finish_non_exhaustive()
    }
}

/// A particle set of the render scene and how its positions are filtered.
#[derive(Debug)]
struct SensorParticleSet {
    id: ParticleSetId,
    /// Packing spacing (m) when enclosed particles are culled.
    packing_spacing_m: Option<f32>,
    /// The drawn positions of the last update (reused buffer).
    drawn: Vec<glam::Vec3>,
}

impl Sensors {
    /// Builds the render scene of `world` with observation `cameras` (uids must be unique) and
    /// the human `render_camera`; `robot` carries link-mounted cameras and defines the robot
    /// mask.
    pub fn new(
        ctx: Arc<RenderContext>,
        world: &dyn RigidWorld,
        robot: Option<ArticulationId>,
        cameras: Vec<CameraConfig>,
        render_camera: CameraConfig,
    ) -> Result<Sensors, EnvError> {
        for (i, cam) in cameras.iter().enumerate() {
            cam.validate()?;
            if cameras[..i].iter().any(|c| c.uid == cam.uid) {
                return Err(EnvError::InvalidConfig(format!(
                    "camera uid {:?} appears twice",
                    cam.uid
                )));
            }
            cam.camera_at(world, robot)?;
        }
        render_camera.validate()?;
        let mut scene = WorldRenderScene::build(&ctx, world)?;
        let robot_ids = robot
            .map(|art| scene.articulation_ids(art))
            .unwrap_or_default();
        let mut marker = Instance::new(
            ctx.unit_sphere_mesh()?,
            Material::color(0.0, 1.0, 0.0),
            Isometry3::identity(),
            SegmentationIds::default(),
        )
        .with_scale(Vector3::repeat(GOAL_MARKER_RADIUS_M));
        marker.visible = false;
        let goal_marker = scene.scene_mut().add_instance(marker);
        Ok(Sensors {
            ctx,
            scene,
            cameras,
            render_camera,
            robot,
            robot_ids,
            goal_marker,
            particle_sets: Vec::new(),
        })
    }

    /// Adds a particle set drawn as `visual` (segmentation object `visual.name`, after the
    /// world's); its index, counted from 0, is the `set` of
    /// [`Sensors::set_particle_positions`].
    pub fn add_particle_set(&mut self, visual: &ParticleVisual) -> Result<usize, EnvError> {
        visual.validate()?;
        self.particle_sets.push(SensorParticleSet {
            id: self.scene.add_particle_set(visual),
            packing_spacing_m: visual.packing_spacing_m,
            drawn: Vec::new(),
        });
        Ok(self.particle_sets.len() - 1)
    }

    /// Turns the shadows of the scene's first directional light on (a 1.5 m sphere around the
    /// table, 2048² texels, as ManiSkill2's `enable_shadow`) or off.
    pub fn set_shadows(&mut self, on: bool) {
        self.scene.scene_mut().lighting.shadow = on.then_some(ms2_render::Shadow {
            center_world: Vector3::new(0.0, 0.0, 0.3),
            radius_m: 1.5,
            resolution: 2048,
        });
    }

    /// Number of particle sets.
    pub fn particle_set_count(&self) -> usize {
        self.particle_sets.len()
    }

    /// Replaces the positions (m, world) of particle set `set` (they are drawn from the next
    /// render on; the count may change). Sets with a packing spacing draw only the particles
    /// not enclosed by neighbours ([`particle_culling`]).
    pub fn set_particle_positions(
        &mut self,
        set: usize,
        positions_world: &[glam::Vec3],
    ) -> Result<(), EnvError> {
        let count = self.particle_sets.len();
        let entry = self.particle_sets.get_mut(set).ok_or_else(|| {
            EnvError::Render(format!("particle set {set} does not exist ({count} sets)"))
        })?;
        match entry.packing_spacing_m {
            Some(spacing) => {
                particle_culling::visible_particles(positions_world, spacing, &mut entry.drawn);
                self.scene.set_particle_positions(entry.id, &entry.drawn)
            }
            None => self.scene.set_particle_positions(entry.id, positions_world),
        }
    }

    /// The observation cameras.
    pub fn cameras(&self) -> &[CameraConfig] {
        &self.cameras
    }

    /// The render scene.
    pub fn render_scene(&self) -> &WorldRenderScene {
        &self.scene
    }

    /// Channel-1 ids of the robot's links.
    pub fn robot_ids(&self) -> &[u32] {
        &self.robot_ids
    }

    /// Copies poses from `world` and renders every observation camera in one submission.
    pub fn capture(&mut self, world: &dyn RigidWorld) -> Result<CameraFrame, EnvError> {
        let cams = self.prepare(world)?;
        let outputs = self
            .ctx
            .renderer()
            .render_sensors(&[(self.scene.scene(), &cams[..])])
            .map_err(render_err)?;
        Ok(self.frame(outputs))
    }

    /// Copies poses from `world` into the render scene and returns the observation cameras at
    /// their current poses (in config order), ready to be drawn with [`Sensors::scene`] — alone
    /// or batched with other envs' scenes ([`capture_batch`](super::capture_batch)).
    pub fn prepare(&mut self, world: &dyn RigidWorld) -> Result<Vec<Camera>, EnvError> {
        self.scene.sync_poses(world)?;
        self.cameras
            .iter()
            .map(|c| c.camera_at(world, self.robot))
            .collect()
    }

    /// The render scene as last synchronised by [`Sensors::prepare`].
    pub fn scene(&self) -> &Scene {
        self.scene.scene()
    }

    /// The shared render context this env draws through.
    pub fn context(&self) -> &Arc<RenderContext> {
        &self.ctx
    }

    /// Wraps the outputs of this env's observation cameras (config order) into a frame.
    pub fn frame(&self, outputs: Vec<CameraOutput>) -> CameraFrame {
        CameraFrame {
            uids: self.cameras.iter().map(|c| c.uid.clone()).collect(),
            outputs,
            robot_ids: self.robot_ids.clone(),
            segmentation: self.cameras.iter().map(|c| c.segmentation).collect(),
        }
    }

    /// Shows `marker` when given (its pose, size and colour); callers hide it again after
    /// drawing, so observation cameras never see it.
    fn show_goal_marker(&mut self, marker: Option<GoalMarker>) -> Result<(), EnvError> {
        let Some(marker) = marker else {
            return Ok(());
        };
        let goal = marker.position_world;
        let instance = self
            .scene
            .scene_mut()
            .instance_mut(self.goal_marker)
            .map_err(render_err)?;
        instance.pose_world_from_mesh = Isometry3::translation(goal.x, goal.y, goal.z);
        instance.scale = Vector3::repeat(marker.radius_m);
        instance.material = Material::color(marker.rgb[0], marker.rgb[1], marker.rgb[2]);
        instance.visible = true;
        Ok(())
    }

    /// Renders the human view (render camera) with `goal_marker` when
    /// given; the marker is hidden again afterwards, so observation cameras never see it.
    pub fn render_human(
        &mut self,
        world: &dyn RigidWorld,
        goal_marker: Option<GoalMarker>,
    ) -> Result<CameraOutput, EnvError> {
        self.scene.sync_poses(world)?;
        let camera = self.render_camera.camera_at(world, self.robot)?;
        self.show_goal_marker(goal_marker)?;
        let result = self
            .ctx
            .renderer()
            .render(&[(self.scene.scene(), &[camera][..])]);
        self.scene
            .scene_mut()
            .set_visible(self.goal_marker, false)
            .map_err(render_err)?;
        let mut outputs = result.map_err(render_err)?;
        outputs
            .pop()
            .ok_or_else(|| EnvError::Render("the renderer returned no image".to_owned()))
    }

    /// Calls `f` with the scene synchronised with `world`, `goal_marker` shown
    /// when given (hidden again afterwards), and the cameras at their poses.
    pub fn with_view<R>(
        &mut self,
        world: &dyn RigidWorld,
        goal_marker: Option<GoalMarker>,
        f: impl FnOnce(&SceneView<'_>) -> R,
    ) -> Result<R, EnvError> {
        let cams = self.prepare(world)?;
        let render_camera = self.render_camera.camera_at(world, self.robot)?;
        self.show_goal_marker(goal_marker)?;
        let view = SceneView {
            renderer: self.ctx.renderer(),
            scene: self.scene.scene(),
            cameras: self
                .cameras
                .iter()
                .map(|c| c.uid.clone())
                .zip(cams)
                .collect(),
            render_camera,
        };
        let out = f(&view);
        self.scene
            .scene_mut()
            .set_visible(self.goal_marker, false)
            .map_err(render_err)?;
        Ok(out)
    }

    /// Triangles drawn per observation camera (the scene's visible triangles).
    pub fn triangles_per_camera(&self) -> usize {
        self.scene.scene().triangle_count(self.ctx.renderer())
    }
}
