#!/usr/bin/env python3
"""Check every SigMF recording (*.sigmf-meta + *.sigmf-data) in a folder.

Optional tool, not run in CI. For each recording:
  1. validates it with the `sigmf` package when importable (schema + checksum);
  2. loads the samples with numpy: np.fromfile(data, dtype='<f8').reshape(-1, n_channels);
  3. recomputes the SHA-512 of the data file and compares it with `core:sha512`;
  4. checks that the sigmf package's own view `rec[:]` equals the numpy array bit for bit.
Note: sigmf's `read_samples()` always returns float32 (sigmf 1.14); use `rec[:]` or numpy for
full f64 precision.
Prints OK/FAIL per file and exits 1 on any failure.

    python3 scripts/check_sigmf.py out/some_run
    (pip install --user sigmf numpy)
"""

import argparse
import hashlib
import json
import sys
from pathlib import Path

import numpy as np

try:
    from sigmf import sigmffile

    try:
        from sigmf import __version__ as SIGMF_VERSION
    except ImportError:
        SIGMF_VERSION = "unknown"
except ImportError:
    sigmffile = None
    SIGMF_VERSION = None

# SigMF real datatypes this project may write, as numpy dtypes.
DTYPES = {"rf64_le": "<f8", "rf32_le": "<f4", "cf64_le": "<c16", "cf32_le": "<c8"}


def sha512_of(path):
    h = hashlib.sha512()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def check(meta_path):
    """Returns a list of problems (empty when the recording is fine) and a summary string."""
    problems = []
    data_path = meta_path.with_suffix(".sigmf-data")
    meta = json.loads(meta_path.read_text())
    g = meta.get("global", {})
    n_ch = int(g.get("core:num_channels", 1))
    datatype = g.get("core:datatype")

    rec = None
    if sigmffile is not None:
        try:
            rec = sigmffile.fromfile(str(meta_path))  # verifies core:sha512 on load
            rec.validate()  # JSON schema of the installed spec version
        except Exception as e:  # noqa: BLE001 - report any validator failure
            problems.append(f"sigmf: {type(e).__name__}: {e}")

    if not data_path.exists():
        return problems + [f"missing {data_path.name}"], ""
    if datatype not in DTYPES:
        return problems + [f"unsupported core:datatype {datatype!r}"], ""
    raw = np.fromfile(data_path, dtype=DTYPES[datatype])
    if n_ch <= 0 or raw.size % n_ch:
        problems.append(f"{raw.size} samples is not a multiple of {n_ch} channels")
        x = raw.reshape(-1, 1)
    else:
        x = raw.reshape(-1, n_ch)

    if rec is not None and x.shape[1] == n_ch and datatype.startswith("rf"):
        view = np.asarray(rec[:]).reshape(x.shape)
        if view.dtype != x.dtype or not np.array_equal(view.view(np.uint8), x.view(np.uint8)):
            problems.append(f"sigmf rec[:] ({view.dtype}) differs from the numpy read")

    names = [c.get("name", "?") for c in g.get("gyroemu:channels", [])]
    if names and len(names) != n_ch:
        problems.append(f"gyroemu:channels has {len(names)} entries, core:num_channels {n_ch}")

    want = g.get("core:sha512")
    got = sha512_of(data_path)
    if want is None:
        problems.append("no core:sha512")
    elif want.lower() != got:
        problems.append(f"sha512 mismatch: meta {want[:16]}..., file {got[:16]}...")

    summary = f"{x.shape[0]} frames x {x.shape[1]} ch @ {g.get('core:sample_rate')} Hz"
    if names:
        summary += " [" + ", ".join(names) + "]"
    return problems, summary


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", type=Path)
    args = ap.parse_args()
    metas = sorted(args.folder.rglob("*.sigmf-meta"))
    if sigmffile is None:
        print("note: the sigmf package is not importable; skipping its validation")
    else:
        print(f"sigmf package {SIGMF_VERSION}")
    if not metas:
        print(f"FAIL no *.sigmf-meta under {args.folder}")
        return 1
    failed = 0
    for m in metas:
        try:
            problems, summary = check(m)
        except Exception as e:  # noqa: BLE001 - one broken file must not stop the scan
            problems, summary = [f"{type(e).__name__}: {e}"], ""
        if problems:
            failed += 1
            print(f"FAIL {m}: " + "; ".join(problems))
        else:
            print(f"OK   {m}: {summary}")
    print(f"{len(metas) - failed}/{len(metas)} recordings OK")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
