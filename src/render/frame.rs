//! One picture of the cloth and its colliders.

use tiny_skia::{
    Color, FillRule, GradientStop, LinearGradient, Paint, PathBuilder, Pixmap, Point, RadialGradient, Shader,
    SpreadMode, Transform,
};

use super::Camera;
use crate::forces::{Collider, Sphere};
use crate::Vec3;

/// What one frame shows.
pub struct Scene3d<'a> {
    pub positions: &'a [Vec3],
    pub triangles: &'a [[u32; 3]],
    pub spheres: &'a [Sphere],
}

impl Scene3d<'_> {
    /// Spheres among a cloth's colliders.
    pub fn spheres_of(colliders: impl IntoIterator<Item = Collider>) -> Vec<Sphere> {
        colliders
            .into_iter()
            .filter_map(|c| match c {
                Collider::Sphere(s) => Some(s),
                _ => None,
            })
            .collect()
    }
}

const LIGHT: [f64; 3] = [-0.35, 0.8, 0.5];
const FRONT: [f32; 3] = [0.95, 0.55, 0.22]; // the paper's orange cloth
const BACK: [f32; 3] = [0.80, 0.42, 0.30];

fn backdrop(pix: &mut Pixmap) {
    let h = pix.height() as f32;
    let shader = LinearGradient::new(
        Point::from_xy(0.0, 0.0),
        Point::from_xy(0.0, h),
        vec![
            GradientStop::new(0.0, Color::from_rgba8(40, 110, 140, 255)),
            GradientStop::new(1.0, Color::from_rgba8(6, 28, 48, 255)),
        ],
        SpreadMode::Pad,
        Transform::identity(),
    );
    let mut paint = Paint::default();
    if let Some(s) = shader {
        paint.shader = s;
    }
    if let Some(rect) = tiny_skia::Rect::from_xywh(0.0, 0.0, pix.width() as f32, h) {
        pix.fill_rect(rect, &paint, Transform::identity(), None);
    }
}

enum Item {
    Triangle([(f32, f32); 3], Color),
    Sphere(f32, f32, f32),
}

/// Renders one frame into `pix` (cleared first).
pub fn render_frame(scene: &Scene3d<'_>, camera: &Camera, pix: &mut Pixmap) {
    backdrop(pix);
    let light = Vec3::new(LIGHT[0], LIGHT[1], LIGHT[2]).normalize();
    let mut items: Vec<(f64, Item)> = Vec::with_capacity(scene.triangles.len() + scene.spheres.len());
    for t in scene.triangles {
        let [a, b, c] = t.map(|i| scene.positions[i as usize]);
        let n = (b - a).cross(&(c - a));
        let len = n.norm();
        if len == 0.0 {
            continue;
        }
        let n = n / len;
        let centre = (a + b + c) / 3.0;
        let facing = n.dot(&camera.towards_eye(&centre)) >= 0.0;
        let n = if facing { n } else { -n };
        let lambert = n.dot(&light).max(0.0) as f32;
        let shade = 0.30 + 0.70 * lambert;
        let base = if facing { FRONT } else { BACK };
        let color =
            Color::from_rgba(base[0] * shade, base[1] * shade, base[2] * shade, 1.0).unwrap_or(Color::WHITE);
        let pa = camera.project(&a);
        let pb = camera.project(&b);
        let pc = camera.project(&c);
        let depth = (pa.2 + pb.2 + pc.2) / 3.0;
        items.push((
            depth,
            Item::Triangle([(pa.0, pa.1), (pb.0, pb.1), (pc.0, pc.1)], color),
        ));
    }
    for s in scene.spheres {
        let (x, y, z) = camera.project(&s.center);
        items.push((z, Item::Sphere(x, y, camera.pixel_radius(s.radius, z))));
    }
    // Painter's algorithm: far to near.
    items.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut paint = Paint {
        anti_alias: true,
        ..Paint::default()
    };
    for (_, item) in items {
        match item {
            Item::Triangle(p, color) => {
                let mut pb = PathBuilder::new();
                pb.move_to(p[0].0, p[0].1);
                pb.line_to(p[1].0, p[1].1);
                pb.line_to(p[2].0, p[2].1);
                pb.close();
                if let Some(path) = pb.finish() {
                    paint.shader = Shader::SolidColor(color);
                    pix.fill_path(&path, &paint, FillRule::Winding, Transform::identity(), None);
                    // A hairline of the same colour closes the anti-aliasing seams between triangles.
                    let stroke = tiny_skia::Stroke {
                        width: 0.6,
                        ..Default::default()
                    };
                    pix.stroke_path(&path, &paint, &stroke, Transform::identity(), None);
                }
            }
            Item::Sphere(x, y, r) => {
                if let Some(circle) = PathBuilder::from_circle(x, y, r.max(1.0)) {
                    let shader = RadialGradient::new(
                        Point::from_xy(x - 0.35 * r, y - 0.35 * r),
                        0.0,
                        Point::from_xy(x, y),
                        r * 1.1,
                        vec![
                            GradientStop::new(0.0, Color::from_rgba8(235, 235, 240, 255)),
                            GradientStop::new(1.0, Color::from_rgba8(80, 85, 100, 255)),
                        ],
                        SpreadMode::Pad,
                        Transform::identity(),
                    );
                    paint.shader =
                        shader.unwrap_or(Shader::SolidColor(Color::from_rgba8(150, 150, 160, 255)));
                    pix.fill_path(&circle, &paint, FillRule::Winding, Transform::identity(), None);
                }
            }
        }
    }
}
