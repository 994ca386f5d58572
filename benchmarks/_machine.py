"""The machine a benchmark ran on, for its printout (one helper for every script here).

CPU speeds differ 3–4× between the machines this project runs on (AVX-512 or AVX2 only),
so every absolute figure is printed beside the CPU it was measured on.
"""

from __future__ import annotations

import os
import platform
from pathlib import Path


def cpu_name() -> str:
    """Model name, family/model numbers, vector extension and core count of this CPU.

    From ``/proc/cpuinfo`` (Linux); elsewhere :func:`platform.processor`.  E.g.
    ``"AMD EPYC (family 25 model 17, AVX-512, 2 cores)"``.
    """
    try:
        info = Path("/proc/cpuinfo").read_text()
    except OSError:
        return f"{platform.processor() or platform.machine()} ({os.cpu_count()} cores)"

    def field(key: str) -> str:
        return next((ln.split(":", 1)[1].strip() for ln in info.splitlines()
                     if ln.split(":", 1)[0].strip() == key), "?")

    flags = f" {field('flags')} "
    vec = "AVX-512" if " avx512f " in flags else "AVX2" if " avx2 " in flags else "no AVX2"
    return (f"{field('model name')} (family {field('cpu family')} model {field('model')}, "
            f"{vec}, {os.cpu_count()} cores)")
