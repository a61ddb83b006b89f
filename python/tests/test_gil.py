"""Tracing releases the GIL: Python threads run while another thread is
inside `intersect`, and two threads trace at once.

Each check compares what happens inside the traced call's interval, which
a thread holding the GIL would make impossible (not merely slower), so
the margins hold on a noisy two-core machine."""

import threading
import time

import numpy as np

import rtgi


def slow_query(scene, seconds):
    """A linear scan and as many rays as take about `seconds` to trace."""
    linear = scene.build("linear")
    origins, directions = scene.box_rays(64, seed=1)
    started = time.perf_counter()
    linear.intersect(origins, directions)
    per_ray = (time.perf_counter() - started) / 64
    count = int(min(max(seconds / per_ray, 64), 2_000_000))
    return linear, scene.box_rays(count, seed=2)


def traced(accel, rays, intervals):
    started = time.perf_counter()
    accel.intersect(*rays)
    intervals.append((started, time.perf_counter()))


def scene():
    # A sphere-ish blob of 4,000 triangles: slow enough for the linear scan.
    rng = np.random.default_rng(1)
    vertices = rng.normal(size=(3000, 3)).astype(np.float32)
    triangles = rng.integers(0, 3000, size=(4000, 3)).astype(np.uint32)
    return rtgi.Scene.from_arrays(vertices, triangles)


def test_python_runs_while_a_thread_is_inside_intersect():
    accel, rays = slow_query(scene(), 0.6)
    intervals = []
    tracer = threading.Thread(target=traced, args=(accel, rays, intervals))
    ticks = []
    tracer.start()
    while tracer.is_alive():
        ticks.append(time.perf_counter())
    tracer.join()
    (started, ended) = intervals[0]
    assert ended - started > 0.2, "the call was too short to tell"
    # Ticks well inside the call: a thread holding the GIL would leave none.
    margin = 0.05 * (ended - started)
    inside = sum(started + margin < t < ended - margin for t in ticks)
    assert inside > 1000, f"the main thread ran {inside} times in {ended - started:.2f} s of intersect"


def test_two_threads_trace_at_once():
    # A second thread calls `intersect` while the first is inside its call.
    # Holding the GIL there, the first would keep the main thread from
    # starting the second until it returned. The calls share rayon's
    # workers, which finish the earlier call's work before the later one's
    # (injected jobs come last), so their end times tell nothing: an earlier
    # version of this test asserted that they end together, and failed four
    # times in six here, before and after the change that exposed it.
    accel, rays = slow_query(scene(), 0.4)
    alone = []
    expected = accel.intersect(*rays)
    traced(accel, rays, alone)
    single = alone[0][1] - alone[0][0]
    intervals, answers = [], []

    def traced_with_answer():
        started = time.perf_counter()
        answers.append(accel.intersect(*rays))
        intervals.append((started, time.perf_counter()))

    first = threading.Thread(target=traced_with_answer)
    first.start()
    time.sleep(0.1 * single)
    second = threading.Thread(target=traced_with_answer)
    second.start()
    first.join()
    second.join()
    (a0, a1), (b0, b1) = sorted(intervals)
    assert single > 0.1, "the call was too short to tell"
    assert b0 < a1 - 0.5 * single, f"the second call began {b0 - a0:.3f} s after the first, which took {a1 - a0:.3f} s"
    for hits in answers:
        for got, want in zip(hits, expected):
            assert np.array_equal(got, want)
