//! What every procedural articulated family shares: the train/test split rule, a small URDF
//! writer (mesh links with named visuals, joints with limits and dynamics) and the writing of a
//! whole family into the PartNet-Mobility layout (atomic files, info files last, a version
//! stamp so a changed generator regenerates its models).

use std::fmt::Write;
use std::path::{Path, PathBuf};

use super::obj::{to_obj, Piece};
use super::{info_path, model_dir, write_atomic, ModelDb, ModelInfo, PROCEDURAL_DIR};
use crate::error::AssetError;

/// The split of variant `index` of any family: `test` for every fourth (`index % 4 == 3`),
/// else `train`.
pub fn split_of(index: usize) -> &'static str {
    if index % 4 == 3 {
        "test"
    } else {
        "train"
    }
}

/// The procedural dataset folder under an asset directory.
pub fn procedural_root(asset_dir: &Path) -> PathBuf {
    asset_dir.join(PROCEDURAL_DIR)
}

/// One generated model: its files and its info entry.
pub(crate) struct GeneratedModel {
    /// Model id (the folder name).
    pub(crate) model_id: String,
    /// The info file category it belongs to (e.g. `cabinet_drawer`).
    pub(crate) category: &'static str,
    /// `train` or `test`.
    pub(crate) split: &'static str,
    /// The info entry.
    pub(crate) info: ModelInfo,
    /// URDF text (written as `mobility_cvx.urdf`).
    pub(crate) urdf: String,
    /// Meshes: file name under `meshes/` and its convex pieces (one OBJ object each).
    pub(crate) meshes: Vec<(String, Vec<Piece>)>,
    /// What the URDF holds (for previews).
    pub(crate) layout: UrdfLayout,
}

impl GeneratedModel {
    /// The model's visual meshes at its zero configuration (model frame), for previews.
    pub(crate) fn preview(&self) -> Vec<PreviewPart> {
        let mut out = Vec::new();
        for (mesh, offset, rgba) in self.layout.visuals() {
            let Some((_, pieces)) = self.meshes.iter().find(|(f, _)| *f == mesh) else {
                continue;
            };
            for piece in pieces {
                let piece = piece.clone().translated(offset);
                out.push(PreviewPart {
                    vertices: piece.vertices.iter().map(|v| f32x3(*v)).collect(),
                    triangles: piece.faces.iter().map(|f| f.map(|i| i as u32)).collect(),
                    rgba,
                });
            }
        }
        out
    }
}

/// One convex piece of a model's visual geometry at rest (model frame, m), with its colour.
#[derive(Clone, Debug, PartialEq)]
pub struct PreviewPart {
    /// Vertices (m).
    pub vertices: Vec<[f32; 3]>,
    /// Triangles, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
    /// Linear RGBA colour.
    pub rgba: [f32; 4],
}

/// What a [`UrdfWriter`] wrote, for previews: materials, each link's visual meshes and each
/// joint's parent, child and origin (translations only, as the families write them).
#[derive(Clone, Debug, Default)]
pub(crate) struct UrdfLayout {
    materials: Vec<(String, [f32; 4])>,
    visuals: Vec<(String, String, String)>,
    joints: Vec<(String, String, [f64; 3])>,
}

impl UrdfLayout {
    /// Link origin (model frame) at the zero configuration.
    fn link_offset(&self, link: &str) -> [f64; 3] {
        let mut at = [0.0; 3];
        let mut current = link.to_string();
        while let Some((parent, _, o)) = self.joints.iter().find(|(_, c, _)| *c == current) {
            for i in 0..3 {
                at[i] += o[i];
            }
            current = parent.clone();
        }
        at
    }

    /// (mesh file, link offset, colour) of every visual.
    fn visuals(&self) -> Vec<(String, [f64; 3], [f32; 4])> {
        self.visuals
            .iter()
            .map(|(link, mesh, material)| {
                let rgba = self
                    .materials
                    .iter()
                    .find(|(m, _)| m == material)
                    .map_or([0.7, 0.7, 0.7, 1.0], |(_, c)| *c);
                (mesh.clone(), self.link_offset(link), rgba)
            })
            .collect()
    }
}

/// Makes sure the models of a family exist under `asset_dir`: when the stamp
/// `meta/<stamp>.version` differs from `version` or an info file of `categories` is missing,
/// writes every model of `generate()` (each file atomically), then the info files, then the
/// stamp. Returns the dataset root.
pub(crate) fn ensure_family(
    asset_dir: &Path,
    stamp: &str,
    version: u32,
    categories: &[&str],
    generate: impl FnOnce() -> Vec<GeneratedModel>,
) -> Result<PathBuf, AssetError> {
    let root = procedural_root(asset_dir);
    let stamp_file = root.join("meta").join(format!("{stamp}.version"));
    let current = version.to_string();
    let up_to_date = std::fs::read_to_string(&stamp_file).is_ok_and(|s| s.trim() == current)
        && categories.iter().all(|c| {
            ["train", "test"]
                .iter()
                .all(|s| info_path(&root, c, s).is_file())
        });
    if up_to_date {
        return Ok(root);
    }
    let mut dbs: Vec<(&str, &str, ModelDb)> = categories
        .iter()
        .flat_map(|c| [(*c, "train", ModelDb::new()), (*c, "test", ModelDb::new())])
        .collect();
    for model in generate() {
        let dir = model_dir(&root, &model.model_id);
        let header = format!("ms2 procedural model {}, metres", model.model_id);
        for (file, pieces) in &model.meshes {
            write_atomic(
                &dir.join("meshes").join(file),
                to_obj(pieces, &header).as_bytes(),
            )?;
        }
        write_atomic(&dir.join(super::URDF_NAMES[0]), model.urdf.as_bytes())?;
        let db = dbs
            .iter_mut()
            .find(|(c, s, _)| *c == model.category && *s == model.split)
            .ok_or_else(|| AssetError::Generation {
                family: stamp.to_string(),
                reason: format!(
                    "model {} has category {} / split {}: expected one of {categories:?} / train, test",
                    model.model_id, model.category, model.split
                ),
            })?;
        db.2.insert(model.model_id, model.info);
    }
    for (category, split, db) in &dbs {
        let text = serde_json::to_string_pretty(db).expect("info serializes");
        write_atomic(&info_path(&root, category, split), text.as_bytes())?;
    }
    write_atomic(&stamp_file, current.as_bytes())?;
    Ok(root)
}

/// Kind of a URDF joint written by [`UrdfWriter::joint`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum JointKind {
    /// Welded.
    Fixed,
    /// Rotation within limits (rad).
    Revolute,
    /// Unlimited rotation.
    Continuous,
    /// Translation within limits (m).
    Prismatic,
}

/// One joint: parent and child links, origin (m, parent frame; no rotation), axis, limits,
/// effort limit (N·m or N) and `<dynamics>` (damping N·m·s/rad or N·s/m, friction N·m or N).
#[derive(Clone, Debug)]
pub(crate) struct JointSpec<'a> {
    pub(crate) name: &'a str,
    pub(crate) kind: JointKind,
    pub(crate) parent: &'a str,
    pub(crate) child: &'a str,
    pub(crate) origin: [f64; 3],
    pub(crate) axis: [f64; 3],
    pub(crate) limits: [f64; 2],
    pub(crate) effort: f64,
    pub(crate) damping: f64,
    pub(crate) friction: f64,
}

/// One visual of a link: its name (ManiSkill2's tasks find handles, wheels and seats by the
/// visual's name), its mesh under `meshes/`, its material, and whether the same mesh is also a
/// collision shape (of the same name).
pub(crate) struct NamedMesh<'a> {
    pub(crate) name: &'a str,
    pub(crate) mesh: &'a str,
    pub(crate) material: &'a str,
    pub(crate) collides: bool,
}

impl<'a> NamedMesh<'a> {
    /// A visual that is also a collision shape.
    pub(crate) fn solid(name: &'a str, mesh: &'a str, material: &'a str) -> Self {
        NamedMesh {
            name,
            mesh,
            material,
            collides: true,
        }
    }
}

/// Writes URDF text for the procedural families.
pub(crate) struct UrdfWriter {
    text: String,
    layout: UrdfLayout,
}

impl UrdfWriter {
    /// A robot named `model_id` with the named RGBA materials.
    pub(crate) fn new(
        model_id: &str,
        family: &str,
        version: u32,
        materials: &[(&str, [f32; 4])],
    ) -> Self {
        let mut text = String::new();
        let _ = writeln!(text, "<?xml version=\"1.0\"?>");
        let _ = writeln!(
            text,
            "<!-- ms2 procedural {family} {model_id} (generator v{version}); metres, radians -->"
        );
        let _ = writeln!(text, "<robot name=\"{model_id}\">");
        for (name, c) in materials {
            let _ = writeln!(
                text,
                "  <material name=\"{name}\"><color rgba=\"{} {} {} {}\"/></material>",
                c[0], c[1], c[2], c[3]
            );
        }
        UrdfWriter {
            text,
            layout: UrdfLayout {
                materials: materials.iter().map(|(n, c)| (n.to_string(), *c)).collect(),
                ..UrdfLayout::default()
            },
        }
    }

    /// A link without geometry (a root frame).
    pub(crate) fn empty_link(&mut self, name: &str) {
        let _ = writeln!(self.text, "  <link name=\"{name}\"/>");
    }

    /// A link whose visuals are `meshes` (each also a collision of the same name), plus extra
    /// collision-only spheres `(name, centre, radius)`.
    pub(crate) fn link(
        &mut self,
        name: &str,
        meshes: &[NamedMesh],
        spheres: &[(&str, [f64; 3], f64)],
    ) {
        let _ = writeln!(self.text, "  <link name=\"{name}\">");
        for m in meshes {
            self.layout
                .visuals
                .push((name.into(), m.mesh.into(), m.material.into()));
            let _ = writeln!(
                self.text,
                "    <visual name=\"{}\"><origin xyz=\"0 0 0\"/><geometry><mesh filename=\"meshes/{}\"/></geometry><material name=\"{}\"/></visual>",
                m.name, m.mesh, m.material
            );
        }
        for m in meshes.iter().filter(|m| m.collides) {
            let _ = writeln!(
                self.text,
                "    <collision name=\"{}\"><origin xyz=\"0 0 0\"/><geometry><mesh filename=\"meshes/{}\"/></geometry></collision>",
                m.name, m.mesh
            );
        }
        for (n, c, r) in spheres {
            let _ = writeln!(
                self.text,
                "    <collision name=\"{n}\"><origin xyz=\"{:.6} {:.6} {:.6}\"/><geometry><sphere radius=\"{r:.6}\"/></geometry></collision>",
                c[0], c[1], c[2]
            );
        }
        let _ = writeln!(self.text, "  </link>");
    }

    /// A joint.
    pub(crate) fn joint(&mut self, j: &JointSpec) {
        self.layout
            .joints
            .push((j.parent.into(), j.child.into(), j.origin));
        let kind = match j.kind {
            JointKind::Fixed => "fixed",
            JointKind::Revolute => "revolute",
            JointKind::Continuous => "continuous",
            JointKind::Prismatic => "prismatic",
        };
        let _ = write!(
            self.text,
            "  <joint name=\"{}\" type=\"{kind}\"><parent link=\"{}\"/><child link=\"{}\"/><origin xyz=\"{:.6} {:.6} {:.6}\" rpy=\"0 0 0\"/>",
            j.name, j.parent, j.child, j.origin[0], j.origin[1], j.origin[2]
        );
        if j.kind != JointKind::Fixed {
            let _ = write!(
                self.text,
                "<axis xyz=\"{} {} {}\"/>",
                j.axis[0], j.axis[1], j.axis[2]
            );
            if matches!(j.kind, JointKind::Revolute | JointKind::Prismatic) {
                let _ = write!(
                    self.text,
                    "<limit lower=\"{:.6}\" upper=\"{:.6}\" effort=\"{}\" velocity=\"3\"/>",
                    j.limits[0], j.limits[1], j.effort
                );
            }
            let _ = write!(
                self.text,
                "<dynamics damping=\"{}\" friction=\"{}\"/>",
                j.damping, j.friction
            );
        }
        let _ = writeln!(self.text, "</joint>");
    }

    /// The finished text and what it holds.
    pub(crate) fn finish(mut self) -> (String, UrdfLayout) {
        let _ = writeln!(self.text, "</robot>");
        (self.text, self.layout)
    }
}

/// `[f64; 3]` → `[f32; 3]`.
pub(crate) fn f32x3(v: [f64; 3]) -> [f32; 3] {
    [v[0] as f32, v[1] as f32, v[2] as f32]
}
