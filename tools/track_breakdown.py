"""Where a dead-reckoning track's error comes from: step lengths or headings.

dr_breakdown(track_csv) reads a `pdnav replay --engine dr` track.csv with a reference (its
err_e_m / err_n_m columns: estimate - reference, one row per step) and returns
  length_ratio            estimated path / reference path
  drms_pct                DRMS of the track, % of the reference path
  drms_pct_true_lengths   the same track rebuilt with the reference's step lengths and the
                          estimate's step directions (what a perfect step length would leave)
  drms_pct_true_headings  rebuilt with the estimate's step lengths along the reference's step
                          directions (what a perfect heading would leave)
All three tracks start at the estimate's first row (the declared start), so the start offset is
in each. Used by tools/whole-walks and tools/demo-table to say why a DR figure misses its bar.
"""
import csv
import math


def dr_breakdown(track_csv):
    est, ref = [], []
    with open(track_csv, newline="") as f:
        for row in csv.DictReader(f):
            try:
                e, n = float(row["e_m"]), float(row["n_m"])
                de, dn = float(row["err_e_m"]), float(row["err_n_m"])
            except (KeyError, ValueError):
                continue
            if all(math.isfinite(v) for v in (e, n, de, dn)):
                est.append((e, n))
                ref.append((e - de, n - dn))
    if len(est) < 3:
        raise ValueError(f"{track_csv}: fewer than 3 rows with a reference")

    def steps(track):
        return [(track[k + 1][0] - track[k][0], track[k + 1][1] - track[k][1]) for k in range(len(track) - 1)]

    est_steps, ref_steps = steps(est), steps(ref)
    ref_path = sum(math.hypot(*s) for s in ref_steps)
    est_path = sum(math.hypot(*s) for s in est_steps)
    if ref_path <= 0:
        raise ValueError(f"{track_csv}: the reference does not move")

    def rebuilt(lengths_from, directions_from):
        e, n = est[0]
        out = [(e, n)]
        for (le, ln), (de, dn) in zip(lengths_from, directions_from):
            d = math.hypot(de, dn)
            if d > 0:
                length = math.hypot(le, ln)
                e, n = e + length * de / d, n + length * dn / d
            out.append((e, n))
        return out

    def drms_pct(track):
        ms = sum((p[0] - r[0]) ** 2 + (p[1] - r[1]) ** 2 for p, r in zip(track, ref)) / len(ref)
        return 100.0 * math.sqrt(ms) / ref_path

    return {
        "length_ratio": est_path / ref_path,
        "drms_pct": drms_pct(est),
        "drms_pct_true_lengths": drms_pct(rebuilt(ref_steps, est_steps)),
        "drms_pct_true_headings": drms_pct(rebuilt(est_steps, ref_steps)),
    }
