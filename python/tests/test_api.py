"""Scenes, structures, rays, the verifier and the experiments from Python."""

import numpy as np
import pytest

import rtgi


def test_a_scene_from_arrays_says_what_it_holds():
    vertices = np.array([[0, 0, 0], [2, 0, 0], [0, 3, 0], [0, 0, 4]], np.float64)  # converted once
    triangles = np.array([[0, 1, 2], [0, 1, 3]], np.int32)
    scene = rtgi.Scene.from_arrays(vertices, triangles, name="two")
    assert (scene.name, scene.triangle_count, len(scene)) == ("two", 2, 2)
    assert scene.bounds.tolist() == [[0, 0, 0], [2, 3, 4]] and scene.bounds.dtype == np.float32
    assert scene.materials[0]["triangles"] == 2 and scene.cameras == [] and scene.lights == []
    corners = scene.vertices[scene.triangles]
    assert corners.shape == (2, 3, 3) and np.array_equal(corners[1], vertices[[0, 1, 3]])
    assert scene.describe()["triangles"] == 2


def test_a_loaded_scene_has_its_cameras_materials_and_lights():
    box = rtgi.cornell_box()
    assert box.triangle_count > 0 and len(box.cameras) == 1 and len(box.materials) > 3
    assert any(m["emission"] != [0, 0, 0] for m in box.materials)


def test_a_build_reports_its_statistics():
    box = rtgi.cornell_box()
    accel = box.build("sah", leaf_size=2, sah_bins=8, sah_axes="longest", traversal_cost=2.0,
                      intersector="moller-trumbore", traversal="fast")
    stats = accel.stats
    assert accel.kind == "sah" and stats["variant"] == "sah" and stats["triangles"] == box.triangle_count
    assert stats["nodes"] > 0 and stats["depth"] > 0 and stats["sah_cost"] > 0 and stats["memory_bytes"] > 0
    assert accel.build_ms == stats["build_ms"] >= 0
    assert accel.params == dict(leaf_size=2, sah_bins=8, sah_axes="longest", traversal_cost=2.0,
                                intersector="moller-trumbore", traversal="fast")
    assert box.build("bvh8").params["leaf_size"] == 8, "the structure's own defaults"


def test_arrays_are_read_in_place_or_converted_once():
    box = rtgi.cornell_box()
    accel = box.build()
    origins, directions = box.box_rays(5000, seed=9)
    reference = accel.intersect(origins, directions)
    # Float64, Fortran order, a strided view: converted, same answers.
    for o, d in [(origins.astype(np.float64), directions), (np.asfortranarray(origins), directions),
                 (np.repeat(origins, 2, axis=0)[::2], directions), (origins.tolist(), directions)]:
        again = accel.intersect(o, d)
        assert all(np.array_equal(a, b) for a, b in zip(again, reference))
    assert np.array_equal(accel.occluded(origins, directions), reference.triangle != rtgi.MISS)
    misses = reference.triangle == rtgi.MISS
    assert np.isinf(reference.t[misses]).all() and (reference.beta[misses] == 0).all()
    # The ray generators are deterministic.
    assert np.array_equal(box.box_rays(5000, seed=9)[0], origins)
    assert not np.array_equal(box.box_rays(5000, seed=10)[0], origins)


def test_empty_and_single_ray_queries():
    accel = rtgi.cornell_box().build()
    hits = accel.intersect(np.zeros((0, 3), np.float32), np.zeros((0, 3), np.float32))
    assert all(a.shape == (0,) for a in hits)
    one = accel.intersect(np.array([[0, 1, 3]], np.float32), np.array([[0, 0, -1]], np.float32))
    assert one.triangle.shape == (1,)


def test_verify_on_the_adversarial_scenes_and_on_a_scene():
    report = rtgi.verify(rays=2000, accel=["bvh8", "sah"])
    assert not report["failed"] and report["scene"] == "built-in adversarial scenes"
    assert {s["structure"].split(" ")[0] for s in report["structures"]} >= {"bvh8", "sah"}
    report = rtgi.verify(rtgi.cornell_box(), rays=2000, accel="all")
    assert not report["failed"] and len(report["kinds"]) > 3


def test_an_experiment_returns_its_report_as_python_objects():
    report = rtgi.experiment("accel", quick=True, repeats=1)
    assert report["knob"] == "accel" and report["question"]
    assert isinstance(report["findings"], list)


def test_names_come_from_the_libraries():
    assert "bvh8" in rtgi.names("accel") and "watertight" in rtgi.names("intersector")
    assert "spp" in rtgi.names("knobs") and "normal" in rtgi.names("aovs")
    assert "samples_per_pixel" in rtgi.names("render")
