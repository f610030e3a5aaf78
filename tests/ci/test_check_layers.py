"""The layering check .ci/check_layers, on small made-up source trees and on the real one."""
import os
import pathlib
import re
import subprocess

SOURCE = pathlib.Path(os.environ.get("MORPHOGEN_SOURCE_DIR",
                                     pathlib.Path(__file__).resolve().parents[2]))
SCRIPT = SOURCE / ".ci" / "check_layers"
LINE = re.compile(r"^src/\S+:\d+: (layer \w+ includes (layer \w+ \(\S+\)|\S+, not in a known layer)"
                  r"|not in a known layer directory of src/ .*)$")


def check(tree, files):
    for name, includes in files.items():
        path = tree / "src" / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("#pragma once\n" + "".join(f'#include "{i}"\n' for i in includes) +
                        "#include <vector>\n")
    res = subprocess.run(["/usr/bin/python3", str(SCRIPT), str(tree)], capture_output=True,
                         text=True)
    return res.returncode, res.stdout.splitlines()


def test_downward_includes_pass(tmp_path):
    rc, out = check(tmp_path, {
        "core/a.hpp": [],
        "grid/b.hpp": ["core/a.hpp"],
        "io/png.hpp": ["grid/b.hpp"],
        "fields/c.cpp": ["io/png.hpp", "grid/b.hpp", "c.hpp"],
        "fields/c.hpp": [],
        "models/m.hpp": [],
        "analysis/s.cpp": ["models/m.hpp", "core/a.hpp", "grid/b.hpp"],
        "app/r.cpp": ["analysis/s.cpp", "fields/c.hpp"],
        "sweep/w.cpp": ["app/r.cpp"],
        "cli/main.cpp": ["sweep/w.cpp", "app/r.cpp"],
        "bench/b.cpp": ["app/r.cpp"],
    })
    assert (rc, out) == (0, [])


def test_upward_includes_fail(tmp_path):
    rc, out = check(tmp_path, {
        "core/a.hpp": ["grid/b.hpp"],
        "grid/b.hpp": ["../fields/c.hpp"],
        "fields/c.hpp": [],
        "app/main.cpp": ["sweep/w.hpp"],
        "sweep/w.hpp": ["app/main.cpp"],
        "analysis/s.cpp": ["operators/st.hpp", "grid/b.hpp"],
        "operators/st.hpp": [],
    })
    assert rc == 1
    assert out == [
        "src/analysis/s.cpp:2: layer analysis includes layer operators (operators/st.hpp)",
        "src/app/main.cpp:2: layer app includes layer sweep (sweep/w.hpp)",
        "src/core/a.hpp:2: layer core includes layer grid (grid/b.hpp)",
        "src/grid/b.hpp:2: layer grid includes layer fields (../fields/c.hpp)",
    ]


def test_unknown_directories_fail(tmp_path):
    rc, out = check(tmp_path, {"gpu/k.cu": [], "core/a.hpp": ["plugins/p.hpp"]})
    assert rc == 1
    assert len(out) == 2
    assert out[0] == "src/core/a.hpp:2: layer core includes plugins/p.hpp, not in a known layer"
    assert out[1].startswith("src/gpu/k.cu:1: not in a known layer directory of src/")


def test_real_tree_output_format():
    res = subprocess.run(["/usr/bin/python3", str(SCRIPT), str(SOURCE)], capture_output=True,
                         text=True)
    assert res.returncode in (0, 1), res.stderr
    assert (res.returncode == 1) == bool(res.stdout)
    for line in res.stdout.splitlines():
        assert LINE.match(line), line
