"""bench/instructions.py: instruction counts per sample from callgrind, by function and by object."""
from __future__ import annotations

import importlib.util
import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
spec = importlib.util.spec_from_file_location("instructions", REPO / "bench" / "instructions.py")
instructions = importlib.util.module_from_spec(spec)
spec.loader.exec_module(instructions)

# A callgrind file in the documented format: compressed names, a call whose inclusive cost must not be
# charged to the caller, relative positions, and a function met again later under its id alone.
CALLGRIND = """# callgrind format
version: 1
positions: line
events: Ir
summary: 1000

ob=(1) /usr/lib/libembree3.so.3
fl=(1) ???
fn=(1) 0x0000000000001000
0 300

ob=(2) /repo/build/neepp
fl=(2) src/path.cpp
fn=(2) neepp::PathIntegrator::Li_batch(int)
10 40
+2 5
cob=(1)
cfi=(1)
cfn=(1)
calls=3 0
12 300
-1 7
fn=(3) neepp::Shape::fill_interaction(int)
fi=(3) src/vec.h
30 20
fe=(2)
31 2
fn=(2)
15 1
"""


def test_parse_callgrind_charges_each_function_its_own_instructions(tmp_path):
    f = tmp_path / "callgrind.out"
    f.write_text(CALLGRIND)
    costs = instructions.parse_callgrind(f)
    assert costs[("/usr/lib/libembree3.so.3", "0x0000000000001000")] == 300
    # 40 + 5 + 7 + 1, not the 300 its call to Embree cost
    assert costs[("/repo/build/neepp", "neepp::PathIntegrator::Li_batch(int)")] == 53
    # an inlined file's lines stay with the function they were inlined into
    assert costs[("/repo/build/neepp", "neepp::Shape::fill_interaction(int)")] == 22
    assert sum(costs.values()) == 375


def test_object_labels_line_two_binaries_up():
    a, b = Path("/x/build/neepp"), Path("/tmp/neepp_other")
    assert instructions.object_label("/x/build/neepp", a) == "neepp"
    assert instructions.object_label("/tmp/neepp_other", b) == "neepp"
    assert instructions.object_label("/usr/lib/x86_64-linux-gnu/libembree3.so.3.13.5", a) == "libembree3.so.3.13.5"
    assert instructions.group_of("libembree3.so.3.13.5") == "Embree"
    assert instructions.group_of("neepp") == "neepp"
    assert instructions.group_of("libc.so.6") == "other"


needs_valgrind = pytest.mark.skipif(shutil.which("valgrind") is None,
                                    reason="valgrind not installed (scripts/test.sh installs it)")


@pytest.fixture(scope="session")
def valgrind_bin(neepp_bin) -> Path:
    """A neepp valgrind can run on this CPU: build-valgrind/neepp (x86-64-v3, scripts/build_valgrind.sh, which
    scripts/test.sh runs), else the ordinary build where valgrind can run it (no AVX-512 in it)."""
    for b in (os.environ.get("NEEPP_VALGRIND_BIN"), REPO / "build-valgrind" / "neepp", neepp_bin):
        if b and Path(b).exists() and instructions.valgrind_problem(Path(b)) is None:
            return Path(b)
    pytest.skip("no neepp that valgrind can run on this CPU: run scripts/build_valgrind.sh")


@needs_valgrind
def test_a_binary_valgrind_cannot_decode_is_named_not_crashed_on(tmp_path):
    # One AVX-512 instruction, which valgrind decodes on no CPU: what a -march=native build on an AVX-512
    # machine holds. The check must say so (and name the way out), on any CPU, instead of a crash mid-run.
    src = tmp_path / "avx512.c"
    src.write_text('int main(void) { __asm__ volatile("vpxorq %zmm0, %zmm0, %zmm0"); return 0; }\n')
    exe = tmp_path / "avx512"
    subprocess.run(["cc", "-o", str(exe), str(src)], check=True)
    why = instructions.valgrind_problem(exe)
    assert why is not None and "build_valgrind.sh" in why
    assert instructions.main([str(REPO / "scenes" / "door-ajar" / "scene.xml"), "--bin", str(exe),
                              "--out", str(tmp_path / "out")]) == 2


@needs_valgrind
def test_counts_a_render_of_the_project_scene(valgrind_bin, tmp_path):
    neepp_bin = valgrind_bin
    scene = REPO / "scenes" / "door-ajar" / "scene.xml"
    rc = instructions.main([str(scene), "--bin", str(neepp_bin), "--res", "16", "--spp", "1,2",
                            "--max-depth", "5", "--top", "5", "--out", str(tmp_path)])
    assert rc == 0
    r = json.loads((tmp_path / "results.json").read_text())["A"]
    # a path tracer's render: both our code and Embree's do work for every sample
    assert r["groups"]["neepp"] > 100 and r["groups"]["Embree"] > 100
    assert r["total"] == pytest.approx(sum(r["groups"].values()))
    assert any(k.startswith("neepp:neepp::PathIntegrator") for k in r["functions"])
    assert (tmp_path / "report.md").read_text().startswith("# Instructions per sample: door-ajar, 16x16")
