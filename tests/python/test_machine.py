"""The machine description the benchmarks print beside their ratios."""
import os
import re

from neepp_tools import machine


def test_describe_names_the_cpu_and_its_vector_width():
    info = machine.describe()
    assert info["cores"] == os.cpu_count()
    assert info["cpu"]
    assert (info["simd"], info["float_lanes"]) in {("AVX-512", 16), ("AVX2", 8), ("SSE", 4), ("unknown", None)}
    if os.path.exists("/proc/cpuinfo"):
        flags = next((line for line in open("/proc/cpuinfo") if line.startswith("flags")), "").split()
        if flags:  # the widest unit the kernel reports, as Mitsuba's llvm variant picks it
            assert info["simd"] == ("AVX-512" if "avx512f" in flags else "AVX2" if "avx2" in flags else "SSE")


def test_summary_is_one_line_with_cores_and_lanes():
    line = machine.summary({"cpu": "Some CPU", "cores": 2, "simd": "AVX2", "float_lanes": 8})
    assert line == "Some CPU, 2 cores, AVX2 (8 float lanes)"
    assert "\n" not in machine.summary()
    assert re.search(r"\d+ cores", machine.summary())
