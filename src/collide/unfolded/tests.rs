use super::*;
use crate::collide::geometry::closest_on_triangle;
use crate::testing::flat_grid as grid;

/// A point of triangle `t` at weights `w`.
fn point(x: &[Vec3], t: &[u32; 3], w: [f64; 3]) -> Vec3 {
    w[0] * x[t[0] as usize] + w[1] * x[t[1] as usize] + w[2] * x[t[2] as usize]
}

#[test]
fn a_grid_qualifies_and_a_holed_notched_slit_or_curved_sheet_does_not() {
    let (rest, triangles) = grid(9, 7, 0.01);
    assert!(Unfolded::new(&rest, &triangles).applies());
    // Turned the other way, and moved off the origin and tilted: still a flat convex sheet.
    let flipped: Vec<[u32; 3]> = triangles.iter().map(|t| [t[0], t[2], t[1]]).collect();
    assert!(Unfolded::new(&rest, &flipped).applies());
    let tilted: Vec<Vec3> = rest
        .iter()
        .map(|p| Vec3::new(p.x, 0.6 * p.y, 0.8 * p.y + 1.0))
        .collect();
    assert!(Unfolded::new(&tilted, &triangles).applies());
    // A hole: the two triangles of one inner quad left out.
    let holed: Vec<[u32; 3]> = triangles
        .iter()
        .enumerate()
        .filter(|(k, _)| *k / 2 != 3 * 8 + 4)
        .map(|(_, t)| *t)
        .collect();
    assert!(!Unfolded::new(&rest, &holed).applies());
    // A notch: a corner quad left out (the border no longer on the hull).
    assert!(!Unfolded::new(&rest, &triangles[2..]).applies());
    // A slit: the lower half's top row of vertices duplicated, so the two halves meet
    // along a seam without sharing vertices.
    let mut slit_rest = rest.clone();
    let copies: Vec<u32> = (0..9)
        .map(|i| {
            slit_rest.push(rest[(3 * 9 + i) as usize]);
            (slit_rest.len() - 1) as u32
        })
        .collect();
    let slit: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| {
            if t.iter().all(|&v| v / 9 <= 3) {
                t.map(|v| if v / 9 == 3 { copies[(v % 9) as usize] } else { v })
            } else {
                *t
            }
        })
        .collect();
    assert!(!Unfolded::new(&slit_rest, &slit).applies());
    // Curved at rest.
    let curved: Vec<Vec3> = rest
        .iter()
        .map(|p| Vec3::new(p.x, p.y, 2.0 * p.x * p.x))
        .collect();
    assert!(!Unfolded::new(&curved, &triangles).applies());
    // A triangle turned over.
    let mut over = triangles.clone();
    over[10] = [over[10][0], over[10][2], over[10][1]];
    assert!(!Unfolded::new(&rest, &over).applies());
}

/// The bands' ends: every segment shorter than `band_end(k, side)`, anywhere and in any
/// direction, meets at most `k` cells along each axis (cells counted as the triangles'
/// cells are, by the floor of the coordinate over the side).
#[test]
fn a_window_of_k_cells_holds_every_segment_shorter_than_its_band() {
    let mut r = crate::testing::numbers(3);
    let side = 0.0123;
    let cell = |u: f64| (u / side).floor() as i64;
    for k in 2..=4 {
        let end = band_end(k, side);
        for n in 0..200_000 {
            // Lengths up to the end, many of them at it (the worst case), and starts on
            // cell borders now and then.
            let d = if n % 3 == 0 {
                end * (1.0 - 1e-12)
            } else {
                end * (r() + 0.5)
            };
            let a = r() * std::f64::consts::TAU;
            let p = if n % 7 == 0 {
                [side * (r() * 100.0).round(), side * (r() * 100.0).round()]
            } else {
                [r() * 1.0, r() * 1.0]
            };
            let q = [p[0] + d * a.cos(), p[1] + d * a.sin()];
            for axis in 0..2 {
                let spanned = (cell(p[axis]) - cell(q[axis])).unsigned_abs() + 1;
                assert!(
                    spanned <= k as u64,
                    "a segment of {d} m meets {spanned} cells of {side} m"
                );
            }
        }
    }
}

/// Known answers: a sheet moved rigidly keeps every distance (proved at every distance); a
/// sheet shrunk to 0.85 of its size brings points 2.2 thicknesses apart at rest to 1.87,
/// inside the reach of 2, so nothing is proved; at 0.95 (2.09) everything is.
#[test]
fn a_sheet_moved_rigidly_is_proved_everywhere_and_one_shrunk_past_the_reach_nowhere() {
    let (rest, triangles) = grid(31, 21, 0.01);
    let (t, e) = (0.004, 0.0088);
    let mut u = Unfolded::new(&rest, &triangles);
    let turn = nalgebra::Rotation3::from_euler_angles(0.3, -1.1, 2.0);
    let moved: Vec<Vec3> = rest
        .iter()
        .map(|p| turn * p + Vec3::new(1.0, -2.0, 0.5))
        .collect();
    assert_eq!(u.certified_below(&moved, &triangles, 2.0 * t, e), f64::INFINITY);
    let shrunk: Vec<Vec3> = moved.iter().map(|p| 0.85 * p).collect();
    assert_eq!(u.certified_below(&shrunk, &triangles, 2.0 * t, e), e);
    let shrunk: Vec<Vec3> = moved.iter().map(|p| 0.95 * p).collect();
    assert_eq!(u.certified_below(&shrunk, &triangles, 2.0 * t, e), f64::INFINITY);
    // A position that is not a number proves nothing.
    let mut bad = moved.clone();
    bad[40].y = f64::NAN;
    assert_eq!(u.certified_below(&bad, &triangles, 2.0 * t, e), e);
}

/// A step's proof (`out_of_reach_throughout`): a sheet carried 5 cm and turned (a rigid
/// step far longer than any step limit) is proved; one mirrored in its plane is not, though
/// both its ends are flat sheets each proved alone (the straight paths between them collapse
/// the sheet onto a line halfway: the bound of both ends' summaries alone would have passed
/// it); one folded over itself by the end of the step is not; a step shrinking the sheet
/// past the reach at its end is not, and one shrinking it less is.
#[test]
fn a_step_is_proved_only_when_no_instant_of_it_comes_within_reach() {
    let (rest, triangles) = grid(31, 21, 0.01);
    let (t, e) = (0.004, 0.0088);
    let mut u = Unfolded::new(&rest, &triangles);
    let reach = 2.0 * t;
    let turn = nalgebra::Rotation3::from_euler_angles(0.02, -0.03, 0.05);
    let carried: Vec<Vec3> = rest
        .iter()
        .map(|p| turn * p + Vec3::new(0.05, -0.01, 0.02))
        .collect();
    assert!(u.out_of_reach_throughout(&rest, &carried, &triangles, reach, e));
    let mirrored: Vec<Vec3> = rest.iter().map(|p| Vec3::new(0.3 - p.x, p.y, p.z)).collect();
    assert_eq!(u.certified_below(&mirrored, &triangles, reach, e), f64::INFINITY);
    assert!(!u.out_of_reach_throughout(&rest, &mirrored, &triangles, reach, e));
    // Folded back over itself round 3 mm beyond x = 0.15 m, the halves 6 mm apart.
    let folded: Vec<Vec3> = rest
        .iter()
        .map(|p| crate::testing::folded_over(p, 0.15, 0.003))
        .collect();
    assert!(!u.out_of_reach_throughout(&rest, &folded, &triangles, reach, e));
    let shrunk: Vec<Vec3> = rest.iter().map(|p| 0.85 * p).collect();
    assert!(!u.out_of_reach_throughout(&rest, &shrunk, &triangles, reach, e));
    let shrunk: Vec<Vec3> = rest.iter().map(|p| 0.97 * p).collect();
    assert!(u.out_of_reach_throughout(&rest, &shrunk, &triangles, reach, e));
    // A position that is not a number proves nothing.
    let mut bad = carried.clone();
    bad[40].y = f64::NAN;
    assert!(!u.out_of_reach_throughout(&rest, &bad, &triangles, reach, e));
}

/// A sheet 40 cm long rolled into a spiral (radius 5 cm growing 6 mm a turn): points a
/// turn apart along the sheet (about 31 cm at rest) lie 6 mm apart, inside a reach of
/// 8 mm, so the proof must stop before that distance, yet its bending (0.4 radians over
/// 2 cm) leaves the short distances proved; a roll of 2 cm (a radian over 2 cm) proves
/// nothing; a gentle bend (radius 30 cm) is proved everywhere.
#[test]
fn a_rolled_sheet_is_proved_only_below_one_turn() {
    let (rest, triangles) = grid(41, 11, 0.01);
    let (t, e) = (0.004, 0.0088);
    let mut u = Unfolded::new(&rest, &triangles);
    let roll = |radius: f64, pitch: f64| -> Vec<Vec3> {
        rest.iter()
            .map(|p| {
                // Arc length p.x along a spiral r = radius + pitch * angle / (2 pi).
                let (mut angle, mut s) = (0.0_f64, 0.0);
                while s < p.x {
                    let r = radius + pitch * angle / std::f64::consts::TAU;
                    let step = 1e-4 / r;
                    angle += step;
                    s += r * step;
                }
                let r = radius + pitch * angle / std::f64::consts::TAU;
                Vec3::new(r * angle.sin(), p.y, r * angle.cos())
            })
            .collect()
    };
    let rolled = roll(0.05, 0.006);
    let below = u.certified_below(&rolled, &triangles, 2.0 * t, e);
    let turn = std::f64::consts::TAU * 0.05;
    assert!(
        below <= turn,
        "proved up to {below} m in a roll whose turn is {turn} m"
    );
    assert!(below > 2.0 * e, "proved only up to {below} m");
    let tight = roll(0.02, 0.006);
    assert_eq!(u.certified_below(&tight, &triangles, 2.0 * t, e), e);
    let gentle = roll(0.3, 0.0);
    assert_eq!(u.certified_below(&gentle, &triangles, 2.0 * t, e), f64::INFINITY);
}

/// The bound itself: on sheets waved, bent and crumpled at random, every pair of points
/// the proof covers (at least the exclusion apart at rest, nearer than what it proves) is
/// at least the reach apart. Random points of random triangles, and the closest point of
/// a triangle to each vertex, are tried; some deformations bring covered-looking pairs
/// within the reach (so the proof has something to refuse), and some are proved whole.
#[test]
fn every_pair_the_proof_covers_is_out_of_reach() {
    let (rest, triangles) = grid(25, 17, 0.01);
    let (t, e) = (0.004, 0.0088);
    let reach = 2.0 * t;
    let mut u = Unfolded::new(&rest, &triangles);
    let mut r = crate::testing::numbers(5);
    let (mut whole, mut partial, mut refused) = (0, 0, 0);
    for case in 0..90 {
        // Waves of random wavelength, direction and height across the sheet, a rotation,
        // and noise at the vertices.
        let waves: Vec<(f64, f64, f64, f64, f64)> = (0..3)
            .map(|_| {
                let k = std::f64::consts::TAU / (0.02 + 0.3 * (r() + 0.5));
                (
                    k,
                    r() * 6.0,
                    r() * 6.0,
                    0.02 * (case as f64 / 90.0) * (r() + 0.5),
                    r(),
                )
            })
            .collect();
        let noise = if case % 5 == 4 { 0.003 } else { 0.0 };
        // Every other sheet folded over across x: flat to `x0`, round a half cylinder of
        // radius `radius`, and back above itself.
        let (x0, radius) = (0.05 + 0.1 * (r() + 0.5), 0.002 + 0.06 * (r() + 0.5));
        // Every fourth a crease: the vertices past a line turned about it by up to 2
        // radians (where the bound is tight: a segment across the crease is shortened by
        // the cosine of half the angle, which is the bound's g).
        // The crease runs along the grid's lines or diagonals, so no triangle straddles it.
        let crease = [std::f64::consts::FRAC_PI_2, 0.0, std::f64::consts::FRAC_PI_4][(case / 4) % 3];
        let turn = 0.2 + 1.8 * (r() + 0.5);
        let fold = |p: &Vec3| -> Vec3 {
            if case % 4 == 1 {
                let (dir, c) = (
                    Vec3::new(crease.cos(), crease.sin(), 0.0),
                    Vec3::new(0.12, 0.08, 0.0),
                );
                let across = Vec3::new(-dir.y, dir.x, 0.0);
                let off = (p - c).dot(&across);
                if off <= 0.0 {
                    return *p;
                }
                let along = (p - c).dot(&dir);
                return c + along * dir + off * (turn.cos() * across + turn.sin() * Vec3::z());
            }
            if case % 2 != 0 || p.x <= x0 {
                return *p;
            }
            let s = p.x - x0;
            let angle = s / radius;
            if angle <= std::f64::consts::PI {
                Vec3::new(x0 + radius * angle.sin(), p.y, radius * (1.0 - angle.cos()))
            } else {
                Vec3::new(x0 - (s - std::f64::consts::PI * radius), p.y, 2.0 * radius)
            }
        };
        let x: Vec<Vec3> = rest
            .iter()
            .map(|p| {
                let z: f64 = waves
                    .iter()
                    .map(|&(k, dir, phase, amp, _)| {
                        amp * (k * (p.x * dir.cos() + p.y * dir.sin()) + phase).sin()
                    })
                    .sum();
                let z = if case % 4 != 3 { 0.1 * z } else { z };
                fold(p) + Vec3::new(0.0, 0.0, z) + noise * Vec3::new(r(), r(), r())
            })
            .collect();
        let below = u.certified_below(&x, &triangles, reach, e);
        if below == f64::INFINITY {
            whole += 1;
        } else if below > e {
            partial += 1;
        }
        let covered = |d: f64| d >= e && d < below;
        // Vertices against the closest point of every triangle; random point pairs.
        for (p, rp) in rest.iter().enumerate() {
            for tri in &triangles {
                let [a, b, c] = tri.map(|i| rest[i as usize]);
                let w = closest_on_triangle(rp, &a, &b, &c);
                let d_rest = (rp - point(&rest, tri, w)).norm();
                let d_now = (x[p] - point(&x, tri, w)).norm();
                if covered(d_rest) {
                    assert!(
                        d_now >= reach,
                        "case {case}: {d_now} m now, {d_rest} m at rest, proved below {below}"
                    );
                } else if d_rest >= e && d_now < reach {
                    refused += 1;
                }
            }
        }
        // Point pairs a few exclusions apart, in every direction.
        let (w, h) = (0.24, 0.16);
        let at = |p: [f64; 2]| -> Option<([u32; 3], [f64; 3])> {
            if !(0.0..w).contains(&p[0]) || !(0.0..h).contains(&p[1]) {
                return None;
            }
            let (i, j) = ((p[0] / 0.01) as u32, (p[1] / 0.01) as u32);
            let (fx, fy) = (p[0] / 0.01 - f64::from(i), p[1] / 0.01 - f64::from(j));
            let k = 2 * (j * 24 + i) as usize;
            // The quad's triangles: (i, j), (i+1, j), (i+1, j+1) below its diagonal,
            // (i, j), (i+1, j+1), (i, j+1) above.
            Some(if fx >= fy {
                (triangles[k], [1.0 - fx, fx - fy, fy])
            } else {
                (triangles[k + 1], [1.0 - fy, fx, fy - fx])
            })
        };
        for _ in 0..50_000 {
            let p = [(r() + 0.5) * w, (r() + 0.5) * h];
            let (d, angle) = (e * (1.0 + 2.0 * (r() + 0.5)), r() * std::f64::consts::TAU);
            let q = [p[0] + d * angle.cos(), p[1] + d * angle.sin()];
            let (Some((t1, w1)), Some((t2, w2))) = (at(p), at(q)) else {
                continue;
            };
            let d_rest = (point(&rest, &t1, w1) - point(&rest, &t2, w2)).norm();
            assert!((d_rest - d).abs() < 1e-12, "the points are where they were put");
            if covered(d_rest) {
                let d_now = (point(&x, &t1, w1) - point(&x, &t2, w2)).norm();
                assert!(
                    d_now >= reach,
                    "case {case}: {d_now} m now, {d_rest} m at rest, proved below {below}"
                );
            }
        }
    }
    assert!(
        whole > 5 && partial > 5,
        "proved whole {whole} times, in part {partial}"
    );
    assert!(refused > 0, "some pairs came within reach");
}
