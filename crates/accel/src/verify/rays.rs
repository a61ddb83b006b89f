//! Rays of the kinds that expose inexact structures, made from nothing but
//! a scene's triangles.

use std::collections::HashMap;

use rtgi_math::{Aabb, MAX_ELONGATION, Ray, Rng, SurfacePoint, Vec3, elongation, geometric_normal, uniform_sphere};

use super::{Expect, ProbeRay, uniform_barycentrics};
use crate::is_hittable;

/// The kinds of rays `rtgi verify` traces; each names what it aims at.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RayKind {
    /// Origins anywhere in (an enlargement of) the scene's bounds, uniform directions.
    Random,
    /// Aimed exactly at a corner of a random triangle.
    Vertex,
    /// Aimed at a point on an edge of a random triangle.
    Edge,
    /// Along ±x, ±y or ±z, the other components +0 or -0, from origins that
    /// often share a coordinate with a vertex (so they lie on box planes).
    AxisParallel,
    /// Leaving a point on a triangle, as a renderer spawns them: mirrored
    /// about the normal, or towards a point on another triangle. A hit on
    /// the triangle the ray leaves is a self-hit (counted for triangles no
    /// more elongated than `rtgi_math::MAX_ELONGATION`, and rays more than
    /// 0.6° off its plane).
    Secondary,
    /// Aimed inside the silhouette where the surface is closed: at interior
    /// points of triangles, edges shared by two triangles and vertices
    /// surrounded by triangles, all facing the ray. Each must hit
    /// something no later than the point aimed at; a miss is a leak.
    Silhouette,
    /// Coherent, as a camera's: 4×4 tiles of rays from one origin through
    /// a small grid around a point on a triangle, one of them exactly at
    /// the triangle's first corner. Sixteen consecutive rays form a tile,
    /// so that batch queries trace them as packets.
    Camera,
    /// Random, vertex, edge and axis-parallel rays whose range starts
    /// behind the origin, by up to twice the scene's size: boxes and
    /// axis-aligned triangles on both sides of it. Their exits behind the
    /// origin take the second exit inverse of the slab test
    /// (`rtgi_math::exit_inverses`), and single-ray queries run them at
    /// the portable level. (Last, so that the other kinds keep their
    /// random streams.)
    BehindOrigin,
}

impl RayKind {
    /// Every kind, in the order reports list them.
    pub const ALL: &'static [RayKind] = &[
        RayKind::Random,
        RayKind::Vertex,
        RayKind::Edge,
        RayKind::AxisParallel,
        RayKind::Secondary,
        RayKind::Silhouette,
        RayKind::Camera,
        RayKind::BehindOrigin,
    ];

    /// The kind's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            RayKind::Random => "random",
            RayKind::Vertex => "vertex",
            RayKind::Edge => "edge",
            RayKind::AxisParallel => "axis-parallel",
            RayKind::Secondary => "secondary",
            RayKind::Silhouette => "silhouette",
            RayKind::Camera => "camera",
            RayKind::BehindOrigin => "behind-origin",
        }
    }

    /// `count` rays of this kind for `triangles` (fewer, possibly none,
    /// when the scene has no feature of the kind).
    pub fn rays(self, triangles: &[[Vec3; 3]], count: usize, seed: u64) -> Vec<ProbeRay> {
        let scene = SceneFeatures::new(triangles);
        if scene.hittable.is_empty() {
            return Vec::new();
        }
        let mut rng = Rng::new(seed, 0x7e51f1 + self as u64);
        match self {
            RayKind::Silhouette => scene.silhouette_rays(count, &mut rng),
            RayKind::Camera => scene.camera_rays(count, &mut rng),
            _ => (0..count).filter_map(|_| scene.ray(self, &mut rng)).collect(),
        }
    }
}

/// What the ray generators need to know of a scene: its hittable
/// triangles, its bounds, and which edges and vertices are surrounded.
struct SceneFeatures<'a> {
    triangles: &'a [[Vec3; 3]],
    hittable: Vec<u32>,
    bounds: Aabb,
}

impl<'a> SceneFeatures<'a> {
    fn new(triangles: &'a [[Vec3; 3]]) -> Self {
        let hittable: Vec<u32> = (0..triangles.len() as u32).filter(|&i| is_hittable(&triangles[i as usize])).collect();
        let bounds = Aabb::from_points(hittable.iter().flat_map(|&i| triangles[i as usize]));
        Self { triangles, hittable, bounds }
    }

    fn random_triangle(&self, rng: &mut Rng) -> (u32, [Vec3; 3]) {
        let index = self.hittable[rng.next_below(self.hittable.len() as u32) as usize];
        (index, self.triangles[index as usize])
    }

    /// A point of the scene's bounds enlarged by half their size on every side.
    fn origin(&self, rng: &mut Rng) -> Vec3 {
        let extent =
            self.bounds.extent().max(Vec3::splat(self.bounds.max.abs().max_element() * 1e-3)).max(Vec3::ONE * 1e-30);
        let u = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 0.5;
        self.bounds.min + u * extent
    }

    /// Tiles of sixteen rays; see [`RayKind::Camera`].
    fn camera_rays(&self, count: usize, rng: &mut Rng) -> Vec<ProbeRay> {
        let mut rays = Vec::with_capacity(count);
        let mut attempts = 0;
        while rays.len() < count && attempts < 20 * count {
            attempts += 1;
            let origin = self.origin(rng);
            let (_, t) = self.random_triangle(rng);
            let (u, v) = (rng.next_f32(), rng.next_f32());
            let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
            let centre = t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0]);
            // Scaled by its largest component before normalising: in scenes
            // of size 1e-30 the squared length underflows to zero (and this
            // loop once never ended there).
            let axis = centre - origin;
            let largest = axis.abs().max_element();
            if !(largest > 0.0 && largest.is_finite()) {
                continue;
            }
            let frame = rtgi_math::Frame::from_z((axis / largest).normalize());
            let spacing = 0.004 * self.bounds.extent().max_element();
            for j in 0..4 {
                for i in 0..4 {
                    let offset = (i as f32 - 1.5) * spacing * frame.x + (j as f32 - 1.5) * spacing * frame.y;
                    let target = if (i, j) == (1, 1) { t[0] } else { centre + offset };
                    rays.push(ProbeRay { ray: Ray::new(origin, target - origin), expect: Expect::Nothing });
                }
            }
        }
        rays.truncate(count);
        rays
    }

    fn ray(&self, kind: RayKind, rng: &mut Rng) -> Option<ProbeRay> {
        let plain = |ray: Ray| Some(ProbeRay { ray, expect: Expect::Nothing });
        match kind {
            RayKind::Random => plain(Ray::new(self.origin(rng), uniform_sphere(rng.next_f32(), rng.next_f32()))),
            RayKind::Vertex => {
                let (_, t) = self.random_triangle(rng);
                let origin = self.origin(rng);
                plain(Ray::new(origin, t[rng.next_below(3) as usize] - origin))
            }
            RayKind::Edge => {
                let (_, t) = self.random_triangle(rng);
                let e = rng.next_below(3) as usize;
                let s = rng.next_f32();
                let target = t[e] + s * (t[(e + 1) % 3] - t[e]);
                let origin = self.origin(rng);
                plain(Ray::new(origin, target - origin))
            }
            RayKind::AxisParallel => {
                let mut origin = self.origin(rng).to_array();
                // Often on the planes of a vertex: the slab test's NaN case.
                let (_, t) = self.random_triangle(rng);
                let corner = t[rng.next_below(3) as usize].to_array();
                for (o, c) in origin.iter_mut().zip(corner) {
                    if rng.next_f32() < 0.7 {
                        *o = c;
                    }
                }
                let axis = rng.next_below(3) as usize;
                let mut direction = [0.0f32; 3];
                for d in direction.iter_mut() {
                    *d = if rng.next_f32() < 0.5 { 0.0 } else { -0.0 };
                }
                direction[axis] = if rng.next_f32() < 0.5 { 1.0 } else { -1.0 };
                plain(Ray::new(Vec3::from(origin), Vec3::from(direction)))
            }
            RayKind::Secondary => {
                let (index, t) = self.random_triangle(rng);
                let point = random_surface_point(&t, rng);
                let ray = if rng.next_f32() < 0.5 {
                    let incoming = uniform_sphere(rng.next_f32(), rng.next_f32());
                    let n = point.normal;
                    point.spawn_ray(incoming - 2.0 * incoming.dot(n) * n)
                } else {
                    let (_, other) = self.random_triangle(rng);
                    point.spawn_ray_to(&random_surface_point(&other, rng))
                };
                // Spawned rays are offset far enough for triangles up to an
                // elongation (see `SurfacePoint::on_triangle`); needles beyond
                // it are traced, but not held to never being hit again. Nor
                // are rays that run along the plane they leave (within 0.6°,
                // towards a point in that plane): they carry no light, and
                // the rounding of their direction alone can tilt them back
                // into it.
                let leaves = ray.direction.normalize_or_zero().dot(point.normal).abs() >= 0.01;
                let expect = if elongation(&t) <= MAX_ELONGATION && leaves {
                    Expect::NotTriangle(index)
                } else {
                    Expect::Nothing
                };
                Some(ProbeRay { ray, expect })
            }
            RayKind::BehindOrigin => {
                let kinds = [RayKind::Random, RayKind::Vertex, RayKind::Edge, RayKind::AxisParallel];
                let mut probe = self.ray(kinds[rng.next_below(4) as usize], rng)?;
                let reach = self.bounds.extent().max_element() / probe.ray.direction.length();
                probe.ray.t_min = -2.0 * rng.next_f32() * reach;
                Some(probe)
            }
            RayKind::Silhouette | RayKind::Camera => unreachable!("made by silhouette_rays and camera_rays"),
        }
    }

    /// Rays that must hit: aimed at triangle interiors, at edges shared by
    /// two consistently wound triangles, and at vertices whose fan of
    /// triangles is closed, from a side all of those triangles face
    /// clearly (|cos| > 0.05). There the surface is locally a height field
    /// over the ray's view, so the ray's line crosses it near the point aimed
    /// at, whatever rounding did to the aim.
    fn silhouette_rays(&self, count: usize, rng: &mut Rng) -> Vec<ProbeRay> {
        let features = Surrounded::find(self.triangles, &self.hittable);
        let mut rays = Vec::with_capacity(count);
        let mut attempts = 0;
        while rays.len() < count && attempts < 20 * count {
            attempts += 1;
            let (target, faces): (Vec3, Vec<u32>) = match rng.next_below(3) {
                0 => {
                    let (index, t) = self.random_triangle(rng);
                    let (u, v) = uniform_barycentrics(rng);
                    // At least 5% of the way from every edge.
                    if u.min(v).min(1.0 - u - v) < 0.05 {
                        continue;
                    }
                    (t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0]), vec![index])
                }
                1 if !features.edges.is_empty() => {
                    let (a, b, faces) = &features.edges[rng.next_below(features.edges.len() as u32) as usize];
                    let s = 0.05 + 0.9 * rng.next_f32();
                    (*a + s * (*b - *a), faces.to_vec())
                }
                2 if !features.vertices.is_empty() => {
                    let (v, faces) = &features.vertices[rng.next_below(features.vertices.len() as u32) as usize];
                    (*v, faces.clone())
                }
                _ => continue,
            };
            // From a few times the size of the surrounding triangles away, so
            // that the aim's rounding stays far smaller than the neighbourhood
            // that the triangles cover around the point aimed at.
            let size = faces.iter().map(|&f| altitude(&self.triangles[f as usize])).fold(f32::INFINITY, f32::min);
            let origin = target + uniform_sphere(rng.next_f32(), rng.next_f32()) * size * (1.0 + 9.0 * rng.next_f32());
            let aim_error = 8.0 * f32::EPSILON * origin.abs().max(target.abs()).max_element();
            if size.is_nan() || 0.05 * size <= 64.0 * aim_error {
                continue;
            }
            let direction = target - origin;
            let unit = direction.normalize_or_zero();
            let facing = |f: &u32| geometric_normal(&self.triangles[*f as usize]).dot(unit);
            let first = facing(&faces[0]);
            let least_facing = faces.iter().map(|f| facing(f) * first.signum()).fold(f32::INFINITY, f32::min);
            if first.abs() < 0.05 || least_facing < 0.05 {
                continue;
            }
            // The aimed point is at t = 1, and the surface within the aim's
            // rounding of it: the crossing lies within that distance, over the
            // cosine of the steepest triangle, of the point aimed at. The
            // test's own distance rounds by a few ulps of the farthest corner's
            // distance times the triangle's elongation (long needles round most).
            let test_error = faces
                .iter()
                .map(|&f| {
                    let t = &self.triangles[f as usize];
                    let extent = t.iter().map(|v| (*v - origin).abs().max_element()).fold(0.0, f32::max);
                    16.0 * f32::EPSILON * extent * elongation(t)
                })
                .fold(0.0, f32::max);
            let slack = (4.0 * aim_error / least_facing + test_error) / direction.length();
            rays.push(ProbeRay { ray: Ray::new(origin, direction), expect: Expect::HitBy(1.0 + slack.max(1e-4)) });
        }
        rays
    }
}

/// The triangle's smallest altitude: how far its interior reaches from any edge.
fn altitude(t: &[Vec3; 3]) -> f32 {
    let [a, b, c] = t.map(|v| v.as_dvec3());
    let twice_area = (b - a).cross(c - a).length();
    let longest = (b - a).length().max((c - b).length()).max((a - c).length());
    (twice_area / longest) as f32
}

/// A uniformly random point on a triangle, as a hit would report it.
pub(super) fn random_surface_point(t: &[Vec3; 3], rng: &mut Rng) -> SurfacePoint {
    let (u, v) = uniform_barycentrics(rng);
    SurfacePoint::on_triangle(t, u, v)
}

/// Edges shared by exactly two consistently wound hittable triangles, and
/// vertices all of whose edges are such edges.
struct Surrounded {
    edges: Vec<(Vec3, Vec3, [u32; 2])>,
    vertices: Vec<(Vec3, Vec<u32>)>,
}

impl Surrounded {
    fn find(triangles: &[[Vec3; 3]], hittable: &[u32]) -> Self {
        let key = |v: Vec3| v.to_array().map(f32::to_bits);
        // Directed edges by the bits of their ends: a closed, consistently
        // wound surface has every directed edge once and its reverse once.
        let mut directed: HashMap<([u32; 3], [u32; 3]), Vec<u32>> = HashMap::new();
        for &i in hittable {
            let t = triangles[i as usize];
            for e in 0..3 {
                directed.entry((key(t[e]), key(t[(e + 1) % 3]))).or_default().push(i);
            }
        }
        let mut edges = Vec::new();
        let mut open_vertex: HashMap<[u32; 3], bool> = HashMap::new();
        let mut faces_at: HashMap<[u32; 3], Vec<u32>> = HashMap::new();
        for &i in hittable {
            let t = triangles[i as usize];
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                faces_at.entry(key(a)).or_default().push(i);
                let forward = &directed[&(key(a), key(b))];
                let twin = directed.get(&(key(b), key(a)));
                let surrounded = forward.len() == 1 && twin.is_some_and(|t| t.len() == 1);
                if !surrounded {
                    open_vertex.insert(key(a), true);
                    open_vertex.insert(key(b), true);
                } else if key(a) < key(b) {
                    edges.push((a, b, [i, twin.expect("checked")[0]]));
                }
            }
        }
        let mut vertices: Vec<(Vec3, Vec<u32>)> = faces_at
            .into_iter()
            .filter(|(k, _)| !open_vertex.contains_key(k))
            .map(|(k, faces)| (Vec3::from(k.map(f32::from_bits)), faces))
            .collect();
        // Hash maps iterate in a random order; rays must not.
        vertices.sort_by_key(|v| key(v.0));
        Self { edges, vertices }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_ray_kind_is_made_for_scenes_at_extreme_scales() {
        // At 1e-30 the camera rays' axis once had a squared length of zero
        // for every try, and making them never ended.
        for scale in [1e-30f32, 1e-20, 1.0, 1e20, 1e30] {
            let triangles = [
                [Vec3::ZERO, Vec3::X * scale, Vec3::Y * scale],
                [Vec3::X * scale, Vec3::new(1.0, 1.0, 0.0) * scale, Vec3::Y * scale],
            ];
            for &kind in RayKind::ALL {
                // Every kind ends; camera rays, which need nothing but a
                // triangle, are made at every scale.
                let rays = kind.rays(&triangles, 64, 7);
                assert!(kind != RayKind::Camera || rays.len() == 64, "{kind:?} at {scale}: {}", rays.len());
                assert!(rays.iter().all(|r| r.ray.origin.is_finite() && r.ray.direction.is_finite()), "{kind:?}");
            }
        }
    }
}
