#!/usr/bin/env python3
"""Benchmark parafront beside the peers, in one sitting, and write BENCHMARKS.md.

    python3 scripts/bench.py                       # corpus + bench 1e6, writes BENCHMARKS.md
    python3 scripts/bench.py --sets corpus --repeat 1 --out /tmp/b.md
    python3 scripts/bench.py --sets bench1e5 --peers gmsh-hxt --threads 1
    python3 scripts/bench.py --sets hard --threads 2 --peers gmsh-hxt,tetgen --append
    python3 scripts/bench.py --sets bench1e6mpi --peers none --append \
        --binary target/release/parafront   # built with --features mpi
    python3 scripts/bench.py --sets bench5e6mem --peers none --threads 1 \
        --repeat 1 --append --binary ...    # issue 22: peak per rank

parafront is timed as a user times it: the whole `parafront mesh` process,
default options, from start to exit (reading, meshing, improvement, checks,
writing). Its peak memory is the peak RSS it reports (VmHWM), median over
the runs. The peers are run by ../shared/tools/peers/peer_mesh.py (`--h
auto`: the mean surface edge, every peer keeping the surface), timed over
their meshing call with their own optimisation. Every parafront mesh is
checked by ../shared/tools/meshcheck.py against its surface. Times are
medians over --repeat runs; compare ratios within one file, not across
sittings.

Needs: python3 with numpy and meshio (meshcheck), and the peers (pip install
gmsh tetgen netgen-mesher) unless --peers none. The release binary is built
if missing.
"""
import argparse
import datetime
import json
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.environ.get("PARAFRONT_SHARED", os.path.join(os.path.dirname(ROOT), "shared"))
GEOMETRY = os.environ.get("PARAFRONT_GEOMETRY", os.path.join(SHARED, "geometry"))

SETS = {
    # The corpus: real surfaces (valid/ and dirty/, which mesh with --heal),
    # and the needle frustum of the CLI's tests.
    "corpus": [
        ("valid/1002_tray_bottom.STL", []),
        ("valid/base_interface_gmsh.stl", []),
        ("valid/boot.obj", []),
        ("valid/discrete_voids.obj", []),
        ("valid/fandisk.off", []),
        ("valid/fertility.off", []),
        ("valid/hinge.stl", []),
        ("valid/plate_holes.STL", []),
        ("valid/round.stl", []),
        ("valid/skull.obj", []),
        ("valid/spot.obj", []),
        ("dirty/angle_block.STL", ["--heal"]),
        ("dirty/idler_riser.STL", ["--heal"]),
        ("@crates/cli/tests/data/needle_frustum.obj", []),
    ],
    # Issue 20's hard surfaces, written by the CLI's hard_surfaces example.
    "hard": [(f"%{n}.obj", []) for n in ["needle_1000", "needle_5000", "schonhardt",
                                          "twisted_square", "squat_tower", "rod", "slot_1e-2",
                                          "slot_1e-3", "boss_1e-4"]]
    + [("%slot_1e-2.obj", ["--size", "0.1"]), ("%slot_1e-3.obj", ["--size", "0.1"]),
       ("%boss_1e-4.obj", ["--size", "0.1"])],
    # The CAD parts under a size finer than their needles (a tenth to a
    # fortieth of their width), where the front leaves thin cracks and,
    # when the cavity fill cannot close them, the region is filled whole.
    "finer": [("valid/1002_tray_bottom.STL", ["--size", "8.875"]),
              ("valid/plate_holes.STL", ["--size", "7.5"]),
              ("valid/hinge.stl", ["--size", "2.5"]),
              ("valid/hinge.stl", ["--size", "1.25"])],
    "bench1e5": [(f"bench/{n}_1e5.stl", []) for n in ["sphere", "torus", "box2holes", "spheres27"]],
    "bench1e6": [(f"bench/{n}_1e6.stl", []) for n in ["sphere", "torus"]],
    # Issue 21's other measure: a uniform size under which parafront makes
    # about as many tets as HXT does by default (864k, 867k); the peers get
    # the same size. The lattice (§2) fills the interior.
    "bench1e6size": [("bench/sphere_1e6.stl", ["--size", "0.037"]),
                     ("bench/torus_1e6.stl", ["--size", "0.032"])],
    # The same on the parallel passes (2 parts), around the lattice; the
    # peers' rows are bench1e6size's.
    "bench1e6parts": [("bench/sphere_1e6.stl", ["--size", "0.037", "--parts", "2"]),
                      ("bench/torus_1e6.stl", ["--size", "0.032", "--parts", "2"])],
    "bench5e6": [(f"bench/{n}_5e6.stl", []) for n in ["sphere"]],
    # Issue 22: the parts on 2 MPI ranks (--mpi R is bench.py's: mpirun -n R
    # --oversubscribe --bind-to none; needs a binary built with --features
    # mpi). The mesh is the threads run's at the same --parts.
    # With the same runs on threads alone beside them.
    "bench1e6mpi": [("bench/box2holes_1e6.stl", ["--parts", "8"]),
                    ("bench/box2holes_1e6.stl", ["--parts", "8", "--mpi", "2"]),
                    ("bench/sphere_1e6.stl", ["--size", "0.037", "--parts", "8"]),
                    ("bench/sphere_1e6.stl", ["--size", "0.037", "--parts", "8", "--mpi", "2"])],
    # Issue 22's memory: the pieces (`--pieces` is bench.py's: -o x.pvtu,
    # merged for meshcheck) of sphere_5e6 at about 5e6 tets, one process
    # beside 4 ranks, at 8 and 32 parts; the notes give each process's peak.
    "bench5e6mem": [("bench/sphere_5e6.stl", ["--size", "0.021", "--parts", p] + m)
                    for p in ["8", "32"] for m in [["--pieces"], ["--pieces", "--mpi", "4"]]],
    # The thin corpus parts whose passes give way at 8 parts: by default
    # (with the peers), merged at 8 parts, and as pieces at 8 parts (the
    # serial front's mesh sent to the parts along a curve).
    "thinpieces": [(f"valid/{n}", m)
                   for n in ["1002_tray_bottom.STL", "base_interface_gmsh.stl", "hinge.stl",
                             "plate_holes.STL", "round.stl"]
                   for m in [[], ["--parts", "8"], ["--parts", "8", "--pieces"]]],
}


def resolve(rel, work):
    if rel.startswith("%"):
        hard = os.path.join(work, "hard")
        if not os.path.exists(os.path.join(hard, rel[1:])):
            subprocess.run(["cargo", "run", "--release", "-q", "-p", "parafront", "--example",
                            "hard_surfaces", "--", hard], cwd=ROOT, check=True,
                           stdout=subprocess.DEVNULL)
        return os.path.join(hard, rel[1:])
    if rel.startswith("@"):
        return os.path.join(ROOT, rel[1:])
    if rel.startswith("bench/"):
        return os.path.join(SHARED, rel)
    return os.path.join(GEOMETRY, rel)


def median(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else None


def parse_summary(out):
    """The numbers of `parafront mesh`'s summary."""
    r = {}
    m = re.search(r"^(\d+) tets, (\d+) points", out, re.M)
    if m:
        r["tets"] = int(m.group(1))
        r["points"] = int(m.group(2))
    m = re.search(r"^seconds: (.*) \(total ([\d.]+), (\d+) threads?\)", out, re.M)
    if m:
        # "name seconds" pairs, comma-separated; names may hold digits
        # ("pass 1 1.771").
        r["stages"] = {}
        for item in m.group(1).split(","):
            k, _, v = item.strip().rpartition(" ")
            r["stages"][k] = float(v)
        r["total"] = float(m.group(2))
    m = re.search(r"^quality: min dihedral ([\d.]+) deg, ([\d.]+)% of tets under 10 deg, "
                  r"mean radius ratio ([\d.]+)", out, re.M)
    if m:
        r["min_dih"] = float(m.group(1))
        r["pct10"] = float(m.group(2))
        r["rr"] = float(m.group(3))
    m = re.search(r"^constrained fill: (\d+) cavit\w+ .*?, (\d+) tets", out, re.M)
    r["fill_cavities"] = int(m.group(1)) if m else 0
    r["fill_tets"] = int(m.group(2)) if m else 0
    m = re.search(r"^peak memory: [\d.]+ MiB \((\d+) bytes/tet\)", out, re.M)
    r["peak_per_tet"] = int(m.group(1)) if m else None
    m = re.search(r"^recovery: (\d+) rounds", out, re.M)
    r["recovery_rounds"] = int(m.group(1)) if m else 0
    r["region_fill"] = "filled whole" in out
    m = re.search(r"^lattice: \d+ tets in \d+ cubes, ([\d.]+)% of the tets", out, re.M)
    r["lattice_pct"] = float(m.group(1)) if m else None
    m = re.search(r"^peak memory: ([\d.]+) MiB", out, re.M)
    r["peak_mib"] = float(m.group(1)) if m else None
    m = re.search(r"^peak memory per process: ([\d., ]+) MiB", out, re.M)
    r["rank_peaks"] = [float(x) for x in m.group(1).split(",")] if m else None
    return r


def run_parafront(binary, surf, extra, threads, out_mesh):
    """One timed run. Its peak memory is the one the summary reports (the
    process's VmHWM): wait4's ru_maxrss would count the Python process the
    child was forked from."""
    cmd = [binary, "mesh", surf, "-o", out_mesh, "--threads", str(threads)] + extra
    if "--pieces" in cmd:
        cmd.remove("--pieces")
    if "--mpi" in extra:
        i = cmd.index("--mpi")
        ranks = cmd[i + 1]
        del cmd[i:i + 2]
        cmd = ["mpirun", "-n", ranks, "--oversubscribe", "--bind-to", "none"] + cmd
    # OpenMPI refuses root (CI, this machine) unless told.
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    t0 = time.perf_counter()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
    wall = time.perf_counter() - t0
    r = parse_summary(p.stdout)
    r["ok"] = p.returncode == 0
    r["wall"] = wall
    r["log"] = p.stdout
    return r


def meshcheck(surf, mesh, healed):
    if mesh.endswith(".pvtu"):
        merged = mesh[:-5] + ".merged.vtu"
        p = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "merge_pvtu.py"), mesh, merged],
                           capture_output=True, text=True)
        if p.returncode != 0:
            return False
        mesh = merged
    cmd = [sys.executable, os.path.join(SHARED, "tools", "meshcheck.py"), "--surface",
           healed or surf, mesh, "--quiet"]
    p = subprocess.run(cmd, capture_output=True, text=True)
    return p.returncode == 0


def run_peers(surf, peers, threads, repeat, jsonl, h="auto", timeout=600):
    if not peers:
        return []
    script = os.path.join(SHARED, "tools", "peers", "peer_mesh.py")
    rows = []
    for _ in range(repeat):
        if os.path.exists(jsonl):
            os.remove(jsonl)
        cmd = [sys.executable, script, surf, "--peers", ",".join(peers), "--h", h,
               "--threads", ",".join(map(str, threads)), "--jsonl", jsonl, "--timeout", str(timeout)]
        # In the scratch folder: TetGen leaves files in its working folder.
        p = subprocess.run(cmd, capture_output=True, text=True, cwd=os.path.dirname(jsonl))
        if os.path.exists(jsonl):
            with open(jsonl) as f:
                rows += [json.loads(line) for line in f if line.strip()]
        else:
            # peer_mesh.py itself failed (e.g. meshio cannot read the file).
            why = (p.stderr.strip().splitlines() or ["no output"])[-1][:120]
            return [{"peer": "peers", "threads": "", "status": "peer_mesh.py failed: " + why}]
    return rows


def fmt(x, spec):
    return "" if x is None else format(x, spec)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sets", default="corpus,bench1e6", help=f"comma list of {','.join(SETS)}")
    ap.add_argument("--only", default="", help="comma list of substrings: inputs to run")
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--peers", default="gmsh-hxt,tetgen,netgen",
                    help="peer_mesh.py names, or none")
    ap.add_argument("--peer-repeat", type=int, default=1)
    ap.add_argument("--peer-timeout", type=int, default=600,
                    help="seconds a peer gets per input and thread count (then: fails: timeout)")
    ap.add_argument("--binary", default=os.path.join(ROOT, "target", "release", "parafront"))
    ap.add_argument("--out", default=os.path.join(ROOT, "BENCHMARKS.md"))
    ap.add_argument("--append", action="store_true",
                    help="add the sets' sections (with their own sitting line) to --out")
    a = ap.parse_args()
    threads = [int(t) for t in a.threads.split(",")]
    peers = [] if a.peers == "none" else a.peers.split(",")
    if not os.path.exists(a.binary):
        subprocess.run(["cargo", "build", "--release", "-p", "parafront"], cwd=ROOT, check=True)
    work = tempfile.mkdtemp(prefix="pf-bench-")
    started = datetime.datetime.now().strftime("%Y-%m-%d %H:%M")
    sections = []
    for set_name in a.sets.split(","):
        rows = []
        stage_rows = []
        for rel, extra in SETS[set_name]:
            if a.only and not any(o in rel for o in a.only.split(",")):
                continue
            surf = resolve(rel, work)
            if not os.path.exists(surf):
                print(f"skip {rel}: not found", file=sys.stderr)
                continue
            name = os.path.basename(surf)
            mesh = os.path.join(work, name + (".pvtu" if "--pieces" in extra else ".vtu"))
            if "--size" in extra:
                name += " --size " + extra[extra.index("--size") + 1]
            if "--parts" in extra:
                name += " --parts " + extra[extra.index("--parts") + 1]
            ranks = 1
            if "--pieces" in extra:
                name += " -o .pvtu"
            if "--mpi" in extra:
                ranks = int(extra[extra.index("--mpi") + 1])
                name += f" on {ranks} ranks"
            healed = None
            if "--heal" in extra:
                healed = os.path.join(work, name + ".healed.stl")
                extra = extra + ["--healed-surface", healed]
            for t in threads:
                runs = [run_parafront(a.binary, surf, extra, t, mesh) for _ in range(a.repeat)]
                last = runs[-1]
                if not last["ok"]:
                    msg = last["log"].strip().splitlines()[-1] if last["log"].strip() else "failed"
                    rows.append([name, "parafront", t, "fails: " + msg.replace("|", "/")])
                    print(f"{name} parafront {t}: {msg}", file=sys.stderr)
                    continue
                valid = meshcheck(surf, mesh, healed)
                wall = median([r["wall"] for r in runs])
                tets = last.get("tets", 0)
                # Per core: every rank runs t threads.
                rows.append([name, "parafront", t, tets, wall,
                             tets / wall / (t * ranks) if wall else None,
                             median([r["peak_per_tet"] for r in runs]), last.get("min_dih"),
                             last.get("pct10"), last.get("rr"),
                             "yes" if valid else "NO",
                             f"{last['fill_cavities']} / {last['fill_tets']}"
                             + (" (region)" if last["region_fill"] else "")
                             + (f"; lattice {last['lattice_pct']:.0f} %"
                                if last["lattice_pct"] is not None else "")
                             + (f"; peak per process {min(last['rank_peaks']):.1f}-"
                                f"{max(last['rank_peaks']):.1f} MiB"
                                if last["rank_peaks"] else
                                f"; peak {last['peak_mib']:.1f} MiB" if "--pieces" in extra
                                and last["peak_mib"] is not None else "")])
                stages = {}
                for r in runs:
                    for k, v in r.get("stages", {}).items():
                        stages.setdefault(k, []).append(v)
                stage_rows.append((name, t, {k: median(v) for k, v in stages.items()}))
                print(f"{name} parafront {t}: {tets} tets {wall:.2f} s valid={valid}", file=sys.stderr)
            if "--parts" in extra:
                continue  # the peers have no parts: their rows are the serial set's
            # Peers mesh what parafront meshed: the healed surface for dirty/.
            peer_surf = healed if healed and os.path.exists(healed) else surf
            h = extra[extra.index("--size") + 1] if "--size" in extra else "auto"
            for r in run_peers(peer_surf, peers, threads, a.peer_repeat, os.path.join(work, "peers.jsonl"), h,
                               a.peer_timeout):
                if r.get("status") != "ok":
                    rows.append([name, r["peer"], r["threads"], "fails: " + str(r.get("status"))])
                    continue
                rows.append([name, r["peer"], r["threads"], r["tets"], r["t_mesh"],
                             r["tets_per_s_per_thread"], r.get("peak_bytes_per_tet"),
                             r["min_dihedral"], 100 * r["frac_min_dih_lt10"], r["radius_ratio_mean"],
                             "kept" if r.get("surface_preserved") else "NOT kept", ""])
        sections.append((set_name, merge_repeats(rows), stage_rows))
    write(a, sections, started, threads, peers)
    print(f"wrote {a.out}", file=sys.stderr)


def merge_repeats(rows):
    """Peer rows repeated over --peer-repeat: one row each, medians of time and rate."""
    groups = {}
    for i, r in enumerate(rows):
        # Only the peers' measured rows repeat; the rest stay as they are.
        key = tuple(r[:3]) if r[1] != "parafront" and not isinstance(r[3], str) else i
        groups.setdefault(key, []).append(r)
    merged = []
    for g in groups.values():
        m = list(g[0])
        if len(g) > 1:
            m[4] = median([x[4] for x in g])
            m[5] = median([x[5] for x in g])
        merged.append(m)
    return merged


def write(a, sections, started, threads, peers):
    try:
        rev = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                             text=True).stdout.strip()
    except OSError:
        rev = "?"
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next((l.split(":", 1)[1].strip() for l in f if l.startswith("model name")), cpu)
    except OSError:
        pass
    L = []
    if a.append:
        L.append(f"## Sitting {started} (commit {rev}): `{command(a)}`\n")
    else:
        header(L, a, started, rev, cpu)
    for name, rows, stage_rows in sections:
        L.append(f"## {name}\n")
        L.append("| input | mesher | threads | tets | s | tets/s/core | peak B/tet | min dih ° | % < 10° "
                 "| mean rr | valid / surface | fill |")
        L.append("|---|---|---|---|---|---|---|---|---|---|---|---|")
        for r in rows:
            if isinstance(r[3], str):
                L.append(f"| {r[0]} | {r[1]} | {r[2]} | {r[3]} | | | | | | | | |")
                continue
            L.append(f"| {r[0]} | {r[1]} | {r[2]} | {r[3]:,} | {fmt(r[4], '.2f')} | {fmt(r[5], ',.0f')} "
                     f"| {fmt(r[6], ',.0f')} | {fmt(r[7], '.2f')} | {fmt(r[8], '.1f')} | {fmt(r[9], '.3f')} "
                     f"| {r[10]} | {r[11]} |")
        # Ratios to the peers, per input and thread count.
        L.append("")
        ratio_lines = []
        by = {}
        for r in rows:
            if not isinstance(r[3], str):
                by[(r[0], r[1], r[2])] = r
        for (inp, mesher, t), r in by.items():
            if mesher != "parafront":
                continue
            parts = []
            for p in peers:
                q = by.get((inp, p, t)) or by.get((inp, p, 1))
                if q and q[4] and r[4]:
                    parts.append(f"{p} {r[4] / q[4]:.1f}x its time")
            if parts:
                ratio_lines.append(f"- {inp}, {t} thread(s): parafront takes " + ", ".join(parts))
        if ratio_lines:
            L.append("Whole run over the peer's meshing call:\n")
            L += ratio_lines
            L.append("")
        if stage_rows:
            keys = []
            for _, _, st in stage_rows:
                for k in st:
                    if k not in keys:
                        keys.append(k)
            L.append("parafront's stages (seconds, medians):\n")
            L.append("| input | threads | " + " | ".join(keys) + " |")
            L.append("|---|---|" + "---|" * len(keys))
            for inp, t, st in stage_rows:
                L.append(f"| {inp} | {t} | " + " | ".join(fmt(st.get(k), '.3f') for k in keys) + " |")
            L.append("")
    with open(a.out, "a" if a.append else "w") as f:
        f.write(("\n" if a.append else "") + "\n".join(L) + "\n")


def command(a):
    """The options of this sitting, as a command line (the header's and an appended section's)."""
    return (f"scripts/bench.py --sets {a.sets}{' --only ' + a.only if a.only else ''} "
            f"--threads {a.threads} --repeat {a.repeat} --peers {a.peers or 'none'}"
            f"{' --peer-timeout ' + str(a.peer_timeout) if a.peer_timeout != 600 else ''}")


def header(L, a, started, rev, cpu):
    L.append("# Benchmarks\n")
    L.append("Written by `scripts/bench.py`; do not edit by hand. To reproduce:\n")
    L.append("```\ncargo build --release -p parafront\npip install numpy meshio gmsh tetgen netgen-mesher\n"
             f"python3 {command(a)}\n```\n")
    L.append(f"Sitting: {started}, commit {rev}, {os.cpu_count()} cores ({cpu}).\n")
    L.append("- **parafront**: the whole `parafront mesh` run as a user times it (default options, "
             "`--threads` as given; read, size field, front, improvement, check, quality, write), "
             f"median of {a.repeat}. Peak B/tet: the process's peak RSS (VmHWM, as its summary "
             "prints it) over the tets.")
    L.append("- **Peers** (`../shared/tools/peers/peer_mesh.py --h auto`, each keeping the surface): "
             "their meshing call, with their own optimisation. Peak B/tet includes the Python process.")
    L.append("- tets/s/core: tets over seconds over threads (over ranks x threads on MPI rows). Quality as meshcheck computes it: "
             "worst min dihedral, share of tets with a dihedral under 10°, mean radius ratio.")
    L.append("- valid: `meshcheck.py --surface` on parafront's mesh (against the healed surface "
             "for dirty/ inputs). fill: cavities closed by the constrained fill / its tets "
             "(region: a region filled whole), and the lattice's share of the tets (§2's "
             "optimal space-filling tets) where it ran. Peers mesh the healed surface of dirty/ inputs, "
             "and take `--h` from an input's `--size` where it has one.\n")


if __name__ == "__main__":
    main()
