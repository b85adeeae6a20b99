"""The GIL is released while the Rust code works: a Python thread keeps counting during
compute_weights."""

import threading
import time

import atlas_skin


def count_for(stop, counter):
    """Increments counter[0] until the event is set."""
    while not stop.is_set():
        counter[0] += 1


def test_a_thread_keeps_running_while_compute_weights_works(demo):
    args = (demo["positions"], demo["triangles"], demo["joint_positions"], demo["parents"])

    # How fast the thread counts alone, over as long as one call lasts.
    start = time.perf_counter()
    atlas_skin.compute_weights(*args)
    call_seconds = time.perf_counter() - start
    stop, counter = threading.Event(), [0]
    thread = threading.Thread(target=count_for, args=(stop, counter))
    thread.start()
    time.sleep(call_seconds)
    stop.set()
    thread.join()
    alone = counter[0]

    # The same thread while compute_weights runs: it counts only if the GIL is free.
    stop, counter = threading.Event(), [0]
    thread = threading.Thread(target=count_for, args=(stop, counter))
    thread.start()
    time.sleep(0.01)
    before = counter[0]
    start = time.perf_counter()
    atlas_skin.compute_weights(*args)
    elapsed = time.perf_counter() - start
    during = counter[0] - before
    stop.set()
    thread.join()
    # Held, the GIL would let the thread count only in the few milliseconds of
    # argument conversion; released, it counts at a good share of its own pace.
    expected = alone * elapsed / call_seconds
    assert during > 0.25 * expected, (during, expected)
