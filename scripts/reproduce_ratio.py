#!/usr/bin/env python3
"""Issue 15, goal 3: how close a full `reproduce` comes to the time the bench predicts.

    python3 scripts/reproduce_ratio.py [--runs N] [--repeats R] BINARY [BINARY ...]

The prediction is the sum over the experiments of their point-samples (each experiment's
`summary.json`, `point_samples_emulated`; the bandwidth sweep's are the closing line's total
less theirs) divided by the bench's `whole chain` rate of the experiment's preset on all
threads, in the lanes a run of that chain uses on this CPU (the row without a lane type; the
best of R runs; the bandwidth sweep at the rate-table chain's rate). The bench is run before and after the `reproduce` runs, and the prediction is
their mean: a shared host's speed moves by 10 % or more within minutes. The binaries'
`reproduce` runs alternate (N each), and each is reported as prediction / wall time, at the
median and at the best run, with the median CPU time of its runs (user + system, from the
children's resource usage): steadier than the wall time between two binaries, it resolves
changes of about 1 % that the wall time's spread hides. The first binary is benched; give the
same CPU's binaries only.

A second figure divides CPU time, not wall time: the point-samples at the bench's one-thread
rates (the same bench's rows on one thread) against each binary's median CPU time. It is the
share of the run's CPU that its sample loops would take at the bench's speed. It does not
depend on the two-thread bench, which reads low when the host slows one vCPU and not the other
(the wall-time figure then reads high); like the wall-time figure, it moves with the host's
speed during the runs.
"""

import argparse
import json
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

# The experiments of `reproduce`: each runs its preset's chain and writes `<preset>/`.
PRESETS = ["m2tfg-rotating", "baw-rotating", "m2tfg-ratetable", "m2tfg-coriolis", "baw-coriolis"]


def bench(binary: str, repeats: int) -> tuple:
    """The best `whole chain` rate of each preset on all threads and on one, point-samples/s,
    and the bench's line naming the CPU."""
    rates, ones, cpu = {}, {}, "cpu: not named by this binary"
    for preset in PRESETS:
        done = subprocess.run(
            [binary, "bench", "--preset", preset, "--repeats", str(repeats)],
            check=True, capture_output=True, text=True,
        )
        out = done.stdout
        cpu = next((l for l in done.stderr.splitlines() if l.startswith("cpu: ")), cpu)
        # The row without a lane type is the chain in the lanes a run of it uses on this CPU
        # (eight, or four where they run faster: `gyroemu_board::max_lanes_for`).
        rows = [line.split() for line in out.splitlines()
                if re.match(r"whole chain +\d", line)]
        # On the most threads, and on one.
        if not rows:
            sys.exit(f"{binary} bench --preset {preset} printed no `whole chain` row")
        best = max(rows, key=lambda r: int(r[-3]))
        rates[preset] = float(best[-2]) * 1e6
        one = min(rows, key=lambda r: int(r[-3]))
        ones[preset] = float(one[-2]) * 1e6
    return rates, ones, cpu


def children_cpu() -> float:
    """User and system seconds of the children waited for so far."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_reproduce(binary: str, out: Path) -> tuple:
    """Wall seconds, the closing line's point-samples and CPU seconds of one full
    `reproduce`."""
    shutil.rmtree(out, ignore_errors=True)
    cpu = children_cpu()
    t = time.perf_counter()
    done = subprocess.run([binary, "reproduce", "--out", str(out)],
                          check=True, capture_output=True, text=True)
    wall = time.perf_counter() - t
    m = re.search(r"reproduce: (\d+) point-samples", done.stdout + done.stderr)
    if m is None:
        sys.exit(f"{binary} reproduce printed no closing line with its point-samples")
    return wall, int(m.group(1)), children_cpu() - cpu


def point_samples(out: Path, total: int) -> dict:
    """Each preset's point-samples, and the bandwidth sweep's (the total less theirs)."""
    per = {}
    for preset in PRESETS:
        per[preset] = json.loads((out / preset / "summary.json").read_text())[
            "point_samples_emulated"]
    per["bandwidth"] = total - sum(per.values())
    return per


def predict(samples: dict, rates: dict) -> float:
    t = sum(n / rates[p] for p, n in samples.items() if p != "bandwidth")
    return t + samples["bandwidth"] / rates["m2tfg-ratetable"]


def check_args(ap: argparse.ArgumentParser, a: argparse.Namespace) -> None:
    """Refuses, before anything runs, what would end in a traceback or an empty median."""
    for name in ("runs", "repeats"):
        if getattr(a, name) < 1:
            ap.error(f"--{name} {getattr(a, name)}: must be at least 1")
    for b in a.binaries:
        # A bare name is looked up on PATH, as the runs will.
        if shutil.which(b) is None:
            ap.error(f"binary {b!r}: not an executable file (nor a command on PATH)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("binaries", nargs="+")
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--repeats", type=int, default=3)
    a = ap.parse_args()
    check_args(ap, a)
    tmp = Path(tempfile.mkdtemp(prefix="reproduce_ratio_"))
    try:
        measure(a, tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def measure(a: argparse.Namespace, tmp: Path) -> None:
    """Runs the benches and the alternating `reproduce` runs in `tmp`, and prints the figures."""
    _, total, _ = run_reproduce(a.binaries[0], tmp / "first")
    samples = point_samples(tmp / "first", total)
    before, before1, cpu = bench(a.binaries[0], a.repeats)
    walls = {b: [] for b in a.binaries}
    cpus = {b: [] for b in a.binaries}
    for _ in range(a.runs):
        for b in a.binaries:
            wall, _, cpu_s = run_reproduce(b, tmp / "run")
            walls[b].append(wall)
            cpus[b].append(cpu_s)
    after, after1, _ = bench(a.binaries[0], a.repeats)
    p = [predict(samples, r) for r in (before, after)]
    pred = statistics.mean(p)
    p1 = [predict(samples, r) for r in (before1, after1)]
    pred1 = statistics.mean(p1)
    print(cpu)
    print("point-samples:", {k: f"{v:.4g}" for k, v in samples.items()})
    for name, r in (("before", before), ("after", after)):
        print(f"bench {name} (M point-samples/s):",
              {k: round(v / 1e6, 1) for k, v in r.items()})
    print(f"prediction {p[0]:.3f} s before, {p[1]:.3f} s after: {pred:.3f} s; "
          f"80 % asks {pred / 0.8:.3f} s")
    for name, r in (("before", before1), ("after", after1)):
        print(f"bench {name}, one thread (M point-samples/s):",
              {k: round(v / 1e6, 1) for k, v in r.items()})
    print(f"the loops' CPU at the one-thread rates: {p1[0]:.3f} s before, {p1[1]:.3f} s after: "
          f"{pred1:.3f} CPU-s")
    for b, w in walls.items():
        w.sort()
        med = statistics.median(w)
        print(f"{b}: wall {w[0]:.2f} to {w[-1]:.2f} s, median {med:.2f} (n={len(w)}): "
              f"{100 * pred / med:.0f} % at the median, {100 * pred / w[0]:.0f} % at the best; "
              f"CPU median {statistics.median(cpus[b]):.3f} s, "
              f"{100 * pred1 / statistics.median(cpus[b]):.0f} % of it the loops at the bench's "
              f"one-thread rates")


if __name__ == "__main__":
    try:
        sys.exit(main())
    except subprocess.CalledProcessError as e:
        # A failed run gives no figure: say which command failed and what it printed.
        sys.exit(f"{' '.join(e.cmd)} exited with {e.returncode}:\n{e.stderr}")
