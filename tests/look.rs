//! The look meter on synthetic caches whose answers are known in closed form.
//!
//! Each field moves the centre column of a hanging 0.4 m grid out of its plane by
//! `z(y, t)`, y the depth below the top edge; the meter must find the drive, the axis and
//! the column by itself and return each descriptor within 5 % (half-waves within 0.1).

use std::f64::consts::PI;

use fraccloth::{GridSpec, Vec3};
use fraccloth_tools::look::{half_waves_cut_at, measure, Look};

const L: f64 = 0.4; // column length, m
const FPS: f64 = 30.0;
const SECONDS: f64 = 8.0;
const F: f64 = 0.5; // drive frequency, Hz
const W: f64 = 2.0 * PI * F;

/// A 21 x 41 grid at 1 cm hanging in the plane z = 0, moved by `z(y, t)`.
fn bake(z: impl Fn(f64, f64) -> f64) -> Look {
    bake_with(21, 41, z, false)
}

/// `lying`: the rest mesh lies flat in the x-y plane and the cache is z-up, as a cloth
/// modelled on the floor in another tool and then hung would be.
fn bake_with(width: u32, height: u32, z: impl Fn(f64, f64) -> f64, lying: bool) -> Look {
    let spacing = L / f64::from(height - 1);
    let grid = GridSpec {
        width,
        height,
        spacing,
        total_mass: 0.1,
    }
    .build()
    .unwrap();
    let rest = grid.rest_positions.clone();
    let frames_n = (SECONDS * FPS) as usize + 1;
    let times: Vec<f64> = (0..frames_n).map(|k| k as f64 / FPS).collect();
    let frames: Vec<Vec<Vec3>> = times
        .iter()
        .map(|&t| {
            rest.iter()
                .map(|p| {
                    let depth = -p.y;
                    let d = z(depth, t);
                    if lying {
                        // Hanging in x-z with z up, displaced along y.
                        Vec3::new(p.x, d, p.y)
                    } else {
                        Vec3::new(p.x, p.y, p.z + d)
                    }
                })
                .collect()
        })
        .collect();
    let (rest_in, up) = if lying {
        // At rest it lies flat: (x, y) in the floor plane z = 0.
        (
            rest.iter().map(|p| Vec3::new(p.x, p.y, 0.0)).collect::<Vec<_>>(),
            Vec3::z(),
        )
    } else {
        (rest, Vec3::y())
    };
    measure(&rest_in, &grid.triangles, &frames, &times, up).unwrap()
}

fn close(got: f64, want: f64, rel: f64, what: &str) {
    assert!(
        (got - want).abs() <= rel * want.abs(),
        "{what}: got {got}, want {want} (within {}%)",
        rel * 100.0
    );
}

fn half_waves(got: f64, want: f64) {
    assert!((got - want).abs() <= 0.1, "half-waves: got {got}, want {want}");
}

fn travelling(c: f64, decay: Option<f64>) -> impl Fn(f64, f64) -> f64 {
    move |y: f64, t: f64| {
        let env = decay.map_or(1.0, |l| (-y / l).exp());
        0.04 * env * (W * (t - y / c)).sin()
    }
}

#[test]
fn travelling_waves_without_decay() {
    for c in [0.05, 0.133, 0.6] {
        let look = bake(travelling(c, None));
        let d = &look.descriptors;
        close(look.drive_frequency, F, 0.01, "drive");
        half_waves(d.half_waves, W * L / (PI * c));
        close(d.travel_speed.expect("a wave travels"), c, 0.05, "travel");
        assert_eq!(d.half_amplitude_depth, None, "c = {c}");
        close(d.mid_ratio, 1.0, 0.05, "mid");
        close(d.bottom_ratio, 1.0, 0.05, "bottom");
        let z = d.zigzag.unwrap();
        assert!((0.9..=1.15).contains(&z), "smooth wave zigzag {z} at c = {c}");
        close(d.hang_depth, L, 0.01, "hang");
    }
}

#[test]
fn travelling_waves_decaying_over_20_and_10_cm() {
    for c in [0.05, 0.133, 0.6] {
        for l in [0.2, 0.1] {
            let look = bake(travelling(c, Some(l)));
            let d = &look.descriptors;
            let visible = (l * 10f64.ln()).min(L);
            half_waves(d.half_waves, W * visible / (PI * c));
            close(d.visible_depth, visible, 0.05, "visible depth");
            close(d.travel_speed.expect("a wave travels"), c, 0.05, "travel");
            close(
                d.half_amplitude_depth.expect("halves"),
                l * 2f64.ln(),
                0.05,
                "half depth",
            );
            close(d.mid_ratio, (-L / 2.0 / l).exp(), 0.05, "mid");
            close(d.bottom_ratio, (-L / l).exp(), 0.05, "bottom");
            let z = d.zigzag.unwrap();
            assert!(
                (0.85..=1.2).contains(&z),
                "decaying wave zigzag {z} at c = {c}, l = {l}"
            );
        }
    }
}

#[test]
fn a_column_hovering_about_the_visible_limit_is_counted_steadily() {
    // A wave at 0.1 m/s (4 half-waves down the column) whose amplitude decays over 5 cm to a
    // plateau at 10.2 % or 9.8 % of the top's: the rows of the two agree within 0.4 % of the
    // top. A hard cut at 10 % reads the whole column in one and stops at 11.6 cm in the other;
    // the count weighs each row's lag by its visibility and moves by about 0.14.
    let c = 0.1;
    let column =
        |plateau: f64| move |y: f64, t: f64| 0.04 * (-y / 0.05).exp().max(plateau) * (W * (t - y / c)).sin();
    let (above, below) = (bake(column(0.102)), bake(column(0.098)));
    let (hard_above, hard_below) = (
        half_waves_cut_at(&above.descriptors.rows, 0.1),
        half_waves_cut_at(&below.descriptors.rows, 0.1),
    );
    assert!(
        hard_above - hard_below > 2.0,
        "the columns hover about the limit: a hard cut reads {hard_above} and {hard_below}"
    );
    let (a, b) = (above.descriptors.half_waves, below.descriptors.half_waves);
    assert!(
        a > b && a - b < 0.2,
        "half-waves {a} and {b} for two columns within 0.4 % of the top's amplitude"
    );
    // Between the lag of the 10 % depth (1.16) and the whole column's (4): the rows below it
    // count for about half.
    assert!((2.2..=2.9).contains(&a), "half-waves {a}");
}

#[test]
fn a_whole_period_lag_is_read_as_the_slow_wave_it_is() {
    // At 0.1 m/s the row three quarters down lags the one a quarter down by exactly one
    // period (a lag search that starts at one frame aliases this): 4 half-waves.
    let look = bake(travelling(0.1, None));
    half_waves(look.descriptors.half_waves, 4.0);
    close(look.descriptors.travel_speed.unwrap(), 0.1, 0.05, "travel");
}

#[test]
fn a_column_moving_in_phase_carries_no_wave() {
    let look = bake(|_, t| 0.04 * (W * t).sin());
    let d = &look.descriptors;
    half_waves(d.half_waves, 0.0);
    assert_eq!(d.travel_speed, None);
    assert_eq!(d.half_amplitude_depth, None);
    close(d.mid_ratio, 1.0, 0.01, "mid");
    assert_eq!(d.bulges, 0.0);
}

#[test]
fn standing_modes_do_not_travel() {
    // Amplitude cos(pi y / 0.8): falls to zero at the bottom, phase constant.
    let look = bake(|y, t| 0.04 * (PI * y / (2.0 * L)).cos() * (W * t).sin());
    let d = &look.descriptors;
    half_waves(d.half_waves, 0.0);
    assert_eq!(d.travel_speed, None);
    close(d.half_amplitude_depth.unwrap(), 2.0 * L / 3.0, 0.05, "half depth");
    close(d.mid_ratio, (PI / 4.0).cos(), 0.05, "mid");
    assert!(d.bottom_ratio < 0.01);
    close(d.visible_depth, 2.0 * L / PI * 0.1f64.acos(), 0.05, "visible");
    // One with a node a sixth of the way down: the rows below the node are not visible.
    let look = bake(|y, t| 0.04 * (3.0 * PI * y / (2.0 * L)).cos() * (W * t).sin());
    assert_eq!(look.descriptors.travel_speed, None);
    half_waves(look.descriptors.half_waves, 0.0);
}

#[test]
fn a_rigid_tilt_lagging_90_degrees_is_not_a_wave() {
    // The column translates with the top and tilts about it a quarter period later.
    let (a, theta) = (0.02, 0.1);
    let look = bake(|y, t| a * (W * t).sin() + theta * y * (W * t - PI / 2.0).sin());
    let d = &look.descriptors;
    assert_eq!(d.travel_speed, None, "a straight column does not carry a wave");
    // By definition: the bottom's phase lag, atan(theta L / a), over pi.
    half_waves(d.half_waves, (theta * L / a).atan() / PI);
    assert_eq!(d.bulges, 0.0, "a straight column has no bulges");
    close(
        d.bottom_ratio,
        (1.0 + (theta * L / a).powi(2)).sqrt(),
        0.05,
        "bottom",
    );
}

#[test]
fn a_top_moving_over_a_still_cloth_carries_no_wave() {
    let look = bake(|y, t| 0.04 * (1.0 - y / 0.05).max(0.0) * (W * t).sin());
    let d = &look.descriptors;
    half_waves(d.half_waves, 0.0);
    assert_eq!(d.travel_speed, None);
    close(d.half_amplitude_depth.unwrap(), 0.025, 0.05, "half depth");
    close(d.visible_depth, 0.045, 0.05, "visible depth");
    assert!(d.mid_ratio < 1e-9 && d.bottom_ratio < 1e-9);
}

#[test]
fn grid_scale_zigzag_on_a_smooth_wave_is_flagged() {
    let smooth = bake(travelling(0.133, Some(0.2)));
    // The same wave with a ripple alternating row to row, 10 % of the local amplitude.
    let rough = bake(|y, t| {
        let row = (y / 0.01).round() as i64;
        let sign = if row % 2 == 0 { 1.0 } else { -1.0 };
        travelling(0.133, Some(0.2))(y, t) * (1.0 + 0.1 * sign)
    });
    let (zs, zr) = (
        smooth.descriptors.zigzag.unwrap(),
        rough.descriptors.zigzag.unwrap(),
    );
    assert!(zs < 1.2, "smooth {zs}");
    assert!(zr > 3.0, "rough {zr}");
    // The ripple does not change the phase: the wave is still read right.
    close(rough.descriptors.travel_speed.unwrap(), 0.133, 0.05, "travel");
    half_waves(rough.descriptors.half_waves, smooth.descriptors.half_waves);
}

#[test]
fn bulges_count_the_side_view_extrema() {
    // Three half-waves of 4 cm: two or three interior extrema per frame, depending on the
    // phase (an extremum near the bottom edge is confirmed only if the column turns back by
    // 5 mm before it ends).
    let b = bake(travelling(0.133, None)).descriptors.bulges;
    assert!((2.2..=3.0).contains(&b), "{b}");
    // A 2 mm wave makes no bulge at all.
    let small = bake(|y, t| 0.002 * (W * (t - y / 0.133)).sin());
    assert_eq!(small.descriptors.bulges, 0.0);
}

#[test]
fn caches_from_other_tools_lying_flat_at_rest_z_up_even_width() {
    // 20 columns: no vertex sits on the centre line; the nearest column is measured.
    let look = bake_with(20, 41, travelling(0.133, Some(0.2)), true);
    let d = &look.descriptors;
    half_waves(d.half_waves, W * L / (PI * 0.133));
    close(d.travel_speed.unwrap(), 0.133, 0.05, "travel");
    close(d.hang_depth, L, 0.01, "hang");
    assert!(
        (look.out_of_plane.abs() - Vec3::y()).norm() < 1e-9,
        "{}",
        look.out_of_plane
    );
}

#[test]
fn json_has_the_documented_keys() {
    let json = bake(travelling(0.133, None)).to_json();
    for key in [
        "half_waves",
        "travel_speed",
        "half_amplitude_depth",
        "mid_ratio",
        "bottom_ratio",
        "zigzag",
        "bulges",
        "hang_depth",
    ] {
        assert!(
            json.contains(&format!("\"{key}\": ")),
            "{key} missing from {json}"
        );
    }
    assert!(json.contains("\"half_amplitude_depth\": null"));
}

/// A staggered mesh (every other row shifted half a spacing, like bricks) has no vertex on
/// every row of its centre line: the meter resamples the column through the rest triangles and
/// reads the same travelling wave as on the grid.
#[test]
fn a_mesh_with_no_vertex_column_is_resampled() {
    let (w, rows) = (21u32, 41u32);
    let h = L / f64::from(rows - 1);
    let mut rest = vec![];
    for j in 0..rows {
        let shift = if j % 2 == 1 { 0.5 * h } else { 0.0 };
        for i in 0..w {
            rest.push(Vec3::new(
                (f64::from(i) - 10.0) * h + shift,
                -f64::from(j) * h,
                0.0,
            ));
        }
    }
    let mut triangles = vec![];
    for j in 0..rows - 1 {
        for i in 0..w - 1 {
            let (a, b, c, d) = (j * w + i, j * w + i + 1, (j + 1) * w + i + 1, (j + 1) * w + i);
            triangles.push([a, d, b]);
            triangles.push([b, d, c]);
        }
    }
    let c = 0.133;
    let z = travelling(c, None);
    let times: Vec<f64> = (0..=(SECONDS * FPS) as usize).map(|k| k as f64 / FPS).collect();
    let frames: Vec<Vec<Vec3>> = times
        .iter()
        .map(|&t| rest.iter().map(|p| Vec3::new(p.x, p.y, z(-p.y, t))).collect())
        .collect();
    let look = measure(&rest, &triangles, &frames, &times, Vec3::y()).unwrap();
    // Points one median edge length apart (the meter's spacing, 1.12 h here) all the way down,
    // not the 21 rows that have a vertex on the line; most are a mix of a triangle's vertices.
    assert!(
        look.column_weights.len() > 30,
        "{} rows",
        look.column_weights.len()
    );
    assert!(look.column_weights.iter().skip(1).any(|r| r.len() == 3));
    let d = &look.descriptors;
    half_waves(d.half_waves, W * L / (PI * c));
    close(d.travel_speed.expect("a wave travels"), c, 0.05, "travel");
    close(d.mid_ratio, 1.0, 0.05, "mid");
}
