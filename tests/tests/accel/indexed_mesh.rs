//! Indexed meshes (`rtgi_accel::IndexedMesh`): every structure built from
//! one answers every ray bit for bit as the same structure built from the
//! equivalent soup, and as the linear scan over that soup, on random meshes
//! and on adversarial ones (shared edges and vertices aimed at exactly,
//! repeated indices, huge and tiny coordinates, closed solids); and
//! invalid indices are reported with the triangle, index and vertex count.

use std::collections::HashMap;

use rtgi_accel::verify::{Answer, Expect, ProbeRay, RayKind, same_hit, solids};
use rtgi_accel::{IndexedMesh, IndexedMeshError, Intersector, LinearScan, Ray, Rng, Vec3};
use rtgi_tests::for_every_variant;

/// A named mesh as vertex positions and index triples, and rays of its own.
struct MeshCase {
    name: String,
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    special_rays: Vec<Ray>,
    /// Whether `rtgi_accel::verify`'s ray kinds are traced too: not at
    /// 1e-30, where their generators look for normals that underflow.
    verify_rays: bool,
}

impl MeshCase {
    fn soup(&self) -> Vec<[Vec3; 3]> {
        self.indices.iter().map(|t| t.map(|i| self.positions[i as usize])).collect()
    }
}

/// An `n × n` grid of unit squares in the plane z = 0 (two triangles each,
/// sharing diagonals, edges and vertices), a fan of eight triangles around
/// one vertex above it, and degenerate triangles with a repeated index;
/// every position scaled by `scale` and moved by `offset`. The special
/// rays aim exactly at grid vertices, edge midpoints and the fan's centre,
/// straight down (with +0 and -0 in the other components) and obliquely.
fn grid_and_fan(name: &str, n: u32, scale: f32, offset: Vec3) -> MeshCase {
    let place = |p: Vec3| p * scale + offset;
    let mut positions = Vec::new();
    for y in 0..=n {
        for x in 0..=n {
            positions.push(place(Vec3::new(x as f32, y as f32, 0.0)));
        }
    }
    let vertex = |x: u32, y: u32| y * (n + 1) + x;
    let mut indices = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let (a, b, c, d) = (vertex(x, y), vertex(x + 1, y), vertex(x + 1, y + 1), vertex(x, y + 1));
            indices.push([a, b, c]);
            indices.push([a, c, d]);
        }
    }
    // The fan: a centre vertex shared by eight triangles, at height 1.
    let centre = positions.len() as u32;
    positions.push(place(Vec3::new(n as f32 / 2.0, n as f32 / 2.0, 1.0)));
    let rim: Vec<u32> = (0..8)
        .map(|k| {
            let angle = k as f32 * std::f32::consts::FRAC_PI_4;
            positions.push(place(Vec3::new(n as f32 / 2.0 + angle.cos(), n as f32 / 2.0 + angle.sin(), 1.0)));
            positions.len() as u32 - 1
        })
        .collect();
    for k in 0..8 {
        indices.push([centre, rim[k], rim[(k + 1) % 8]]);
    }
    // Degenerate triangles: never hit, whatever the ray.
    indices.push([0, 0, 1]);
    indices.push([centre, rim[0], centre]);
    indices.push([vertex(1, 1), vertex(1, 1), vertex(1, 1)]);

    let mut special_rays = Vec::new();
    let mut targets = vec![positions[centre as usize]];
    for y in 0..=n {
        for x in 0..=n {
            targets.push(place(Vec3::new(x as f32, y as f32, 0.0)));
            targets.push(place(Vec3::new(x as f32 + 0.5, y as f32, 0.0)));
            targets.push(place(Vec3::new(x as f32 + 0.5, y as f32 + 0.5, 0.0)));
        }
    }
    for target in targets {
        for zero in [0.0, -0.0] {
            special_rays.push(Ray::new(target + Vec3::Z * 2.0 * scale, Vec3::new(zero, zero, -1.0)));
            special_rays.push(Ray::new(target - Vec3::Z * 2.0 * scale, Vec3::new(zero, -zero, 1.0)));
        }
        let origin = target + Vec3::new(0.3, -0.7, 3.0) * scale;
        special_rays.push(Ray::new(origin, target - origin));
        // Along the grid's plane, through its vertices and edges.
        special_rays.push(Ray::new(target - Vec3::X * 100.0 * scale, Vec3::X));
    }
    MeshCase { name: name.into(), positions, indices, special_rays, verify_rays: scale > 1e-20 }
}

/// Random triangles over a small shared vertex pool: many triangles share
/// vertices and edges, some repeat an index.
fn random_mesh(seed: u64) -> MeshCase {
    let mut rng = Rng::new(seed, 7);
    let positions: Vec<Vec3> =
        (0..200).map(|_| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 10.0).collect();
    let indices = (0..600).map(|_| [0; 3].map(|_| rng.next_below(positions.len() as u32))).collect();
    MeshCase { name: format!("random {seed}"), positions, indices, special_rays: Vec::new(), verify_rays: true }
}

fn cases() -> Vec<MeshCase> {
    let mut cases = vec![
        grid_and_fan("grid and fan", 6, 1.0, Vec3::ZERO),
        grid_and_fan("huge grid", 4, 1e30, Vec3::ZERO),
        grid_and_fan("tiny grid", 4, 1e-15, Vec3::ZERO),
        grid_and_fan("tinier grid", 4, 1e-30, Vec3::ZERO),
        grid_and_fan("grid far away", 4, 1.0, Vec3::new(1e6, -3e6, 7e5)),
        random_mesh(1),
        random_mesh(2),
    ];
    for (name, solid) in solids() {
        let mesh = solid.mesh;
        cases.push(MeshCase {
            name: name.to_owned(),
            positions: mesh.vertices,
            indices: mesh.faces,
            special_rays: Vec::new(),
            verify_rays: true,
        });
    }
    cases
}

#[test]
fn indexed_meshes_agree_bit_for_bit_with_their_soups_and_the_linear_scan() {
    let mut failures = Vec::new();
    for case in cases() {
        let mesh = IndexedMesh::new(&case.positions, &case.indices).expect("the cases' indices are valid");
        let soup = case.soup();
        let mut probes: Vec<ProbeRay> = Vec::new();
        if case.verify_rays {
            probes.extend(RayKind::ALL.iter().flat_map(|kind| kind.rays(&soup, 150, 3)));
        }
        probes.extend(case.special_rays.iter().map(|&ray| ProbeRay { ray, expect: Expect::Nothing }));
        let linear: HashMap<Intersector, Vec<Answer>> =
            Intersector::ALL.iter().map(|&i| (i, Answer::all(&LinearScan::new(&soup, i), &probes))).collect();
        let mut from_soup = HashMap::new();
        for_every_variant(&soup, |label, accel, _| {
            from_soup.insert(label.to_owned(), Answer::all(accel, &probes));
        });
        let mut variants = 0;
        for_every_variant(&mesh, |label, accel, params| {
            variants += 1;
            let indexed = Answer::all(accel, &probes);
            for (reference_name, reference) in
                [("its soup build", &from_soup[label]), ("the linear scan", &linear[&params.intersector])]
            {
                let disagreeing = indexed
                    .iter()
                    .zip(reference)
                    .zip(&probes)
                    .filter(|((a, b), _)| !same_hit(a.closest, b.closest) || a.any != b.any)
                    .map(|((a, b), probe)| format!("{:?}: {a:?} vs {b:?}", probe.ray))
                    .collect::<Vec<_>>();
                if let Some(first) = disagreeing.first() {
                    failures.push(format!(
                        "{}: {label}: {} of {} rays differ from {reference_name}; first {first}",
                        case.name,
                        disagreeing.len(),
                        probes.len()
                    ));
                }
            }
        });
        assert_eq!(variants, from_soup.len(), "{}: one label per variant", case.name);
    }
    assert!(failures.is_empty(), "{} failures:\n{}", failures.len(), failures[..failures.len().min(30)].join("\n"));
}

#[test]
fn shared_vertices_are_hit_and_degenerate_triangles_never_are() {
    let case = grid_and_fan("grid and fan", 6, 1.0, Vec3::ZERO);
    let mesh = IndexedMesh::new(&case.positions, &case.indices).unwrap();
    let degenerate = (case.indices.len() - 3) as u32..case.indices.len() as u32;
    for_every_variant(&mesh, |label, accel, params| {
        // A ray straight down onto a vertex shared by six grid triangles.
        let hit = accel.intersect(&Ray::new(Vec3::new(2.0, 2.0, 0.5), -Vec3::Z));
        if params.intersector.is_watertight() {
            assert!(hit.is_some_and(|h| h.t == 0.5), "{label}: {hit:?}");
        }
        assert_eq!(accel.build_stats().excluded_triangles, 3, "{label}");
        for ray in &case.special_rays {
            if let Some(hit) = accel.intersect(ray) {
                assert!(!degenerate.contains(&hit.triangle), "{label}: {ray:?} hit a degenerate triangle");
            }
        }
    });
}

#[test]
fn out_of_range_indices_are_reported_with_triangle_index_and_vertex_count() {
    let positions = [Vec3::ZERO, Vec3::X, Vec3::Y];
    assert!(IndexedMesh::new(&positions, &[[0, 1, 2], [2, 1, 0]]).is_ok());
    assert!(IndexedMesh::new(&[], &[]).is_ok_and(|mesh| rtgi_accel::TriangleSource::is_empty(&mesh)));

    let error = IndexedMesh::new(&positions, &[[0, 1, 2], [0, 1, 2], [1, 3, 7]]).unwrap_err();
    assert_eq!(error, IndexedMeshError { triangle: 2, corner: 1, index: 3, vertex_count: 3 });
    let message = error.to_string();
    for part in ["triangle 2", "index 3", "corner 1", "3 vertices"] {
        assert!(message.contains(part), "{message:?} lacks {part:?}");
    }
    let boxed: Box<dyn std::error::Error> = Box::new(error);
    assert_eq!(boxed.to_string(), message);

    let error = IndexedMesh::new(&[], &[[0, 0, 0]]).unwrap_err();
    assert_eq!((error.triangle, error.corner, error.index, error.vertex_count), (0, 0, 0, 0));
    let error = IndexedMesh::new(&positions, &[[0, 1, u32::MAX]]).unwrap_err();
    assert_eq!(error.index, u32::MAX);
}

#[test]
fn an_indexed_mesh_reads_the_callers_buffers() {
    let case = grid_and_fan("grid", 2, 1.0, Vec3::ZERO);
    let mesh = IndexedMesh::new(&case.positions, &case.indices).unwrap();
    assert!(std::ptr::eq(mesh.positions(), case.positions.as_slice()));
    assert!(std::ptr::eq(mesh.indices(), case.indices.as_slice()));
    let soup = case.soup();
    assert_eq!(rtgi_accel::TriangleSource::len(&mesh), soup.len());
    for (index, corners) in soup.iter().enumerate() {
        assert_eq!(rtgi_accel::TriangleSource::corners(&mesh, index), *corners);
    }
}
