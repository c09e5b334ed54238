//! What ManiSkill2's MS1 tasks read from a model's visual names: the handles of an articulated
//! model (the visuals whose name contains `handle`, ManiSkill2's rule for cabinets), read from
//! the model's URDF with their mesh vertices in link frames, and every link's visual names
//! (PushChair finds its wheels, seat and support by them).

use std::collections::BTreeMap;
use std::path::Path;

use nalgebra::{Point3, Translation3, UnitQuaternion, Vector3};

use crate::error::EnvError;
use crate::geometry::Pose3;

/// One link's handle geometry: its mesh vertices (m, link frame, model scale applied).
#[derive(Debug, Clone, PartialEq)]
pub struct HandleGeometry {
    /// Vertices of every `handle` visual mesh of the link (m, link frame).
    pub points: Vec<Point3<f32>>,
}

impl HandleGeometry {
    /// Axis-aligned bounds of the points in the link frame: (min, max).
    pub fn bounds(&self) -> (Point3<f32>, Point3<f32>) {
        let mut lo = Point3::from(Vector3::repeat(f32::INFINITY));
        let mut hi = Point3::from(Vector3::repeat(f32::NEG_INFINITY));
        for p in &self.points {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        (lo, hi)
    }

    /// Centre of the bounds (m, link frame).
    pub fn center(&self) -> Point3<f32> {
        let (lo, hi) = self.bounds();
        nalgebra::center(&lo, &hi)
    }
}

/// The handles of the model `urdf` loaded at `scale`, by link name. Links without a handle
/// visual are absent. Errors name the file.
pub fn read_handles(urdf: &Path, scale: f32) -> Result<BTreeMap<String, HandleGeometry>, EnvError> {
    let bad = |what: String| EnvError::Asset(format!("{}: {what}", urdf.display()));
    let text = std::fs::read_to_string(urdf).map_err(|e| bad(e.to_string()))?;
    let doc = roxmltree::Document::parse(&text).map_err(|e| bad(e.to_string()))?;
    let dir = urdf.parent().unwrap_or(Path::new("."));
    let mut handles = BTreeMap::new();
    for link in doc.descendants().filter(|n| n.has_tag_name("link")) {
        let name = link.attribute("name").unwrap_or_default();
        let mut points = Vec::new();
        for visual in link.children().filter(|n| n.has_tag_name("visual")) {
            if !visual
                .attribute("name")
                .unwrap_or_default()
                .contains("handle")
            {
                continue;
            }
            let origin = visual
                .children()
                .find(|n| n.has_tag_name("origin"))
                .map(|o| origin_pose(o.attribute("xyz"), o.attribute("rpy")))
                .transpose()
                .map_err(&bad)?
                .unwrap_or_else(Pose3::identity);
            let Some(mesh) = visual.descendants().find(|n| n.has_tag_name("mesh")) else {
                continue;
            };
            let file = mesh
                .attribute("filename")
                .ok_or_else(|| bad(format!("link {name}: a handle mesh without filename")))?;
            let mesh_scale = match mesh.attribute("scale") {
                Some(s) => triple(s).map_err(&bad)?,
                None => [1.0; 3],
            };
            let path = dir.join(file.trim_start_matches("package://"));
            for v in obj_vertices(&path)? {
                let local = Point3::new(
                    v[0] * mesh_scale[0],
                    v[1] * mesh_scale[1],
                    v[2] * mesh_scale[2],
                );
                points.push(Point3::from((origin * local).coords * scale));
            }
        }
        if !points.is_empty() {
            handles.insert(name.to_owned(), HandleGeometry { points });
        }
    }
    Ok(handles)
}

/// The visual names of every link of the model `urdf`, by link name (links without a named
/// visual map to an empty list). Errors name the file.
pub fn link_visual_names(urdf: &Path) -> Result<BTreeMap<String, Vec<String>>, EnvError> {
    let bad = |what: String| EnvError::Asset(format!("{}: {what}", urdf.display()));
    let text = std::fs::read_to_string(urdf).map_err(|e| bad(e.to_string()))?;
    let doc = roxmltree::Document::parse(&text).map_err(|e| bad(e.to_string()))?;
    Ok(doc
        .descendants()
        .filter(|n| n.has_tag_name("link"))
        .map(|link| {
            let names = link
                .children()
                .filter(|n| n.has_tag_name("visual"))
                .filter_map(|v| v.attribute("name").map(str::to_owned))
                .collect();
            (link.attribute("name").unwrap_or_default().to_owned(), names)
        })
        .collect())
}

fn triple(s: &str) -> Result<[f32; 3], String> {
    let v: Vec<f32> = s
        .split_whitespace()
        .map(str::parse)
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{s:?}: {e}"))?;
    v.try_into()
        .map_err(|v: Vec<f32>| format!("expected 3 numbers, got {}", v.len()))
}

fn origin_pose(xyz: Option<&str>, rpy: Option<&str>) -> Result<Pose3, String> {
    let [x, y, z] = xyz.map(triple).transpose()?.unwrap_or([0.0; 3]);
    let [r, p, yaw] = rpy.map(triple).transpose()?.unwrap_or([0.0; 3]);
    Ok(Pose3::from_parts(
        Translation3::new(x, y, z),
        UnitQuaternion::from_euler_angles(r, p, yaw),
    ))
}

/// The `v` lines of an OBJ file.
fn obj_vertices(path: &Path) -> Result<Vec<[f32; 3]>, EnvError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| EnvError::Asset(format!("{}: {e}", path.display())))?;
    text.lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|rest| {
            let mut it = rest.split_whitespace().map(str::parse::<f32>);
            match (it.next(), it.next(), it.next()) {
                (Some(Ok(x)), Some(Ok(y)), Some(Ok(z))) => Ok([x, y, z]),
                _ => Err(EnvError::Asset(format!(
                    "{}: bad vertex line {rest:?}: expected three numbers",
                    path.display()
                ))),
            }
        })
        .collect()
}
