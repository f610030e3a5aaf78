"""postproc/vs_ready.py: Ready's input file (read back with VTK's XML image reader, the reader
Ready uses, and its RD element checked against what Ready's loader requires), the two-count
timing against a stand-in `rdy` whose per-step time is known, and its one-line errors.
Ready itself is not installable here; the stand-in checks the arguments Ready's utility takes
(-i FILE -n N, as in Ready's src/cmd/main.cpp) and sleeps a start-up time plus a fixed time
per step."""
import importlib.util
import json
import os
import stat
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest
from conftest import EXE, MPIEXEC, SOURCE

SCRIPT = os.path.join(SOURCE, "postproc", "vs_ready.py")
STEP_SECONDS = 5e-4  # the stand-in's time per step
START_SECONDS = 0.3  # and its start-up (Ready compiles its OpenCL kernel), which must cancel

FAKE_RDY = f"""#!/usr/bin/python3
import sys, time, xml.etree.ElementTree as ET
a = sys.argv[1:]
if "-i" not in a or "-n" not in a:
    print("It looks like one of the required arguments is missing"); sys.exit(1)
root = ET.parse(a[a.index("-i") + 1]).getroot()
if root.find("RD/rule").get("type") != "formula":
    print("Unsupported rule type"); sys.exit(1)
if root.find("RD/FAIL") is not None or "FAIL" in a:
    print("boom: OpenCL build failed"); sys.exit(3)
time.sleep({START_SECONDS} + {STEP_SECONDS} * int(a[a.index("-n") + 1]))
"""


def load_script():
    spec = importlib.util.spec_from_file_location("vs_ready", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def fake_rdy(tmp_path, body=FAKE_RDY):
    path = tmp_path / "rdy"
    path.write_text(body)
    path.chmod(path.stat().st_mode | stat.S_IEXEC)
    return str(path)


def run_script(*args):
    return subprocess.run([sys.executable, SCRIPT, "--morphogen", EXE, "--mpiexec", MPIEXEC,
                           *args], capture_output=True, text=True)


@pytest.mark.parametrize("dim,n", [(2, 16), (3, 8)])
def test_ready_file_reads_as_double_image_with_formula_rule(tmp_path, dim, n):
    from vtkmodules.vtkCommonCore import VTK_DOUBLE
    from vtkmodules.vtkIOXML import vtkXMLImageDataReader
    path = str(tmp_path / "case.vti")
    load_script().write_ready_file(path, dim, n)
    reader = vtkXMLImageDataReader()
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    assert image.GetDimensions() == (n, n, n if dim == 3 else 1)
    pd = image.GetPointData()
    assert [pd.GetArrayName(i) for i in range(pd.GetNumberOfArrays())] == ["a", "b"]
    for i in range(2):  # Ready takes its data type from the first array: double
        assert pd.GetArray(i).GetDataType() == VTK_DOUBLE
        assert pd.GetArray(i).GetNumberOfTuples() == n**dim
    rd = ET.parse(path).getroot().find("RD")
    assert int(rd.get("format_version")) <= 6  # newer than Ready's 6 only warns
    rule = rd.find("rule")
    assert (rule.get("name"), rule.get("type"), rule.get("wrap")) == ("Gray-Scott", "formula", "1")
    params = {p.get("name"): float(p.text) for p in rule.findall("param")}
    assert params == {"timestep": 1, "D_a": 0.082, "D_b": 0.041, "K": 0.064, "F": 0.035}
    formula = rule.find("formula")
    assert formula.get("number_of_chemicals") == "2" and formula.get("accuracy") == "medium"
    assert rd.find("initial_pattern_generator").get("apply_when_loading") == "true"


def test_rates_from_two_step_counts(tmp_path):
    out = tmp_path / "r.json"
    n = 512
    r = run_script("--rdy", fake_rdy(tmp_path), "--cases", f"2d:{n}", "--updates",
                   str(1000 * n * n), "--repeat", "2", "--ranks", "2", "--workdir",
                   str(tmp_path / "w"), "--json", str(out))
    assert r.returncode == 0, r.stderr
    res = json.loads(out.read_text())["results"]
    assert len(res) == 1 and res[0]["case"] == "2d:512" and res[0]["stencil"] == "9pt"
    assert res[0]["steps"] == [100, 1100]
    expect = n * n / STEP_SECONDS  # the stand-in's rate; start-up cancels in the difference
    assert res[0]["ready"] == pytest.approx(expect, rel=0.25)
    assert 1e7 < res[0]["morphogen"] < 1e11
    assert res[0]["ratio"] == pytest.approx(res[0]["morphogen"] / res[0]["ready"], rel=1e-12)
    line = [l for l in r.stdout.splitlines() if l.startswith("2d:512")]
    assert line and ">= 1.3" in line[0]
    # morphogen ran the case it names: a 9-point run of 512^2 cells on 2 ranks
    used = (tmp_path / "w" / "morphogen_2d_512" / "options_used.yaml").read_text()
    assert "9pt" in used and "512,512" in used.replace(" ", "")


def test_errors_are_one_line(tmp_path):
    r = run_script("--rdy", str(tmp_path / "missing"))
    assert r.returncode == 2 and r.stderr.strip().count("\n") == 0
    assert "--rdy" in r.stderr and "not an executable" in r.stderr
    r = run_script("--rdy", fake_rdy(tmp_path), "--cases", "4d:12")
    assert r.returncode == 2 and "--cases 4d:12" in r.stderr
    r = run_script("--rdy", fake_rdy(tmp_path), "--cases", "2d:30")  # Ready's 4-cell blocks
    assert r.returncode == 2 and "--cases 2d:30" in r.stderr and "multiple of 4" in r.stderr
    failing = fake_rdy(tmp_path, FAKE_RDY.replace('"FAIL" in a', "True"))
    r = run_script("--rdy", failing, "--cases", "2d:16", "--updates", "2560", "--repeat", "1")
    assert r.returncode == 2 and r.stderr.strip().count("\n") == 0
    assert "rdy (" in r.stderr and "code 3" in r.stderr and "OpenCL build failed" in r.stderr
    # morphogen's own error line, not mpiexec's banner after it (the stand-in is timed first:
    # 100 and 1100 steps, 0.5 s apart, so that a loaded machine cannot make them look equal)
    r = run_script("--rdy", fake_rdy(tmp_path), "--cases", "2d:16", "--updates", "256000",
                   "--repeat", "1", "--morphogen", str(tmp_path / "no_such_morphogen"))
    assert r.returncode == 2 and "morphogen (" in r.stderr, r.stderr
