#!/usr/bin/env python3
"""Runs the gyroemu binary on preset configs with one key changed, to find panics and hangs.

    python3 scripts/fuzz_keys.py [--seed S] [--runs N] [--timeout T] [--optional] BINARY

Each run takes one preset (`gyroemu config --preset NAME`), changes one key (a key the preset
sets: replaced by an odd value or removed; with --optional, a key the user guide's section 3
lists that the preset leaves out, added with an odd value; with --pairs, one of each), shortens the averaging so an
accepted config runs in seconds, and runs the preset's command (`run`, `selfcal`, `sweep`,
`montecarlo`) on one thread. It reports the runs that panicked or died by a signal (their
configs kept in --keep), and those still running after --timeout seconds, which deserve a
look: a plan line that promises seconds for a run of hours is a wrong number too (a
`pll.lock_s` of 2^40 s was found this way). Refusals (exit 2) and accepted runs count as
passes. Not part of CI: seeded, but each run takes up to --timeout seconds.
"""

import argparse
import json
import math
import os
import random
import re
import shutil
import subprocess
import tempfile
import tomllib
from pathlib import Path

COMMANDS = {"m2tfg-selfcal": "selfcal", "m2tfg-sweep": "sweep", "m2tfg-montecarlo": "montecarlo"}
ODD = [0, -1, 0.0, -0.0, 1e-300, 1e300, 1e20, -1e20, float("nan"), float("inf"), float("-inf"),
       0.5, 3, 2**40, "x", [], True, [1e300], [float("nan")], [0.0], [-1.0]]
PLAUSIBLE = [1e-3, 0.01, 2, 16, 24, 1, 1e-9, 1e-15, 300.0, "hann", "sinusoid", "coriolis",
             "rotating", "log", "linear", "normal", "uniform", ["drive", "tia"], ["nope"],
             [100.0], [25.0]]


def toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return json.dumps(v)
    return "[" + ", ".join(toml_value(x) for x in v) + "]"


def toml_text(d: dict) -> str:
    lines = [f"{k} = {toml_value(v)}" for k, v in d.items() if not isinstance(v, dict)]
    for sec, kv in d.items():
        if isinstance(kv, dict):
            lines.append(f"[{sec}]")
            lines += [f"{k} = {toml_value(v)}" for k, v in kv.items()]
    return "\n".join(lines) + "\n"


def shorten(d: dict, cmd: str) -> None:
    """Seconds, not minutes, for an accepted config (keys the change did not touch)."""
    e = d.get("experiment")
    if isinstance(e, dict) and cmd in ("run", "selfcal"):
        if isinstance(e.get("average_s"), (int, float)):
            e["average_s"] = min(e["average_s"], 0.05)
        if isinstance(e.get("rates_dps"), list) and len(e["rates_dps"]) > 2:
            e["rates_dps"] = e["rates_dps"][:2]
    sc = d.get("selfcal")
    if isinstance(sc, dict):
        for k, v in (("allan_record_s", 2.0), ("tau_max_s", 1.0)):
            if isinstance(sc.get(k), (int, float)) and sc[k] > v:
                sc[k] = v
        if isinstance(sc.get("drift_delta_t_k"), list):
            sc["drift_delta_t_k"] = sc["drift_delta_t_k"][:2]


def guide_keys(guide: Path) -> list:
    """(section, key) of every row of the user guide's section 3 tables."""
    keys, sec = [], None
    text = guide.read_text().split("## 4.")[0]
    for line in text.splitlines():
        m = re.match(r"^### \[(\w+)\]", line)
        if m:
            sec = m.group(1)
        m = re.match(r"^\| `([a-z0-9_]+)` \|", line)
        if m and sec:
            keys.append((sec, m.group(1)))
    return keys


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("binary")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--runs", type=int, default=400)
    ap.add_argument("--timeout", type=float, default=20.0)
    ap.add_argument("--optional", action="store_true")
    ap.add_argument("--pairs", action="store_true",
                    help="two changes per run: a set key and an optional one")
    ap.add_argument("--keep", default="fuzz-keys-found")
    a = ap.parse_args()
    names = [line.split()[0] for line in subprocess.run(
        [a.binary, "config", "--list"], check=True, capture_output=True, text=True).stdout.splitlines()]
    presets = {n: subprocess.run([a.binary, "config", "--preset", n], check=True,
                                 capture_output=True, text=True).stdout for n in names}
    guide = Path(__file__).resolve().parent.parent / "docs" / "user-guide.md"
    rng = random.Random(a.seed)
    jobs = []
    for name, text in presets.items():
        base = tomllib.loads(text)
        optional = [(name, sec, key, v) for sec, key in guide_keys(guide)
                    if key not in base.get(sec, {}) for v in ODD + PLAUSIBLE]
        present = [(name, sec, k, v) for sec, kv in base.items() if isinstance(kv, dict)
                   for k in kv for v in ODD + [None]]
        if a.pairs:
            jobs += [(p, rng.choice(optional)) for p in present]
        else:
            jobs += [(j, None) for j in (optional if a.optional else present)]
    rng.shuffle(jobs)
    found, slow, passed = [], [], 0
    with tempfile.TemporaryDirectory() as tmp:
        for first, second in jobs[: a.runs]:
            name = first[0]
            d = tomllib.loads(presets[name])
            changes = []
            for _, sec, key, value in [c for c in (first, second) if c]:
                if value is None:
                    d[sec].pop(key, None)
                else:
                    d.setdefault(sec, {})[key] = value
                changes.append(f"{sec}.{key} = {'(removed)' if value is None else toml_value(value)}")
            cmd = COMMANDS.get(name, "run")
            shorten(d, cmd)
            cfg, out = Path(tmp, "c.toml"), Path(tmp, "out")
            shutil.rmtree(out, ignore_errors=True)
            cfg.write_text(toml_text(d))
            what = f"{name}: {', '.join(changes)}"
            try:
                r = subprocess.run([a.binary, "--threads", "1", cmd, str(cfg), "--out", str(out)],
                                   capture_output=True, text=True, timeout=a.timeout)
            except subprocess.TimeoutExpired:
                slow.append(what)
                continue
            said = r.stdout + r.stderr
            if r.returncode < 0 or "panicked" in said:
                os.makedirs(a.keep, exist_ok=True)
                shutil.copy(cfg, Path(a.keep, f"found-{len(found)}.toml"))
                found.append(f"{what}: exit {r.returncode}: {said[-300:]}")
            else:
                passed += 1
    print(f"{passed} refused or ran, {len(found)} panicked or died, {len(slow)} still running "
          f"after {a.timeout} s")
    for line in found:
        print("FOUND", line)
    for line in slow:
        print("SLOW", line)


if __name__ == "__main__":
    main()
