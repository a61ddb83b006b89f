"""`rtgi.render` gives the pixels `rtgi render -o x.exr` gives with the same
options (the test runs the command line: two front ends compared), and the
rays `rtgi rays` writes."""

import subprocess

import numpy as np
import pytest

import rtgi


def rtgi_render(binary, tmp_path, scene, options):
    output = tmp_path / "cli.exr"
    subprocess.run([binary, "render", *([str(scene)] if scene else []), "-o", str(output), *options],
                   check=True, capture_output=True)
    return rtgi.read_exr(output)


def bits(image):
    return np.ascontiguousarray(image, np.float32).view(np.uint32)


@pytest.mark.parametrize(
    "cli, python",
    [
        (["--width", "40", "--height", "30", "--spp", "4", "--seed", "7"],
         dict(width=40, height=30, samples_per_pixel=4, seed=7)),
        (["--width", "32", "--height", "32", "--spp", "2", "--accel", "sah", "--leaf-size", "2", "--integrator",
          "direct", "--sampler", "sobol", "--max-depth", "3", "--fov", "50"],
         dict(width=32, height=32, samples_per_pixel=2, accel="sah", leaf_size=2, integrator="direct",
              sampler="sobol", max_depth=3, fov=50.0)),
    ],
)
def test_render_gives_the_pixels_of_rtgi_render(rtgi_binary, tmp_path, cli, python):
    reference = rtgi_render(rtgi_binary, tmp_path, None, cli)
    image, aovs, outcome = rtgi.render(None, **python)
    assert image.shape == reference.shape and image.dtype == np.float32
    assert np.array_equal(bits(image), bits(reference)), "the in-memory render differs from rtgi render's EXR"
    assert outcome["render"]["width"] == python["width"] and outcome["outputs"] == [] and aovs == {}
    # A Scene object (rendered as given, its structure built by the package) gives the same pixels.
    given, _, _ = rtgi.render(rtgi.cornell_box(), **python)
    assert np.array_equal(bits(given), bits(reference))


def test_render_of_a_file_with_aovs_and_output(rtgi_binary, bunny_path, tmp_path):
    options = ["--width", "24", "--height", "20", "--spp", "2", "--aov", "normal,depth"]
    reference = rtgi_render(rtgi_binary, tmp_path, bunny_path, options)
    reference_normal = rtgi.read_exr(tmp_path / "cli.normal.exr")
    written = tmp_path / "python.exr"
    image, aovs, outcome = rtgi.render(bunny_path, width=24, height=20, samples_per_pixel=2,
                                       aovs=["normal", "depth"], output=written)
    assert np.array_equal(bits(image), bits(reference))
    assert np.array_equal(bits(aovs["normal"]), bits(reference_normal)) and set(aovs) == {"normal", "depth"}
    assert np.array_equal(bits(rtgi.read_exr(written)), bits(reference))
    assert [o["kind"] for o in outcome["outputs"]] == ["image", "normal", "depth"]
    assert outcome["scene"]["triangles"] == 69451 and outcome["build"]["variant"] == "bvh8"


def test_rays_are_those_rtgi_rays_writes(rtgi_binary, bunny_path, bunny, tmp_path):
    scene = rtgi.load(bunny_path)
    for kind, ours in [
        ("random", scene.box_rays(1000, seed=3)),
        ("surface", scene.surface_rays(1000, seed=3)),
        ("camera", scene.camera_rays(24, 16)),
    ]:
        path = tmp_path / f"{kind}.bin"
        subprocess.run([rtgi_binary, "rays", str(bunny_path), "--kind", kind, "--count", "1000", "--seed", "3",
                        "--width", "24", "--height", "16", "-o", str(path)], check=True, capture_output=True)
        records = np.fromfile(path, dtype="<f4").reshape(-1, 8)
        assert np.array_equal(records[:, 0:3].view(np.uint32), ours[0].view(np.uint32)), kind
        assert np.array_equal(records[:, 3:6].view(np.uint32), ours[1].view(np.uint32)), kind


def test_render_returns_what_the_outcome_says():
    image, aovs, outcome = rtgi.render(None, width=16, height=12, samples_per_pixel=1, integrator="normal",
                                       aovs=["albedo"])
    assert image.shape == (12, 16, 3) and aovs["albedo"].shape == (12, 16, 3)
    assert outcome["render"]["samples_done"] == 1 and outcome["camera"]["source"]
    assert np.isfinite(image).all() and image.std() > 0
