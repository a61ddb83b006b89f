"""Errors are Python exceptions carrying the library's message and naming
the argument, never a crash of the interpreter."""

import numpy as np
import pytest

import rtgi


def triangle_scene():
    return rtgi.Scene.from_arrays(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32), np.array([[0, 1, 2]], np.uint32))


def test_a_missing_file_is_a_scene_error_naming_it(tmp_path):
    path = tmp_path / "nowhere.obj"
    with pytest.raises(rtgi.SceneError, match="nowhere.obj"):
        rtgi.load(path)
    with pytest.raises(rtgi.SceneError, match="nowhere.obj"):
        rtgi.render(str(path), width=8, height=8)
    assert issubclass(rtgi.SceneError, rtgi.RtgiError) and issubclass(rtgi.RequestError, rtgi.RtgiError)


def test_a_reference_outside_the_scene_folder_is_refused_unless_allowed(tmp_path):
    (tmp_path / "inside").mkdir()
    (tmp_path / "shared.mtl").write_text("newmtl red\nKd 1 0 0\n")
    (tmp_path / "inside" / "scene.obj").write_text("mtllib ../shared.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n")
    refused = rtgi.load(tmp_path / "inside" / "scene.obj")
    assert any("outside" in w for w in refused.warnings), refused.warnings
    allowed = rtgi.load(tmp_path / "inside" / "scene.obj", allow_outside=True)
    assert [m["name"] for m in allowed.materials] == ["red"] and allowed.materials[0]["base_color"] == [1, 0, 0]


@pytest.mark.parametrize(
    "argument, origins, directions, message",
    [
        ("origins", np.zeros((4, 3), np.int64), np.ones((4, 3), np.float32), "origins: .*float32.*int64"),
        ("directions", np.zeros((4, 3), np.float32), np.ones((4, 3), bool), "directions: .*float32.*bool"),
        ("origins", np.zeros((4, 2), np.float32), np.ones((4, 3), np.float32), r"origins: .*\(N, 3\).*\(4, 2\)"),
        ("directions", np.zeros((4, 3), np.float32), np.ones((5, 3), np.float32), "directions: 5 rays, and origins has 4"),
        ("origins", "a string", np.ones((1, 3), np.float32), "origins"),
    ],
)
def test_bad_arrays_are_request_errors_naming_the_argument(argument, origins, directions, message):
    accel = triangle_scene().build()
    with pytest.raises(rtgi.RequestError, match=message):
        accel.intersect(origins, directions)
    with pytest.raises(rtgi.RequestError, match=argument):
        accel.occluded(origins, directions)


def test_bad_bounds_and_meshes_are_request_errors():
    accel = triangle_scene().build()
    rays = np.zeros((3, 3), np.float32), np.ones((3, 3), np.float32)
    with pytest.raises(rtgi.RequestError, match=r"tmax: .*\(3,\).*\(2,\)"):
        accel.intersect(*rays, tmax=np.ones(2, np.float32))
    with pytest.raises(rtgi.RequestError, match="tmin: .*NaN"):
        accel.intersect(*rays, tmin=float("nan"))
    vertices = np.zeros((3, 3), np.float32)
    with pytest.raises(rtgi.RequestError, match="triangles: row 1 names vertex 3, and there are 3 vertices"):
        rtgi.Scene.from_arrays(vertices, np.array([[0, 1, 2], [0, 1, 3]], np.uint32))
    with pytest.raises(rtgi.RequestError, match="triangles: index -1"):
        rtgi.Scene.from_arrays(vertices, np.array([[0, 1, -1]], np.int64))
    with pytest.raises(rtgi.RequestError, match="triangles: .*uint32.*float32"):
        rtgi.Scene.from_arrays(vertices, np.array([[0, 1, 2]], np.float32))


def test_bad_option_values_are_request_errors_naming_the_option():
    scene = triangle_scene()
    cases = [
        (lambda: scene.build("octree"), "accel: unknown acceleration structure 'octree'"),
        (lambda: scene.build("sah", leaf_size=0), "leaf size 0: expected 1 to 255"),
        (lambda: scene.build("sah", sah_bins=1), "SAH bins 1: expected 2 to 256"),
        (lambda: scene.build("sah", intersector="fast"), "intersector: unknown intersector 'fast'"),
        (lambda: rtgi.render(scene, integrator="photon"), "integrator: unknown integrator 'photon'"),
        (lambda: rtgi.render(scene, width=0), "width: 0: expected 1 to 16384"),
        (lambda: rtgi.render(scene, samples_per_pixel="many"), "samples_per_pixel"),
        (lambda: rtgi.render(scene, lights=["point:0,1,0"]), "lights"),
        (lambda: rtgi.render(scene, widht=64), "widht: not an argument of render"),
        (lambda: rtgi.render(scene, aovs=["path"]), "AOV path: not an output variable"),
        (lambda: rtgi.render(scene, checkpoint="x.accum"), "the checkpoint is for renders written to files"),
        (lambda: rtgi.render(scene, output="x.txt"), r"x.txt: the output is an image \(.png, .exr\)"),
        (lambda: rtgi.experiment("nothing"), "knob: unknown knob 'nothing'"),
        (lambda: rtgi.names("colours"), "what: unknown 'colours'"),
    ]
    for call, message in cases:
        with pytest.raises(rtgi.RequestError, match=message):
            call()
