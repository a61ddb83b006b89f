//! Diagnostic: the secondary rays of `rtgi experiment intersector` (the
//! solids of `verify::solids` placed at (1, 0.75, -0.5)·2^e, rays of
//! `RayKind::Secondary` with the experiment's seeds, regenerated here to
//! know their surface points), each tested against the triangle it leaves
//! with every intersector; every self-hit is described: the triangle, the
//! point's error bound in ulps, the origin's height above the exact plane
//! (f64) and the exact distance to it. Also counts self-hits of rays the
//! experiment does not hold (grazing, needles) and segments that hit the
//! triangle of their target.
//!
//! `cargo run --release -p rtgi-accel --example self_hits -- [rays per solid] [first e] [last e]`
//! (20000 0 23 are the experiment's).
use rtgi_accel::Intersector;
use rtgi_accel::verify::{Expect, RayKind, solids};
use rtgi_math::{Ray, Rng, SurfacePoint, Vec3, elongation, uniform_sphere};

fn ulp(x: f32) -> f32 {
    rtgi_math::next_float_up(x.abs()) - x.abs()
}

fn bary(rng: &mut Rng) -> (f32, f32) {
    let (u, v) = (rng.next_f32(), rng.next_f32());
    if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) }
}

fn main() {
    let per_solid: usize = std::env::args().nth(1).map(|s| s.parse().unwrap()).unwrap_or(20_000);
    let (lo, hi): (i32, i32) = (
        std::env::args().nth(2).map(|s| s.parse().unwrap()).unwrap_or(0),
        std::env::args().nth(3).map(|s| s.parse().unwrap()).unwrap_or(23),
    );
    let mut counts = [0usize; 3];
    let mut total = 0;
    let mut target_hits = [0usize; 3];
    let mut unfiltered = [0usize; 3];
    for e in lo..=hi {
        let offset = Vec3::new(1.0, 0.75, -0.5) * 2f32.powi(e);
        let scale = 1f32.max(64.0 * ulp(offset.abs().max_element()));
        let seed = 3 + e as u64;
        for (name, solid) in solids() {
            let tris = solid.mesh.placed(scale, offset).triangles();
            let probes = RayKind::Secondary.rays(&tris, per_solid, seed);
            let hittable: Vec<u32> =
                (0..tris.len() as u32).filter(|&i| rtgi_accel::is_hittable(&tris[i as usize])).collect();
            let mut rng = Rng::new(seed, 0x7e51f1 + RayKind::Secondary as u64);
            let pick = |rng: &mut Rng| hittable[rng.next_below(hittable.len() as u32) as usize];
            for probe in &probes {
                let index = pick(&mut rng);
                let t = tris[index as usize];
                let (u, v) = bary(&mut rng);
                let point = SurfacePoint::on_triangle(&t, u, v);
                let mut target = None;
                let ray: Ray = if rng.next_f32() < 0.5 {
                    let incoming = uniform_sphere(rng.next_f32(), rng.next_f32());
                    let n = point.normal;
                    point.spawn_ray(incoming - 2.0 * incoming.dot(n) * n)
                } else {
                    let o = pick(&mut rng);
                    let (u2, v2) = bary(&mut rng);
                    target = Some(o);
                    point.spawn_ray_to(&SurfacePoint::on_triangle(&tris[o as usize], u2, v2))
                };
                assert_eq!(
                    (ray.origin, ray.direction, ray.t_min, ray.t_max),
                    (probe.ray.origin, probe.ray.direction, probe.ray.t_min, probe.ray.t_max)
                );
                if let Some(o) = target
                    && o != index
                {
                    for (c, i) in target_hits.iter_mut().zip(Intersector::ALL) {
                        *c += i.intersect(ray.origin, ray.direction, ray.t_min, ray.t_max, &tris[o as usize]).is_some()
                            as usize;
                    }
                }
                for (c, i) in unfiltered.iter_mut().zip(Intersector::ALL) {
                    *c += i.intersect(ray.origin, ray.direction, ray.t_min, ray.t_max, &t).is_some() as usize;
                }
                let Expect::NotTriangle(own) = probe.expect else { continue };
                assert_eq!(own, index);
                total += 1;
                let hits: Vec<_> = Intersector::ALL
                    .iter()
                    .map(|i| i.intersect(ray.origin, ray.direction, ray.t_min, ray.t_max, &t))
                    .collect();
                if hits.iter().all(|h| h.is_none()) {
                    continue;
                }
                for (c, h) in counts.iter_mut().zip(&hits) {
                    *c += h.is_some() as usize;
                }
                // Exact geometry in f64.
                let [a, b, c] = t.map(|v| v.as_dvec3());
                let n = (b - a).cross(c - a).normalize();
                let o = ray.origin.as_dvec3();
                let d = ray.direction.as_dvec3();
                let pos = point.position.as_dvec3();
                let u_p = ulp(point.position.abs().max_element()) as f64;
                let h_pos = (pos - a).dot(n);
                let h_origin = (o - a).dot(n);
                let side = if d.dot(n) < 0.0 { -1.0 } else { 1.0 };
                let exact_t = -h_origin / d.dot(n);
                let size = (b - a).length().max((c - b).length()).max((a - c).length());
                println!(
                    "e={e} {name} tri {index} elong {:.2} size/|p| {:.2e} size/ulp {:.1}\n  corners {:?}\n  bary ({u}, {v}) pos {:?} err {:?} (ulps {:?}) normal {:?}\n  origin {:?} dir {:?} cos {:.4} (to point: {})\n  pos height {:+.3} ulp, origin height {:+.3} ulp (on side {side}: {:+.3} ulp), exact t {:.3e}\n  hits {:?}",
                    elongation(&t),
                    size / pos.abs().max_element(),
                    size / u_p,
                    t,
                    point.position,
                    point.error,
                    point.error / ulp(point.position.abs().max_element()),
                    point.normal,
                    ray.origin,
                    ray.direction,
                    d.normalize().dot(n),
                    ray.t_max < 1.5,
                    h_pos / u_p,
                    h_origin / u_p,
                    side * h_origin / u_p,
                    exact_t,
                    hits
                );
            }
        }
    }
    println!("self-hits on any triangle, grazing rays and needles included: {unfiltered:?}");
    println!("segments that hit their target's (other) triangle: {target_hits:?}");
    println!(
        "secondary rays held to no self-hit: {total}; self-hits per intersector {:?} ({:?})",
        counts,
        Intersector::ALL
    );
}
