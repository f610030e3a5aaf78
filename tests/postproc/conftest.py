"""Shared helpers for the postproc tests.

pytest imports this file as the module `conftest` before the test modules of this directory,
so their `from conftest import ...` finds this file, not tests/app/conftest.py (which
test_postproc.py still puts on sys.path): it re-exports that file's EXE, MPIEXEC, SOURCE and
run, loaded under another name, and adds launch_runs (the morphogen runs behind the `runs`
fixtures of test_morphogen_h5.py and test_paraview.py) and option_value."""
import importlib.util
import os
import sys

_APP_CONFTEST = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "app", "conftest.py")


def _load_app_conftest(name="morphogen_app_conftest"):
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, _APP_CONFTEST)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]


_app = _load_app_conftest()
EXE, MPIEXEC, SOURCE, run = _app.EXE, _app.MPIEXEC, _app.SOURCE, _app.run


def option_value(options, flag, default=None):
    """The word after flag in the option list, or default when flag is absent."""
    return options[options.index(flag) + 1] if flag in options else default


def launch_runs(base, table, steps, every, options=()):
    """Run morphogen once per entry of table {key: (cells, lengths, extra options, ranks)}, in
    base (cwd) into base/key, on `ranks` ranks, with
        -grid_n CELLS -grid_L LENGTHS -steps STEPS -snapshot_every EVERY OPTIONS -output_dir DIR EXTRA
    and assert that each run succeeded. Returns {key: dict(dir, name, n, h, extra, ranks)}: the
    output directory, the output name (-output_name, default morphogen), the cells, the cell
    sizes, the entry's extra options and ranks."""
    out = {}
    for key, (n, L, extra, ranks) in table.items():
        d = base / key
        args = ["-grid_n", ",".join(map(str, n)), "-grid_L", ",".join(map(str, L)),
                "-steps", str(steps), "-snapshot_every", str(every)] + list(options) + \
               ["-output_dir", str(d)] + extra
        proc = run(args, cwd=base, ranks=ranks)
        assert proc.returncode == 0, f"{key}: {proc.stdout}\n{proc.stderr}"
        out[key] = dict(dir=d, name=option_value(extra, "-output_name", "morphogen"), n=n,
                        h=[L[a] / n[a] for a in range(len(n))], extra=extra, ranks=ranks)
    return out
