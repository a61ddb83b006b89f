//! Rays from the centre of a box in random directions, each leaving it
//! through the slab test, and a frame turning a direction into local
//! coordinates and back: the pieces of `rtgi-math` a tracer uses first.
//!
//! `cargo run -p rtgi-math --example rays_and_boxes`

use rtgi_math::{Aabb, Frame, Ray, Rng, Vec3, uniform_sphere};

fn main() {
    let unit_box = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
    // Random numbers are a function of (seed, pixel, sample): the same here on every run.
    let mut rng = Rng::for_sample(7, 0, 0);
    let mut longest: f32 = 0.0;
    for _ in 0..1000 {
        let direction = uniform_sphere(rng.next_f32(), rng.next_f32());
        let ray = Ray::new(Vec3::ZERO, direction);
        let (enter, exit) = unit_box.intersect(&ray.with_inverse()).expect("a ray from inside leaves the box");
        assert!(enter <= 0.0 && exit >= 1.0 && exit <= 3f32.sqrt() * (1.0 + 1e-5));
        longest = longest.max(exit);
    }
    println!("1000 rays from the centre left the box, the longest after {longest:.3} (at most sqrt(3) = 1.732)");

    let normal = Vec3::new(0.0, 1.0, 1.0).normalize();
    let frame = Frame::from_z(normal);
    let v = Vec3::new(0.3, -0.2, 0.9).normalize();
    let local = frame.to_local(v);
    println!("{v} is {local} in the frame of the normal {normal}; cos theta = {:.3}", local.z);
    assert!((frame.to_world(local) - v).length() < 1e-5);
}

#[test]
fn runs() {
    main();
}
