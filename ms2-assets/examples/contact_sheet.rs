//! Renders contact sheets of the procedural object families with ms2-render (offscreen):
//! `cargo run --release -p ms2-assets --example contact_sheet -- <asset dir> <out dir>`
//! writes `<out dir>/objects_household.png` (12 household objects),
//! `<out dir>/objects_egad.png` (12 EGAD-like shapes, one per complexity × difficulty corner
//! and diagonal cell), `<out dir>/articulated_cabinets.png` (6 drawer and 6 door cabinets) and
//! `<out dir>/articulated_chairs_buckets.png` (8 swivel chairs, 4 buckets).

use std::path::{Path, PathBuf};

use ms2_assets::objects::{
    ensure_family_in, load_model_db, model_files, read_visual_parts, ObjectFamily, ObjectKind,
    Split,
};
use ms2_render::{
    Camera, Instance, Material, MeshData, Renderer, RendererConfig, Scene, SegmentationIds,
};
use nalgebra::{Isometry3, Point3, Vector3};

fn flat(piece: &ms2_assets::objects::MeshPiece) -> MeshData {
    let mut m = MeshData::default();
    for t in &piece.triangles {
        let [a, b, c] = t.map(|i| Vector3::from(piece.vertices[i as usize]));
        let n = (b - a)
            .cross(&(c - a))
            .try_normalize(1e-12)
            .unwrap_or(Vector3::z());
        for p in [a, b, c] {
            m.indices.push(m.positions.len() as u32);
            m.positions.push([p.x, p.y, p.z]);
            m.normals.push([n.x, n.y, n.z]);
        }
    }
    m
}

/// One model of a sheet: its pieces (model frame) with their colours, and its yaw (rad) and
/// lift (m) on the grid.
struct SheetModel {
    parts: Vec<(MeshData, [f32; 3])>,
    yaw: f32,
    lift: f32,
}

/// Renders up to 12 models on a 4-wide grid `spacing` m apart, seen from −y and above.
fn render_grid(
    renderer: &Renderer,
    models: &[SheetModel],
    spacing: f32,
    out: &Path,
) -> Result<(), Box<dyn std::error::Error>> {
    let mut scene = Scene::new();
    scene.lighting.background = [0.18, 0.2, 0.24];
    let ground = renderer.add_mesh(&MeshData::plane(2.0 * spacing / 0.3, 2.0 * spacing / 0.3))?;
    let rows = models.len().div_ceil(4) as f32;
    for (k, model) in models.iter().enumerate() {
        let (col, row) = ((k % 4) as f32, (k / 4) as f32);
        let pose = Isometry3::new(
            Vector3::new(
                (col - 1.5) * spacing,
                ((rows - 1.0) / 2.0 - row) * spacing,
                model.lift,
            ),
            Vector3::z() * model.yaw,
        );
        for (j, (mesh, c)) in model.parts.iter().enumerate() {
            let mesh = renderer.add_mesh(mesh)?;
            let ids = SegmentationIds {
                actor: k as u32 + 1,
                link: j as u32 + 1,
            };
            scene.add_instance(Instance::new(
                mesh,
                Material::color(c[0], c[1], c[2]),
                pose,
                ids,
            ));
        }
    }
    scene.add_instance(Instance::new(
        ground,
        Material::color(0.42, 0.42, 0.4),
        Isometry3::identity(),
        SegmentationIds {
            actor: 99,
            link: 99,
        },
    ));
    let cam = Camera::new(960, 720, 0.6, 0.01, 10.0 * spacing / 0.3).looking_at(
        Point3::new(0.0, -spacing * 4.6, spacing * 4.4),
        Point3::new(0.0, 0.0, 0.0),
        Vector3::z(),
    );
    let images = renderer.render(&[(&scene, &[cam][..])])?;
    images[0].save_rgb_png(out)?;
    println!("wrote {}", out.display());
    Ok(())
}

fn sheet(
    renderer: &Renderer,
    root: &Path,
    kind: ObjectKind,
    ids: &[String],
    spacing: f32,
    out: &Path,
) -> Result<(), Box<dyn std::error::Error>> {
    let db = load_model_db(root, kind, Some(Split::of_egad_id(&ids[0])))?;
    let mut models = Vec::new();
    for (k, id) in ids.iter().enumerate() {
        let info = db.get(id)?;
        let lift = -info.bbox.map(|b| b.min[2]).unwrap_or(0.0) as f32;
        let files = model_files(root, kind, id);
        let mut parts = Vec::new();
        for part in read_visual_parts(&files.visual, id)? {
            let c = part.rgba.unwrap_or({
                // EGAD-like shapes carry no colour (ManiSkill2 picks one per episode).
                let h = (k as f32 * 0.37).fract();
                [0.3 + 0.5 * h, 0.75 - 0.4 * h, 0.35 + 0.3 * (1.0 - h), 1.0]
            });
            parts.push((flat(&part), [c[0], c[1], c[2]]));
        }
        models.push(SheetModel {
            parts,
            yaw: 0.0,
            lift,
        });
    }
    render_grid(renderer, &models, spacing, out)
}

/// A sheet of procedural articulated models (`(category, index)`), at rest, fronts (−x)
/// turned towards the camera.
fn articulated_sheet(
    renderer: &Renderer,
    picks: &[(&str, usize)],
    spacing: f32,
    out: &Path,
) -> Result<(), Box<dyn std::error::Error>> {
    let mut models = Vec::new();
    for (category, index) in picks {
        let parts = ms2_assets::partnet::preview(category, *index)?
            .into_iter()
            .map(|p| {
                let piece = ms2_assets::objects::MeshPiece {
                    name: String::new(),
                    vertices: p.vertices,
                    triangles: p.triangles,
                    rgba: None,
                };
                (flat(&piece), [p.rgba[0], p.rgba[1], p.rgba[2]])
            })
            .collect();
        models.push(SheetModel {
            parts,
            yaw: std::f32::consts::FRAC_PI_2,
            lift: 0.0,
        });
    }
    render_grid(renderer, &models, spacing, out)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let dir = args
        .next()
        .map(PathBuf::from)
        .unwrap_or_else(ms2_assets::asset_dir);
    let out = args
        .next()
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("."));
    let renderer = Renderer::new(RendererConfig::default())?;

    let root = ensure_family_in(ObjectFamily::Household, &dir)?;
    let db = load_model_db(&root, ObjectKind::Ycb, None)?;
    let all: Vec<String> = db.ids().map(str::to_owned).collect();
    // Every category: the first can, box, bottle, jar, mug, bowl, 3 fruit, 3 tools.
    let pick = [0, 10, 20, 27, 34, 42, 47, 51, 53, 56, 57, 59];
    let ids: Vec<String> = pick.iter().map(|&i| all[i].clone()).collect();
    sheet(
        &renderer,
        &root,
        ObjectKind::Ycb,
        &ids,
        0.3,
        &out.join("objects_household.png"),
    )?;

    let root = ensure_family_in(ObjectFamily::Egad, &dir)?;
    let cells = [
        (0, 0),
        (0, 3),
        (0, 6),
        (2, 1),
        (2, 5),
        (3, 3),
        (4, 0),
        (4, 6),
        (5, 2),
        (6, 0),
        (6, 3),
        (6, 6),
    ];
    let ids: Vec<String> = cells
        .iter()
        .map(|&(c, d)| format!("{}_0", ms2_assets::objects::egad::cell_name(c, d)))
        .collect();
    sheet(
        &renderer,
        &root,
        ObjectKind::Egad,
        &ids,
        0.16,
        &out.join("objects_egad.png"),
    )?;

    use ms2_assets::partnet::{bucket, cabinet, chair};
    let cabinets: Vec<(&str, usize)> = [0, 1, 2, 4, 5, 6]
        .iter()
        .map(|&i| (cabinet::DRAWER_CATEGORY, i))
        .chain([0, 1, 2, 4, 5, 6].iter().map(|&i| (cabinet::DOOR_CATEGORY, i)))
        .collect();
    articulated_sheet(&renderer, &cabinets, 1.25, &out.join("articulated_cabinets.png"))?;
    let seats: Vec<(&str, usize)> = (0..8)
        .map(|i| (chair::CATEGORY, i))
        .chain((0..4).map(|i| (bucket::CATEGORY, i)))
        .collect();
    articulated_sheet(&renderer, &seats, 0.8, &out.join("articulated_chairs_buckets.png"))?;
    Ok(())
}
