//! The look meter: from any point cache of a hanging cloth driven at its top edge (ours, or
//! one another tool wrote) to the look descriptors of its centre column.
//!
//! 1. **Material frame.** The rest mesh is taken as flat: its two principal axes span the
//!    material plane. The material "up" is the in-plane direction along which the cloth's
//!    mean height over the measured frames rises fastest (so a cloth that was modelled lying
//!    flat and hangs in the cache is read correctly); "across" is perpendicular to it.
//! 2. **Centre column.** The vertex of the top edge nearest the middle of the cloth's width,
//!    and every vertex within a quarter of the mesh spacing of its across coordinate, ordered
//!    by rest depth below the top. When those vertices cover fewer than three quarters of the
//!    rows one spacing apart that the column's depth holds (a mesh whose vertices do not line
//!    up), the column is resampled instead: one point a spacing apart down that line, each
//!    carried by the rest triangle it lies in (barycentric weights of its three vertices).
//! 3. **Drive.** The out-of-plane axis is the principal horizontal direction of the top
//!    vertex's motion over the second half of the cache; the drive frequency is its dominant
//!    harmonic there ([`super::harmonic::dominant_frequency`]).
//! 4. **Window.** The last whole number of drive periods that fits in the second half.
//! 5. **Harmonics and descriptors** ([`super::descriptors`]), in absolute coordinates.

use nalgebra::{Complex, Matrix2, Matrix3, SymmetricEigen, Vector2};

use super::descriptors::{describe, ColumnMotion, Descriptors};
use super::harmonic::{complex_amplitude, dominant_frequency};
use fraccloth::error::Error;
use fraccloth::math::Vec3;

/// A measured look: the drive, the column and its descriptors.
#[derive(Clone, Debug, PartialEq)]
pub struct Look {
    /// Drive frequency found in the top's motion, Hz.
    pub drive_frequency: f64,
    /// Unit out-of-plane axis (horizontal), in the cache's coordinates.
    pub out_of_plane: Vec3,
    /// Unit up axis used, in the cache's coordinates.
    pub up: Vec3,
    /// Vertex indices of the centre column, top first (for a resampled column, the vertex of
    /// largest weight of each point).
    pub column: Vec<usize>,
    /// Each row of the column as vertices and weights (one vertex of weight 1 unless the column
    /// was resampled).
    pub column_weights: Vec<Vec<(usize, f64)>>,
    /// Measured window: start and end time, s, and the whole drive periods it holds.
    pub window: (f64, f64, u32),
    /// The descriptors.
    pub descriptors: Descriptors,
    /// The column's motion over the window (absolute coordinates), for pictures.
    pub motion: ColumnMotion,
    /// The column's motion over the whole cache, for the space-time picture.
    pub history: ColumnMotion,
}

/// Median edge length of the triangles, m.
fn spacing(rest: &[Vec3], triangles: &[[u32; 3]]) -> Result<f64, Error> {
    let mut lengths: Vec<f64> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k] as usize, t[(k + 1) % 3] as usize)))
        .filter_map(|(a, b)| Some((rest.get(a)? - rest.get(b)?).norm()))
        .filter(|l| *l > 0.0)
        .collect();
    if lengths.is_empty() {
        return Err(Error::invalid(
            "the rest mesh has no faces with edges of positive length",
        ));
    }
    let mid = lengths.len() / 2;
    let (_, m, _) = lengths.select_nth_unstable_by(mid, f64::total_cmp);
    Ok(*m)
}

/// Two orthonormal vectors spanning the rest mesh's plane (its largest principal axes).
fn material_plane(rest: &[Vec3]) -> (Vec3, Vec3, Vec3) {
    let n = rest.len().max(1) as f64;
    let c = rest.iter().sum::<Vec3>() / n;
    let mut cov = Matrix3::zeros();
    for p in rest {
        let d = p - c;
        cov += d * d.transpose();
    }
    let eig = SymmetricEigen::new(cov);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    let e1: Vec3 = eig.eigenvectors.column(order[0]).into();
    let e2: Vec3 = eig.eigenvectors.column(order[1]).into();
    (c, e1, e2)
}

/// Measures the look of a cache: `rest` positions and `triangles` of the rest mesh,
/// `frames[k]` the positions at `times[k]` (s, increasing), `up` the vertical (any length).
pub fn measure(
    rest: &[Vec3],
    triangles: &[[u32; 3]],
    frames: &[Vec<Vec3>],
    times: &[f64],
    up: Vec3,
) -> Result<Look, Error> {
    let n = rest.len();
    if n < 4 {
        return Err(Error::invalid("the rest mesh needs at least 4 vertices"));
    }
    if frames.len() != times.len() || frames.len() < 8 {
        return Err(Error::invalid(format!(
            "the cache needs at least 8 frames with a time each, got {} frames and {} times",
            frames.len(),
            times.len()
        )));
    }
    if let Some((k, f)) = frames.iter().enumerate().find(|(_, f)| f.len() != n) {
        return Err(Error::invalid(format!(
            "frame {k} has {} vertices, the rest mesh {n}",
            f.len()
        )));
    }
    if times.windows(2).any(|w| w[1].is_nan() || w[1] <= w[0]) || times.iter().any(|t| !t.is_finite()) {
        return Err(Error::invalid("frame times must be finite and increasing"));
    }
    if frames.iter().flatten().any(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(Error::invalid("the cache holds a non-finite position"));
    }
    let up = up
        .try_normalize(0.0)
        .ok_or_else(|| Error::invalid("the up axis must be a non-zero vector"))?;
    let h = spacing(rest, triangles)?;

    // The second half of the cache.
    let t_mid = 0.5 * (times[0] + times[times.len() - 1]);
    let second: Vec<usize> = (0..times.len()).filter(|&k| times[k] >= t_mid).collect();

    // 1. Material frame: up in the material plane from the mean heights of the second half.
    let (c, e1, e2) = material_plane(rest);
    let s: Vec<Vector2<f64>> = rest
        .iter()
        .map(|p| Vector2::new((p - c).dot(&e1), (p - c).dot(&e2)))
        .collect();
    let mean_height: Vec<f64> = (0..n)
        .map(|i| second.iter().map(|&k| frames[k][i].dot(&up)).sum::<f64>() / second.len() as f64)
        .collect();
    let (mut a, mut b) = (Matrix3::<f64>::zeros(), nalgebra::Vector3::<f64>::zeros());
    for i in 0..n {
        let row = nalgebra::Vector3::new(1.0, s[i].x, s[i].y);
        a += row * row.transpose();
        b += row * mean_height[i];
    }
    let grad = a
        .cholesky()
        .map(|ch| ch.solve(&b))
        .map(|g| Vector2::new(g[1], g[2]))
        .filter(|g| g.norm() > 0.1)
        .ok_or_else(|| {
            Error::invalid("the cloth does not hang: its height does not follow the rest mesh's plane")
        })?;
    let g_up = grad.normalize();
    let across = Matrix2::new(0.0, -1.0, 1.0, 0.0) * g_up;
    let height: Vec<f64> = s.iter().map(|v| v.dot(&g_up)).collect();
    let width: Vec<f64> = s.iter().map(|v| v.dot(&across)).collect();

    // 2. Centre column.
    let top_h = height.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let (wmin, wmax) = width
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &w| {
            (a.min(w), b.max(w))
        });
    let mid = 0.5 * (wmin + wmax);
    let top_vertex = (0..n)
        .filter(|&i| height[i] >= top_h - 0.5 * h)
        .min_by(|&i, &j| (width[i] - mid).abs().total_cmp(&(width[j] - mid).abs()))
        .ok_or_else(|| Error::invalid("no top edge found"))?;
    let mut column: Vec<usize> = (0..n)
        .filter(|&i| (width[i] - width[top_vertex]).abs() < 0.25 * h)
        .collect();
    column.sort_by(|&i, &j| height[j].total_cmp(&height[i]));
    column.dedup_by(|a, b| (height[*a] - height[*b]).abs() < 1e-9 * h.max(1e-30));
    if column.len() < 4 || column[0] != top_vertex {
        return Err(Error::invalid(format!(
            "the centre column has {} rows; at least 4 are needed",
            column.len()
        )));
    }
    let mut depths: Vec<f64> = column.iter().map(|&i| height[top_vertex] - height[i]).collect();
    let mut rows: Vec<Vec<(usize, f64)>> = column.iter().map(|&i| vec![(i, 1.0)]).collect();
    // Sparse: resample the line through the top vertex, one point a spacing apart.
    let bottom_h = height.iter().copied().fold(f64::INFINITY, f64::min);
    let expected = ((height[top_vertex] - bottom_h) / h).floor() as usize + 1;
    if 4 * column.len() < 3 * expected {
        let line = width[top_vertex];
        let locate = |hh: f64| -> Option<Vec<(usize, f64)>> {
            triangles.iter().find_map(|t| {
                let [a, b, c] = t.map(|i| i as usize);
                let p = |i: usize| Vector2::new(width[i], height[i]);
                let (pa, pb, pc) = (p(a), p(b), p(c));
                let m = Matrix2::from_columns(&[pb - pa, pc - pa]);
                let uv = m.try_inverse()? * (Vector2::new(line, hh) - pa);
                let (u, v) = (uv.x, uv.y);
                let eps = 1e-9;
                (u >= -eps && v >= -eps && u + v <= 1.0 + eps).then(|| vec![(a, 1.0 - u - v), (b, u), (c, v)])
            })
        };
        let mut resampled = (vec![], vec![]);
        for k in 0..expected {
            let d = k as f64 * h;
            if let Some(w) = locate(height[top_vertex] - d) {
                resampled.0.push(d);
                resampled.1.push(w);
            }
        }
        if resampled.0.len() >= 4 {
            (depths, rows) = resampled;
            column = rows
                .iter()
                .map(|w| {
                    w.iter()
                        .max_by(|a, b| a.1.total_cmp(&b.1))
                        .map_or(top_vertex, |x| x.0)
                })
                .collect();
        }
    }
    let at = |f: &[Vec3], row: &[(usize, f64)]| -> Vec3 { row.iter().map(|&(i, w)| w * f[i]).sum() };

    // 3. Drive: principal horizontal direction of the top's motion, then its frequency.
    let horiz = |p: Vec3| p - up * p.dot(&up);
    let top_path: Vec<Vec3> = second.iter().map(|&k| horiz(frames[k][top_vertex])).collect();
    let tm = top_path.iter().sum::<Vec3>() / top_path.len() as f64;
    let mut cov = Matrix3::zeros();
    for p in &top_path {
        let d = p - tm;
        cov += d * d.transpose();
    }
    let eig = SymmetricEigen::new(cov);
    let k_max = eig.eigenvalues.imax();
    let axis: Vec3 = eig.eigenvectors.column(k_max).into();
    if eig.eigenvalues[k_max].is_nan() || eig.eigenvalues[k_max] <= 0.0 {
        return Err(Error::invalid(
            "the top edge does not move in the second half of the cache",
        ));
    }
    // Orient the axis along the cloth's own normal side (+ for our scenes' z).
    let axis = if axis
        .iter()
        .copied()
        .fold(0.0, |s: f64, c| if c.abs() > s.abs() { c } else { s })
        < 0.0
    {
        -axis
    } else {
        axis
    };
    let t2: Vec<f64> = second.iter().map(|&k| times[k]).collect();
    let z_top: Vec<f64> = top_path.iter().map(|p| p.dot(&axis)).collect();
    let omega = dominant_frequency(&t2, &z_top)
        .ok_or_else(|| Error::invalid("no drive frequency found in the top's motion"))?;

    // 4. Window: whole periods ending at the last frame.
    let period = std::f64::consts::TAU / omega;
    let t_end = times[times.len() - 1];
    let periods = ((t_end - t_mid) / period + 1e-2).floor();
    if periods < 1.0 {
        return Err(Error::invalid(format!(
            "the second half of the cache ({:.3} s) is shorter than one drive period ({period:.3} s)",
            t_end - t_mid
        )));
    }
    let t_start = t_end - periods * period;
    let tol = 1e-2 * period;
    let window: Vec<usize> = (0..times.len()).filter(|&k| times[k] >= t_start - tol).collect();

    // 5. Harmonics of every row and the descriptors.
    let motion_of = |ks: &[usize]| ColumnMotion {
        depths: depths.clone(),
        times: ks.iter().map(|&k| times[k]).collect(),
        offsets: ks
            .iter()
            .map(|&k| rows.iter().map(|r| at(&frames[k], r).dot(&axis)).collect())
            .collect(),
        heights: ks
            .iter()
            .map(|&k| rows.iter().map(|r| at(&frames[k], r).dot(&up)).collect())
            .collect(),
    };
    let motion = motion_of(&window);
    let amplitudes: Vec<Complex<f64>> = (0..rows.len())
        .map(|j| {
            let z: Vec<f64> = motion.offsets.iter().map(|f| f[j]).collect();
            complex_amplitude(&motion.times, &z, omega)
                .ok_or_else(|| Error::invalid("too few frames in the measured window"))
        })
        .collect::<Result<_, _>>()?;
    let descriptors = describe(&motion, &amplitudes, omega);
    let all: Vec<usize> = (0..times.len()).collect();
    let history = motion_of(&all);
    Ok(Look {
        drive_frequency: omega / std::f64::consts::TAU,
        out_of_plane: axis,
        up,
        column,
        column_weights: rows,
        window: (t_start, t_end, periods as u32),
        descriptors,
        history,
        motion,
    })
}

impl Look {
    /// One JSON object: the descriptors, the drive, the window and every row's harmonic.
    pub fn to_json(&self) -> String {
        let d = &self.descriptors;
        let num = |v: f64| {
            if v.is_finite() {
                format!("{v:.6}")
            } else {
                "null".into()
            }
        };
        let opt = |v: Option<f64>| v.map_or("null".into(), num);
        let rows: Vec<String> = d
            .rows
            .iter()
            .map(|r| format!("[{}, {}, {}]", num(r.depth), num(r.amplitude), num(r.lag)))
            .collect();
        format!(
            "{{\"half_waves\": {}, \"travel_speed\": {}, \"half_amplitude_depth\": {}, \"mid_ratio\": {}, \"bottom_ratio\": {}, \"zigzag\": {}, \"bulges\": {}, \"hang_depth\": {}, \"visible_depth\": {}, \"top_amplitude\": {}, \"drive_frequency\": {}, \"out_of_plane_axis\": [{}, {}, {}], \"window\": {{\"start\": {}, \"end\": {}, \"periods\": {}}}, \"column_rows\": {}, \"rows\": {{\"columns\": [\"depth_m\", \"amplitude_m\", \"lag_rad\"], \"data\": [{}]}}}}",
            num(d.half_waves),
            opt(d.travel_speed),
            opt(d.half_amplitude_depth),
            num(d.mid_ratio),
            num(d.bottom_ratio),
            opt(d.zigzag),
            num(d.bulges),
            num(d.hang_depth),
            num(d.visible_depth),
            num(d.top_amplitude),
            num(self.drive_frequency),
            num(self.out_of_plane.x),
            num(self.out_of_plane.y),
            num(self.out_of_plane.z),
            num(self.window.0),
            num(self.window.1),
            self.window.2,
            self.column.len(),
            rows.join(", ")
        )
    }

    /// A few lines for people.
    pub fn summary(&self) -> String {
        let d = &self.descriptors;
        let opt =
            |v: Option<f64>, unit: &str, none: &str| v.map_or(none.to_string(), |x| format!("{x:.3}{unit}"));
        format!(
            "drive              {:.3} Hz, top amplitude {:.4} m, {} rows, window {:.2}-{:.2} s ({} periods)\nhalf-waves         {:.2}\ntravel speed       {}\nhalf-amplitude at  {}\nmid / bottom ratio {:.3} / {:.3}\nzigzag             {}\nbulges             {:.2}\nhang depth         {:.3} m\n",
            self.drive_frequency,
            d.top_amplitude,
            self.column.len(),
            self.window.0,
            self.window.1,
            self.window.2,
            d.half_waves,
            opt(d.travel_speed, " m/s", "none (no wave travels)"),
            opt(d.half_amplitude_depth, " m", "never"),
            d.mid_ratio,
            d.bottom_ratio,
            opt(d.zigzag, "", "n/a"),
            d.bulges,
            d.hang_depth
        )
    }
}
