#!/usr/bin/python3
"""Runs `pdnav eval-terrain` and checks the issue-5 bar on its last line.

  check_eval_bar.py PDNAV DEM [extra eval-terrain args...]

Bar: median PF/DR DRMS ratio X <= 0.35 and 1-sigma coverage 0.55 <= Y <= 0.80, all finite.
"""
import math
import re
import subprocess
import sys


def main(argv):
    pdnav, dem = argv[1], argv[2]
    cmd = [pdnav, "eval-terrain", "--dem", dem, "--walks", "20", "--seed", "1", "--particles", "500", *argv[3:]]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    sys.stdout.write(proc.stdout)
    sys.stderr.write(proc.stderr)
    if proc.returncode != 0:
        print(f"FAIL: {' '.join(cmd)} exited with {proc.returncode}")
        return 1
    lines = [l for l in proc.stdout.splitlines() if l.strip()]
    m = re.fullmatch(r"median_ratio: (\S+) coverage: (\S+)", lines[-1].strip()) if lines else None
    if not m:
        print(f"FAIL: last line is not 'median_ratio: X coverage: Y': {lines[-1] if lines else '(no output)'}")
        return 1
    x, y = float(m.group(1)), float(m.group(2))
    rows = [l for l in lines if re.match(r"^\s*\d+\s", l)]
    ok = math.isfinite(x) and math.isfinite(y) and x <= 0.35 and 0.55 <= y <= 0.80 and len(rows) == 20
    ok = ok and "nan" not in proc.stdout.lower()
    print(f"{'PASS' if ok else 'FAIL'}: median_ratio {x} (bar <= 0.35), coverage {y} (bar 0.55..0.80), "
          f"{len(rows)} walks")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
