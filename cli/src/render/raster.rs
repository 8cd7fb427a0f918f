//! A small z-buffered rasteriser with smooth shading: the normal is interpolated across each
//! triangle from the vertex normals and shaded per sample, so a smooth surface draws smooth
//! (flat shading draws every row of facets as a band of its own) and only real ripples of
//! the cloth show as stripes. Supersampled for anti-aliasing, then composited over the
//! backdrop.

use tiny_skia::{Pixmap, PremultipliedColorU8};

use fraccloth::Vec3;

/// Colour samples with depth, `ss x ss` per output pixel.
pub(super) struct ZBuffer {
    w: usize,
    h: usize,
    ss: usize,
    depth: Vec<f32>,
    rgb: Vec<[f32; 3]>,
}

/// A projected vertex: pixel x, pixel y (down), depth along the view.
pub(super) type ScreenVertex = (f32, f32, f32);

impl ZBuffer {
    pub(super) fn new(width: u32, height: u32, ss: usize) -> Self {
        let (w, h) = (width as usize * ss, height as usize * ss);
        Self {
            w,
            h,
            ss,
            depth: vec![f32::INFINITY; w * h],
            rgb: vec![[0.0; 3]; w * h],
        }
    }

    /// Fills a triangle, interpolating depth and normal; `shade` colours a sample from its
    /// interpolated (not normalised) normal.
    pub(super) fn triangle(&mut self, v: [ScreenVertex; 3], n: [Vec3; 3], shade: impl Fn(Vec3) -> [f32; 3]) {
        let s = self.ss as f32;
        let p: [(f32, f32); 3] = v.map(|(x, y, _)| (x * s, y * s));
        let area = (p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[2].0 - p[0].0) * (p[1].1 - p[0].1);
        if area.abs() < 1e-12 || !area.is_finite() {
            return;
        }
        let (xmin, xmax) = (p[0].0.min(p[1].0).min(p[2].0), p[0].0.max(p[1].0).max(p[2].0));
        let (ymin, ymax) = (p[0].1.min(p[1].1).min(p[2].1), p[0].1.max(p[1].1).max(p[2].1));
        let x0 = xmin.floor().max(0.0) as usize;
        let y0 = ymin.floor().max(0.0) as usize;
        let x1 = (xmax.ceil().max(0.0) as usize).min(self.w);
        let y1 = (ymax.ceil().max(0.0) as usize).min(self.h);
        let edge =
            |a: (f32, f32), b: (f32, f32), x: f32, y: f32| (b.0 - a.0) * (y - a.1) - (b.1 - a.1) * (x - a.0);
        for py in y0..y1 {
            for px in x0..x1 {
                let (x, y) = (px as f32 + 0.5, py as f32 + 0.5);
                let w0 = edge(p[1], p[2], x, y) / area;
                let w1 = edge(p[2], p[0], x, y) / area;
                let w2 = 1.0 - w0 - w1;
                // Inclusive edges (a tiny tolerance) so that shared edges leave no cracks.
                if w0 < -1e-4 || w1 < -1e-4 || w2 < -1e-4 {
                    continue;
                }
                let z = w0 * v[0].2 + w1 * v[1].2 + w2 * v[2].2;
                let k = py * self.w + px;
                if z < self.depth[k] {
                    self.depth[k] = z;
                    let nn = n[0] * f64::from(w0) + n[1] * f64::from(w1) + n[2] * f64::from(w2);
                    self.rgb[k] = shade(nn);
                }
            }
        }
    }

    /// Fills a sphere drawn as a disc of radius `r` px at (cx, cy), its front at depth
    /// `depth - radius_world * sqrt(1 - d^2)`; `shade` colours a sample from the sphere's
    /// normal in camera space (x right, y up, z towards the viewer).
    pub(super) fn sphere(
        &mut self,
        c: ScreenVertex,
        r: f32,
        radius_world: f32,
        shade: impl Fn([f32; 3]) -> [f32; 3],
    ) {
        let s = self.ss as f32;
        let (cx, cy, rr) = (c.0 * s, c.1 * s, r.max(0.5) * s);
        let x0 = (cx - rr).floor().max(0.0) as usize;
        let y0 = (cy - rr).floor().max(0.0) as usize;
        let x1 = ((cx + rr).ceil().max(0.0) as usize).min(self.w);
        let y1 = ((cy + rr).ceil().max(0.0) as usize).min(self.h);
        for py in y0..y1 {
            for px in x0..x1 {
                let (dx, dy) = ((px as f32 + 0.5 - cx) / rr, (py as f32 + 0.5 - cy) / rr);
                let d2 = dx * dx + dy * dy;
                if d2 >= 1.0 {
                    continue;
                }
                let nz = (1.0 - d2).sqrt();
                let z = c.2 - radius_world * nz;
                let k = py * self.w + px;
                if z < self.depth[k] {
                    self.depth[k] = z;
                    self.rgb[k] = shade([dx, -dy, nz]);
                }
            }
        }
    }

    /// Averages each pixel's samples and blends them over `pix` by their coverage.
    pub(super) fn composite(&self, pix: &mut Pixmap) {
        let (pw, ss) = (pix.width() as usize, self.ss);
        let n = (ss * ss) as f32;
        let pixels = pix.pixels_mut();
        for (k, out) in pixels.iter_mut().enumerate() {
            let (ox, oy) = (k % pw, k / pw);
            let (mut sum, mut hits) = ([0.0f32; 3], 0.0f32);
            for sy in 0..ss {
                for sx in 0..ss {
                    let i = (oy * ss + sy) * self.w + ox * ss + sx;
                    if i < self.depth.len() && self.depth[i].is_finite() {
                        for c in 0..3 {
                            sum[c] += self.rgb[i][c];
                        }
                        hits += 1.0;
                    }
                }
            }
            if hits == 0.0 {
                continue;
            }
            let a = hits / n;
            let bg = [out.red(), out.green(), out.blue()].map(f32::from);
            let mix =
                |c: usize| ((sum[c] / hits).clamp(0.0, 1.0) * 255.0 * a + bg[c] * (1.0 - a)).round() as u8;
            if let Some(p) = PremultipliedColorU8::from_rgba(mix(0), mix(1), mix(2), 255) {
                *out = p;
            }
        }
    }
}

/// Area-weighted vertex normals of a triangle mesh (zero for a vertex with no area).
pub(super) fn vertex_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut n = vec![Vec3::zeros(); positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| i as usize);
        if a.max(b).max(c) >= positions.len() {
            continue;
        }
        let f = (positions[b] - positions[a]).cross(&(positions[c] - positions[a]));
        n[a] += f;
        n[b] += f;
        n[c] += f;
    }
    for v in &mut n {
        *v = v.try_normalize(0.0).unwrap_or_else(Vec3::zeros);
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearer_triangles_hide_farther_ones_and_edges_leave_no_cracks() {
        let mut z = ZBuffer::new(20, 20, 2);
        let up = [Vec3::z(); 3];
        // Two triangles making a square at depth 2, a farther one over all of it at depth 5.
        z.triangle([(0.0, 0.0, 5.0), (20.0, 0.0, 5.0), (0.0, 20.0, 5.0)], up, |_| {
            [0.0, 0.0, 1.0]
        });
        z.triangle([(2.0, 2.0, 2.0), (18.0, 2.0, 2.0), (18.0, 18.0, 2.0)], up, |_| {
            [1.0, 0.0, 0.0]
        });
        z.triangle([(2.0, 2.0, 2.0), (18.0, 18.0, 2.0), (2.0, 18.0, 2.0)], up, |_| {
            [1.0, 0.0, 0.0]
        });
        let mut pix = Pixmap::new(20, 20).unwrap();
        z.composite(&mut pix);
        // Inside the square every pixel is the near colour: no crack along the diagonal.
        for y in 3..17 {
            for x in 3..17 {
                let p = pix.pixel(x, y).unwrap();
                assert_eq!((p.red(), p.blue()), (255, 0), "({x}, {y})");
            }
        }
        assert_eq!(pix.pixel(1, 1).unwrap().blue(), 255);
    }
}
