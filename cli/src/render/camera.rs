//! A pinhole camera that frames a box of the scene.

use fraccloth::Vec3;

/// Perspective camera; `project` maps world points to pixels (y down) and a depth.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    pub eye: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    /// Focal length in pixels.
    focal: f64,
    pub width: u32,
    pub height: u32,
}

impl Camera {
    /// Looks at `target` from `eye` with the given vertical field of view (radians).
    pub fn look_at(eye: Vec3, target: Vec3, fov_y: f64, width: u32, height: u32) -> Self {
        let forward = (target - eye).normalize();
        let mut right = forward.cross(&Vec3::y());
        if right.norm() < 1e-9 {
            right = Vec3::x();
        }
        let right = right.normalize();
        let up = right.cross(&forward);
        let focal = 0.5 * f64::from(height) / (0.5 * fov_y).tan();
        Self {
            eye,
            right,
            up,
            forward,
            focal,
            width,
            height,
        }
    }

    /// A fixed 3/4 view that keeps the box `[lo, hi]` (world, m) in frame.
    pub fn framing(lo: Vec3, hi: Vec3, width: u32, height: u32) -> Self {
        let center = 0.5 * (lo + hi);
        let radius = 0.5 * (hi - lo).norm().max(1e-3);
        let fov = 40f64.to_radians();
        let distance = 0.95 * radius / (0.5 * fov).sin();
        let dir = Vec3::new(0.62, 0.28, 0.73).normalize();
        Self::look_at(center + distance * dir, center, fov, width, height)
    }

    /// The fixed preview camera of a cloth: its rest box, widened by how far the built-in
    /// scenes move it (8 cm sideways, 4 cm vertically, 12 cm out of plane).
    pub fn for_rest_shape(rest: &[Vec3], width: u32, height: u32) -> Self {
        let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
        for p in rest {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let margin = Vec3::new(0.08, 0.04, 0.12);
        Self::framing(lo - margin, hi + margin, width, height)
    }

    /// Pixel coordinates (x right, y down) and the distance along the view direction.
    pub fn project(&self, p: &Vec3) -> (f32, f32, f64) {
        let d = p - self.eye;
        let z = d.dot(&self.forward).max(1e-6);
        let x = 0.5 * f64::from(self.width) + self.focal * d.dot(&self.right) / z;
        let y = 0.5 * f64::from(self.height) - self.focal * d.dot(&self.up) / z;
        (x as f32, y as f32, z)
    }

    /// Radius in pixels of a sphere of radius `r` at depth `z`.
    pub fn pixel_radius(&self, r: f64, z: f64) -> f32 {
        (self.focal * r / z) as f32
    }

    /// Unit vector from `p` towards the eye.
    pub fn towards_eye(&self, p: &Vec3) -> Vec3 {
        (self.eye - p).normalize()
    }
}
