"""Ctrl-C stops a solve with KeyboardInterrupt; the GIL is released while solving."""

import json
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
import tomllib

import stamp
from conftest import MESHES

SPHERE = MESHES / "sphere-ss.toml"


def long_problem():
    """sphere-ss.toml on a 60 x 60 mesh in 400 steps: tens of seconds of solving."""
    with open(SPHERE, "rb") as f:
        t = tomllib.load(f)
    t["mesh"]["rectangle"]["n"] = [60, 60]
    t["solver"] = {"steps": 400, "max_increment": 0.0025}
    t["output"] = {"vtu": False, "csv": False, "plot": False}
    return t


CHILD = textwrap.dedent(
    """
    import json, sys, time, tomllib
    import stamp
    sys.path.insert(0, {tests!r})
    from test_interrupt import long_problem
    p = stamp.Problem(long_problem(), name="long")
    print("solving", flush=True)
    start = time.monotonic()
    try:
        p.solve(out={out!r})
        print("finished", flush=True)
    except KeyboardInterrupt as e:
        print("KeyboardInterrupt", time.monotonic() - start, str(e).replace(chr(10), " "), flush=True)
    # the next solve in the same process runs to its end: the interrupt was forgotten
    r = stamp.Problem.from_toml({sphere!r}).solve(quiet=True)
    print("next solve", r.summary["status"], flush=True)
    """
)


def test_ctrl_c_raises_keyboard_interrupt_and_the_next_solve_runs(tmp_path):
    out = tmp_path / "out"
    code = CHILD.format(tests=os.path.dirname(__file__), out=str(out), sphere=str(SPHERE))
    child = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "solving"
    time.sleep(3.0)
    sent = time.monotonic()
    child.send_signal(signal.SIGINT)
    stdout, stderr = child.communicate(timeout=120)
    assert child.returncode == 0, stderr
    # after the table of the converged steps (on stdout, as `stamp run` prints it)
    lines = [line for line in stdout.strip().split("\n") if line.startswith(("KeyboardInterrupt", "next solve", "finished"))]
    assert lines[0].startswith("KeyboardInterrupt"), stdout + stderr
    # it stopped soon after the signal (one Newton iteration), long before the 400 steps
    assert time.monotonic() - sent < 30
    assert "interrupted after load step" in lines[0]
    assert lines[1] == "next solve converged"
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "interrupted" and "SIGINT" in summary["error"]
    assert 0 < len(summary["steps"]) < 400
    # the converged steps' history was written
    assert (out / "history.csv").read_text().count("\n") == len(summary["steps"]) + 1


def test_other_python_threads_run_while_solving():
    """A thread counts while the main thread solves: it gets the GIL the whole time."""
    p = stamp.Problem(long_problem() | {"solver": {"steps": 8, "max_increment": 0.125}}, name="long")
    counts, done = [], threading.Event()

    def count():
        n = 0
        while not done.is_set():
            n += 1
            if n % 1000 == 0:
                counts.append((time.monotonic(), n))

    t = threading.Thread(target=count)
    t.start()
    try:
        start = time.monotonic()
        p.solve(quiet=True)
        end = time.monotonic()
    finally:
        done.set()
        t.join()
    during = [c for c in counts if start < c[0] < end]
    # the counter advanced all along the solve, in every quarter of it
    quarters = {int(4 * (c[0] - start) / (end - start)) for c in during}
    assert end - start > 0.5 and quarters == {0, 1, 2, 3}, (end - start, len(during))
