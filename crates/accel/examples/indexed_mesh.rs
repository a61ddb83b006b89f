//! Builds every structure from an indexed mesh (shared vertex positions
//! and index triples, borrowed as they are, with no triangle soup built)
//! and traces rays at its shared vertices and edges: each structure gives
//! the linear scan's answer, and the same answer as from the soup.
//!
//! `cargo run -p rtgi-accel --example indexed_mesh`

use rtgi_accel::{AccelKind, BuildParams, IndexedMesh, Ray, TriangleSource, Vec3};

fn main() {
    // A 3 x 3 grid of vertices in the plane z = 0 (the ones of a heightfield
    // or of a loaded file), and two triangles per cell that share them.
    let side = 3u32;
    let positions: Vec<Vec3> = (0..side * side).map(|i| Vec3::new((i % side) as f32, (i / side) as f32, 0.0)).collect();
    let mut indices = Vec::new();
    for y in 0..side - 1 {
        for x in 0..side - 1 {
            let v = |dx: u32, dy: u32| (y + dy) * side + x + dx;
            indices.push([v(0, 0), v(1, 0), v(1, 1)]);
            indices.push([v(0, 0), v(1, 1), v(0, 1)]);
        }
    }
    let mesh = match IndexedMesh::new(&positions, &indices) {
        Ok(mesh) => mesh,
        Err(error) => panic!("the grid's indices are valid: {error}"),
    };
    println!("{} vertices, {} triangles", positions.len(), mesh.len());

    // An index past the last vertex is an error that says where it is.
    let broken = [[0, 1, 9]];
    if let Err(error) = IndexedMesh::new(&positions, &broken) {
        println!("rejected: {error}");
    }

    // The soup is built here only to show the answers are the same.
    let soup: Vec<[Vec3; 3]> = (0..mesh.len()).map(|i| mesh.corners(i)).collect();
    let linear = AccelKind::Linear.build(&mesh, &BuildParams::default());
    let rays = [
        // Straight down onto the centre vertex, shared by six triangles: a
        // tie at the same t, which the lowest index wins.
        Ray::new(Vec3::new(1.0, 1.0, 1.0), -Vec3::Z),
        // Inside one triangle of the upper right cell.
        Ray::new(Vec3::new(1.75, 1.25, 1.0), -Vec3::Z),
        // Onto the middle of a shared diagonal, and of a shared edge.
        Ray::new(Vec3::new(0.5, 0.5, 1.0), -Vec3::Z),
        Ray::new(Vec3::new(1.0, 0.5, 1.0), -Vec3::Z),
        // Past the grid.
        Ray::new(Vec3::new(3.0, 3.0, 1.0), -Vec3::Z),
    ];
    for &kind in AccelKind::ALL {
        let params = kind.default_params();
        let from_mesh = kind.build(&mesh, &params);
        let from_soup = kind.build(&soup, &params);
        for ray in &rays {
            let hit = from_mesh.intersect(ray);
            assert_eq!(hit, linear.intersect(ray), "{kind}");
            assert_eq!(hit, from_soup.intersect(ray), "{kind}");
        }
    }
    for ray in &rays {
        match linear.intersect(ray) {
            Some(hit) => {
                let corners = indices[hit.triangle as usize];
                println!(
                    "ray at ({}, {}) hits triangle {} (vertices {corners:?}) at t = {}",
                    ray.origin.x, ray.origin.y, hit.triangle, hit.t
                );
            }
            None => println!("ray at ({}, {}) misses", ray.origin.x, ray.origin.y),
        }
    }
    println!("every structure built from the indexed mesh agrees with the linear scan and with its soup build");
}

#[test]
fn runs() {
    main();
}
