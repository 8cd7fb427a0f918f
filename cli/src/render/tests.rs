//! The preview renderer: requested size, a plausible cloth area, motion between frames, and
//! colliders in the picture.

use crate::render::{render_frame, Camera, Scene3d};
use fraccloth_tools::scenes::{SceneKind, SceneSpec, Variant};
use tiny_skia::Pixmap;

fn camera(scene: &fraccloth_tools::scenes::Scene, w: u32, h: u32) -> Camera {
    Camera::for_rest_shape(&scene.cloth.topology().rest_positions, w, h)
}

fn draw(scene: &fraccloth_tools::scenes::Scene, cam: &Camera) -> Pixmap {
    let mut pix = Pixmap::new(cam.width, cam.height).unwrap();
    let spheres = Scene3d::spheres_of(scene.cloth.colliders().iter().copied());
    render_frame(
        &Scene3d {
            positions: scene.cloth.positions(),
            triangles: &scene.cloth.topology().triangles,
            spheres: &spheres,
        },
        cam,
        &mut pix,
    );
    pix
}

/// Cloth pixels are orange: red well above blue (the backdrop is blue-green).
fn is_cloth(p: &tiny_skia::PremultipliedColorU8) -> bool {
    p.red() > 60 && u16::from(p.red()) > u16::from(p.blue()) + 40
}

/// Sphere pixels are grey-white: all channels close.
fn is_sphere(p: &tiny_skia::PremultipliedColorU8) -> bool {
    let (r, g, b) = (i16::from(p.red()), i16::from(p.green()), i16::from(p.blue()));
    r > 90 && (r - g).abs() < 20 && (r - b).abs() < 25
}

#[test]
fn frames_have_the_requested_size_a_plausible_cloth_and_change_over_time() {
    let mut scene = SceneSpec {
        width: 31,
        height: 21,
        ..SceneSpec::paper(SceneKind::Swing, Variant::Fractional)
    }
    .build()
    .unwrap();
    let cam = camera(&scene, 200, 150);
    let first = draw(&scene, &cam);
    assert_eq!((first.width(), first.height()), (200, 150));
    let cloth = first.pixels().iter().filter(|p| is_cloth(p)).count() as f64 / (200.0 * 150.0);
    assert!(
        (0.05..0.8).contains(&cloth),
        "cloth covers {:.1} % of the picture",
        100.0 * cloth
    );
    scene.run_until(1.0).unwrap();
    let later = draw(&scene, &cam);
    let changed = first
        .pixels()
        .iter()
        .zip(later.pixels())
        .filter(|(a, b)| a != b)
        .count() as f64
        / (200.0 * 150.0);
    assert!(
        changed > 0.01,
        "only {:.2} % of pixels changed after 1 s of swinging",
        100.0 * changed
    );
}

#[test]
fn the_sphere_appears_in_the_picture() {
    let mut scene = SceneSpec {
        width: 31,
        height: 21,
        ..SceneSpec::paper(SceneKind::Sphere, Variant::Fractional)
    }
    .build()
    .unwrap();
    scene.run_until(3.5).unwrap(); // the sphere has pushed through the cloth and come out in front
    let cam = camera(&scene, 200, 150);
    let pix = draw(&scene, &cam);
    let sphere = pix.pixels().iter().filter(|p| is_sphere(p)).count();
    assert!(sphere > 50, "{sphere} sphere pixels");
    // Without colliders there are (almost) none of those pixels.
    let swing = SceneSpec {
        width: 31,
        height: 21,
        ..SceneSpec::paper(SceneKind::Swing, Variant::Fractional)
    }
    .build()
    .unwrap();
    let plain = draw(&swing, &cam);
    let none = plain.pixels().iter().filter(|p| is_sphere(p)).count();
    assert!(none < sphere / 10, "{none} grey pixels without a sphere");
}

/// A smoothly bent sheet draws smoothly: along a vertical line through the cloth, the
/// brightness changes by small steps (flat shading jumps at every row of facets, drawing
/// horizontal stripes that are not in the cloth).
#[test]
fn a_smooth_bend_draws_without_stripes() {
    let grid = fraccloth::GridSpec {
        width: 31,
        height: 21,
        spacing: 0.02,
        total_mass: 0.1,
    }
    .build()
    .unwrap();
    let bent: Vec<fraccloth::Vec3> = grid
        .rest_positions
        .iter()
        .map(|p| fraccloth::Vec3::new(p.x, p.y, 0.06 * (p.y * 9.0).sin()))
        .collect();
    let cam = Camera::for_rest_shape(&grid.rest_positions, 320, 240);
    let mut pix = Pixmap::new(320, 240).unwrap();
    render_frame(
        &Scene3d {
            positions: &bent,
            triangles: &grid.triangles,
            spheres: &[],
        },
        &cam,
        &mut pix,
    );
    // The brightest jump between vertically adjacent cloth pixels in the middle column.
    let (top, bottom) = (
        cam.project(&grid.rest_positions[15]),
        cam.project(&grid.rest_positions[20 * 31 + 15]),
    );
    let x = ((top.0 + bottom.0) / 2.0) as u32;
    let mut worst = 0i32;
    let mut last: Option<i32> = None;
    for y in (top.1 as u32 + 4)..(bottom.1 as u32 - 4) {
        let p = pix.pixel(x, y).unwrap();
        if !is_cloth(&p) {
            last = None;
            continue;
        }
        let lum = i32::from(p.red()) + i32::from(p.green());
        if let Some(l) = last {
            worst = worst.max((lum - l).abs());
        }
        last = Some(lum);
    }
    assert!(worst > 0, "no cloth found along the line");
    assert!(
        worst <= 12,
        "brightness jumps by {worst} between adjacent pixels: stripes"
    );
}
