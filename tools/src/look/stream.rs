//! What a cloth held still in a current does: how far it leans downstream, and how its free
//! edge flutters. For the `current` and `kelp` scenes and any cache of an undriven cloth whose
//! root (a pinned point) and tip (the free edge's middle) are known.

use super::harmonic::dominant_frequency;
use fraccloth::error::Error;
use fraccloth::math::Vec3;

/// Flutter below this (m, rms) is stillness: no frequency is reported.
pub const STILL: f64 = 1e-4;

/// A streaming cloth's numbers over the second half of a cache.
#[derive(Clone, Debug, PartialEq)]
pub struct Stream {
    /// Angle between the mean root-to-tip direction and the rest one, degrees.
    pub angle_degrees: f64,
    /// Root-mean-square distance of the tip from its mean position, m.
    pub flutter_amplitude: f64,
    /// Dominant frequency of the tip's motion along its main direction, Hz (None when it is
    /// still: flutter below [`STILL`]).
    pub flutter_frequency: Option<f64>,
}

impl Stream {
    pub fn summary(&self) -> String {
        format!(
            "streaming angle    {:.1} degrees from the rest direction\nflutter            {:.4} m rms at the tip, {}\n",
            self.angle_degrees,
            self.flutter_amplitude,
            self.flutter_frequency
                .map_or("no dominant frequency".to_string(), |f| format!("{f:.2} Hz"))
        )
    }

    pub fn to_json(&self) -> String {
        format!(
            "{{\"streaming_angle_degrees\": {:.3}, \"flutter_amplitude\": {:.6}, \"flutter_frequency\": {}}}",
            self.angle_degrees,
            self.flutter_amplitude,
            self.flutter_frequency
                .map_or("null".to_string(), |f| format!("{f:.4}"))
        )
    }
}

/// Measures `frames` (positions at `times`, s) of a cloth whose vertex `root` is held and whose
/// vertex `tip` is free; `rest` the rest positions.
pub fn measure_stream(
    rest: &[Vec3],
    frames: &[Vec<Vec3>],
    times: &[f64],
    root: usize,
    tip: usize,
) -> Result<Stream, Error> {
    if frames.len() != times.len() || frames.len() < 8 {
        return Err(Error::invalid(
            "the cache needs at least 8 frames with a time each",
        ));
    }
    let n = rest.len();
    if root >= n || tip >= n || frames.iter().any(|f| f.len() != n) {
        return Err(Error::invalid("root and tip must be vertices of every frame"));
    }
    let t_mid = 0.5 * (times[0] + times[times.len() - 1]);
    let second: Vec<usize> = (0..times.len()).filter(|&k| times[k] >= t_mid).collect();
    let rest_dir = (rest[tip] - rest[root])
        .try_normalize(0.0)
        .ok_or_else(|| Error::invalid("root and tip coincide at rest"))?;
    let count = second.len() as f64;
    let mean_dir = second
        .iter()
        .map(|&k| frames[k][tip] - frames[k][root])
        .sum::<Vec3>()
        / count;
    let cos = (mean_dir.dot(&rest_dir) / mean_dir.norm()).clamp(-1.0, 1.0);
    let angle_degrees = if mean_dir.norm() > 0.0 {
        cos.acos().to_degrees()
    } else {
        0.0
    };
    let mean_tip = second.iter().map(|&k| frames[k][tip]).sum::<Vec3>() / count;
    let offsets: Vec<Vec3> = second.iter().map(|&k| frames[k][tip] - mean_tip).collect();
    let flutter_amplitude = (offsets.iter().map(|d| d.norm_squared()).sum::<f64>() / count).sqrt();
    let mut cov = nalgebra::Matrix3::zeros();
    for d in &offsets {
        cov += d * d.transpose();
    }
    let eig = nalgebra::SymmetricEigen::new(cov);
    let axis: Vec3 = eig.eigenvectors.column(eig.eigenvalues.imax()).into();
    let along: Vec<f64> = offsets.iter().map(|d| d.dot(&axis)).collect();
    let t: Vec<f64> = second.iter().map(|&k| times[k]).collect();
    // Below a tenth of a millimetre the tip is still: no frequency to speak of.
    let flutter_frequency = if flutter_amplitude > STILL {
        dominant_frequency(&t, &along).map(|w| w / std::f64::consts::TAU)
    } else {
        None
    };
    Ok(Stream {
        angle_degrees,
        flutter_amplitude,
        flutter_frequency,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_leaning_fluttering_strip_reads_its_angle_amplitude_and_frequency() {
        // A rigid strip from root (0, 0, 0) to tip at rest (0, -0.4, 0), leaning 20 degrees
        // towards +x, its tip fluttering 1 cm at 1.5 Hz along z.
        let rest = vec![Vec3::zeros(), Vec3::new(0.0, -0.4, 0.0)];
        let lean = 20f64.to_radians();
        let times: Vec<f64> = (0..=600).map(|k| k as f64 / 30.0).collect();
        let frames: Vec<Vec<Vec3>> = times
            .iter()
            .map(|&t| {
                let z = 0.01 * (std::f64::consts::TAU * 1.5 * t).sin();
                vec![Vec3::zeros(), Vec3::new(0.4 * lean.sin(), -0.4 * lean.cos(), z)]
            })
            .collect();
        let s = measure_stream(&rest, &frames, &times, 0, 1).unwrap();
        assert!((s.angle_degrees - 20.0).abs() < 0.05, "{s:?}");
        assert!((s.flutter_amplitude - 0.01 / 2f64.sqrt()).abs() < 2e-4, "{s:?}");
        assert!((s.flutter_frequency.unwrap() - 1.5).abs() < 0.05, "{s:?}");
        // Still: no frequency, no amplitude.
        let still: Vec<Vec<Vec3>> = times.iter().map(|_| rest.clone()).collect();
        let s = measure_stream(&rest, &still, &times, 0, 1).unwrap();
        assert!(
            s.angle_degrees < 1e-6 && s.flutter_amplitude < 1e-12 && s.flutter_frequency.is_none(),
            "{s:?}"
        );
    }
}
