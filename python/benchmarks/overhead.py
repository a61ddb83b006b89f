"""Python's overhead: the cost of a call of `Accel.intersect` and the rate
of 1 M rays, against the Rust API (`rtgi_accel::parallel::intersect_all`) on the
same rays, in alternating runs.

The Rust side is the example `benches/examples/trace_rate.rs`; build it and
the package in the release profile first:

    cargo build --release -p rtgi-benches --example trace_rate
    pip install ./python
    python python/benchmarks/overhead.py [--scene PATH] [--rays 1000000] [--rounds 5] [--repeats 5]

Both sides return new answers each call (the Rust side allocates its
`Vec<Option<Hit>>` in the timed call, as Python's new arrays are); the Rust
side into a buffer reused every time is shown too. Each round runs the Python side (`repeats` timed traces after a warm-up)
and then the Rust example (the same), so that drift on a shared machine
falls on both; the table gives the median, min and max over all timed
traces. Both sides trace the rays `Scene.box_rays(rays, seed)` makes (the
Rust side makes them with the same generator, `rtgi_render::rays::box_rays`),
and the checksums of their answers must agree.
"""

import argparse
import json
import os
import platform
import statistics
import subprocess
import time
from pathlib import Path

import numpy as np

import rtgi

WORKSPACE = Path(__file__).resolve().parents[2]


def checksum(hits):
    """The sum of the bits of t and of the triangle indices, as trace_rate.rs sums them."""
    return int(hits.t.view(np.uint32).astype(np.uint64).sum() + hits.triangle.astype(np.uint64).sum()) % 2**64


def python_side(accel, origins, directions, repeats):
    accel.intersect(origins, directions)  # warm-up
    times = []
    for _ in range(repeats):
        started = time.perf_counter()
        hits = accel.intersect(origins, directions)
        times.append((time.perf_counter() - started) * 1e3)
    return times, hits


def call_cost(accel, origins, directions, calls=20_000):
    one_o, one_d = origins[:1].copy(), directions[:1].copy()
    started = time.perf_counter()
    for _ in range(calls):
        accel.intersect(one_o, one_d)
    return (time.perf_counter() - started) * 1e6 / calls


def summary(values):
    return statistics.median(values), min(values), max(values)


def main():
    scenes = Path(os.environ.get("RTGI_SCENES") or WORKSPACE / ".." / "shared" / "scenes")
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scene", default=str(scenes / "bunny" / "stanford-bunny.obj"))
    parser.add_argument("--rays", type=int, default=1_000_000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--accel", default="bvh8")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--repeats", type=int, default=5)
    target = Path(os.environ.get("CARGO_TARGET_DIR") or WORKSPACE / "target")
    parser.add_argument("--rust", default=str(target / "release" / "examples" / "trace_rate"),
                        help="the trace_rate example (cargo build --release -p rtgi-benches --example trace_rate)")
    args = parser.parse_args()
    if not Path(args.rust).is_file():
        parser.error(f"{args.rust}: not built (cargo build --release -p rtgi-benches --example trace_rate)")

    scene = rtgi.load(args.scene)
    accel = scene.build(args.accel)
    origins, directions = scene.box_rays(args.rays, seed=args.seed)
    command = [args.rust, args.scene, str(args.rays), str(args.seed), args.accel, str(args.repeats)]
    python_ms, rust_ms, reused_ms, rust_call_us = [], [], [], []
    for round in range(args.rounds):
        times, hits = python_side(accel, origins, directions, args.repeats)
        python_ms += times
        rust = json.loads(subprocess.run(command, check=True, capture_output=True, text=True).stdout)
        rust_ms += rust["trace_ms"]
        reused_ms += rust["reused_ms"]
        rust_call_us.append(rust["call_us"])
        if rust["checksum"] != checksum(hits) or rust["hits"] != int((hits.triangle != rtgi.MISS).sum()):
            raise SystemExit(f"the two sides answered differently: {rust} against {checksum(hits)}")
        print(f"round {round + 1}: python {statistics.median(times):.1f} ms, rust {statistics.median(rust['trace_ms']):.1f} ms")
    python_call_us = [call_cost(accel, origins, directions) for _ in range(args.rounds)]

    rate = lambda ms: args.rays / ms / 1e3  # Mrays/s
    p, r, u = summary(python_ms), summary(rust_ms), summary(reused_ms)
    pc, rc = summary(python_call_us), summary(rust_call_us)
    print()
    print(f"{scene.name}: {scene.triangle_count} triangles, {args.accel}, {args.rays:,} box rays (seed {args.seed}), "
          f"{rust['threads']} threads, {args.rounds} rounds × {args.repeats} traces each side, "
          f"{platform.processor() or platform.machine()}, {time.strftime('%Y-%m-%d')}")
    print()
    print("| | Python (`Accel.intersect`) | Rust (`parallel::intersect_all`) | Python / Rust |")
    print("|---|---|---|---|")
    print(f"| {args.rays:,} rays: ms, median (min–max) | {p[0]:.1f} ({p[1]:.1f}–{p[2]:.1f}) | "
          f"{r[0]:.1f} ({r[1]:.1f}–{r[2]:.1f}) | {p[0] / r[0]:.3f} |")
    print(f"| the same, Rust's answers into a buffer reused every time | | {u[0]:.1f} ({u[1]:.1f}–{u[2]:.1f}) | "
          f"{p[0] / u[0]:.3f} |")
    print(f"| Mrays/s, median (at max–min time) | {rate(p[0]):.1f} ({rate(p[2]):.1f}–{rate(p[1]):.1f}) | "
          f"{rate(r[0]):.1f} ({rate(r[2]):.1f}–{rate(r[1]):.1f}) | |")
    print(f"| one ray per call: µs a call, median (min–max) | {pc[0]:.2f} ({pc[1]:.2f}–{pc[2]:.2f}) | "
          f"{rc[0]:.2f} ({rc[1]:.2f}–{rc[2]:.2f}) | +{pc[0] - rc[0]:.2f} µs |")


if __name__ == "__main__":
    main()
