"""Every structure's hits equal the linear scan's, bit for bit, from
Python: on the bunny and on generated hard cases (shared edges and
vertices, axis-parallel rays with ±0 components, rays in the plane of the
triangles, a closed mesh seen from inside)."""

import numpy as np
import pytest

import rtgi

# Our structures (held to the exactness contract); Embree is a peer, compared below.
STRUCTURES = [name for name in rtgi.names("accel") if name not in ("linear", "embree")]


def assert_same_hits(ours, reference, label):
    """t, beta and gamma compared as bits (so -0 and 0, NaN payloads count), triangles as numbers."""
    for name, a, b in zip(("t", "triangle", "beta", "gamma"), ours, reference):
        assert a.dtype == b.dtype and a.shape == b.shape, (label, name)
        bits_a = a.view(np.uint32)
        bits_b = b.view(np.uint32)
        different = np.flatnonzero(bits_a != bits_b)
        assert different.size == 0, f"{label}: {name} differs on {different.size} rays, first {different[:5]}"


def check_every_structure(scene, origins, directions, configurations, tmin=None, tmax=None):
    references = {}
    for accel, knobs in configurations:
        intersector = knobs.get("intersector", "watertight")
        if intersector not in references:
            linear = scene.build("linear", intersector=intersector)
            references[intersector] = (
                linear.intersect(origins, directions, tmin, tmax),
                linear.occluded(origins, directions, tmin, tmax),
            )
        closest, occluded = references[intersector]
        built = scene.build(accel, **knobs)
        label = f"{accel} {knobs}"
        assert_same_hits(built.intersect(origins, directions, tmin, tmax), closest, label)
        assert np.array_equal(built.occluded(origins, directions, tmin, tmax), occluded), label
        assert np.array_equal(occluded, closest.triangle != rtgi.MISS), label
    return references


def test_every_structure_answers_as_the_linear_scan_on_the_bunny(bunny):
    # The linear scan is slow on 69,451 triangles: a few hundred rays of each kind rtgi rays makes.
    parts = [bunny.box_rays(400, seed=1), bunny.surface_rays(400, seed=2), bunny.camera_rays(20, 20)]
    origins = np.concatenate([p[0] for p in parts])
    directions = np.concatenate([p[1] for p in parts])
    configurations = [(accel, {}) for accel in STRUCTURES] + [("sah", {"leaf_size": 1, "sah_bins": 4})]
    references = check_every_structure(bunny, origins, directions, configurations)
    hits = references["watertight"][0].triangle != rtgi.MISS
    assert 0.2 < hits.mean() < 1.0, "the rays hit the bunny and miss it"


def grid(n):
    """An n×n grid of unit squares in the plane z = 0, two triangles each:
    every inner edge and vertex is shared."""
    xs, ys = np.meshgrid(np.arange(n + 1, dtype=np.float32), np.arange(n + 1, dtype=np.float32))
    vertices = np.stack([xs.ravel(), ys.ravel(), np.zeros(xs.size, np.float32)], axis=1)
    index = lambda i, j: i * (n + 1) + j
    triangles = []
    for i in range(n):
        for j in range(n):
            a, b, c, d = index(i, j), index(i, j + 1), index(i + 1, j), index(i + 1, j + 1)
            triangles += [[a, b, d], [a, d, c]]
    return vertices, np.array(triangles, np.uint32)


def hard_rays(n):
    """Rays straight down and up through every vertex and edge midpoint of
    the grid, with ±0 in their direction, and rays lying in its plane."""
    points = []
    for i in range(2 * n + 1):
        for j in range(2 * n + 1):
            points.append((i / 2, j / 2))
    points = np.array(points, np.float32)
    origins, directions = [], []
    for dz, oz in ((-1.0, 2.0), (1.0, -2.0)):
        for zero in (0.0, -0.0):
            origins.append(np.column_stack([points, np.full(len(points), oz, np.float32)]))
            directions.append(np.tile(np.array([zero, zero, dz], np.float32), (len(points), 1)))
            directions[-1][:, 1] = -zero
    # In the plane z = 0, along the grid lines and diagonals (grazing every triangle they pass).
    lines = np.arange(n + 1, dtype=np.float32)
    for d in ((1, 0, 0), (0, 1, 0), (1, 1, 0)):
        origins.append(np.column_stack([np.full(n + 1, -1, np.float32), lines, np.zeros(n + 1, np.float32)]))
        directions.append(np.tile(np.array(d, np.float32), (n + 1, 1)))
    return np.concatenate(origins).astype(np.float32), np.concatenate(directions).astype(np.float32)


def test_every_structure_and_knob_answers_as_the_linear_scan_on_hard_cases():
    n = 8
    vertices, triangles = grid(n)
    scene = rtgi.Scene.from_arrays(vertices, triangles, name="grid")
    origins, directions = hard_rays(n)
    configurations = [
        (accel, knobs)
        for accel in STRUCTURES
        for knobs in ({}, {"leaf_size": 1}, {"leaf_size": 2, "intersector": "moller-trumbore"},
                      {"intersector": "watertight-f64"})
    ]
    references = check_every_structure(scene, origins, directions, configurations)
    # Watertight: every vertical ray through a vertex or an edge of the grid hits it.
    vertical = np.abs(directions[:, 2]) == 1
    for intersector in ("watertight", "watertight-f64"):
        assert (references[intersector][0].triangle[vertical] != rtgi.MISS).all(), intersector


def test_ranges_of_t_are_kept_bit_for_bit():
    vertices, triangles = grid(4)
    scene = rtgi.Scene.from_arrays(vertices, triangles)
    origins, directions = hard_rays(4)
    count = len(origins)
    # Per-ray ranges: half of the vertical rays end just before the plane (t = 2 hits it).
    tmax = np.where(np.arange(count) % 2 == 0, np.float32(np.nextafter(np.float32(2), np.float32(0))), np.inf)
    check_every_structure(scene, origins, directions, [(a, {}) for a in STRUCTURES], tmin=0.5, tmax=tmax.astype(np.float32))
    hits = scene.build("bvh8").intersect(origins, directions, tmin=0.5, tmax=tmax.astype(np.float32))
    vertical = np.abs(directions[:, 2]) == 1
    even = np.arange(count) % 2 == 0
    assert (hits.triangle[vertical & even] == rtgi.MISS).all(), "a hit at t = 2 beyond tmax"
    assert (hits.triangle[vertical & ~even] != rtgi.MISS).all(), "a miss within the range"


def test_a_closed_mesh_seen_from_inside_never_leaks():
    # An octahedron: every ray from its centre hits it; rays through its six vertices and twelve edges.
    vertices = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], np.float32)
    triangles = np.array(
        [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]], np.uint32
    )
    scene = rtgi.Scene.from_arrays(vertices, triangles)
    edges = [(a, b) for t in triangles for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))]
    targets = np.concatenate([vertices, np.array([(vertices[a] + vertices[b]) / 2 for a, b in edges], np.float32)])
    directions = targets.astype(np.float32)
    origins = np.zeros_like(directions)
    references = check_every_structure(scene, origins, directions, [(a, {}) for a in STRUCTURES])
    assert (references["watertight"][0].triangle != rtgi.MISS).all()


def test_embree_builds_and_agrees_as_a_peer(bunny):
    if not rtgi.EMBREE:
        from conftest import missing

        missing("rtgi was built without the embree feature", "RTGI_REQUIRE_EMBREE")
    assert "embree" in rtgi.names("accel")
    origins, directions = bunny.box_rays(20_000, seed=5)
    ours = bunny.build("bvh8").intersect(origins, directions)
    embree = bunny.build("embree").intersect(origins, directions)
    # A peer is held to tolerances, not bits: it differs at ties and on grazing rays.
    same_triangle = (ours.triangle == embree.triangle).mean()
    assert same_triangle > 0.999, same_triangle
    both = (ours.triangle != rtgi.MISS) & (ours.triangle == embree.triangle)
    assert np.allclose(ours.t[both], embree.t[both], rtol=1e-4)
