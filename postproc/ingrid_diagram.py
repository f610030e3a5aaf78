#!/usr/bin/python3
"""In-grid phase diagram of one morphogen run whose parameters vary linearly across the grid.

    /usr/bin/python3 postproc/ingrid_diagram.py SNAPSHOT_OR_RUN_DIR [--species a]
        [--x-param alpha --x-range 8 20] [--y-param beta --y-range 8 20]
        [--out FILE.png] [--no-stability]

Sanderson et al. 2006 Fig. 2 / Lawlor's parameter map (input/turing_phase_diagram.yaml):
one run in which, say, alpha = 8 + 12*i/(nx-1) grows along x and beta = 8 + 12*j/(ny-1) along
y, so the final field is itself a phase diagram. Draws that field (viridis, origin at the lower
left, i to the right, j up) with the axes labelled in parameter values instead of cells.

Input: a run's output directory (the newest <name>_<step>.vtkhdf snapshot in it is used) or a
snapshot file; options_used.yaml is read from the same directory. Without --x-param/--y-param
the axes are found there: a params_* option whose expression (any "+- noise" part dropped) is
a linear function of i or x only is the x axis, of j or y only the y axis; the range is its
value at the first and last cell centres. Expressions are evaluated by a small whitelisting
evaluator (numbers, + - * / ( ), i j x y nx ny Lx Ly hx hy: no other names or calls), never
by eval. An axis without a parameter is labelled in cells. --x-param NAME alone takes the
range from the options; --x-range LO HI gives it (values at the first and last cell centres).

For the `turing` model (Turk's form) the linear-stability boundaries of the homogeneous state
a* = beta - alpha, b* = beta/(beta - alpha) are drawn over the field (--no-stability: not):
with delta = beta - alpha > 0 and d = D_b/D_a, the Turing threshold (solid white)
d beta = delta (sqrt(delta) + sqrt(d))^2 (Turing-unstable where d beta exceeds the right-hand
side and alpha < delta^2) and the Hopf line (dashed) alpha = delta^2, where the trace of the
Jacobian changes sign (oscillatory instability for alpha > delta^2). The Turing-unstable
region is the wedge between the two lines. This is the
continuous-Laplacian threshold of an infinite domain; the grid's finite set of modes shifts it
slightly. Turk's alpha = 12, beta = 16 lies exactly on the Turing boundary.

Prints a one-line summary. Bad input: a one-line error on stderr and exit status 1.
"""
import argparse
import ast
import math
import os
import re
import sys

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

PROG = "ingrid_diagram"
VARIABLES = ("i", "j", "x", "y", "nx", "ny", "Lx", "Ly", "hx", "hy")


class InputError(Exception):
    """Bad input: reported as one line and exit status 1."""


# ----------------------------------------------------------------------------------------------
# options_used.yaml and safe expressions
# ----------------------------------------------------------------------------------------------

def read_options_text(text):
    """The flat `key: "value"` YAML that morphogen writes (options_used.yaml), as {key: str}."""
    opts = {}
    for line in text.splitlines():
        s = line.strip()
        if not s or s.startswith("#") or ":" not in s:
            continue
        key, _, val = s.partition(":")
        val = val.strip()
        if len(val) >= 2 and val[0] == val[-1] and val[0] in "\"'":
            val = val[1:-1].replace('\\"', '"')
        else:
            val = re.sub(r"\s+#.*$", "", val)
        opts[key.strip()] = val
    return opts


def read_options(path):
    with open(path) as f:
        return read_options_text(f.read())


def strip_perturbation(value):
    """The EXPR of `EXPR +- AMOUNT[%] [uniform|gauss]` (a top-level "+-" outside parentheses)."""
    depth = 0
    for k, ch in enumerate(value):
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth -= 1
        elif ch == "+" and depth == 0 and value[k + 1:k + 2] == "-":
            return value[:k].strip()
    return value.strip()


_BINOPS = {ast.Add: lambda a, b: a + b, ast.Sub: lambda a, b: a - b,
           ast.Mult: lambda a, b: a * b, ast.Div: lambda a, b: a / b}
_UNOPS = {ast.USub: lambda a: -a, ast.UAdd: lambda a: a}


def parse_expression(text, variables=VARIABLES):
    """A checked syntax tree of `text`: only numbers, + - * / ( ) and the given variables;
    raises ValueError for anything else."""
    if len(text) > 500 or "**" in text or "//" in text:
        raise ValueError(f"not a simple expression: {text!r}")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError:
        raise ValueError(f"not a simple expression: {text!r}")
    for node in ast.walk(tree):
        if isinstance(node, (ast.Expression, ast.Load)) or type(node) in _BINOPS or type(node) in _UNOPS:
            continue
        if isinstance(node, ast.BinOp) and type(node.op) in _BINOPS:
            continue
        if isinstance(node, ast.UnaryOp) and type(node.op) in _UNOPS:
            continue
        if isinstance(node, ast.Constant) and type(node.value) in (int, float):
            continue
        if isinstance(node, ast.Name) and node.id in variables:
            continue
        raise ValueError(f"not a simple expression: {text!r}")
    return tree


def evaluate(tree, env):
    def ev(n):
        if isinstance(n, ast.Expression):
            return ev(n.body)
        if isinstance(n, ast.BinOp):
            return _BINOPS[type(n.op)](ev(n.left), ev(n.right))
        if isinstance(n, ast.UnaryOp):
            return _UNOPS[type(n.op)](ev(n.operand))
        if isinstance(n, ast.Constant):
            return float(n.value)
        if isinstance(n, ast.Name):
            return float(env[n.id])
        raise ValueError("unsupported expression")

    return ev(tree)


def constant_value(text):
    """The number of a value without variables (noise dropped), or None."""
    try:
        v = evaluate(parse_expression(strip_perturbation(text), variables=()), {})
    except (ValueError, ZeroDivisionError, KeyError):
        return None
    return v if math.isfinite(v) else None


def grid_of(options, shape=None):
    """{"nx", "ny", "Lx", "Ly", "hx", "hy"} from grid_n / grid_L (shape (ny, nx) as fallback)."""
    try:
        n = [int(float(s)) for s in options.get("grid_n", "").split(",") if s.strip()]
    except ValueError:
        n = []
    if len(n) < 2:
        if shape is None:
            raise InputError("options: no grid_n")
        n = [shape[1], shape[0]]
    try:
        L = [float(s) for s in options.get("grid_L", "").split(",") if s.strip()]
    except ValueError:
        L = []
    if not L:
        L = [float(n[0]), float(n[1])]
    elif len(L) == 1:
        L = [L[0], L[0]]
    return {"nx": n[0], "ny": n[1], "Lx": L[0], "Ly": L[1], "hx": L[0] / n[0], "hy": L[1] / n[1]}


def _env(grid, i, j):
    e = dict(grid)
    e.update(i=i, j=j, x=(i + 0.5) * grid["hx"], y=(j + 0.5) * grid["hy"])
    return e


def linear_axis(expr_text, grid):
    """("x" or "y", value at the first cell centre, value at the last) when the expression is a
    linear function of i/x only or of j/y only; else None."""
    try:
        tree = parse_expression(strip_perturbation(expr_text))
        nx, ny = grid["nx"], grid["ny"]

        def f(i, j):
            return evaluate(tree, _env(grid, i, j))

        f00 = f(0, 0)
        fx, fy, fxy = f(nx - 1, 0), f(0, ny - 1), f(nx - 1, ny - 1)
    except (ValueError, ZeroDivisionError, KeyError, OverflowError):
        return None
    vals = [f00, fx, fy, fxy]
    if not all(math.isfinite(v) for v in vals):
        return None
    scale = max(abs(v) for v in vals) or 1.0
    tol = 1e-9 * scale
    dx, dy = abs(fx - f00) > tol, abs(fy - f00) > tol
    if dx == dy:  # constant, or varies along both axes
        return None
    axis, n = ("x", nx) if dx else ("y", ny)
    v0, v1 = f00, (fx if dx else fy)
    if abs(fxy - (fx if dx else fy)) > tol:
        return None
    for m in sorted({(n - 1) // 3, (n - 1) // 2, (2 * (n - 1)) // 3}):
        try:
            fm = f(m, 0) if dx else f(0, m)
        except (ZeroDivisionError, OverflowError):
            return None
        if abs(fm - (v0 + (v1 - v0) * m / (n - 1))) > 1e-7 * scale:
            return None
    return axis, v0, v1


def detect_axes(options, shape=None):
    """{"x": (param, lo, hi), "y": (param, lo, hi)} for the params_* options of `options`
    (a dict of option -> value text, as in options_used.yaml) that vary linearly along x
    (i) or y (j); lo/hi are the values at the first/last cell centres. Axes without such a
    parameter are left out (the first matching parameter in option order wins)."""
    grid = grid_of(options, shape)
    found = {}
    for key, text in options.items():
        if not key.startswith("params_"):
            continue
        r = linear_axis(text, grid)
        if r is not None and r[0] not in found:
            found[r[0]] = (key[len("params_"):], r[1], r[2])
    return found


# ----------------------------------------------------------------------------------------------
# Turing model (Turk's form): closed-form linear stability of the homogeneous state
# ----------------------------------------------------------------------------------------------

def turing_model_stability(alpha, beta, Da, Db):
    """(turing_unstable, trace, margin) arrays for R_a = s(ab - a - alpha), R_b = s(beta - ab)
    at a* = beta - alpha, b* = beta/(beta - alpha), continuous Laplacian (s > 0 drops out):
    J/s = [[alpha/delta, delta], [-beta/delta, -delta]], det = delta, delta = beta - alpha.
    Turing unstable: trace < 0 and margin = Db J11 + Da J22 - 2 sqrt(Da Db det) > 0.
    trace and margin are NaN without a positive steady state (delta <= 0)."""
    alpha = np.asarray(alpha, dtype=float)
    beta = np.asarray(beta, dtype=float)
    delta = beta - alpha
    ok = delta > 0
    d = np.where(ok, delta, np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):
        trace = alpha / d - d
        margin = Db * alpha / d - Da * d - 2 * np.sqrt(Da * Db * d)
        turing = ok & (trace < 0) & (margin > 0)
    return turing, trace, margin


# ----------------------------------------------------------------------------------------------
# Input files
# ----------------------------------------------------------------------------------------------

def newest_snapshot(directory, output_name=None):
    pat = re.compile(r"^(.*)_(\d+)\.vtkhdf$")
    found = []
    for name in os.listdir(directory):
        m = pat.match(name)
        if m and (output_name is None or m.group(1) == output_name) and m.group(1) != "checkpoint":
            found.append((int(m.group(2)), name))
    if not found and output_name is not None:
        return newest_snapshot(directory, None)
    if not found:
        return None
    return os.path.join(directory, max(found)[1])


def read_snapshot_field(path, species):
    """(field (ny, nx) float, species, spacing (hx, hy) or None)."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    try:
        from phase_diagram import read_field
    finally:
        sys.path.pop(0)
    field, species = read_field(path, species)
    spacing = None
    try:
        import h5py

        with h5py.File(path, "r") as f:
            sp = f["VTKHDF"].attrs.get("Spacing")
            if sp is not None:
                spacing = (float(sp[0]), float(sp[1]))
    except Exception:  # noqa: BLE001 - spacing is only a fallback
        pass
    return field, species, spacing


def param_range(name, options, grid, want):
    """(lo, hi) of parameter `name` along axis `want` from its options expression."""
    key = name if name.startswith("params_") else "params_" + name
    if key not in options:
        raise InputError(f"--{want}-param {name}: no option {key} in options_used.yaml; give --{want}-range LO HI")
    r = linear_axis(options[key], grid)
    if r is None or r[0] != want:
        raise InputError(f"--{want}-param {name}: {key} = {options[key]!r} is not a linear function of "
                         f"{'i/x' if want == 'x' else 'j/y'}; give --{want}-range LO HI")
    return r[1], r[2]


# ----------------------------------------------------------------------------------------------

def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("path", help="run output directory or a .vtkhdf snapshot")
    ap.add_argument("--species", default=None, help="species drawn (default: the first in the snapshot)")
    ap.add_argument("--x-param", default=None)
    ap.add_argument("--x-range", nargs=2, type=float, metavar=("LO", "HI"), default=None)
    ap.add_argument("--y-param", default=None)
    ap.add_argument("--y-range", nargs=2, type=float, metavar=("LO", "HI"), default=None)
    ap.add_argument("--out", default=None, help="output PNG (default <run dir>/ingrid_<species>.png)")
    ap.add_argument("--no-stability", action="store_true", help="no Turing/Hopf boundary overlay")
    args = ap.parse_args(argv)
    try:
        summary = run(args)
    except InputError as e:
        sys.exit(f"{PROG}: error: {e}")
    except OSError as e:
        sys.exit(f"{PROG}: error: {e}")
    print(summary)
    return 0


def run(args):
    path = args.path
    if os.path.isdir(path):
        run_dir = path
        snapshot = None
    elif os.path.isfile(path):
        run_dir, snapshot = os.path.dirname(path) or ".", path
    else:
        raise InputError(f"{path}: no such file or directory")
    opt_path = os.path.join(run_dir, "options_used.yaml")
    options = read_options(opt_path) if os.path.isfile(opt_path) else {}
    if snapshot is None:
        snapshot = newest_snapshot(run_dir, options.get("output_name"))
        if snapshot is None:
            raise InputError(f"{run_dir}: no <name>_<step>.vtkhdf snapshot (run with -snapshot_every, or pass a file)")
    try:
        field, species, spacing = read_snapshot_field(snapshot, args.species)
    except KeyError as e:
        raise InputError(f"{snapshot}: {e.args[0] if e.args else e}")
    except Exception as e:  # noqa: BLE001 - h5py errors, bad layout
        raise InputError(f"{snapshot}: cannot read: {e}")
    ny, nx = field.shape
    if options:
        grid = grid_of(options, field.shape)
        if (grid["nx"], grid["ny"]) != (nx, ny):
            raise InputError(f"{snapshot}: field {nx} x {ny} but options_used.yaml has grid_n {grid['nx']},{grid['ny']}")
    else:
        hx, hy = spacing or (1.0, 1.0)
        grid = {"nx": nx, "ny": ny, "Lx": nx * hx, "Ly": ny * hy, "hx": hx, "hy": hy}

    axes = {}
    for want in ("x", "y"):
        name, rng = getattr(args, f"{want}_param"), getattr(args, f"{want}_range")
        if rng is not None and name is None:
            raise InputError(f"--{want}-range needs --{want}-param NAME")
        if name is not None:
            if rng is None:
                rng = param_range(name, options, grid, want)
            axes[want] = (name[len("params_"):] if name.startswith("params_") else name, rng[0], rng[1])
    if "x" not in axes and "y" not in axes:
        if not options:
            raise InputError(f"{run_dir}: no options_used.yaml to find the parameter axes in; "
                             f"give --x-param NAME --x-range LO HI and/or --y-param NAME --y-range LO HI")
        axes = detect_axes(options, field.shape)
        if not axes:
            raise InputError(f"{opt_path}: no params_* option varies linearly along i/x or j/y; "
                             f"give --x-param NAME --x-range LO HI and/or --y-param NAME --y-range LO HI")

    # extents: the ranges are the values at the first and last cell centres
    def ext(want, n):
        if want in axes:
            _, lo, hi = axes[want]
            step = (hi - lo) / (n - 1) if n > 1 else 1.0
            return lo - 0.5 * step, hi + 0.5 * step, axes[want][0]
        return 0.0, float(n), f"{want} (cells)"

    x0, x1, xlabel = ext("x", nx)
    y0, y1, ylabel = ext("y", ny)

    plot_w = 6.0 if nx >= ny else 6.0 * nx / ny
    plot_h = plot_w * ny / nx
    fig = plt.figure(figsize=(plot_w + 2.4, plot_h + 1.4), dpi=100)
    W, H = fig.get_size_inches()
    ax = fig.add_axes([0.85 / W, 0.75 / H, plot_w / W, plot_h / H])
    cax = fig.add_axes([(0.85 + plot_w + 0.15) / W, 0.75 / H, 0.18 / W, plot_h / H])
    finite = np.isfinite(field)
    vmin = float(field[finite].min()) if finite.any() else 0.0
    vmax = float(field[finite].max()) if finite.any() else 1.0
    im = ax.imshow(np.where(finite, field, np.nan), origin="lower", extent=(x0, x1, y0, y1),
                   aspect="auto", cmap="viridis", vmin=vmin, vmax=vmax if vmax > vmin else vmin + 1,
                   interpolation="nearest")
    fig.colorbar(im, cax=cax)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    model = options.get("model", "")
    ax.set_title(f"{model + ': ' if model else ''}{species}, {os.path.basename(snapshot)}", fontsize=10)

    overlay = "no stability overlay"
    if not args.no_stability and model == "turing":
        overlay = draw_turing_overlay(ax, axes, options, (x0, x1, y0, y1))
    out = args.out or os.path.join(run_dir, f"ingrid_{species}.png")
    fig.savefig(out, dpi=100)
    plt.close(fig)
    desc = ", ".join(f"{w} = {axes[w][0]} {axes[w][1]:.6g}..{axes[w][2]:.6g}" for w in ("x", "y") if w in axes)
    return f"{PROG}: {snapshot}: {species} {nx} x {ny}, {desc}; {overlay}; wrote {out}"


def draw_turing_overlay(ax, axes, options, extent):
    """Turing (solid) and Hopf (dashed) boundaries of the `turing` model over the plot."""
    names = {axes[w][0]: w for w in axes}
    if not ({"alpha", "beta"} & set(names)):
        return "no stability overlay (neither alpha nor beta is an axis)"
    x0, x1, y0, y1 = extent
    X, Y = np.meshgrid(np.linspace(x0, x1, 601), np.linspace(y0, y1, 601))
    coord = {"x": X, "y": Y}
    vals = {}
    defaults = {"D_a": 1.0 / 16.0, "D_b": 0.25}
    for p in ("alpha", "beta", "D_a", "D_b"):
        if p in names:
            vals[p] = coord[names[p]]
            continue
        key = p if p.startswith("D_") else "params_" + p
        v = constant_value(options[key]) if key in options else defaults.get(p)
        if v is None:
            return f"no stability overlay ({key} is not a constant)"
        vals[p] = v
    if np.any(np.asarray(vals["D_a"]) <= 0) or np.any(np.asarray(vals["D_b"]) <= 0):
        return "no stability overlay (a diffusion coefficient is zero)"
    turing, trace, margin = turing_model_stability(vals["alpha"], vals["beta"], vals["D_a"], vals["D_b"])
    handles, drawn = [], []
    # the Turing threshold where the homogeneous state is stable (it ends on the Hopf line)
    m = np.ma.masked_where(~np.isfinite(margin) | ~(trace < 0), margin)
    if m.count() and m.min() < 0 < m.max():
        ax.contour(X, Y, m, levels=[0.0], colors="white", linewidths=1.8)
        handles.append(Line2D([], [], color="white", lw=1.8, label="Turing threshold (linear theory)"))
        drawn.append("Turing")
    tr = np.ma.masked_invalid(trace)
    if tr.count() and tr.min() < 0 < tr.max():
        ax.contour(X, Y, tr, levels=[0.0], colors="white", linewidths=1.4, linestyles="dashed")
        handles.append(Line2D([], [], color="white", lw=1.4, ls="--", label="Hopf (trace J = 0, det J > 0)"))
        drawn.append("Hopf")
    if not handles:
        return "no stability boundary in range"
    leg = ax.legend(handles=handles, loc="upper left", fontsize=8, framealpha=0.35, facecolor="0.3")
    for t in leg.get_texts():
        t.set_color("white")
    return " and ".join(drawn) + " boundary drawn"


if __name__ == "__main__":
    sys.exit(main())
