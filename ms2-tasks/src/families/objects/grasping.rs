//! Antipodal grasps of an object from its convex collision pieces, and the gripper poses that
//! realise them.
//!
//! [`sample_antipodal`] draws points on the surface of the pieces (area-weighted), and for each
//! looks along its normal for the contacts the closing fingers would touch: the two outermost
//! surface points (ray casts from outside the object on both sides: the fingers enclose all
//! the line crosses) and the thinnest layer through the point (from its surface to where the
//! material first ends: a wall at a bowl's or mug's rim, a handle; the far finger then sits in
//! the free space beyond, which the planner checks). A pair is kept when both contacts'
//! normals lie within a friction cone of the closing direction and it is narrower than the
//! open gripper. [`grasp_poses`] turns each line into TCP poses (closing axis along the line,
//! approach axis across it, from above where possible, the fingertips kept off the ground),
//! best first.
//!
//! Frames: the sampler works in the object's model frame (m); poses are in the robot base
//! frame. The TCP convention is ms2-plan's: +z approaches, y closes.

use ms2_plan::parry3d::math::Vector;
use ms2_plan::parry3d::query::Ray;
use ms2_plan::parry3d::shape::SharedShape;
use ms2_plan::{GraspKind, GraspPose};
use nalgebra::{Isometry3, Matrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};
use rand::Rng;

/// How far (m) outside a sampled surface point the near finger's contact is looked for.
const LOCAL_START: f64 = 0.01;
/// Step (m) of the walk through the material to where it ends (thinner layers may be missed).
const LOCAL_STEP: f64 = 0.001;

/// An antipodal contact pair on an object (model frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AntipodalGrasp {
    /// Midpoint of the two contacts (m, model frame).
    pub centre: Vector3<f64>,
    /// Unit direction from one contact to the other (the fingers close along it).
    pub closing: Vector3<f64>,
    /// Distance between the contacts (m).
    pub width: f64,
    /// Largest angle (rad) between a contact's inward normal and the closing line.
    pub cone_angle: f64,
}

/// The object's collision pieces as one parry compound (model frame), `None` when no piece has
/// a hull with volume.
pub fn object_shape(pieces: &[Vec<Point3<f32>>]) -> Option<SharedShape> {
    let parts: Vec<_> = pieces
        .iter()
        .filter_map(|piece| {
            let pts: Vec<Vector> = piece.iter().map(|p| Vector::new(p.x, p.y, p.z)).collect();
            SharedShape::convex_hull(&pts)
                .map(|hull| (ms2_plan::parry3d::math::Pose::IDENTITY, hull))
        })
        .collect();
    (!parts.is_empty()).then(|| SharedShape::compound(parts))
}

/// Surface triangles (model frame) of the pieces' hulls with their areas.
fn hull_triangles(pieces: &[Vec<Point3<f32>>]) -> Vec<([Vector3<f64>; 3], f64)> {
    let mut out = Vec::new();
    for piece in pieces {
        let pts: Vec<Vector> = piece.iter().map(|p| Vector::new(p.x, p.y, p.z)).collect();
        let Some(hull) = SharedShape::convex_hull(&pts) else {
            continue;
        };
        let Some(poly) = hull.as_convex_polyhedron() else {
            continue;
        };
        let (vertices, indices) = poly.to_trimesh();
        let v = |i: u32| {
            let p = vertices[i as usize];
            Vector3::new(f64::from(p.x), f64::from(p.y), f64::from(p.z))
        };
        for [a, b, c] in indices {
            let tri = [v(a), v(b), v(c)];
            let area = 0.5 * (tri[1] - tri[0]).cross(&(tri[2] - tri[0])).norm();
            if area > 1e-10 {
                out.push((tri, area));
            }
        }
    }
    out
}

/// Up to `count` antipodal grasps of the object made of `pieces`, from `3 · count` surface
/// samples drawn with `rng`: contacts at most `max_width` (m) apart whose inward normals are
/// within `cone_angle` (rad) of the closing line. Deterministic for a given `rng` state.
pub fn sample_antipodal(
    pieces: &[Vec<Point3<f32>>],
    count: usize,
    max_width: f64,
    cone_angle: f64,
    rng: &mut impl Rng,
) -> Vec<AntipodalGrasp> {
    let (Some(shape), triangles) = (object_shape(pieces), hull_triangles(pieces)) else {
        return Vec::new();
    };
    let total: f64 = triangles.iter().map(|t| t.1).sum();
    if triangles.is_empty() || total <= 0.0 {
        return Vec::new();
    }
    let reach = (max_width + 0.05) as f32;
    let to_parry = |v: &Vector3<f64>| Vector::new(v.x as f32, v.y as f32, v.z as f32);
    let identity = ms2_plan::parry3d::math::Pose::IDENTITY;
    // The outermost surface point along `dir` through `through`, seen from outside, and the
    // outward normal there.
    let outermost = |through: &Vector3<f64>, dir: &Vector3<f64>| {
        let origin = to_parry(&(through - dir * f64::from(reach)));
        if shape.contains_point(&identity, origin) {
            return None;
        }
        let ray = Ray::new(origin, to_parry(dir));
        let hit = shape.cast_ray_and_get_normal(&identity, &ray, 2.0 * reach, true)?;
        let p = ray.point_at(hit.time_of_impact);
        let n = Vector3::new(hit.normal.x, hit.normal.y, hit.normal.z).cast::<f64>();
        Some((
            Vector3::new(p.x, p.y, p.z).cast::<f64>(),
            n.try_normalize(1e-9)?,
        ))
    };
    // The first surface point along `dir` from `from` (which must lie outside the object),
    // at most `reach` away, and the outward normal there.
    let first_hit = |from: &Vector3<f64>, dir: &Vector3<f64>, reach: f32| {
        let origin = to_parry(from);
        if shape.contains_point(&identity, origin) {
            return None;
        }
        let ray = Ray::new(origin, to_parry(dir));
        let hit = shape.cast_ray_and_get_normal(&identity, &ray, reach, true)?;
        let p = ray.point_at(hit.time_of_impact);
        let n = Vector3::new(hit.normal.x, hit.normal.y, hit.normal.z).cast::<f64>();
        Some((
            Vector3::new(p.x, p.y, p.z).cast::<f64>(),
            n.try_normalize(1e-9)?,
        ))
    };
    // The contact pair of the thinnest material layer through `point` along `closing`: the
    // near contact seen from just outside `point`, the far one where the material first ends
    // beyond it (a bowl's or mug's wall at its rim, a handle): the far finger then sits in the
    // free space there (the planner checks that it fits).
    let local = |point: &Vector3<f64>, closing: &Vector3<f64>| {
        let (near, n_near) = first_hit(
            &(point - closing * LOCAL_START),
            closing,
            2.0 * LOCAL_START as f32,
        )?;
        let steps = (max_width / LOCAL_STEP).ceil() as usize + 1;
        let free = (1..=steps)
            .map(|k| near + closing * (k as f64 * LOCAL_STEP))
            .find(|q| !shape.contains_point(&identity, to_parry(q)))?;
        let (far, n_far) = first_hit(&free, &-closing, (2.0 * LOCAL_STEP) as f32)?;
        Some(((near, n_near), (far, n_far)))
    };
    let angle = |n: &Vector3<f64>, inward: &Vector3<f64>| (-n).dot(inward).clamp(-1.0, 1.0).acos();
    // A grasp from its two contacts when it fits the gripper and the friction cone.
    let grasp = |closing: &Vector3<f64>,
                 (near, n_near): (Vector3<f64>, Vector3<f64>),
                 (far, n_far): (Vector3<f64>, Vector3<f64>)| {
        let width = (far - near).dot(closing);
        if !(width > 1e-3 && width <= max_width) {
            return None;
        }
        let worst = angle(&n_near, closing).max(angle(&n_far, &-closing));
        (worst <= cone_angle).then(|| AntipodalGrasp {
            centre: 0.5 * (near + far),
            closing: *closing,
            width,
            cone_angle: worst,
        })
    };
    let mut grasps = Vec::new();
    for _ in 0..3 * count {
        if grasps.len() >= count {
            break;
        }
        let mut pick = rng.random_range(0.0..total);
        let (tri, _) = triangles
            .iter()
            .find(|t| {
                pick -= t.1;
                pick <= 0.0
            })
            .unwrap_or(&triangles[triangles.len() - 1]);
        let (mut u, mut v) = (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        let point = tri[0] + (tri[1] - tri[0]) * u + (tri[2] - tri[0]) * v;
        let Some(normal) = (tri[1] - tri[0])
            .cross(&(tri[2] - tri[0]))
            .try_normalize(1e-12)
        else {
            continue;
        };
        // Fingers close along −normal: one meets the surface on the normal's side, the
        // other on the far side — either outside everything on the line (enclosing every
        // part it crosses) or where the material through the point first ends.
        let closing = -normal;
        let enclosing = outermost(&point, &closing)
            .zip(outermost(&point, &-closing))
            .and_then(|(near, far)| grasp(&closing, near, far));
        let layer = local(&point, &closing).and_then(|(near, far)| grasp(&closing, near, far));
        let thinner = layer.filter(|l| enclosing.is_none_or(|e| l.width < e.width - LOCAL_STEP));
        grasps.extend(enclosing);
        grasps.extend(thinner);
    }
    grasps.truncate(count);
    grasps
}

/// The fingertips' extent around the TCP (m, TCP frame: +z approaches, y closes), used to keep
/// them off the ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fingertips {
    /// How far the fingertips reach past the TCP along the approach.
    pub past_tcp: f64,
    /// Half their width along the TCP's x.
    pub half_width: f64,
    /// Their outer faces' distance from the TCP along the closing axis, fingers open.
    pub outer_reach: f64,
}

/// The Panda's rubber fingertips (ManiSkill2's `panda_v2.urdf`: 18.5 mm pads centred 0.5 mm
/// short of the TCP, 17.5 mm wide, 15.2 mm thick, each finger open 40 mm).
pub const PANDA_FINGERTIPS: Fingertips = Fingertips {
    past_tcp: 0.0095,
    half_width: 0.00875,
    outer_reach: 0.0552,
};

/// How [`grasp_poses`] turns contact lines into hand poses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseOptions {
    /// Turns (rad) of the approach axis about the closing line away from the most downward
    /// approach, tried for every line.
    pub approach_turns: &'static [f64],
    /// How far (m) the TCP goes past the contact line along the approach, so the contacts sit
    /// on the finger pads rather than at their tips.
    pub pad_depth: f64,
    /// Least pad depth (m, negative: the contact between the TCP and the fingertips) the
    /// depth is lowered to, on low objects, so that the fingertips stay
    /// [`PoseOptions::ground_clearance`] above the ground; poses that would need less are
    /// dropped.
    pub min_pad_depth: f64,
    /// Height (m) the fingertips keep above the ground.
    pub ground_clearance: f64,
    /// The gripper's fingertips.
    pub fingertips: Fingertips,
    /// Weight (1/m) in the score (rad-equivalent per metre) of the centre of mass's offset
    /// from the contact line: its horizontal distance from the line (gravity's lever arm about
    /// the line, about which two pads hold least) plus a quarter of its distance along it.
    pub com_weight: f64,
}

/// The default: upright first, then tilted up to a side grasp; contacts at the TCP (the middle
/// of the Panda's pads, which reach 9 mm above and 9.5 mm below it), down to 2.5 mm from the
/// fingertips on low objects (the fingertips 1.5 mm above the ground).
pub const DEFAULT_POSE_OPTIONS: PoseOptions = PoseOptions {
    approach_turns: &[0.0, 0.35, -0.35, 0.7, -0.7, 1.05, -1.05, 1.4, -1.4],
    pad_depth: 0.0,
    min_pad_depth: -0.007,
    ground_clearance: 0.0015,
    fingertips: PANDA_FINGERTIPS,
    com_weight: 20.0,
};

/// Where the object to grasp is (robot base frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GraspSite {
    /// The object's model frame (m).
    pub pose_base_from_object: Isometry3<f64>,
    /// Its centre of mass (m).
    pub com: Vector3<f64>,
    /// Height of the ground (m).
    pub ground_z: f64,
}

impl PoseOptions {
    /// The pad depth (m) for a contact line centred at `centre` grasped along `approach` with
    /// the closing axis `y` and `x = y × approach`: [`PoseOptions::pad_depth`], lowered until
    /// the fingertips clear the ground at `ground_z`; `None` below
    /// [`PoseOptions::min_pad_depth`].
    fn depth_above_ground(
        &self,
        centre: &Vector3<f64>,
        approach: &Vector3<f64>,
        x: &Vector3<f64>,
        y: &Vector3<f64>,
        ground_z: f64,
    ) -> Option<f64> {
        let tips = &self.fingertips;
        // Lowest fingertip corner relative to the TCP, apart from the approach term.
        let lateral = -x.z.abs() * tips.half_width - y.z.abs() * tips.outer_reach;
        let lowest = |depth: f64| centre.z + approach.z * (depth + tips.past_tcp) + lateral;
        let floor = ground_z + self.ground_clearance;
        if lowest(self.pad_depth) >= floor {
            return Some(self.pad_depth);
        }
        if approach.z > -1e-3 {
            return None; // the depth does not lift the fingertips
        }
        let depth = (floor - centre.z - lateral) / approach.z - tips.past_tcp;
        (depth >= self.min_pad_depth).then_some(depth.min(self.pad_depth))
    }
}

/// TCP poses (base frame) realising `grasps` on the object at `site`, best first: the approach
/// closest to straight down, the line passing closest to the centre of mass, the hand turned least
/// from `tcp_now`, the tightest cone. The
/// fingertips are kept off the ground ([`PoseOptions::min_pad_depth`]).
pub fn grasp_poses(
    grasps: &[AntipodalGrasp],
    site: &GraspSite,
    tcp_now: &Isometry3<f64>,
    options: &PoseOptions,
) -> Vec<GraspPose> {
    let down = -Vector3::z();
    let pose_base_from_object = &site.pose_base_from_object;
    let mut scored: Vec<(f64, GraspPose)> = Vec::new();
    for g in grasps {
        let centre = pose_base_from_object * Point3::from(g.centre);
        let line = pose_base_from_object.rotation * g.closing;
        // The approach across the line closest to straight down.
        let mut base_approach = down - line * down.dot(&line);
        if base_approach.norm() < 1e-3 {
            // A vertical line: approach horizontally, away from the robot base.
            base_approach = Vector3::new(centre.x, centre.y, 0.0);
            if base_approach.norm() < 1e-6 {
                base_approach = Vector3::x();
            }
        }
        let base_approach = base_approach.normalize();
        // The centre of mass's horizontal offset from the closing line: gravity's lever arm
        // about the line, about which two pads hold least (a quarter of the offset along the
        // line counts too).
        let to_com = site.com - centre.coords;
        let along = to_com.dot(&line);
        let off_com = (to_com - line * along).xy().norm() + 0.25 * along.abs();
        for &turn in options.approach_turns {
            let approach =
                UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(line), turn)
                    * base_approach;
            let tilt = approach.dot(&down).clamp(-1.0, 1.0).acos();
            if tilt > 0.5 * std::f64::consts::PI + 1e-6 {
                continue; // from below
            }
            for y in [line, -line] {
                let x = y.cross(&approach);
                let Some(depth) =
                    options.depth_above_ground(&centre.coords, &approach, &x, &y, site.ground_z)
                else {
                    continue;
                };
                let frame =
                    Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[x, y, approach]));
                let rotation = UnitQuaternion::from_rotation_matrix(&frame);
                let position = centre.coords + approach * depth;
                let pose = Isometry3::from_parts(Translation3::from(position), rotation);
                let turn_from_hand = rotation.angle_to(&tcp_now.rotation);
                let score =
                    tilt + options.com_weight * off_com + 0.3 * turn_from_hand + 0.5 * g.cone_angle;
                let kind = if tilt < std::f64::consts::FRAC_PI_4 {
                    GraspKind::TopDown
                } else {
                    GraspKind::Side
                };
                scored.push((
                    score,
                    GraspPose {
                        pose_base_from_tcp: pose,
                        kind,
                        width: g.width,
                    },
                ));
            }
        }
    }
    scored.sort_by(|a, b| a.0.total_cmp(&b.0));
    scored.into_iter().map(|(_, g)| g).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn block(hx: f32, hy: f32, hz: f32) -> Vec<Point3<f32>> {
        let mut v = Vec::new();
        for sx in [-1.0, 1.0] {
            for sy in [-1.0, 1.0] {
                for sz in [-1.0, 1.0] {
                    v.push(Point3::new(sx * hx, sy * hy, sz * hz));
                }
            }
        }
        v
    }

    #[test]
    fn a_box_is_grasped_across_its_narrow_sides_only() {
        // 3 cm along x, 12 cm along y (too wide), 5 cm tall.
        let pieces = vec![block(0.015, 0.06, 0.025)];
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let grasps = sample_antipodal(&pieces, 50, 0.072, 0.3, &mut rng);
        assert!(grasps.len() >= 10, "{} grasps", grasps.len());
        for g in &grasps {
            let across_x = g.closing.x.abs() > 0.95 && (g.width - 0.03).abs() < 1e-3;
            let across_z = g.closing.z.abs() > 0.95 && (g.width - 0.05).abs() < 1e-3;
            assert!(across_x || across_z, "{g:?}");
            assert!(g.centre.norm() < 0.07);
        }
    }

    #[test]
    fn an_l_shape_is_grasped_on_its_outermost_surfaces() {
        // Two pieces: a 2 cm thick slab and a post on one end; a line through both must
        // measure from outermost to outermost surface.
        let slab = block(0.05, 0.01, 0.01);
        let post: Vec<_> = block(0.01, 0.01, 0.04)
            .into_iter()
            .map(|p| p + Vector3::new(0.04, 0.0, 0.05))
            .collect();
        let pieces = vec![slab, post];
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let grasps = sample_antipodal(&pieces, 80, 0.072, 0.3, &mut rng);
        assert!(!grasps.is_empty());
        let shape = object_shape(&pieces).unwrap();
        for g in &grasps {
            for side in [-0.5, 0.5] {
                let contact = g.centre + g.closing * (side * g.width);
                let outside = contact + g.closing * (side.signum() * 0.002);
                let p = Vector::new(outside.x as f32, outside.y as f32, outside.z as f32);
                assert!(
                    !shape.contains_point(&ms2_plan::parry3d::math::Pose::IDENTITY, p),
                    "{g:?}"
                );
            }
        }
    }

    /// A cup `2·radius` wide and `height` tall: a bottom slab and `walls` wall slabs
    /// `thickness` thick around it.
    fn cup(radius: f32, height: f32, thickness: f32, walls: usize) -> Vec<Vec<Point3<f32>>> {
        let mut pieces = vec![block(radius, radius, 0.5 * thickness)];
        let half_side = radius * (std::f32::consts::PI / walls as f32).tan();
        for k in 0..walls {
            let a = std::f32::consts::TAU * k as f32 / walls as f32;
            let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), a);
            let offset = Vector3::new(radius - 0.5 * thickness, 0.0, 0.5 * height);
            pieces.push(
                block(0.5 * thickness, half_side, 0.5 * height)
                    .into_iter()
                    .map(|p| Point3::from(turn * (p.coords + offset)))
                    .collect(),
            );
        }
        pieces
    }

    #[test]
    fn a_cup_wider_than_the_gripper_is_grasped_across_its_wall() {
        // 10 cm wide (the Panda opens 8 cm), 4 mm walls.
        let pieces = cup(0.05, 0.08, 0.004, 12);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let grasps = sample_antipodal(&pieces, 100, 0.075, 0.45, &mut rng);
        let across_wall: Vec<_> = grasps
            .iter()
            .filter(|g| g.width < 0.006 && g.closing.z.abs() < 0.1)
            .collect();
        assert!(
            across_wall.len() >= 10,
            "{} of {grasps:?}",
            across_wall.len()
        );
        for g in across_wall {
            let radial = Vector3::new(g.centre.x, g.centre.y, 0.0);
            // The line crosses the wall, at the wall.
            assert!((radial.norm() - 0.048).abs() < 0.003, "{g:?}");
            assert!(g.closing.dot(&radial.normalize()).abs() > 0.9, "{g:?}");
        }
        // Nothing spans the whole cup.
        assert!(grasps.iter().all(|g| g.width <= 0.075));
    }

    #[test]
    fn low_objects_are_grasped_with_the_fingertips_above_the_ground() {
        // A 12 mm thick spoon-like bar lying on the ground (z = 0), grasped across its 3 cm.
        let grasp = AntipodalGrasp {
            centre: Vector3::new(0.0, 0.0, 0.006),
            closing: Vector3::x(),
            width: 0.03,
            cone_angle: 0.0,
        };
        let site = GraspSite {
            pose_base_from_object: Isometry3::translation(0.5, 0.0, 0.0),
            com: Vector3::new(0.5, 0.0, 0.006),
            ground_z: 0.0,
        };
        let hand = Isometry3::from_parts(
            Translation3::new(0.4, 0.0, 0.3),
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI),
        );
        let options = DEFAULT_POSE_OPTIONS;
        let poses = grasp_poses(&[grasp], &site, &hand, &options);
        assert!(!poses.is_empty());
        let tips = options.fingertips;
        for p in &poses {
            let tcp = p.pose_base_from_tcp;
            let approach = tcp.rotation * Vector3::z();
            let depth = (tcp.translation.vector - Vector3::new(0.5, 0.0, 0.006)).dot(&approach);
            assert!(depth >= options.min_pad_depth - 1e-9 && depth <= options.pad_depth + 1e-9);
            // Every fingertip corner above the ground by the clearance.
            for sx in [-1.0, 1.0] {
                for sy in [-1.0, 1.0] {
                    let corner = tcp
                        * Point3::new(sx * tips.half_width, sy * tips.outer_reach, tips.past_tcp);
                    assert!(corner.z >= options.ground_clearance - 1e-9, "{p:?}");
                }
            }
        }
        // The upright grasp is among them, its contacts 4.5 mm up from the fingertips' ends.
        let upright = &poses[0].pose_base_from_tcp;
        assert!((upright.rotation * Vector3::z()).z < -0.999);
        assert!(
            (upright.translation.vector.z - (0.006 + 0.0015 + tips.past_tcp - 0.006)).abs() < 1e-3
        );
    }

    #[test]
    fn poses_close_along_the_line_and_prefer_a_downward_approach() {
        let grasp = AntipodalGrasp {
            centre: Vector3::new(0.0, 0.0, 0.02),
            closing: Vector3::x(),
            width: 0.04,
            cone_angle: 0.0,
        };
        let object = Isometry3::translation(0.5, 0.1, 0.0);
        let hand = Isometry3::from_parts(
            Translation3::new(0.4, 0.0, 0.3),
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI),
        );
        let site = GraspSite {
            pose_base_from_object: object,
            com: Vector3::new(0.5, 0.1, 0.02),
            ground_z: -0.1,
        };
        let poses = grasp_poses(&[grasp], &site, &hand, &DEFAULT_POSE_OPTIONS);
        assert_eq!(poses.len(), 2 * DEFAULT_POSE_OPTIONS.approach_turns.len());
        let best = poses[0].pose_base_from_tcp;
        assert!((best.rotation * Vector3::z() - (-Vector3::z())).norm() < 1e-9);
        assert!((best.rotation * Vector3::y()).x.abs() > 1.0 - 1e-9);
        // The TCP (the middle of the pads) on the contact line.
        assert!((best.translation.vector - Vector3::new(0.5, 0.1, 0.02)).norm() < 1e-9);
        assert_eq!(poses[0].kind, GraspKind::TopDown);
        assert_eq!(poses.last().unwrap().kind, GraspKind::Side);
    }

    #[test]
    fn a_line_through_the_centre_of_mass_ranks_above_one_beside_it() {
        // Two contact lines centred 4 cm from the centre of mass, horizontal: one pointing
        // at it (gravity has no lever arm about it), one across (a 4 cm lever arm).
        let line = |closing: Vector3<f64>| AntipodalGrasp {
            centre: Vector3::new(0.04, 0.0, 0.05),
            closing,
            width: 0.03,
            cone_angle: 0.1,
        };
        let grasps = [line(Vector3::y()), line(Vector3::x())];
        let site = GraspSite {
            pose_base_from_object: Isometry3::translation(0.5, 0.0, 0.0),
            com: Vector3::new(0.5, 0.0, 0.05),
            ground_z: 0.0,
        };
        let tcp_now = Isometry3::translation(0.5, 0.0, 0.3);
        let options = PoseOptions {
            approach_turns: &[0.0],
            ..DEFAULT_POSE_OPTIONS
        };
        let poses = grasp_poses(&grasps, &site, &tcp_now, &options);
        assert_eq!(poses.len(), 4, "two lines, two hand orientations each");
        // The best pose closes along x (its y axis, the closing axis, is ±x).
        let closing = poses[0].pose_base_from_tcp.rotation * Vector3::y();
        assert!(closing.x.abs() > 0.99, "{closing:?}");
    }
}
