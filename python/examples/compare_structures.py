"""Three acceleration structures on one scene: their build times, their
trace rates on coherent (camera) and incoherent (box) rays, and whether
their hits agree with the linear scan's, bit for bit; a bar chart of the
rates goes to a PNG.

    python python/examples/compare_structures.py [SCENE] [--out compare_structures.png]

Without a scene, the Stanford bunny of the shared scenes ($RTGI_SCENES or
../shared/scenes) if present, else the built-in Cornell box.
"""

import argparse
import os
import statistics
import time
from pathlib import Path

import numpy as np

import rtgi

STRUCTURES = ["object-median", "sah", "bvh8"]


def default_scene():
    folder = Path(os.environ.get("RTGI_SCENES") or Path(__file__).resolve().parents[2] / ".." / "shared" / "scenes")
    bunny = folder / "bunny" / "stanford-bunny.obj"
    return rtgi.load(bunny) if bunny.is_file() else rtgi.cornell_box()


def rate(accel, rays, repeats=5):
    """Million rays a second, the median of `repeats` traces after a warm-up."""
    accel.intersect(*rays)
    times = []
    for _ in range(repeats):
        started = time.perf_counter()
        accel.intersect(*rays)
        times.append(time.perf_counter() - started)
    return len(rays[0]) / statistics.median(times) / 1e6


def same_bits(a, b):
    """Rays whose four answers agree bit for bit."""
    return (
        (a.t.view(np.uint32) == b.t.view(np.uint32))
        & (a.triangle == b.triangle)
        & (a.beta.view(np.uint32) == b.beta.view(np.uint32))
        & (a.gamma.view(np.uint32) == b.gamma.view(np.uint32))
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", nargs="?")
    parser.add_argument("--out", default="compare_structures.png")
    parser.add_argument("--rays", type=int, default=500_000)
    args = parser.parse_args()

    scene = rtgi.load(args.scene) if args.scene else default_scene()
    print(f"{scene.name}: {scene.triangle_count:,} triangles")
    rays = {
        "camera (coherent)": scene.camera_rays(720, 720),
        "box (incoherent)": scene.box_rays(args.rays, seed=1),
    }
    # The linear scan answers a sample of each kind: it tests every triangle.
    sample = {kind: (o[:: max(1, len(o) // 2000)], d[:: max(1, len(d) // 2000)]) for kind, (o, d) in rays.items()}
    linear = scene.build("linear")
    reference = {kind: linear.intersect(*r) for kind, r in sample.items()}

    structures = STRUCTURES + (["embree"] if rtgi.EMBREE else [])
    rows = []
    for name in structures:
        accel = scene.build(name)
        rates = {kind: rate(accel, r) for kind, r in rays.items()}
        agree = {kind: same_bits(accel.intersect(*sample[kind]), reference[kind]).mean() for kind in rays}
        stats = accel.stats
        rows.append((name, accel.build_ms, stats["nodes"], stats["memory_bytes"], rates, agree))
        print(f"{name:>14}: built in {accel.build_ms:7.1f} ms, {stats['nodes']:6} nodes, "
              f"{stats['memory_bytes'] / 2**20:5.1f} MiB; "
              + ", ".join(f"{kind} {rates[kind]:6.1f} Mrays/s, {100 * agree[kind]:.2f}% as the linear scan"
                          for kind in rays))

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4.5))
    width = 0.8 / len(rays)
    for k, kind in enumerate(rays):
        xs = np.arange(len(rows)) + (k - (len(rays) - 1) / 2) * width
        bars = ax.bar(xs, [row[4][kind] for row in rows], width, label=kind)
        for bar, row in zip(bars, rows):
            ax.annotate(f"{100 * row[5][kind]:.1f}%", (bar.get_x() + bar.get_width() / 2, bar.get_height()),
                        ha="center", va="bottom", fontsize=8)
    ax.set_xticks(np.arange(len(rows)))
    ax.set_xticklabels([f"{row[0]}\nbuilt in {row[1]:.0f} ms" for row in rows])
    ax.set_ylabel("million rays per second")
    ax.set_title(f"{Path(scene.name).name}: {scene.triangle_count:,} triangles "
                 f"(labels: hits equal to the linear scan's, bit for bit)", fontsize=10)
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
