#!/usr/bin/python3
"""tools/track_breakdown.py against tracks whose error source is known.

A reference walk (an L: 100 steps of 0.6 m north, then 100 east) and three estimates of it:
steps 20 % long in the right directions, steps of the right length turned 5 deg clockwise, and
both. The rebuilt tracks must remove exactly the error the oracle knows about:
  long steps   -> length ratio 1.2, no error left with the true lengths, all of it with the true headings;
  turned steps -> ratio 1.0, all of the error left with the true lengths, none with the true headings.
Tolerance 1e-6 % (pure arithmetic). Exit 1 on the first failure.
"""
import csv
import math
import os
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
from track_breakdown import dr_breakdown  # noqa: E402


def write_track(path, scale, turn_deg):
    ref = [(0.0, 0.0)]
    for k in range(200):
        de, dn = (0.0, 0.6) if k < 100 else (0.6, 0.0)
        ref.append((ref[-1][0] + de, ref[-1][1] + dn))
    est = [(0.0, 0.0)]
    c, s = math.cos(math.radians(turn_deg)), math.sin(math.radians(turn_deg))
    for k in range(200):
        de, dn = ref[k + 1][0] - ref[k][0], ref[k + 1][1] - ref[k][1]
        de, dn = scale * (c * de + s * dn), scale * (-s * de + c * dn)  # clockwise in (east, north)
        est.append((est[-1][0] + de, est[-1][1] + dn))
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t_ns", "e_m", "n_m", "err_e_m", "err_n_m"])
        for k, (p, r) in enumerate(zip(est, ref)):
            w.writerow([k, p[0], p[1], p[0] - r[0], p[1] - r[1]])


def main():
    failures = []

    def near(what, got, want, tol=1e-6):
        if not abs(got - want) <= tol:
            failures.append(f"{what}: {got} (expected {want} +- {tol})")

    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "track.csv")
        write_track(path, 1.2, 0.0)
        b = dr_breakdown(path)
        near("long steps: length ratio", b["length_ratio"], 1.2)
        near("long steps: DRMS with the true lengths", b["drms_pct_true_lengths"], 0.0)
        near("long steps: DRMS with the true headings", b["drms_pct_true_headings"], b["drms_pct"])
        if not b["drms_pct"] > 5.0:
            failures.append(f"long steps: DRMS {b['drms_pct']} % should be well above 0")
        write_track(path, 1.0, 5.0)
        b = dr_breakdown(path)
        near("turned steps: length ratio", b["length_ratio"], 1.0)
        near("turned steps: DRMS with the true lengths", b["drms_pct_true_lengths"], b["drms_pct"])
        near("turned steps: DRMS with the true headings", b["drms_pct_true_headings"], 0.0)
        write_track(path, 1.2, 5.0)
        b = dr_breakdown(path)
        if not (0.0 < b["drms_pct_true_lengths"] < b["drms_pct"] and 0.0 < b["drms_pct_true_headings"] < b["drms_pct"]):
            failures.append(f"both: each oracle should remove part of the error: {b}")
        with open(path, "w") as f:
            f.write("t_ns,e_m,n_m\n0,0,0\n")
        try:
            dr_breakdown(path)
            failures.append("a track without a reference was accepted")
        except ValueError as e:
            if "fewer than 3 rows" not in str(e):
                failures.append(f"unexpected error text: {e}")
    for f in failures:
        print("FAIL", f)
    print("track_breakdown:", "ok" if not failures else f"{len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
