use fraccloth::scenes::*;
use fraccloth::Vec3;
fn main() {
    for kick in [false, true] {
        let mut spec = SceneSpec::paper(SceneKind::Swing, Variant::Fractional);
        spec.width = 31;
        spec.height = 21;
        let mut s = spec.build().unwrap();
        if kick {
            let v: Vec<Vec3> = (0..s.cloth.vertex_count())
                .map(|i| Vec3::new(0.02, 0.0, 0.15 * ((i % 7) as f64 - 3.0) / 3.0))
                .collect();
            s.cloth.set_velocities(&v).unwrap();
        }
        for k in 0..20 {
            let e = s.cloth.energy();
            let ke: f64 = s
                .cloth
                .velocities()
                .iter()
                .zip(&s.cloth.topology().masses)
                .map(|(v, m)| 0.5 * m * v.norm_squared())
                .sum();
            println!("kick={kick} t={:.2} E={:.6e} KE={:.3e}", s.cloth.time(), e, ke);
            for _ in 0..100 {
                s.cloth.step(spec.dt).unwrap();
            }
            let _ = k;
        }
    }
}
