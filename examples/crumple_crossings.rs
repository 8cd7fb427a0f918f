//! Where the brisk crumple still crosses itself: the 61 x 41 towel swung 8 cm at 2 Hz with
//! self-collision 4 mm (`collision_cost` case 1), baked 4 s at the automatic step. At every
//! frame with a crossing it prints the crossing triangle pairs (`collide::intersections`),
//! sorted by how near the two triangles are at rest: sharing a vertex, or with a vertex of
//! one nearer the other than self-collision's exclusion radius (`EXCLUDED` thicknesses: a pair
//! self-collision never tests), or further apart. And the impact zones' totals so far. See
//! docs/collisions.md.
//!
//! `cargo run --release --example crumple_crossings`

use fraccloth::collide::geometry::closest_on_triangle;
use fraccloth::collide::intersections::crossing_pairs;
use fraccloth::collide::self_collision::EXCLUDED;
use fraccloth::{Model, Vec3};
use fraccloth_tools::scenes::SceneSpec;

const THICKNESS: f64 = 0.004;
const FPS: f64 = 30.0;

/// The rest distance from vertex `p` to triangle `t`.
fn to_triangle(rest: &[Vec3], p: u32, t: &[u32; 3]) -> f64 {
    let [a, b, c] = t.map(|i| rest[i as usize]);
    let w = closest_on_triangle(&rest[p as usize], &a, &b, &c);
    (rest[p as usize] - (w[0] * a + w[1] * b + w[2] * c)).norm()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let model = Model {
        self_collision_thickness: THICKNESS,
        ..Model::underwater()
    };
    let spec = SceneSpec::underwater_swing(61, 41, 2.0, 0.08, model);
    let mut scene = spec.build()?;
    let tris = scene.cloth.topology().triangles.clone();
    let rest = scene.cloth.topology().rest_positions.clone();
    let excluded = EXCLUDED * THICKNESS;
    println!("frame  time  crossing  sharing a vertex  excluded at rest  further  zone steps  passages");
    let (mut worst, mut totals) = (0, [0usize; 3]);
    for f in 1..=(4.0 * FPS) as usize {
        scene.run_until(f as f64 / FPS)?;
        let pairs = crossing_pairs(scene.cloth.positions(), &tris);
        if pairs.is_empty() {
            continue;
        }
        let mut kinds = [0usize; 3];
        for &(a, b) in &pairs {
            let (ta, tb) = (&tris[a as usize], &tris[b as usize]);
            let kind = if ta.iter().any(|i| tb.contains(i)) {
                0
            } else {
                let near = ta
                    .iter()
                    .map(|&p| to_triangle(&rest, p, tb))
                    .chain(tb.iter().map(|&p| to_triangle(&rest, p, ta)))
                    .fold(f64::INFINITY, f64::min);
                if near < excluded {
                    1
                } else {
                    2
                }
            };
            kinds[kind] += 1;
        }
        for (t, k) in totals.iter_mut().zip(kinds) {
            *t += k;
        }
        worst = worst.max(pairs.len());
        let z = scene.cloth.self_collision_zones();
        println!(
            "{f:>5} {:>5.2} {:>9} {:>17} {:>17} {:>8} {:>11} {:>9}",
            f as f64 / FPS,
            pairs.len(),
            kinds[0],
            kinds[1],
            kinds[2],
            z.steps,
            z.passages
        );
    }
    println!(
        "most crossing pairs at a frame: {worst}; over all frames, sharing a vertex {}, excluded at rest {}, further {}",
        totals[0], totals[1], totals[2]
    );
    Ok(())
}
