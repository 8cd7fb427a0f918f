//! One picture of the cloth and its colliders.

use tiny_skia::{Color, GradientStop, LinearGradient, Paint, Pixmap, Point, SpreadMode, Transform};

use super::raster::{vertex_normals, ZBuffer};
use super::Camera;
use fraccloth::forces::{Collider, Sphere};
use fraccloth::Vec3;

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

/// Supersampling per axis.
const SUPERSAMPLE: usize = 2;

fn shade(base: [f32; 3], brightness: f32) -> [f32; 3] {
    base.map(|c| c * brightness)
}

/// Renders one frame into `pix` (cleared first): the cloth smooth-shaded from its vertex
/// normals (both sides, lit from above), spheres shaded, everything depth-tested.
pub fn render_frame(scene: &Scene3d<'_>, camera: &Camera, pix: &mut Pixmap) {
    backdrop(pix);
    let light = Vec3::new(LIGHT[0], LIGHT[1], LIGHT[2]).normalize();
    let normals = vertex_normals(scene.positions, scene.triangles);
    let mut z = ZBuffer::new(pix.width(), pix.height(), SUPERSAMPLE);
    for t in scene.triangles {
        let idx = t.map(|i| i as usize);
        if idx.iter().any(|&i| i >= scene.positions.len()) {
            continue;
        }
        let [a, b, c] = idx.map(|i| scene.positions[i]);
        let centre = (a + b + c) / 3.0;
        let eye = camera.towards_eye(&centre);
        let v = [a, b, c].map(|p| {
            let (x, y, d) = camera.project(&p);
            (x, y, d as f32)
        });
        z.triangle(v, idx.map(|i| normals[i]), |n| {
            // The side facing the camera is lit; its colour says which side it is.
            let facing = n.dot(&eye) >= 0.0;
            let n = if facing { n } else { -n };
            let n = n.try_normalize(0.0).unwrap_or(eye);
            let lambert = n.dot(&light).max(0.0) as f32;
            shade(if facing { FRONT } else { BACK }, 0.30 + 0.70 * lambert)
        });
    }
    // Light in camera space for the spheres: up, a little left, towards the viewer.
    let l = [-0.35f32, 0.6, 0.72];
    for s in scene.spheres {
        let (x, y, d) = camera.project(&s.center);
        let r = camera.pixel_radius(s.radius, d);
        z.sphere((x, y, d as f32), r, s.radius as f32, |n| {
            let lambert = (n[0] * l[0] + n[1] * l[1] + n[2] * l[2]).max(0.0);
            shade([0.86, 0.87, 0.9], 0.3 + 0.7 * lambert)
        });
    }
    z.composite(pix);
}
