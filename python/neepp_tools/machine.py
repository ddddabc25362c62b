"""What machine a benchmark ran on, for its report.

Speed ratios against Mitsuba 3 depend on the CPU's vector width: Mitsuba's llvm variant runs as many
lanes as the widest vector unit (16 with AVX-512, 8 with AVX2), while neepp shades one path at a time
and only its Embree packets follow that width. The same code measured 1.13x Mitsuba on bathroom on an
AVX2 machine and 0.94x on an AVX-512 one, so a figure without the machine is not comparable.
"""
import os
import platform


def describe() -> dict:
    """CPU model, core count and widest vector unit (from /proc/cpuinfo where there is one)."""
    model, flags = None, set()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, _, value = line.partition(":")
                if key.strip() == "model name" and model is None:
                    model = value.strip()
                elif key.strip() == "flags":
                    flags = set(value.split())
                    break
    except OSError:
        pass
    model = model or platform.processor() or platform.machine()
    if "avx512f" in flags:
        simd, lanes = "AVX-512", 16
    elif "avx2" in flags:
        simd, lanes = "AVX2", 8
    elif flags:
        simd, lanes = "SSE", 4
    else:
        simd, lanes = "unknown", None
    return {"cpu": model, "cores": os.cpu_count(), "simd": simd, "float_lanes": lanes}


def summary(info: dict | None = None) -> str:
    """One line for a report: 'AMD EPYC, 2 cores, AVX2 (8 float lanes)'."""
    info = info or describe()
    lanes = f" ({info['float_lanes']} float lanes)" if info.get("float_lanes") else ""
    return f"{info['cpu']}, {info['cores']} cores, {info['simd']}{lanes}"
