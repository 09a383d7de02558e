#!/usr/bin/python3
"""Run `pdnav eval-route ...` and assert the issue-6 bar on its output.

The last line must be `median_turn_error_m: X p95_turn_error_m: Y gnss_median_error_m: Z`
and a line before it `overall_median_error_m: M ...`. Bar: X <= --max-median-turn,
Y <= --max-p95-turn, Z / M >= --min-gnss-ratio.

usage: check_eval_route.py --max-median-turn 3 --max-p95-turn 10 --min-gnss-ratio 2 -- CMD...
"""
import argparse
import re
import subprocess
import sys


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--max-median-turn", type=float, required=True)
    ap.add_argument("--max-p95-turn", type=float, required=True)
    ap.add_argument("--min-gnss-ratio", type=float, required=True)
    ap.add_argument("cmd", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    cmd = a.cmd[1:] if a.cmd and a.cmd[0] == "--" else a.cmd
    r = subprocess.run(cmd, capture_output=True, text=True)
    sys.stdout.write(r.stdout)
    sys.stderr.write(r.stderr)
    if r.returncode != 0:
        print(f"FAIL: command exited with {r.returncode}")
        return 1
    lines = [l for l in r.stdout.splitlines() if l.strip()]
    last = re.fullmatch(r"median_turn_error_m: ([0-9.]+) p95_turn_error_m: ([0-9.]+) "
                        r"gnss_median_error_m: ([0-9.]+)", lines[-1].strip()) if lines else None
    overall = None
    for l in lines:
        m = re.match(r"overall_median_error_m: ([0-9.]+)", l)
        if m:
            overall = float(m.group(1))
    if not last or overall is None:
        print("FAIL: output lacks the overall_median_error_m line or the final bar line")
        return 1
    med, p95, gnss = (float(x) for x in last.groups())
    ok = True
    for name, good, text in [
        ("median turn error", med <= a.max_median_turn, f"{med:.2f} m <= {a.max_median_turn} m"),
        ("p95 turn error", p95 <= a.max_p95_turn, f"{p95:.2f} m <= {a.max_p95_turn} m"),
        ("overall vs GNSS", overall > 0 and gnss / overall >= a.min_gnss_ratio,
         f"GNSS median {gnss:.2f} m / overall median {overall:.2f} m = "
         f"{gnss / overall if overall > 0 else float('inf'):.2f} >= {a.min_gnss_ratio}"),
    ]:
        print(("PASS" if good else "FAIL") + f": {name}: {text}")
        ok = ok and good
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
