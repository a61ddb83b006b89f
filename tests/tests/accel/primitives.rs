//! User primitives (`rtgi_accel::PrimitiveBvh`): triangles wrapped as
//! primitives answer every ray bit for bit as every triangle structure
//! does (through `for_every_variant`), on random and adversarial soups;
//! spheres give the closest hit of a scan over the spheres for every split
//! method and leaf size, ties to the lowest index; empty inputs, boxes
//! that cannot be built over and primitives whose hits lie outside their
//! own box follow the documented rule without panicking.

use rtgi_accel::verify::{Answer, ProbeRay, RayKind, adversarial_cases, same_hit};
use rtgi_accel::{
    Aabb, BuildParams, Hit, Intersector, Primitive, PrimitiveBvh, PrimitiveHit, Ray, Rng, SplitMethod, Vec3,
    intersect_primitive,
};
use rtgi_tests::for_every_variant;

const SPLIT_METHODS: [SplitMethod; 4] =
    [SplitMethod::ObjectMedian, SplitMethod::SpatialMedian, SplitMethod::BinnedSah, SplitMethod::SweepSah];

/// Every split method with leaf sizes 1, 4 and 16 (and 2 and 32 bins for the binned SAH).
fn every_build() -> Vec<(SplitMethod, BuildParams)> {
    let mut builds = Vec::new();
    for method in SPLIT_METHODS {
        for max_leaf_size in [1, 4, 16] {
            builds.push((method, BuildParams { max_leaf_size, ..BuildParams::default() }));
        }
    }
    for sah_bins in [2, 32] {
        builds.push((SplitMethod::BinnedSah, BuildParams { sah_bins, ..BuildParams::default() }));
    }
    builds
}

/// A triangle as a user primitive, tested with the crate's own test.
struct Triangle {
    corners: [Vec3; 3],
    intersector: Intersector,
}

impl Primitive for Triangle {
    /// `(beta, gamma)`.
    type Payload = (f32, f32);

    fn bounds(&self) -> Aabb {
        Aabb::from_points(self.corners)
    }

    fn intersect(&self, ray: &Ray, t_max: f32) -> Option<(f32, (f32, f32))> {
        let hit = self.intersector.intersect(ray.origin, ray.direction, ray.t_min, t_max, &self.corners)?;
        Some((hit.t, (hit.beta, hit.gamma)))
    }
}

fn as_hit(hit: Option<PrimitiveHit<(f32, f32)>>) -> Option<Hit> {
    hit.map(|h| Hit { t: h.t, triangle: h.primitive, beta: h.payload.0, gamma: h.payload.1 })
}

#[test]
fn triangles_as_primitives_agree_bit_for_bit_with_every_triangle_structure() {
    let mut rng = Rng::new(5, 5);
    let mut point = |scale: f32| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * scale;
    let random: Vec<[Vec3; 3]> = (0..400)
        .map(|_| {
            let base = point(10.0);
            [base, base + point(1.5), base + point(1.5)]
        })
        .collect();
    let mut soups = vec![("random".to_owned(), random, Vec::new())];
    soups.extend(adversarial_cases(300, 21).into_iter().map(|case| (case.name, case.triangles, case.special_rays)));

    let mut failures = Vec::new();
    for (name, triangles, special_rays) in soups {
        // Random, vertex, edge and axis-parallel rays (with +0 and -0
        // components), secondary, silhouette and camera rays; the
        // coincident case has exact duplicates for ties.
        let mut probes: Vec<ProbeRay> = RayKind::ALL.iter().flat_map(|kind| kind.rays(&triangles, 120, 9)).collect();
        probes.extend(special_rays.into_iter().flat_map(|(_, rays)| rays.into_iter().take(200)));
        let references: Vec<(Intersector, Vec<Answer>)> = Intersector::ALL
            .iter()
            .map(|&intersector| {
                let wrapped = || triangles.iter().map(|&corners| Triangle { corners, intersector }).collect();
                let builds: Vec<PrimitiveBvh<Triangle>> = every_build()
                    .iter()
                    .map(|(method, params)| PrimitiveBvh::new(wrapped(), *method, params))
                    .collect();
                let answers: Vec<Answer> = probes
                    .iter()
                    .map(|probe| {
                        let first = &builds[0];
                        let answer =
                            Answer { closest: as_hit(first.intersect(&probe.ray)), any: first.occluded(&probe.ray) };
                        for (bvh, (method, params)) in builds.iter().zip(every_build()).skip(1) {
                            let other = as_hit(bvh.intersect(&probe.ray));
                            assert!(
                                same_hit(other, answer.closest) && bvh.occluded(&probe.ray) == answer.any,
                                "{name}: {method:?} leaf {}: {:?}: {other:?} vs {:?}",
                                params.max_leaf_size,
                                probe.ray,
                                answer.closest
                            );
                        }
                        answer
                    })
                    .collect();
                (intersector, answers)
            })
            .collect();
        for_every_variant(&triangles, |label, accel, params| {
            let reference = &references.iter().find(|(i, _)| *i == params.intersector).expect("every intersector").1;
            let answers = Answer::all(accel, &probes);
            let differing: Vec<String> = answers
                .iter()
                .zip(reference)
                .zip(&probes)
                .filter(|((a, b), _)| !same_hit(a.closest, b.closest) || a.any != b.any)
                .map(|((a, b), probe)| format!("{:?}: {a:?} vs primitives {b:?}", probe.ray))
                .collect();
            if let Some(first) = differing.first() {
                failures.push(format!(
                    "{name}: {label}: {} of {} rays differ; first {first}",
                    differing.len(),
                    probes.len()
                ));
            }
        });
    }
    assert!(failures.is_empty(), "{} failures:\n{}", failures.len(), failures[..failures.len().min(30)].join("\n"));
}

/// A sphere; the payload is the index of the root hit (0 nearer, 1 farther).
#[derive(Clone, Copy, Debug)]
struct Sphere {
    centre: Vec3,
    radius: f32,
}

impl Primitive for Sphere {
    type Payload = u8;

    fn bounds(&self) -> Aabb {
        Aabb::new(self.centre - self.radius, self.centre + self.radius)
    }

    fn intersect(&self, ray: &Ray, t_max: f32) -> Option<(f32, u8)> {
        let oc = ray.origin - self.centre;
        let a = ray.direction.length_squared();
        let b = oc.dot(ray.direction);
        let c = oc.length_squared() - self.radius * self.radius;
        let discriminant = b * b - a * c;
        if discriminant < 0.0 {
            return None;
        }
        let root = discriminant.sqrt();
        [(-b - root) / a, (-b + root) / a].into_iter().zip([0, 1]).find(|&(t, _)| t >= ray.t_min && t <= t_max)
    }
}

/// The reference: every primitive under the hit rule, smallest `t`, then lowest index.
fn scan<P: Primitive>(primitives: &[P], ray: &Ray) -> Option<PrimitiveHit<P::Payload>> {
    let mut best: Option<PrimitiveHit<P::Payload>> = None;
    for (index, primitive) in primitives.iter().enumerate() {
        if let Some((t, payload)) = intersect_primitive(primitive, ray)
            && best.as_ref().is_none_or(|b| t < b.t)
        {
            best = Some(PrimitiveHit { t, primitive: index as u32, payload });
        }
    }
    best
}

fn same<P: PartialEq + std::fmt::Debug>(a: &Option<PrimitiveHit<P>>, b: &Option<PrimitiveHit<P>>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => a.t.to_bits() == b.t.to_bits() && a.primitive == b.primitive && a.payload == b.payload,
        _ => false,
    }
}

fn spheres_and_rays() -> (Vec<Sphere>, Vec<Ray>) {
    let mut rng = Rng::new(17, 3);
    let mut unit = || rng.next_f32();
    let mut spheres: Vec<Sphere> = (0..600)
        .map(|_| Sphere { centre: Vec3::new(unit(), unit(), unit()) * 40.0 - 20.0, radius: 0.1 + 2.0 * unit() })
        .collect();
    // Coincident copies (ties go to the lowest index), spread through the input.
    let copied = spheres[10];
    for at in [50, 300, 599] {
        spheres.insert(at, copied);
    }
    let mut rays = Vec::new();
    for k in 0..2000 {
        let origin = Vec3::new(unit(), unit(), unit()) * 60.0 - 30.0;
        let direction = if k % 2 == 0 {
            Vec3::new(unit(), unit(), unit()) - 0.5
        } else {
            // Aimed at a sphere's centre, or at a point of its box's surface.
            let sphere = spheres[k % spheres.len()];
            let target = if k % 4 == 1 { sphere.centre } else { sphere.centre + Vec3::new(sphere.radius, 0.0, 0.0) };
            target - origin
        };
        rays.push(Ray::new(origin, direction));
    }
    // Axis-parallel rays with +0 and -0 components, through the copies.
    for zero in [0.0, -0.0] {
        rays.push(Ray::new(copied.centre - Vec3::X * 50.0, Vec3::new(1.0, zero, zero)));
        rays.push(Ray::new(copied.centre + Vec3::Y * 50.0, Vec3::new(-zero, -1.0, zero)));
    }
    // Starting inside a sphere, and bounded rays.
    rays.push(Ray::new(spheres[0].centre, Vec3::new(0.3, -0.2, 0.9)));
    rays.push(Ray::with_range(copied.centre - Vec3::Z * 30.0, Vec3::Z, 0.0, 30.0 - copied.radius));
    rays.push(Ray::with_range(copied.centre - Vec3::Z * 30.0, Vec3::Z, 30.0 - copied.radius, 30.0));
    (spheres, rays)
}

#[test]
fn spheres_give_the_scans_closest_hit_for_every_split_method_and_leaf_size() {
    let (spheres, rays) = spheres_and_rays();
    let reference: Vec<_> = rays.iter().map(|ray| scan(&spheres, ray)).collect();
    assert!(reference.iter().filter(|hit| hit.is_some()).count() > rays.len() / 3, "enough rays hit");
    for (method, params) in every_build() {
        let bvh = PrimitiveBvh::new(spheres.clone(), method, &params);
        assert_eq!(bvh.build_stats().excluded_triangles, 0);
        let largest_leaf = bvh.build_stats().leaf_size_histogram.len() - 1;
        assert!(largest_leaf <= params.max_leaf_size, "{method:?}: a leaf of {largest_leaf}");
        for (ray, expected) in rays.iter().zip(&reference) {
            let hit = bvh.intersect(ray);
            assert!(same(&hit, expected), "{method:?} leaf {}: {ray:?}: {hit:?} vs {expected:?}", params.max_leaf_size);
            assert_eq!(bvh.occluded(ray), expected.is_some(), "{method:?}: {ray:?}");
        }
    }
}

#[test]
fn coincident_spheres_tie_to_the_lowest_index_and_inside_rays_hit_the_far_side() {
    let (spheres, _) = spheres_and_rays();
    let copied = spheres[10];
    let copies: Vec<u32> = (0..spheres.len() as u32)
        .filter(|&i| spheres[i as usize].centre == copied.centre && spheres[i as usize].radius == copied.radius)
        .collect();
    assert_eq!(copies.len(), 4);
    for (method, params) in every_build() {
        let bvh = PrimitiveBvh::new(spheres.clone(), method, &params);
        for zero in [0.0, -0.0] {
            let ray = Ray::new(copied.centre - Vec3::X * 1e-3, Vec3::new(zero, zero, 1.0));
            // From the centre of the copies: all four are hit at the same t on their far side.
            let hit = bvh.intersect(&ray).expect("a ray from inside hits");
            let nearest = scan(&spheres, &ray).unwrap();
            assert_eq!((hit.primitive, hit.payload), (nearest.primitive, nearest.payload), "{method:?}");
            if nearest.primitive == copies[0] || copies.contains(&nearest.primitive) {
                assert_eq!(hit.primitive, copies[0], "{method:?}: the lowest index wins the tie");
                assert_eq!(hit.payload, 1, "{method:?}: the far root of a sphere the ray starts in");
            }
        }
        let outside = Ray::new(copied.centre - Vec3::Z * 100.0, Vec3::Z);
        let hit = bvh.intersect(&outside).unwrap();
        let expected = scan(&spheres, &outside).unwrap();
        assert_eq!((hit.t, hit.primitive), (expected.t, expected.primitive));
    }
    // Alone, the copies always tie at the lowest index.
    let alone = vec![copied; 9];
    for (method, params) in every_build() {
        let bvh = PrimitiveBvh::new(alone.clone(), method, &params);
        let hit = bvh.intersect(&Ray::new(copied.centre - Vec3::Z * 100.0, Vec3::Z)).unwrap();
        assert_eq!((hit.primitive, hit.payload), (0, 0), "{method:?}");
        let inside = bvh.intersect(&Ray::new(copied.centre, Vec3::Z)).unwrap();
        assert_eq!((inside.primitive, inside.payload), (0, 1), "{method:?}");
    }
}

#[test]
fn empty_inputs_and_primitives_that_cannot_be_built_over_are_never_hit() {
    let ray = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
    for (method, params) in every_build() {
        let empty = PrimitiveBvh::<Sphere>::new(Vec::new(), method, &params);
        assert!(empty.intersect(&ray).is_none() && !empty.occluded(&ray));
        assert!(empty.nodes().is_empty() && empty.primitives().is_empty() && empty.bounds().is_empty());

        let bad = vec![
            Sphere { centre: Vec3::new(f32::NAN, 0.0, 0.0), radius: 1.0 },
            Sphere { centre: Vec3::ZERO, radius: f32::INFINITY },
            Sphere { centre: Vec3::ZERO, radius: -1.0 },
            Sphere { centre: Vec3::ZERO, radius: 1.0 },
        ];
        let bvh = PrimitiveBvh::new(bad, method, &params);
        assert_eq!(bvh.build_stats().excluded_triangles, 3);
        assert_eq!(bvh.primitives().len(), 4);
        let hit = bvh.intersect(&ray).unwrap();
        assert_eq!((hit.t, hit.primitive), (4.0, 3));
        // Invalid rays hit nothing.
        assert!(bvh.intersect(&Ray::new(Vec3::ZERO, Vec3::ZERO)).is_none());
        assert!(!bvh.occluded(&Ray::new(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Z)));
    }
}

/// A unit cube at `x` in `[offset, offset + 1]` whose `intersect` reports
/// whatever `t` it is told to, in or out of its box and range.
struct Liar {
    offset: f32,
    t: f32,
}

impl Primitive for Liar {
    type Payload = ();

    fn bounds(&self) -> Aabb {
        Aabb::new(Vec3::new(self.offset, 0.0, 0.0), Vec3::new(self.offset + 1.0, 1.0, 1.0))
    }

    fn intersect(&self, _ray: &Ray, _t_max: f32) -> Option<(f32, ())> {
        Some((self.t, ()))
    }
}

#[test]
fn hits_outside_their_own_box_follow_the_rule() {
    // A ray along +x at y = z = 0.5 from x = -10 enters the cube at offset
    // o at t = 10 + o and leaves it at 11 + o.
    let ray = Ray::with_range(Vec3::new(-10.0, 0.5, 0.5), Vec3::X, 1.0, 1000.0);
    let rule = |offset: f32, t: f32| intersect_primitive(&Liar { offset, t }, &ray).map(|(t, ())| t);
    // Below the box's entry: raised to it.
    assert_eq!(rule(0.0, 3.0), Some(10.0));
    // Inside the box: kept.
    assert_eq!(rule(0.0, 10.5), Some(10.5));
    // Beyond the box's exit but in the ray's range: kept as it is.
    assert_eq!(rule(0.0, 500.0), Some(500.0));
    // Outside the ray's range, or NaN: dropped.
    assert_eq!(rule(0.0, 0.5), None);
    assert_eq!(rule(0.0, 2000.0), None);
    assert_eq!(rule(0.0, f32::NAN), None);
    assert_eq!(rule(0.0, f32::INFINITY), None);
    // A box the ray misses: nothing, whatever the primitive says.
    assert_eq!(
        intersect_primitive(&Liar { offset: 0.0, t: 10.5 }, &Ray::new(Vec3::new(-10.0, 5.0, 0.5), Vec3::X)),
        None
    );

    // Many liars: every build agrees with the scan under the same rule.
    let mut rng = Rng::new(4, 4);
    let liars: Vec<Liar> = (0..300)
        .map(|_| {
            let offset = rng.next_f32() * 200.0;
            let t = match rng.next_below(6) {
                0 => rng.next_f32() * 2000.0 - 500.0,
                1 => f32::NAN,
                2 => 10.0 + offset + rng.next_f32(),
                3 => 10.0 + offset - rng.next_f32() * 5.0,
                4 => f32::NEG_INFINITY,
                _ => 10.0 + offset + 1.0 + rng.next_f32() * 50.0,
            };
            Liar { offset, t }
        })
        .collect();
    let rays: Vec<Ray> = (0..200)
        .map(|k| {
            let origin = Vec3::new(-10.0, 0.5 + (k % 3) as f32 * 0.25, 0.5);
            let direction = Vec3::new(1.0, if k % 2 == 0 { 0.0 } else { -0.0 }, (k % 5) as f32 * 1e-3);
            Ray::with_range(origin, direction, (k % 7) as f32, 100.0 + k as f32 * 5.0)
        })
        .collect();
    for (method, params) in every_build() {
        let bvh = PrimitiveBvh::new(
            liars.iter().map(|liar| Liar { offset: liar.offset, t: liar.t }).collect(),
            method,
            &params,
        );
        for ray in &rays {
            let expected = scan(&liars, ray);
            let hit = bvh.intersect(ray);
            assert!(
                same(&hit, &expected),
                "{method:?} leaf {}: {ray:?}: {hit:?} vs {expected:?}",
                params.max_leaf_size
            );
            assert_eq!(bvh.occluded(ray), expected.is_some());
        }
    }
}

#[test]
fn the_builders_sort_by_the_primitives_own_centroid() {
    /// A needle along x of its own length, hit where the ray enters its box (the rule raises
    /// the `t_min` it reports to that entry); with `own_centroid` its
    /// centroid is its first end instead of its box's centre.
    struct Needle {
        start: Vec3,
        length: f32,
        own_centroid: bool,
    }
    impl Primitive for Needle {
        type Payload = ();
        fn bounds(&self) -> Aabb {
            Aabb::new(self.start, self.start + Vec3::new(self.length, 0.1, 0.1))
        }
        fn centroid(&self) -> Vec3 {
            if self.own_centroid { self.start } else { self.bounds().centroid() }
        }
        fn intersect(&self, ray: &Ray, _t_max: f32) -> Option<(f32, ())> {
            Some((ray.t_min, ()))
        }
    }
    let mut rng = Rng::new(8, 8);
    let shapes: Vec<(Vec3, f32)> = (0..500)
        .map(|_| (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 20.0, 0.5 + 8.0 * rng.next_f32()))
        .collect();
    let needles = |own_centroid: bool| -> Vec<Needle> {
        shapes.iter().map(|&(start, length)| Needle { start, length, own_centroid }).collect()
    };
    let rays: Vec<Ray> = (0..300)
        .map(|_| {
            let origin = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 40.0 - 10.0;
            Ray::new(origin, Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5)
        })
        .collect();
    let reference: Vec<_> = rays.iter().map(|ray| scan(&needles(false), ray)).collect();
    assert!(reference.iter().any(Option::is_some));
    for (method, params) in every_build() {
        let centred = PrimitiveBvh::new(needles(false), method, &params);
        let own = PrimitiveBvh::new(needles(true), method, &params);
        // A different tree (each centroid moved by half its needle) ...
        assert!(centred.nodes() != own.nodes(), "{method:?} leaf {}: the same tree", params.max_leaf_size);
        // ... with the same answers.
        for (ray, expected) in rays.iter().zip(&reference) {
            assert!(same(&own.intersect(ray), expected), "{method:?}: {ray:?}");
            assert!(same(&centred.intersect(ray), expected), "{method:?}: {ray:?}");
        }
    }
}
