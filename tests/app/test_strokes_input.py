"""Stroke files (strokes(...), strokes_directed(...), strokes_distance(...) in any value): bad
files never run. Each case exits non-zero, prints exactly one error line naming the option, the
file and what is wrong (a syntax error with its line and column), and leaves an existing output
directory untouched; on 1 rank (a few also on 2). Covered: malformed JSON, a missing file, an empty stroke,
a one-point stroke, a zero-length stroke, a bad point, unknown units and keys, an unknown
extension, a stroke outside the domain, an SVG with an unsupported path command (line and
column), a transform, no viewBox, or bad path data. Valid files: an SVG path and the same
stroke in JSON (cells, y up) give the same field; a deck with strokes in a subdirectory finds
its file relative to the deck."""
import os

import pytest
from conftest import SOURCE, error_lines, run

GRID = ["-model", "turing", "-grid_n", "32,32", "-grid_bc", "neumann", "-steps", "1",
        "-png_every", "0", "-summary", "false"]

# The 4 of "[3 4]" is the unexpected token: line 2, column 26.
MALFORMED = '{"strokes": [\n  {"points": [[1, 2], [3 4]]}\n]}\n'
SVG_ARC = ('<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 32 32">\n'
           '  <path d="M 1 1 L 10 10\n           A 5 5 0 0 1 20 20"/>\n</svg>\n')

CASES = [
    # (id, file name, file text or None (missing), substrings the error line must contain)
    ("malformed_json", "s.json", MALFORMED,
     ["-init_a", "strokes file s.json: line 2, column 26:", "syntax error"]),
    ("missing_file", "nope.json", None, ["-init_a", "strokes file nope.json", "cannot be read"]),
    ("empty_stroke", "s.json", '{"strokes": [{"points": [[1, 1], [5, 5]]}, {"points": []}]}',
     ["strokes file s.json: stroke 2 is empty", "at least 2 points"]),
    ("one_point", "s.json", '{"strokes": [{"points": [[1, 1]]}]}',
     ["stroke 1 has 1 point", "at least 2"]),
    ("zero_length", "s.json", '{"strokes": [{"points": [[1, 1], [1, 1]]}]}',
     ["stroke 1 has no length"]),
    ("bad_point", "s.json", '{"strokes": [{"points": [[1, 1], [2]]}]}',
     ["strokes[0].points[1]: [2]", "expected [x, y]"]),
    ("bad_units", "s.json", '{"units": "pixels", "strokes": [{"points": [[1, 1], [2, 2]]}]}',
     ['"units": "pixels"', '"domain", "cells" or "fraction"']),
    ("unknown_key", "s.json", '{"stroke": []}', ['unknown key "stroke"', "allowed: strokes, units"]),
    ("no_strokes", "s.json", '{"strokes": []}', ["strokes file s.json: no strokes"]),
    ("unknown_extension", "s.txt", "M 0 0 L 1 1", ["strokes file s.txt", "allowed: .json or .svg"]),
    ("outside_domain", "s.json", '{"strokes": [{"points": [[100, 100], [200, 200]]}]}',
     ["no stroke passes within one cell of the domain"]),
    ("svg_arc", "s.svg", SVG_ARC,
     ["strokes file s.svg: line 3, column 12:", "unsupported path command 'A'", "M L H V C S Q T Z"]),
    ("svg_transform", "s.svg",
     '<svg viewBox="0 0 32 32"><g transform="scale(2)"><path d="M 1 1 L 5 5"/></g></svg>',
     ["line 1, column 29", "transform attributes are not supported"]),
    ("svg_no_viewbox", "s.svg", '<svg><path d="M 1 1 L 5 5"/></svg>', ["no usable viewBox"]),
    ("svg_bad_number", "s.svg", '<svg viewBox="0 0 32 32"><path d="M 1 1 L x 5"/></svg>',
     ["line 1, column 43", "expected a number"]),
]




# Every case on 1 rank, a few on 2 (each rank reads the file and fails alike).
ON_TWO = ("malformed_json", "missing_file", "empty_stroke", "svg_arc")
RUNS = [(c, 1) for c in CASES] + [(c, 2) for c in CASES if c[0] in ON_TWO]


@pytest.mark.parametrize("case,ranks", RUNS, ids=[f"{c[0]}-np{r}" for c, r in RUNS])
def test_bad_stroke_file(case, ranks, workdir):
    _, name, text, needles = case
    if text is not None:
        (workdir / name).write_text(text)
    out = workdir / "out"
    out.mkdir()
    sentinel = out / "a_final.png"
    sentinel.write_text("previous result")
    value = f'4 + (strokes_distance("{name}") < 2 ? 1 : 0)'
    proc = run(GRID + ["-init_a", value, "-output_dir", str(out)], cwd=workdir, ranks=ranks,
               timeout=120)
    assert proc.returncode != 0, proc.stdout
    lines = error_lines(proc)
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("morphogen: error: -init_a "), lines[0]
    for n in needles:
        assert n in lines[0], lines[0]
    assert sorted(os.listdir(out)) == ["a_final.png"]
    assert sentinel.read_text() == "previous result"


def final_png(workdir, name, text, value, ranks=1):
    (workdir / name).write_text(text)
    out = workdir / ("out_" + name.replace(".", "_"))
    proc = run(GRID + ["-steps", "0", "-init_a", value.replace("FILE", name), "-output_dir",
                       str(out)], cwd=workdir, ranks=ranks)
    assert proc.returncode == 0, proc.stderr
    return (out / "a_final.png").read_bytes()


@pytest.mark.parametrize("func", ["strokes", "strokes_directed", "strokes_distance"])
def test_svg_and_json_give_the_same_field(func, workdir):
    # SVG user units: y down, viewBox stretched over the 32 x 32 domain; the same polyline in
    # JSON cells has y = 32 - y_svg. The cubic from (28, 12) to (4, 24) has its control points
    # at 1/3 and 2/3 of the chord: a straight line, flattened into the JSON's last segment.
    svg = ('<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 32 32">'
           '<path d="M 4 4 l 20 4 H 28 V 12 C 20 16, 12 20, 4 24"/></svg>')
    js = '{"units": "cells", "strokes": [{"points": [[4, 28], [24, 24], [28, 24], [28, 20], [4, 8]]}]}'
    value = "4 + " + func + '("FILE")'
    a = final_png(workdir, "s.svg", svg, value)
    b = final_png(workdir, "s.json", js, value, ranks=2)
    assert a == b


def test_deck_finds_stroke_file_beside_it(workdir):
    deck = workdir / "deck.yaml"
    (workdir / "strokes").mkdir()
    (workdir / "strokes" / "line.json").write_text(
        '{"units": "fraction", "strokes": [{"points": [[0.1, 0.5], [0.9, 0.5]]}]}')
    deck.write_text("model: turing\ngrid:\n  n: 32,32\ndiffusion: tensor\ntensor:\n"
                    "  a: {theta: 'strokes(\"strokes/line.json\")', l1: 4, l2: 1}\n"
                    "steps: 2\npng_every: 0\nsummary: false\n")
    elsewhere = workdir / "run"
    elsewhere.mkdir()
    proc = run([str(deck), "-output_dir", str(elsewhere / "o")], cwd=elsewhere)
    assert proc.returncode == 0, proc.stderr
