"""Wall and CPU time of cutting frames of a scene from one Python thread and from two
(docs/PYTHON.md, "Threads, measured"); the two runs' arrays must be equal.
Usage: PYTHONPATH=build/python python3 scripts/python_threads.py SCENE [TOLERANCE] [FRAMES]"""
import sys
import threading
import time

import numpy as np

import apparent

scene = apparent.load(sys.argv[1])
tolerance = sys.argv[2] if len(sys.argv) > 2 else None
count = int(sys.argv[3]) if len(sys.argv) > 3 else 8
times = list(scene.frame_times[1:1 + count])
scene.cut(times[0], scene.model, tolerance=tolerance)  # the stage and worlds, built once
for repeat in range(3):
    wall, cpu = time.perf_counter(), time.process_time()
    alone = [scene.cut(t, scene.model, tolerance=tolerance) for t in times]
    wall1, cpu1 = time.perf_counter() - wall, time.process_time() - cpu
    shared = [None] * len(times)

    def work(first):
        for k in range(first, len(times), 2):
            shared[k] = scene.cut(times[k], scene.model, tolerance=tolerance)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    wall, cpu = time.perf_counter(), time.process_time()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    wall2, cpu2 = time.perf_counter() - wall, time.process_time() - cpu
    assert all(np.array_equal(a.positions, b.positions) and np.array_equal(a.triangles, b.triangles)
               for a, b in zip(alone, shared))
    print("%d frames: one thread wall %.3f s CPU %.3f s (%.2f cores); two threads wall %.3f s CPU %.3f s (%.2f cores)"
          % (len(times), wall1, cpu1, cpu1 / wall1, wall2, cpu2, cpu2 / wall2))
