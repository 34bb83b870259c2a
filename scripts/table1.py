#!/usr/bin/env python3
"""The paper's Table 1 on one machine: MPI ranks (nproc) times threads per
rank (nprol), every product up to the machine's cores, one surface at a
fixed `--parts`, generation only (`parafront bench` under mpirun: no
improvement, no quality report, as in the paper's tables).

    python3 scripts/table1.py SURFACE                  # sweep, print the section
    python3 scripts/table1.py SURFACE --cores 16 --parts 16 --append
    python3 scripts/table1.py SURFACE --from-log LOG --append   # format a saved sweep

The sweep runs, for nproc in 1, 2, 4, ... up to --cores:
`MPIRUN -n nproc PARAFRONT bench SURFACE --parts P --threads t1,t2,...`
with every t such that nproc * t <= cores, and keeps its output (--log).
PARAFRONT is a binary built with `--features mpi` (default
target/release/parafront); MPIRUN defaults to `mpirun --oversubscribe
--bind-to none` (no binding: a rank's threads need their own cores).
--from-log formats such a saved output instead (a sweep run elsewhere, on
a machine lent for it). With --append the section goes to the end of
BENCHMARKS.md, else to standard output.
"""
import argparse
import datetime
import os
import re
import shlex
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def parse(text, surface):
    """Rows of `parafront bench` output on `surface` (a file name): (ranks,
    threads, stats). A block whose head names no MPI ranks ran in one
    process (its first column is the parts, its third the threads)."""
    rows, ranks, ours = [], 1, False
    for line in text.splitlines():
        m = re.search(r"^(.*): \d+ points, \d+ triangles(?: \((\d+) MPI ranks\))?$", line)
        if m:
            ours = os.path.basename(m.group(1)) == os.path.basename(surface)
            ranks = int(m.group(2) or 1)
            continue
        if not ours:
            continue
        cells = line.split("|")
        head = cells[0].split()
        if len(cells) != 6 or len(head) != 7 or not all(c.isdigit() for c in head[:4]):
            continue
        stages = [float(x) for x in cells[1].split()]
        tail = cells[5].split()
        threads = int(head[2]) // ranks
        rows.append((ranks, threads, {
            "tets": int(head[3]), "wall": float(head[4]), "ddg": stages[0],
            "part": stages[1], "passes": stages[2:6], "cpu": float(tail[0]),
            "ddg_share": float(tail[1]),
        }))
    return rows


def sweep(a):
    binary = a.binary or os.path.join(ROOT, "target", "release", "parafront")
    mpirun = shlex.split(a.mpirun)
    out = []
    n = 1
    while n <= a.cores:
        ts, t = [], 1
        while n * t <= a.cores:
            ts.append(str(t))
            t *= 2
        cmd = mpirun + ["-n", str(n), binary, "bench", a.surface, "--parts", str(a.parts),
                        "--threads", ",".join(ts)]
        print("$ " + " ".join(cmd), file=sys.stderr, flush=True)
        r = subprocess.run(cmd, capture_output=True, text=True)
        sys.stderr.write(r.stdout[-2000:])
        if r.returncode != 0:
            sys.exit(f"table1: {' '.join(cmd)} failed ({r.returncode}):\n{r.stderr[-2000:]}")
        out.append(r.stdout)
        n *= 2
    text = "\n".join(out)
    if a.log:
        with open(a.log, "w") as f:
            f.write(text)
    return text


def machine():
    try:
        with open("/proc/cpuinfo") as f:
            model = next((l.split(":", 1)[1].strip() for l in f if l.startswith("model name")), "?")
    except OSError:
        model = "?"
    return f"{os.cpu_count()} cores ({model})"


def section(rows, a, where):
    if not rows:
        sys.exit("table1: no bench rows found")
    rows = sorted(rows, key=lambda r: (r[0] * r[1], r[0]))
    base = next((r[2]["wall"] for r in rows if r[0] == 1 and r[1] == 1), None)
    rev = a.commit or subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                                     capture_output=True, text=True).stdout.strip() or "?"
    started = a.when or datetime.datetime.now().strftime("%Y-%m-%d %H:%M")
    L = [f"## Sitting {started} (commit {rev}): `scripts/table1.py` on {where}\n",
         f"## table1: {os.path.basename(a.surface)}, --parts {a.parts}, generation only\n",
         "nproc: MPI ranks, nprol: threads per rank. s: wall seconds of the slowest rank. "
         "AbsSpeed: tets per second; RelSpeed: per core. Speed-up over nproc = nprol = 1. "
         "ddg: the DDG and its partition (the DDG's passes run over the ranks from "
         "commit e9c5944 on, before it every rank built the whole DDG; every rank "
         "runs the partition). "
         "cpu s: all ranks' CPU seconds.\n",
         "| nproc | nprol | ncore | nelem | s | AbsSpeed | RelSpeed | speed-up | ddg s | pass 1 | "
         "pass 2 | pass 3 | pass 4 | ddg % of s | cpu s |",
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for ranks, threads, s in rows:
        n = ranks * threads
        up = f"{base / s['wall']:.2f}" if base else ""
        p = s["passes"]
        L.append(f"| {ranks} | {threads} | {n} | {s['tets']:,} | {s['wall']:.2f} | "
                 f"{s['tets'] / s['wall']:,.0f} | {s['tets'] / s['wall'] / n:,.0f} | {up} | "
                 f"{s['ddg'] + s['part']:.2f} | {p[0]:.2f} | {p[1]:.2f} | {p[2]:.2f} | {p[3]:.2f} | "
                 f"{s['ddg_share']:.0f} | {s['cpu']:.1f} |")
    L.append("")
    return "\n".join(L) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("surface")
    ap.add_argument("--cores", type=int, default=os.cpu_count())
    ap.add_argument("--parts", type=int, default=16)
    ap.add_argument("--binary", help="parafront built with --features mpi")
    ap.add_argument("--mpirun", default="mpirun --oversubscribe --bind-to none")
    ap.add_argument("--log", help="keep the sweep's raw output here")
    ap.add_argument("--from-log", help="format this saved sweep instead of running one")
    ap.add_argument("--where", help="the machine, as the section names it (default: this one)")
    ap.add_argument("--when", help="when the sweep ran (default: now)")
    ap.add_argument("--commit", help="the commit the binary was built from (default: HEAD)")
    ap.add_argument("--append", action="store_true", help="append to BENCHMARKS.md")
    a = ap.parse_args()
    if a.from_log:
        with open(a.from_log) as f:
            text = f.read()
    else:
        text = sweep(a)
    md = section(parse(text, a.surface), a, a.where or machine())
    if a.append:
        with open(os.path.join(ROOT, "BENCHMARKS.md"), "a") as f:
            f.write("\n" + md)
    else:
        sys.stdout.write(md)


if __name__ == "__main__":
    main()
