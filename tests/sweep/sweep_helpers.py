"""Helpers shared by the sweep tests: a finished command and a sweep's table."""
import json
import os


def ok(r):
    """r, after asserting that the command succeeded (its output's tail in the message)."""
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    return r


def table(d):
    """sweep.json of sweep directory d."""
    with open(os.path.join(d, "sweep.json")) as f:
        return json.load(f)
