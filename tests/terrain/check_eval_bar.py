#!/usr/bin/python3
"""Runs `pdnav eval-terrain` and checks the issue-5 bar on its last line.

  check_eval_bar.py PDNAV DEM [--bar MAX_RATIO,MIN_COV,MAX_COV] [extra eval-terrain args...]

Bar: median PF/DR DRMS ratio X <= 0.35 and 1-sigma coverage 0.55 <= Y <= 0.80 (issue 5; --bar
sets others, e.g. issue 17's per-area 0.45,0.60,0.80), all finite.
"""
import math
import re
import subprocess
import sys


def main(argv):
    pdnav, dem, extra = argv[1], argv[2], argv[3:]
    max_ratio, min_cov, max_cov = 0.35, 0.55, 0.80
    if len(extra) >= 2 and extra[0] == "--bar":
        max_ratio, min_cov, max_cov = (float(v) for v in extra[1].split(","))
        extra = extra[2:]
    cmd = [pdnav, "eval-terrain", "--dem", dem, "--walks", "20", "--seed", "1", "--particles", "500", *extra]
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
    ok = math.isfinite(x) and math.isfinite(y) and x <= max_ratio and min_cov <= y <= max_cov and len(rows) == 20
    ok = ok and "nan" not in proc.stdout.lower()
    print(f"{'PASS' if ok else 'FAIL'}: median_ratio {x} (bar <= {max_ratio}), coverage {y} (bar {min_cov}..{max_cov}), "
          f"{len(rows)} walks")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
