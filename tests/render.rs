//! The preview renderer: requested size, a plausible cloth area, motion between frames, and
//! colliders in the picture.

use fraccloth::render::{render_frame, Camera, Scene3d};
use fraccloth::scenes::{SceneKind, SceneSpec, Variant};
use tiny_skia::Pixmap;

fn camera(scene: &fraccloth::scenes::Scene, w: u32, h: u32) -> Camera {
    Camera::for_rest_shape(&scene.cloth.topology().rest_positions, w, h)
}

fn draw(scene: &fraccloth::scenes::Scene, cam: &Camera) -> Pixmap {
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
    scene.run_until(3.0).unwrap(); // the sphere has pushed through the cloth towards the camera
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
