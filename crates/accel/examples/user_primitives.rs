//! A BVH over spheres, a primitive of the user's own: the `Primitive`
//! trait asks for a box and a ray test, the BVH is built by the same
//! builders as the triangle BVHs, and its closest hit is the one a scan
//! over all spheres finds (smallest distance, then lowest index).
//!
//! `cargo run -p rtgi-accel --example user_primitives`

use rtgi_accel::{Aabb, BuildParams, Primitive, PrimitiveBvh, Ray, Rng, SplitMethod, Vec3, intersect_primitive};

/// A sphere, reporting the unit normal where it is hit.
struct Sphere {
    centre: Vec3,
    radius: f32,
}

impl Primitive for Sphere {
    type Payload = Vec3;

    fn bounds(&self) -> Aabb {
        Aabb::new(self.centre - self.radius, self.centre + self.radius)
    }

    fn intersect(&self, ray: &Ray, t_max: f32) -> Option<(f32, Vec3)> {
        // |o + t d - c|² = r², as a t² + 2 b t + c = 0.
        let oc = ray.origin - self.centre;
        let a = ray.direction.length_squared();
        let b = oc.dot(ray.direction);
        let c = oc.length_squared() - self.radius * self.radius;
        let discriminant = b * b - a * c;
        if discriminant < 0.0 {
            return None;
        }
        let root = discriminant.sqrt();
        // The nearer root in range, else the farther one (the ray starts inside).
        let t = [(-b - root) / a, (-b + root) / a].into_iter().find(|&t| t >= ray.t_min && t <= t_max)?;
        Some((t, (ray.at(t) - self.centre) / self.radius))
    }
}

fn main() {
    let mut rng = Rng::new(1, 0);
    let mut unit = || rng.next_f32();
    let spheres: Vec<Sphere> = (0..1000)
        .map(|_| Sphere { centre: Vec3::new(unit(), unit(), unit()) * 100.0, radius: 0.5 + 2.0 * unit() })
        .collect();
    let rays: Vec<Ray> = (0..200)
        .map(|_| Ray::new(Vec3::new(unit(), unit(), -1.0) * 100.0, Vec3::new(unit() - 0.5, unit() - 0.5, 2.0)))
        .collect();

    // The reference: every sphere, under the same hit rule as the BVH.
    let scan = |ray: &Ray| {
        let mut best: Option<(f32, u32)> = None;
        for (index, sphere) in spheres.iter().enumerate() {
            if let Some((t, _)) = intersect_primitive(sphere, ray)
                && best.is_none_or(|(best_t, _)| t < best_t)
            {
                best = Some((t, index as u32));
            }
        }
        best
    };
    let expected: Vec<Option<(f32, u32)>> = rays.iter().map(scan).collect();

    // The BVH owns the spheres; hits name them by their index in the input.
    let mut bvh = PrimitiveBvh::new(spheres, SplitMethod::BinnedSah, &BuildParams::default());
    for method in [SplitMethod::ObjectMedian, SplitMethod::SpatialMedian, SplitMethod::SweepSah, SplitMethod::BinnedSah]
    {
        bvh = PrimitiveBvh::new(bvh.into_primitives(), method, &BuildParams::default());
        let stats = bvh.build_stats();
        let hits = rays.iter().zip(&expected).filter(|(ray, expected)| {
            let hit = bvh.intersect(ray);
            assert_eq!(hit.map(|h| (h.t, h.primitive)), **expected, "{method:?}");
            assert_eq!(bvh.occluded(ray), expected.is_some());
            hit.is_some()
        });
        println!(
            "{:>14}: {} nodes, depth {:>2}, SAH cost {:>6.2}: {} of {} rays hit a sphere, as the scan says",
            method.name(),
            stats.nodes,
            stats.depth,
            stats.sah_cost,
            hits.count(),
            rays.len()
        );
    }
    if let Some(hit) = rays.iter().find_map(|ray| bvh.intersect(ray)) {
        let sphere = &bvh.primitives()[hit.primitive as usize];
        println!(
            "first hit: sphere {} (centre {}, radius {:.2}) at t = {:.3}, normal {:.3}",
            hit.primitive, sphere.centre, sphere.radius, hit.t, hit.payload
        );
    }
}

#[test]
fn runs() {
    main();
}
