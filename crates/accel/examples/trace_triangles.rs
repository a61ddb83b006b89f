//! Builds a BVH over a small grid of triangles and traces rays through it:
//! the closest hit of each, and a shadow-ray (any hit) query, compared with
//! the linear scan, which every structure agrees with bit for bit.
//!
//! `cargo run -p rtgi-accel --example trace_triangles`

use rtgi_accel::{AccelKind, BuildParams, Ray, Vec3};

fn main() {
    // A 4 x 4 grid of unit squares in the plane z = 0, two triangles each.
    let mut triangles = Vec::new();
    for y in 0..4 {
        for x in 0..4 {
            let corner = |dx: i32, dy: i32| Vec3::new((x + dx) as f32, (y + dy) as f32, 0.0);
            triangles.push([corner(0, 0), corner(1, 0), corner(1, 1)]);
            triangles.push([corner(0, 0), corner(1, 1), corner(0, 1)]);
        }
    }
    let bvh = AccelKind::Sah.build(&triangles, &AccelKind::Sah.default_params());
    let linear = AccelKind::Linear.build(&triangles, &BuildParams::default());
    let stats = bvh.build_stats();
    println!(
        "{} triangles: {} nodes, depth {}, SAH cost {:.2}",
        stats.triangles, stats.nodes, stats.depth, stats.sah_cost
    );

    // Rays from above, looking down the -Z axis at a few points of the grid.
    for (x, y) in [(0.25, 0.75), (1.5, 1.2), (3.9, 3.1), (5.0, 5.0)] {
        let ray = Ray::new(Vec3::new(x, y, 2.0), -Vec3::Z);
        let hit = bvh.intersect(&ray);
        assert_eq!(hit, linear.intersect(&ray));
        match hit {
            Some(hit) => {
                // The barycentrics interpolate anything given per corner; here the position.
                let [a, b, c] = triangles[hit.triangle as usize];
                let p = (1.0 - hit.beta - hit.gamma) * a + hit.beta * b + hit.gamma * c;
                println!("ray at ({x}, {y}) hits triangle {} at t = {} (point {p})", hit.triangle, hit.t);
            }
            None => println!("ray at ({x}, {y}) misses"),
        }
    }

    // A shadow ray between two points above the grid is not blocked; one
    // through it is.
    let above = Ray::with_range(Vec3::new(0.5, 0.5, 1.0), Vec3::X, 0.0, 3.0);
    let through = Ray::with_range(Vec3::new(0.5, 0.5, 1.0), -Vec3::Z, 0.0, 2.0);
    assert!(!bvh.occluded(&above) && bvh.occluded(&through));
    println!("shadow rays: along the grid unblocked, through it blocked");
}

#[test]
fn runs() {
    main();
}
