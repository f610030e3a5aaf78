"""`morphogen sweep`, end to end on 1 and 2 ranks: a Gray-Scott F x k sweep (16 x 16 points of a
small grid) finishes and writes a table of every point with a class; a sweep stopped halfway
(SIGUSR1: exit 3; or killed outright) resumes without redoing finished points; chunks for job
arrays cover the sweep exactly once; results (and the stability map, computed by all ranks) do not
depend on the rank-group layout; bad sweep input is refused with one line."""
import os
import signal
import subprocess
import sys
import time

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "app"))
sys.path.insert(0, os.path.dirname(__file__))
from sweep_helpers import ok, table  # noqa: E402
from conftest import EXE, MPIEXEC, SOURCE, run  # noqa: E402

DECK = os.path.join(SOURCE, "input", "gray_scott_sweep.yaml")
SMALL = ["-grid_n", "32,32", "-grid_L", "0.3125", "-steps", "2000"]
CLASSES = {"uniform", "spots", "holes", "stripes", "labyrinth", "mixed", "oscillating",
           "chaotic", "blowup"}


def test_gray_scott_16x16_sweep_on_2_ranks(tmp_path):
    r = ok(run(["sweep", DECK] + SMALL + ["-output_dir", "s"], tmp_path, 2, timeout=900))
    assert "256 to run" in r.stdout and "sweep: ran 256 points" in r.stdout
    t = table(tmp_path / "s")
    assert t["points"] == 256 and t["finished"] == 256
    assert [a["option"] for a in t["axes"]] == ["params_F", "params_k"]
    assert {rec["class"] for rec in t["records"]} <= CLASSES
    assert sum(t["classes"].values()) == 256
    assert len(t["classes"]) >= 3, t["classes"]  # a phase diagram, not one colour
    with open(tmp_path / "s/sweep.csv") as f:
        rows = f.read().splitlines()
    assert len(rows) == 257 and rows[0].startswith("index,params_F,params_k,class,")
    assert all(os.path.exists(tmp_path / "s" / rec["file"]) for rec in t["records"])
    sm = t["stability_map"]
    assert len(sm["turing"]) == len(sm["axes"][0]) * len(sm["axes"][1])


def points_mtimes(d):
    p = os.path.join(d, "points")
    return {f: os.stat(os.path.join(p, f)).st_mtime_ns for f in os.listdir(p)
            if f.endswith(".json")}


@pytest.mark.parametrize("how", ["SIGUSR1", "SIGKILL"])
def test_stopped_sweep_resumes_without_redoing_points(tmp_path, how):
    args = ["sweep", DECK] + SMALL + ["-steps", "6000", "-sweep_params_F",
                                      "linspace(0.02, 0.06, 6)", "-sweep_params_k",
                                      "linspace(0.05, 0.065, 4)", "-output_dir",
                                      str(tmp_path / "s")]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    p = subprocess.Popen([MPIEXEC, "--oversubscribe", "-n", "2", EXE] + args, cwd=tmp_path,
                         env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         start_new_session=True)
    finished = 0
    for line in p.stdout:
        finished += line.startswith("point ")
        if finished == 6:
            break
    assert finished == 6, "the sweep ended before 6 points were done"
    if how == "SIGUSR1":
        p.send_signal(signal.SIGUSR1)  # mpiexec forwards it to the ranks
    else:  # mpiexec and the ranks, mid-point (their command lines name the output dir)
        subprocess.run(["pkill", "-KILL", "-f", str(tmp_path / "s")])
    out, err = p.communicate(timeout=300)
    while subprocess.run(["pgrep", "-f", str(tmp_path / "s")], capture_output=True).returncode == 0:
        time.sleep(0.1)
    if how == "SIGUSR1":
        assert p.returncode == 3, out + err
        assert "stopped by a signal" in out
    done = points_mtimes(tmp_path / "s")
    assert 6 <= len(done) < 24
    r = ok(run(args, tmp_path, 2, timeout=600))
    assert f"{24 - len(done)} to run, {len(done)} already done" in r.stdout
    assert r.stdout.count("\npoint ") + r.stdout.startswith("point ") == 24 - len(done)
    after = points_mtimes(tmp_path / "s")
    assert len(after) == 24
    assert all(after[f] == t for f, t in done.items()), "a finished point was run again"
    assert table(tmp_path / "s")["finished"] == 24


def test_chunks_cover_the_sweep_once(tmp_path):
    base = ["sweep", DECK] + SMALL + ["-steps", "500", "-sweep_params_F", "0.03,0.04,0.05",
                                      "-sweep_params_k", "0.055,0.06", "-output_dir", "s"]
    r0 = ok(run(base + ["-sweep_chunks", "2", "-sweep_chunk", "0"], tmp_path))
    assert "3 to run" in r0.stdout and table(tmp_path / "s")["finished"] == 3
    r1 = ok(run(base + ["-sweep_chunks", "2", "-sweep_chunk", "1"], tmp_path, 2))
    assert "3 to run" in r1.stdout
    t = table(tmp_path / "s")
    assert t["finished"] == 6 and sorted(r["index"] for r in t["records"]) == list(range(6))


def test_group_layout_does_not_change_results(tmp_path):
    base = ["sweep", DECK] + SMALL + ["-steps", "1500", "-sweep_params_F", "0.03,0.05",
                                      "-sweep_params_k", "0.06,0.065"]
    ok(run(base + ["-output_dir", "g1", "-sweep_group_size", "1"], tmp_path, 2))
    ok(run(base + ["-output_dir", "g2", "-sweep_group_size", "2"], tmp_path, 2))
    a = {r["index"]: r for r in table(tmp_path / "g1")["records"]}
    b = {r["index"]: r for r in table(tmp_path / "g2")["records"]}
    assert a.keys() == b.keys() and len(a) == 4
    for i in a:
        assert a[i]["class"] == b[i]["class"]
        assert a[i]["metrics"]["mean"] == pytest.approx(b[i]["metrics"]["mean"], rel=1e-12)
        assert b[i]["ranks"] == 2 and a[i]["ranks"] == 1
    # The stability map's points are shared among the ranks: the same map as on one rank.
    ok(run(base + ["-output_dir", "r1"], tmp_path, 1))
    maps = [table(tmp_path / d)["stability_map"] for d in ("g1", "g2", "r1")]
    assert len(maps[2]["hopf"]) == 25 and 0 < sum(maps[2]["hopf"]) < 25
    assert maps[0] == maps[2] and maps[1] == maps[2]


def test_stability_map_of_a_large_grid_on_rank_0(tmp_path):
    # Over 2^20 cells the other ranks do not set up a copy of the run: rank 0 computes the map.
    base = ["sweep", DECK, "-grid_n", "1040,1040", "-grid_L", "10.15625", "-steps", "1",
            "-sweep_params_F", "0.03,0.05", "-sweep_params_k", "0.06,0.065"]
    ok(run(base + ["-output_dir", "one"], tmp_path, 1))
    ok(run(base + ["-output_dir", "two"], tmp_path, 2))
    maps = [table(tmp_path / d)["stability_map"] for d in ("one", "two")]
    assert len(maps[0]["hopf"]) == 25 and 0 < sum(maps[0]["hopf"]) < 25
    assert maps[0] == maps[1]


@pytest.mark.parametrize("args,needle", [
    (["-sweep_axes", "params_F", "-sweep_params_F", "linspace(1,2)"], "-sweep_params_F"),
    (["-sweep_params_F", "0.01,zz"], "-sweep_params_F"),
    (["-sweep_params_F", "0.01,7"], "-params_F 7: out of range"),
    (["-sweep_axes", "params_F,params_q"], "-sweep_params_q: missing"),
    (["-sweep_group_size", "3"], "-sweep_group_size 3"),
    (["-sweep_chunk", "2", "-sweep_chunks", "2"], "-sweep_chunk 2"),
    (["-sweep_species", "zz"], "-sweep_species zz"),
    (["-sweep_groupsize", "1"], "did you mean"),
])
def test_bad_sweep_input(tmp_path, args, needle):
    r = run(["sweep", DECK] + SMALL + args + ["-output_dir", "s"], tmp_path, 2)
    assert r.returncode == 1, r.stdout + r.stderr
    lines = [l for l in r.stderr.splitlines() if l.startswith("morphogen: error:")]
    assert lines and needle in lines[0], r.stderr
    assert not (tmp_path / "s").exists()


def test_point_that_cannot_run_is_recorded_and_rerun(tmp_path):
    # each axis value is valid alone; dt 1.5 with D_b 0.25 exceeds the explicit bound
    deck = tmp_path / "combo.yaml"
    deck.write_text("model: turing\ngrid: {n: '16,16'}\nsteps: 20\noutput_dir: c\n"
                    "sweep: {axes: 'dt,D_b', dt: '0.5,1.5', D_b: '0.1,0.25'}\n")
    r = ok(run(["sweep", str(deck)], tmp_path, 2, timeout=120))
    rec = {x["index"]: x for x in table(tmp_path / "c")["records"]}
    assert rec[3]["class"] == "error" and "-dt 1.5" in rec[3]["reason"]
    assert all(rec[i]["class"] != "error" for i in (0, 1, 2))
    r = ok(run(["sweep", str(deck), "-force_dt"], tmp_path, 2, timeout=120))
    assert "1 to run, 3 already done" in r.stdout  # the error point runs again
    assert table(tmp_path / "c")["records"][3]["class"] != "error"


def test_changed_axes_are_refused_on_resume(tmp_path):
    base = ["sweep", DECK] + SMALL + ["-steps", "50", "-sweep_params_F", "0.03,0.04",
                                      "-sweep_params_k", "0.06", "-output_dir", "s"]
    ok(run(base, tmp_path))
    before = (tmp_path / "s/options_used.yaml").read_text()
    r = run(base[:-4] + ["-sweep_params_k", "0.065", "-output_dir", "s"], tmp_path)
    assert r.returncode == 1 and "the axes changed" in r.stderr, r.stderr
    assert (tmp_path / "s/options_used.yaml").read_text() == before
