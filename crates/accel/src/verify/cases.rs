//! The built-in adversarial scenes: each class of input on which a
//! structure that is not exact gives itself away.

use rtgi_math::{Ray, Rng, Vec3, uniform_sphere};

use super::rays::random_surface_point;
use super::shapes::{ClosedMesh, cylinder, icosphere, quad, rays_through_diagonal, tessellated_cube};
use super::{Expect, ProbeRay, RayKind, point_in_cube};

/// One adversarial scene: its triangles, and rays made for it on top of
/// the generic [`RayKind`]s.
#[derive(Clone, Debug)]
pub struct Case {
    /// The case's name in reports.
    pub name: String,
    /// The scene, as triangle corners.
    pub triangles: Vec<[Vec3; 3]>,
    /// Rays made for this scene, by kind (for example rays aimed inside
    /// closed meshes, which must all hit).
    pub special_rays: Vec<(&'static str, Vec<ProbeRay>)>,
}

impl Case {
    /// The special rays and `per_kind` rays of every generic kind, by kind name.
    pub fn rays(&self, per_kind: usize, seed: u64) -> Vec<(&'static str, Vec<ProbeRay>)> {
        let mut rays = self.special_rays.clone();
        for &kind in RayKind::ALL {
            rays.push((kind.name(), kind.rays(&self.triangles, per_kind, seed)));
        }
        rays
    }
}

/// The built-in adversarial set, with about `special` case-specific rays
/// per case: coincident triangles, exact copies of meshes, closed meshes
/// far from the origin and at extreme scales, degenerate triangles mixed
/// in, a huge plane beside small objects, rays exactly through shared
/// edges and vertices, touching axis-aligned boxes, and large triangles and
/// needles.
pub fn adversarial_cases(special: usize, seed: u64) -> Vec<Case> {
    let mut cases = vec![coincident(seed), copies()];
    cases.extend(closed_meshes(special, seed));
    cases.push(degenerate(seed));
    cases.push(mixed_scales(special, seed));
    cases.push(shared_edges(special, seed));
    cases.push(touching_boxes());
    cases.push(walls_and_needles(25 * special, seed));
    cases.push(hollow_needles(special, seed));
    cases.push(crossing_planks(special, seed));
    cases
}

/// Quads given twice, split along either diagonal, plus exact duplicates
/// with their corners rotated, random and axis-aligned (as the walls of the
/// Cornell box, whose file has such pairs).
fn coincident(seed: u64) -> Case {
    let mut rng = Rng::new(seed, 1);
    let mut point = |size: f32| point_in_cube(&mut rng, size);
    let mut triangles = Vec::new();
    for k in 0..48 {
        let a = point(8.0);
        let (u, v) = if k % 2 == 0 {
            (point(3.0), point(3.0))
        } else {
            // Axis-aligned, with exactly representable corners.
            let axis = k % 3;
            let (mut u, mut v) = ([0.0; 3], [0.0; 3]);
            u[(axis + 1) % 3] = 2.0;
            v[(axis + 2) % 3] = 1.5;
            (Vec3::from(u), Vec3::from(v))
        };
        let a = if k % 2 == 0 { a } else { a.round() };
        let (b, c, d) = (a + u, a + u + v, a + v);
        triangles.extend([[a, b, c], [a, c, d], [a, b, d], [b, c, d], [b, c, a]]);
    }
    Case { name: "coincident".into(), triangles, special_rays: Vec::new() }
}

/// Twelve exact copies each of a sphere and a cube, in the same place.
fn copies() -> Case {
    let mut triangles = Vec::new();
    let (sphere, cube) = (icosphere(2).triangles(), tessellated_cube(3).placed(0.75, Vec3::splat(0.5)).triangles());
    for _ in 0..12 {
        triangles.extend_from_slice(&sphere);
        triangles.extend_from_slice(&cube);
    }
    Case { name: "copies".into(), triangles, special_rays: Vec::new() }
}

/// A closed mesh and the points strictly inside it that rays are aimed at.
#[derive(Clone, Debug)]
pub struct Solid {
    /// The mesh, scaled to about unit size.
    pub mesh: ClosedMesh,
    /// A point inside the unit-sized shape, from two to three uniform numbers.
    pub inside: fn(&mut Rng) -> Vec3,
}

/// The closed solids of the adversarial set, by name: an icosphere, a
/// tessellated cube and a cylinder, each of unit size around the origin
/// (place them with [`ClosedMesh::placed`]).
pub fn solids() -> [(&'static str, Solid); 3] {
    fn in_ball(rng: &mut Rng) -> Vec3 {
        uniform_sphere(rng.next_f32(), rng.next_f32()) * 0.8 * rng.next_f32().cbrt()
    }
    fn in_cube(rng: &mut Rng) -> Vec3 {
        (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0) * 0.9
    }
    fn in_cylinder(rng: &mut Rng) -> Vec3 {
        let (r, phi) = (0.85 * rng.next_f32().sqrt(), std::f32::consts::TAU * rng.next_f32());
        Vec3::new(r * phi.cos(), r * phi.sin(), (rng.next_f32() * 2.0 - 1.0) * 0.9)
    }
    [
        ("sphere", Solid { mesh: icosphere(2), inside: in_ball }),
        ("cube", Solid { mesh: tessellated_cube(4), inside: in_cube }),
        ("cylinder", Solid { mesh: cylinder(24, 3), inside: in_cylinder }),
    ]
}

/// Rays from random points around a placed solid (`scale`, `offset`)
/// aimed at random points inside it: every one must hit by the point.
fn rays_inside(solid: &Solid, scale: f32, offset: Vec3, count: usize, rng: &mut Rng) -> Vec<ProbeRay> {
    (0..count)
        .map(|_| {
            let origin = offset + uniform_sphere(rng.next_f32(), rng.next_f32()) * (2.0 + 6.0 * rng.next_f32()) * scale;
            let target = offset + (solid.inside)(rng) * scale;
            ProbeRay { ray: Ray::new(origin, target - origin), expect: Expect::HitBy(1.0 + 1e-3) }
        })
        .collect()
}

/// The ulp of `x`: the gap between it and the next float up.
fn ulp(x: f32) -> f32 {
    rtgi_math::next_float_up(x.abs()) - x.abs()
}

/// Each solid at offsets 2^0 … 2^23 from the origin (sizes of at least
/// 2^6 ulps there, so that its shape survives rounding) and at scales
/// 2^-20 … 2^20 near the origin.
fn closed_meshes(count: usize, seed: u64) -> Vec<Case> {
    let mut placements = Vec::new();
    for exponent in [0, 4, 8, 12, 16, 20, 23] {
        let offset = Vec3::new(1.0, 0.75, -0.5) * 2f32.powi(exponent);
        for scale in [1.0f32, 16.0, 256.0] {
            if scale >= 64.0 * ulp(offset.abs().max_element()) {
                placements.push((scale, offset));
            }
        }
    }
    for exponent in [-20, -10, 10, 20] {
        let scale = 2f32.powi(exponent);
        placements.push((scale, Vec3::new(3.0, -1.0, 2.0) * scale));
    }
    let per_placement = count.div_ceil(placements.len()).max(1);
    let mut rng = Rng::new(seed, 2);
    solids()
        .into_iter()
        .map(|(name, solid)| {
            let mut triangles = Vec::new();
            let mut rays = Vec::new();
            for &(scale, offset) in &placements {
                // Solids placed far apart relative to their size: a ray aimed
                // into one meets no other first.
                triangles.extend(solid.mesh.placed(scale, offset).triangles());
                rays.extend(rays_inside(&solid, scale, offset, per_placement, &mut rng));
            }
            Case { name: format!("closed-{name}"), triangles, special_rays: vec![("inside", rays)] }
        })
        .collect()
}

/// A random soup with unhittable triangles mixed in: collinear, repeated
/// corners, NaN and infinite coordinates, and tiny and huge (but hittable)
/// ones.
fn degenerate(seed: u64) -> Case {
    let mut rng = Rng::new(seed, 3);
    let mut point = |size: f32| point_in_cube(&mut rng, size);
    let mut triangles = Vec::new();
    for k in 0..300 {
        let a = point(10.0);
        let (e1, e2) = (point(2.0), point(2.0));
        triangles.push(match k % 8 {
            0 => [a, a + e1, a + 2.0 * e1],
            1 => [a, a, a + e2],
            2 => [a, a + e1, Vec3::new(f32::NAN, a.y, a.z)],
            3 => [a, Vec3::new(f32::INFINITY, 0.0, 0.0), a + e2],
            4 => [a, a + e1 * 1e-30, a + e2 * 1e-30],
            5 => [a, a + e1 * 1e-6, a + e1 * 2e-6 + e2 * 1e-12],
            6 => [a * 1e30, (a + e1) * 1e30, (a + e2) * 1e30],
            _ => [a, a + e1, a + e2],
        });
    }
    Case { name: "degenerate".into(), triangles, special_rays: Vec::new() }
}

/// A ground plane 2^15 wide, as an 8 × 8 grid of quads, with spheres of
/// radius 1 resting on it near its centre; rays leave the plane at grazing
/// angles and skim it from just above.
fn mixed_scales(count: usize, seed: u64) -> Case {
    let mut triangles = Vec::new();
    let half = 16384.0f32;
    for i in 0..8 {
        for j in 0..8 {
            let corner = Vec3::new(-half + i as f32 * 4096.0, -half + j as f32 * 4096.0, 0.0);
            triangles.extend(quad(4096.0, corner));
        }
    }
    let plane = triangles.len() as u32;
    let mut rng = Rng::new(seed, 4);
    let sphere = icosphere(2);
    for _ in 0..20 {
        let centre = Vec3::new(rng.next_f32() * 100.0 - 50.0, rng.next_f32() * 100.0 - 50.0, 1.0);
        triangles.extend(sphere.placed(1.0, centre).triangles());
    }
    let mut rays = Vec::new();
    for k in 0..count {
        let index = rng.next_below(plane);
        let point = random_surface_point(&triangles[index as usize], &mut rng);
        let phi = std::f32::consts::TAU * rng.next_f32();
        let rise = 10f32.powf(-1.0 - 5.0 * rng.next_f32());
        let direction = Vec3::new(phi.cos(), phi.sin(), rise);
        if k % 2 == 0 {
            // Leaving the plane, barely upwards.
            rays.push(ProbeRay { ray: point.spawn_ray(direction), expect: Expect::NotTriangle(index) });
        } else {
            // Skimming it from just above, near the spheres.
            let origin = Vec3::new(rng.next_f32() * 200.0 - 100.0, rng.next_f32() * 200.0 - 100.0, rise);
            rays.push(ProbeRay { ray: Ray::new(origin, -direction), expect: Expect::Nothing });
        }
    }
    Case { name: "mixed-scales".into(), triangles, special_rays: vec![("grazing", rays)] }
}

/// Squares whose shared diagonal rays pass exactly through, at unit size,
/// far from the origin and tiny, and fans of eight triangles around a
/// shared vertex that rays pass exactly through.
fn shared_edges(count: usize, seed: u64) -> Case {
    let mut triangles = Vec::new();
    let mut rays = Vec::new();
    let setups = [
        (1.0, Vec3::new(8.0, 8.0, 0.0), 20),
        (1024.0, Vec3::splat(1_048_576.0), 13),
        (65536.0, Vec3::splat(16_777_216.0), 15),
        (2f32.powi(-40), Vec3::ZERO, 20),
    ];
    let per_setup = count.div_ceil(2 * setups.len()).max(1);
    for (size, offset, bits) in setups {
        triangles.extend(quad(size, offset));
        let through = rays_through_diagonal(size, offset, bits, per_setup, seed ^ size.to_bits() as u64);
        rays.extend(through.into_iter().map(|ray| ProbeRay { ray, expect: Expect::HitBy(1.0 + 1e-3) }));
    }
    let mut rng = Rng::new(seed, 5);
    let ring = [(1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (-1.0, 1.0), (-1.0, 0.0), (-1.0, -1.0), (0.0, -1.0), (1.0, -1.0)];
    for (size, centre) in [(1.0f32, Vec3::new(-8.0, -8.0, 0.0)), (16.0, Vec3::new(-1_048_576.0, 1_048_576.0, 4096.0))] {
        let p = |(x, y): (f32, f32)| centre + Vec3::new(x, y, 0.0) * size;
        triangles.extend((0..8).map(|i| [centre, p(ring[i]), p(ring[(i + 1) % 8])]));
        for _ in 0..per_setup {
            let (i, j) = (rng.next_below(13) as f32 - 6.0, rng.next_below(13) as f32 - 6.0);
            let height = if rng.next_f32() < 0.5 { 1.0 } else { -3.0 };
            let origin = centre + Vec3::new(i * 0.25, j * 0.5, height) * size;
            rays.push(ProbeRay { ray: Ray::new(origin, centre - origin), expect: Expect::HitBy(1.0 + 1e-3) });
        }
    }
    Case { name: "shared-edges".into(), triangles, special_rays: vec![("through-edge", rays)] }
}

/// Large triangles around the origin (rays leave them near their corners,
/// far from their other corners, as on the walls of a Cornell box), and
/// needles up to 1000 times longer than wide (as the mouldings of Sponza):
/// where a ray/triangle test's distances round most.
fn walls_and_needles(count: usize, seed: u64) -> Case {
    let mut rng = Rng::new(seed, 6);
    let mut point = |size: f32| point_in_cube(&mut rng, size);
    let mut triangles = Vec::new();
    for k in 0..200 {
        let a = point(1.0);
        let triangle = if k % 2 == 0 {
            [a, a + point(16.0), a + point(16.0)]
        } else {
            let along = point(12.0);
            let across = along.cross(point(1.0)).normalize_or_zero() * along.length() / [8.0, 64.0, 1000.0][k % 3];
            [a, a + along, a + 0.5 * along + across]
        };
        triangles.push(triangle);
    }
    // Self-hits are rare (about one ray in 10^5 on real scenes, were the
    // offset too small): many secondary rays.
    let leaving = RayKind::Secondary.rays(&triangles, count, seed ^ 0x5e1f);
    Case { name: "walls-and-needles".into(), triangles, special_rays: vec![("leaving", leaving)] }
}

/// A closed needle: a 64-sided cylinder of radius `radius` and length
/// `length` along x, centred on `centre`, its sides single facets the full
/// length, capped by fans.
pub fn needle(radius: f32, length: f32, centre: Vec3) -> ClosedMesh {
    let unit = cylinder(64, 1);
    let vertices =
        unit.vertices.iter().map(|v| centre + Vec3::new(0.5 * length * v.z, radius * v.x, radius * v.y)).collect();
    ClosedMesh { vertices, faces: unit.faces }
}

/// Closed needles (aspect 16384 : 1) at offsets 2^0 … 2^23 from the origin,
/// and rays from inside them nearly parallel to their axis: each leaves
/// through a long facet near the edge it shares with the next, where the
/// sheared coordinates of the watertight test lose most of their digits to
/// cancellation. (A leak of this kind was found in the single-precision
/// test: both facets beside the exit refused the ray.)
pub fn hollow_needles(count: usize, seed: u64) -> Case {
    let mut rng = Rng::new(seed, 8);
    let offsets = [0, 8, 12, 16, 20, 22, 23];
    let per_needle = count.div_ceil(offsets.len()).max(1);
    let (mut triangles, mut rays) = (Vec::new(), Vec::new());
    for exponent in offsets {
        let offset = 2f32.powi(exponent);
        // 256 ulps across the radius wherever it is: the facets survive rounding.
        let radius = 32f32.max(256.0 * ulp(offset));
        let length = 16384.0 * radius;
        let centre = Vec3::splat(offset);
        triangles.extend(needle(radius, length, centre).triangles());
        for _ in 0..per_needle {
            let along = (rng.next_f32() - 0.5) * 0.5 * length;
            let around = uniform_sphere(rng.next_f32(), rng.next_f32()) * 0.6 * radius;
            let origin = centre + Vec3::new(along, around.y, around.z);
            // Towards either end, leaning out by 10⁻⁴ to 1 of the radius over the length.
            let lean = radius / length * 10f32.powf(4.0 * rng.next_f32());
            let sideways = uniform_sphere(rng.next_f32(), rng.next_f32());
            let sign = if rng.next_f32() < 0.5 { -1.0 } else { 1.0 };
            let direction = Vec3::new(sign, lean * sideways.y, lean * sideways.z);
            rays.push(ProbeRay { ray: Ray::new(origin, direction), expect: Expect::HitBy(2.0 * length) });
        }
    }
    Case { name: "hollow-needles".into(), triangles, special_rays: vec![("inside", rays)] }
}

/// A lattice of long thin planks in the cube [0, 32]³: along x, along z,
/// upright, and tilted across the whole cube, each crossing many others,
/// which spatial splits (`sbvh`) cut into references on both sides of
/// planes. The cube's bounds make the root's candidate planes the integers,
/// and the rays go where a cut could lose a hit: lying in the planes
/// `x = k` or `z = k` (a zero direction component, the slab test's NaN
/// case) and aimed at points of the planks on those planes, some nearly
/// parallel to them; rays aimed at a plank must hit it.
fn crossing_planks(count: usize, seed: u64) -> Case {
    let quad = |a: Vec3, b: Vec3, c: Vec3, d: Vec3| [[a, b, c], [a, c, d]];
    let mut planks: Vec<[Vec3; 4]> = Vec::new();
    for k in 0..16 {
        let (at, level) = (2.0 * k as f32, (k % 4) as f32 * 8.0);
        let (x, z) = (Vec3::X * 32.0, Vec3::Z * 32.0);
        let across = 0.25;
        let along_x = Vec3::new(0.0, level + 1.0, at + 0.5);
        planks.push([along_x, along_x + x, along_x + x + Vec3::Z * across, along_x + Vec3::Z * across]);
        let along_z = Vec3::new(at + 1.5, level + 5.0, 0.0);
        planks.push([along_z, along_z + Vec3::X * across, along_z + Vec3::X * across + z, along_z + z]);
        if k % 4 == 0 {
            let post = Vec3::new(at + 0.75, 0.0, 31.0 - at);
            planks.push([post, post + Vec3::X * across, post + Vec3::new(across, 32.0, 0.0), post + Vec3::Y * 32.0]);
        }
        if k % 8 == 0 {
            // Corner to corner, rising: most of its box holds none of it,
            // so some of its pieces hold none of it either.
            let from = Vec3::new(0.0, level, at);
            let to = Vec3::new(32.0, 32.0 - level, 32.0 - at);
            let side = (to - from).cross(Vec3::Y).normalize() * across;
            planks.push([from, to, to + side, from + side]);
        }
    }
    let triangles: Vec<[Vec3; 3]> = planks.iter().flat_map(|&[a, b, c, d]| quad(a, b, c, d)).collect();
    let mut rng = Rng::new(seed, 9);
    let mut rays = Vec::new();
    while rays.len() < count {
        // A point on a plank where its length crosses an integer plane.
        let [a, b, _, d] = planks[rng.next_below(planks.len() as u32) as usize];
        let (long, across) = if (b - a).length() > (d - a).length() { (b - a, d - a) } else { (d - a, b - a) };
        let axis = long.abs().max_position();
        // Strictly between the plank's ends: a ray through an end, an open
        // edge, may rightly miss.
        let (start, end) = (a[axis].min(a[axis] + long[axis]), a[axis].max(a[axis] + long[axis]));
        let plane = start.floor() + 1.0 + rng.next_below((end.ceil() - start.floor() - 1.0) as u32) as f32;
        let u = (plane - a[axis]) / long[axis];
        let mut target = a + long * u + across * (0.05 + 0.9 * rng.next_f32());
        if long.abs().cmpgt(Vec3::ZERO).bitmask().count_ones() == 1 {
            // Along an axis: exactly on the plane, still on the plank.
            target[axis] = plane;
        }
        let mut direction = uniform_sphere(rng.next_f32(), rng.next_f32());
        match rng.next_below(3) {
            // In the plane: the component across it is zero, of either sign.
            0 => direction[axis] = if rng.next_f32() < 0.5 { 0.0 } else { -0.0 },
            // Nearly in it.
            1 => direction[axis] = direction[axis].signum() * 10f32.powf(-7.0 * rng.next_f32()),
            _ => {}
        }
        let distance = 1.0 + 40.0 * rng.next_f32();
        let origin = target - direction * distance;
        let ray = Ray::new(origin, target - origin);
        // The plank's plane must not hold the ray (a grazing ray may miss it rightly).
        let normal = long.cross(across).normalize();
        let expect = if ray.direction.normalize().dot(normal).abs() > 1e-3 {
            Expect::HitBy(1.0 + 1e-3)
        } else {
            Expect::Nothing
        };
        rays.push(ProbeRay { ray, expect });
    }
    Case { name: "crossing-planks".into(), triangles, special_rays: vec![("on-planes", rays)] }
}

/// A 4 × 4 × 4 block of unit cubes that touch: neighbouring faces coincide,
/// and every face lies on box planes that axis-parallel rays start on.
fn touching_boxes() -> Case {
    let cube = tessellated_cube(1);
    let mut triangles = Vec::new();
    for x in 0..4 {
        for y in 0..4 {
            for z in 0..4 {
                triangles.extend(cube.placed(0.5, Vec3::new(x as f32, y as f32, z as f32) + 0.5).triangles());
            }
        }
    }
    Case { name: "touching-boxes".into(), triangles, special_rays: Vec::new() }
}
