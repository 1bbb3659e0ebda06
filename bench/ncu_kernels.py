#!/usr/bin/env python3
"""Sums Nsight Compute's per-launch kernel times by kernel name.

Usage (on the GPU machine, after `tar -xJf .carry-pack/carry.tar.xz`):
  ncu --csv --page raw --print-units base --clock-control none \
      --metrics gpu__time_duration.sum --kernel-name-base demangled BINARY ARGS > kernels.csv
  python3 bench/ncu_kernels.py kernels.csv [TOP]
Prints the TOP (default 25) kernels by total time: launches, total ms, share of all kernels.
"""
import csv
import re
import sys
from collections import defaultdict


def short_name(name: str) -> str:
    """The kernel's own name and the galpha functors in its template arguments, which a Thrust
    kernel's name (transform_kernel<policy, tuple<counting_iterator<...>>, ...>) buries; a
    kernel without one (CUB's sorts and scans) keeps the start of its full name."""
    kernel = name.split("<", 1)[0].removeprefix("void ")
    functors = []
    for found in re.findall(r"galpha::(?:detail::)?[A-Za-z_][A-Za-z0-9_]*", name):
        if found not in functors:
            functors.append(found)
    return f"{kernel} [{', '.join(functors)}]" if functors else name.removeprefix("void ")[:140]


def main() -> int:
    path = sys.argv[1]
    top = int(sys.argv[2]) if len(sys.argv) > 2 else 25
    with open(path, newline="") as f:
        # ncu prints its own progress lines before the CSV header ("==PROF==" ...).
        rows = [line for line in f if line.startswith('"')]
    reader = csv.DictReader(rows)
    total_ns = defaultdict(float)
    launches = defaultdict(int)
    for row in reader:
        name = row.get("Kernel Name", "")
        value = row.get("gpu__time_duration.sum") or ""  # a cut-off last row has none
        try:
            ns = float(value.replace(",", ""))
        except ValueError:
            continue  # the units row
        total_ns[name] += ns
        launches[name] += 1
    everything = sum(total_ns.values())
    print(f"all kernels: {everything / 1e6:.2f} ms in {sum(launches.values())} launches")
    for name, ns in sorted(total_ns.items(), key=lambda kv: -kv[1])[:top]:
        print(f"{ns / 1e6:9.2f} ms {100 * ns / everything:5.1f}% {launches[name]:6d}x  {short_name(name)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
