#!/usr/bin/python3
"""`pdnav simulate` writes a session log with every expected line type and a truth CSV, and is
reproducible: the same seed gives byte-identical files, another seed a different walk.

  check_simulate.py PDNAV DEM SCRATCH_DIR
"""
import csv
import filecmp
import os
import subprocess
import sys


def simulate(pdnav, dem, log, seed):
    r = subprocess.run([pdnav, "simulate", "--dem", dem, "-o", log, "--seed", str(seed),
                        "--min-length", "1000", "--max-length", "1500"], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"FAIL: simulate exited {r.returncode}: {r.stderr}")
    return r.stdout


def main(argv):
    pdnav, dem, scratch = argv[1:4]
    os.makedirs(scratch, exist_ok=True)
    a, b, c = (os.path.join(scratch, n) for n in ("sim_a.txt", "sim_b.txt", "sim_c.txt"))
    print(simulate(pdnav, dem, a, 5), end="")
    simulate(pdnav, dem, b, 5)
    simulate(pdnav, dem, c, 6)
    failures = []
    if not filecmp.cmp(a, b, shallow=False) or not filecmp.cmp(a + ".truth.csv", b + ".truth.csv", shallow=False):
        failures.append("same seed gave different files")
    if filecmp.cmp(a + ".truth.csv", c + ".truth.csv", shallow=False):
        failures.append("different seeds gave the same walk")
    counts = {}
    with open(a) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            kind = line.split(",", 1)[0]
            counts[kind] = counts.get(kind, 0) + 1
    for kind in ("Meta", "StepDetector", "RotationVector", "Pressure", "Truth"):
        if counts.get(kind, 0) == 0:
            failures.append(f"no {kind} lines in the log (counts {counts})")
    if counts.get("StepDetector") != counts.get("Truth"):
        failures.append(f"one Truth line per step expected: {counts}")
    with open(a + ".truth.csv") as f:
        rows = list(csv.DictReader(f))
    if len(rows) != counts.get("StepDetector", -1):
        failures.append(f"truth CSV has {len(rows)} rows for {counts.get('StepDetector')} steps")
    if rows and not (42.3 < float(rows[0]["lat_deg"]) < 42.8 and 1.3 < float(rows[0]["lon_deg"]) < 1.8):
        failures.append(f"truth outside the Andorra tile: {rows[0]}")
    print("FAIL: " + "; ".join(failures) if failures else f"PASS: line counts {counts}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
