"""Instructions per sample of a render, by function: where the path tracer's work goes, as exact counts.

Timings on the shared 2-core machine scatter by ±10-15 % from run to run (two identical binaries run at
once, one per core, differed by up to 22 %), so a change of a few per cent cannot be timed there.
Instruction counts can: valgrind's callgrind counts every instruction executed, the same from run to run.
They are not time (a cache miss or a division costs more than an add), so they show what a change saved
in work, and timings must still confirm the large effects.

The script renders the scene twice under callgrind, at two sample counts; the difference between the two,
divided by the extra samples, is the render alone (loading, building and writing the image cancel out).
Functions are grouped by object: Embree (the ray queries), neepp itself (shading, sampling, the
integrator) and the rest (libc, libm, TBB).

    .venv/bin/python bench/instructions.py                       # cornell-box 64x64, 1 and 3 spp
    .venv/bin/python bench/instructions.py bathroom --res 96 --top 40
    .venv/bin/python bench/instructions.py cornell-box --bin-b build-ab/neepp   # A/B of two binaries

Needs valgrind (`apt install valgrind`), and on a CPU with AVX-512 a binary valgrind can run:
scripts/build_valgrind.sh builds one (build-valgrind/neepp, for x86-64-v3); pass it as --bin. Runs on one thread; takes about a minute at the defaults.
Writes bench/out/instructions/ (git-ignored): report.md, results.json.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from collections import Counter
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "python"))
from neepp_tools import SCENES_DIR, machine, report, runner  # noqa: E402


def parse_callgrind(path: Path) -> Counter:
    """Self instruction counts per (object, function) from a callgrind output file.

    The format (valgrind's docs, "Callgrind Format Specification"): `ob=` and `fn=` set the current object
    and function, names compressed as `(id) name` the first time and `(id)` after; a cost line is a
    position followed by the event counts (here only Ir); the cost line right after `calls=` is the
    callee's inclusive cost, charged to the call, not to the caller's own instructions, so it is skipped.
    """
    names: dict[tuple[str, str], str] = {}

    def name(kind: str, value: str) -> str:
        value = value.strip()
        if value.startswith("("):
            ident, _, rest = value.partition(")")
            key = (kind, ident + ")")
            if rest.strip():
                names[key] = rest.strip()
            return names.get(key, value)
        return value

    costs: Counter = Counter()
    ob = fn = "?"
    skip_next = False
    with open(path, errors="replace") as f:
        for line in f:
            c = line[:1]
            if c.isdigit() or c in "+-*":
                if skip_next:
                    skip_next = False
                    continue
                fields = line.split()
                if len(fields) >= 2:
                    costs[(ob, fn)] += int(fields[1])
            elif line.startswith("ob="):
                ob = name("ob", line[3:])
            elif line.startswith("fn="):
                fn = name("fn", line[3:])
            elif line.startswith("calls="):
                skip_next = True
            elif line.startswith("cob="):
                name("ob", line[4:])  # a callee's object or function may be named here first
            elif line.startswith("cfn="):
                name("fn", line[4:])
    return costs


def object_label(obj: str, binary: Path) -> str:
    """The object's file name; the neepp binary under test is "neepp" whatever it is called, so that two
    binaries' functions line up."""
    if Path(obj).name == binary.name or Path(obj).resolve() == binary.resolve():
        return "neepp"
    return Path(obj).name


def group_of(label: str) -> str:
    return "Embree" if "embree" in label else "neepp" if label == "neepp" else "other"


def valgrind_problem(binary: Path) -> str | None:
    """Why valgrind cannot run `binary`, or None when it can.

    Valgrind decodes no AVX-512: a -march=native build on such a CPU (any Xeon since Skylake-SP) dies under it
    with SIGILL, already in its static initialisers. scripts/build_valgrind.sh builds a neepp that runs under
    valgrind everywhere (x86-64-v3)."""
    r = subprocess.run(["valgrind", "--tool=none", str(binary), "--help"], capture_output=True, text=True,
                       env=dict(os.environ, NEEPP_NO_HUGE_PAGES="1"))
    if r.returncode == 0:
        return None
    if "SIGILL" in r.stderr or "unhandled instruction" in r.stderr or r.returncode == 128 + 4:
        return (f"valgrind cannot run {binary}: it contains instructions valgrind does not decode (AVX-512, "
                f"from -march=native on this CPU); build one that it can run with scripts/build_valgrind.sh "
                f"and pass --bin build-valgrind/neepp")
    return f"valgrind could not run {binary} --help (exit {r.returncode}):\n{r.stderr[-2000:]}"


def callgrind_render(binary: Path, scene: Path, res: int, spp: int, max_depth: int, workdir: Path) -> Counter:
    out = workdir / f"callgrind_{spp}.out"
    cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", str(binary), "render", str(scene),
           "-o", str(workdir / "image.exr"), "--spp", str(spp), "-D", f"resx={res}", "-D", f"resy={res}",
           "-D", f"max_depth={max_depth}", "--threads", "1", "--quiet"]
    # neepp restarts itself with huge pages; callgrind would then count the first process only.
    env = dict(os.environ, NEEPP_NO_HUGE_PAGES="1")
    r = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if r.returncode != 0 or not out.exists():
        raise SystemExit(f"callgrind run failed ({r.returncode}): {' '.join(cmd)}\n{r.stderr[-3000:]}")
    return parse_callgrind(out)


def per_sample(binary: Path, scene: Path, res: int, spp_a: int, spp_b: int, max_depth: int, workdir: Path) -> dict:
    """Per-function instructions per sample of the render alone: (run at spp_b - run at spp_a) / samples."""
    a = callgrind_render(binary, scene, res, spp_a, max_depth, workdir)
    b = callgrind_render(binary, scene, res, spp_b, max_depth, workdir)
    samples = res * res * (spp_b - spp_a)
    keys = set(a) | set(b)
    labels = {obj: object_label(obj, binary) for obj, _ in keys}
    functions: Counter = Counter()
    for obj, fn in keys:
        functions[(labels[obj], fn)] += (b[(obj, fn)] - a[(obj, fn)]) / samples
    groups: Counter = Counter()
    for (label, _), v in functions.items():
        groups[group_of(label)] += v
    return {"functions": functions, "groups": dict(groups), "total": sum(functions.values())}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene", nargs="?", default="cornell-box",
                    help="one of the evaluation scenes under ../shared/scenes, or a scene XML file")
    ap.add_argument("--res", type=int, default=64, help="square image size (default 64)")
    ap.add_argument("--spp", default="1,3", help="the two sample counts whose difference is measured")
    ap.add_argument("--max-depth", type=int, default=17, help="as bench_path.py (default 17)")
    ap.add_argument("--bin", default=None, help="neepp binary (default: NEEPP_BIN or build/neepp)")
    ap.add_argument("--bin-b", default=None, help="a second binary, compared function by function")
    ap.add_argument("--top", type=int, default=25, help="functions listed")
    ap.add_argument("--out", default=str(REPO / "bench" / "out" / "instructions"))
    a = ap.parse_args(argv)
    if shutil.which("valgrind") is None:
        print("valgrind not found (apt install valgrind)", file=sys.stderr)
        return 2
    spp_a, spp_b = (int(x) for x in a.spp.split(","))
    if not 0 < spp_a < spp_b:
        ap.error("--spp needs two counts, the first smaller: e.g. 1,3")
    scene = Path(a.scene) if a.scene.endswith(".xml") else SCENES_DIR / a.scene / "scene.xml"
    if not scene.exists():
        print(f"scene not found: {scene}", file=sys.stderr)
        return 2
    bin_a = Path(a.bin) if a.bin else runner.find_neepp()
    if bin_a is None or not bin_a.exists():
        print("neepp binary not found (--bin, NEEPP_BIN or build/neepp)", file=sys.stderr)
        return 2
    binaries = {"A": bin_a} | ({"B": Path(a.bin_b)} if a.bin_b else {})
    for b in binaries.values():
        if (why := valgrind_problem(b)) is not None:
            print(why, file=sys.stderr)
            return 2
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="neepp_callgrind_") as tmp:
        results = {k: per_sample(b, scene, a.res, spp_a, spp_b, a.max_depth, Path(tmp)) for k, b in binaries.items()}

    def fmt(v):
        return f"{v:,.0f}"

    A, B = results["A"], results.get("B")
    lines = [f"# Instructions per sample: {scene.parent.name if scene.name == 'scene.xml' else scene.name}, "
             f"{a.res}x{a.res}, max_depth {a.max_depth}, render only (spp {spp_b} minus spp {spp_a}), 1 thread\n",
             f"machine: {machine.summary()}; A = {binaries['A']}" + (f", B = {binaries['B']}" if B else "") + "\n"]
    group_rows = []
    for g in ("neepp", "Embree", "other"):
        row = {"part": g, "A": fmt(A["groups"].get(g, 0))}
        if B:
            row |= {"B": fmt(B["groups"].get(g, 0)),
                    "B/A": f"{B['groups'].get(g, 0) / A['groups'][g]:.4f}" if A["groups"].get(g) else "-"}
        group_rows.append(row)
    total = {"part": "total", "A": fmt(A["total"])}
    if B:
        total |= {"B": fmt(B["total"]), "B/A": f"{B['total'] / A['total']:.4f}"}
    group_rows.append(total)
    cols = ["part", "A"] + (["B", "B/A"] if B else [])
    lines.append("\n" + report.markdown_table(group_rows, cols, {c: c for c in cols}) + "\n")

    # The functions that cost most (in A, or that changed most between A and B).
    keys = set(A["functions"]) | (set(B["functions"]) if B else set())
    if B:
        def rank(k):
            return -abs(B["functions"].get(k, 0) - A["functions"].get(k, 0))
    else:
        def rank(k):
            return -A["functions"].get(k, 0)
    fn_rows = []
    for obj, fn in sorted(keys, key=rank)[: a.top]:
        row = {"function": fn.split("(")[0][:100], "object": obj, "A": f"{A['functions'].get((obj, fn), 0):,.1f}"}
        if B:
            row |= {"B": f"{B['functions'].get((obj, fn), 0):,.1f}",
                    "B-A": f"{B['functions'].get((obj, fn), 0) - A['functions'].get((obj, fn), 0):+,.1f}"}
        fn_rows.append(row)
    cols = ["function", "object", "A"] + (["B", "B-A"] if B else [])
    lines.append("\n" + ("largest changes" if B else "largest functions") + " (instructions per sample, "
                 "the function's own, not its callees'):\n\n" + report.markdown_table(fn_rows, cols, {c: c for c in cols}))
    md = "".join(lines)
    (out / "report.md").write_text(md)
    (out / "results.json").write_text(json.dumps(
        {k: {"groups": r["groups"], "total": r["total"],
             "functions": {f"{o}:{f}": v for (o, f), v in r["functions"].items() if abs(v) > 0.05}}
         for k, r in results.items()}, indent=1))
    print(md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
