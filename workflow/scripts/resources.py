"""Write config/resources.yaml, the Slurm resources of each rule, from the benchmark files a
run of the workflow wrote (target/codes/benchmarks): per problem (and code) the largest level's
peak memory (max_rss, MB) and wall time (s), with margins: memory x2 and at least 1000 MB,
time x3 and at least 5 minutes (Slurm's `runtime` is in minutes). A run shorter than Snakemake's benchmark
sampling interval (1 s) reads the shell's memory alone: the minimums cover it.

    python3 workflow/scripts/resources.py [target/codes/benchmarks] > config/resources.yaml
"""

import csv
import math
import sys
from pathlib import Path


def read(path):
    with open(path) as f:
        row = next(csv.DictReader(f, delimiter="\t"))
    return float(row["max_rss"]) if row["max_rss"] not in ("", "NA", "-") else 0.0, float(row["s"])


def resources(rss_mb, seconds):
    return {"mem_mb": max(1000, int(math.ceil(2 * rss_mb / 100.0)) * 100),
            "runtime": max(5, int(math.ceil(3 * seconds / 60.0)))}


def main():
    root = Path(sys.argv[1] if len(sys.argv) > 1 else "target/codes/benchmarks")
    out = ["# Written by `python3 workflow/scripts/resources.py`: the Slurm resources of each rule,",
           "# measured on 2 cores at each problem's largest level (memory x2, at least 1000 MB;",
           "# time x3, at least 5 min). Measured: peak RSS (MB) and wall time (s) in the comments.",
           "resources:"]
    out.append("  export:")
    for f in sorted((root / "export").glob("*.tsv")):
        rss, s = read(f)
        r = resources(rss, s)
        out.append(f"    {f.stem}: {{mem_mb: {r['mem_mb']}, runtime: {r['runtime']}}}  # {rss:.0f} MB, {s:.1f} s")
    out.append("  solve:")
    for problem in sorted(p for p in (root / "solve").iterdir() if p.is_dir()):
        out.append(f"    {problem.name}:")
        for code in sorted(c for c in problem.iterdir() if c.is_dir()):
            levels = sorted(code.glob("level_*.tsv"), key=lambda p: int(p.stem.split("_")[1]))
            rss, s = read(levels[-1])
            r = resources(rss, s)
            out.append(f"      {code.name}: {{mem_mb: {r['mem_mb']}, runtime: {r['runtime']}}}  # {levels[-1].stem}: {rss:.0f} MB, {s:.1f} s")
    out.append("  grade:")
    for problem in sorted(p for p in (root / "grade").iterdir() if p.is_dir()):
        out.append(f"    {problem.name}:")
        for f in sorted(problem.glob("*.tsv")):
            rss, s = read(f)
            r = resources(rss, s)
            out.append(f"      {f.stem}: {{mem_mb: {r['mem_mb']}, runtime: {r['runtime']}}}  # {rss:.0f} MB, {s:.1f} s")
    codes = root / "codes.tsv"
    if codes.exists():
        rss, s = read(codes)
        r = resources(rss, s)
        out.append(f"  codes: {{mem_mb: {r['mem_mb']}, runtime: {r['runtime']}}}  # {rss:.0f} MB, {s:.1f} s")
    print("\n".join(out))


main()
