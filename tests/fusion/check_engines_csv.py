#!/usr/bin/python3
"""`pdnav replay`'s engines.csv (which engine said what when the fused estimate moved): a
simulated phone session with a scripted GNSS outage, replayed with DEM, walkway graph and
broadcast ephemeris. Checks: (1) the header; (2) one row per running engine at most once per
second of log time, in time order; (3) every engine the session runs is there (dead reckoning,
terrain, route, GNSS); (4) rows carry the reference (the log's truth) and the error against it,
and the error agrees with the track CSV's at the same time for the engine the fused estimate
showed there; (5) the engines' errors are those of working engines: GNSS median <= 10 m while
it has signal, route and terrain median <= 60 m over the whole session.

  check_engines_csv.py PDNAV DEM GRAPH NAV SCRATCH_DIR
"""
import csv
import json
import math
import os
import re
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_eval_outage import run  # noqa: E402  (exits with the command's output on failure)

HEADER = ("t_ns,engine,status,lat_deg,lon_deg,cov_ee_m2,cov_en_m2,cov_nn_m2,semi_major_m,ref_lat_deg,ref_lon_deg,"
          "err_e_m,err_n_m,reason")


def main(argv):
    pdnav, dem, graph, nav, scratch = argv[1:6]
    os.makedirs(scratch, exist_ok=True)
    log = os.path.join(scratch, "session.log")
    run([pdnav, "simulate", "--session", "--dem", dem, "--graph", graph, "--nav", nav, "-o", log, "--seed", "5",
         "--lead", "180", "--outage-min", "3", "--outage-max", "3", "--tail", "120"])
    out = os.path.join(scratch, "out")
    r = run([pdnav, "replay", log, "--dem", dem, "--graph", graph, "--nav", nav, "--out", out, "--quiet"])
    failures = []
    if "engines.csv" not in r.stdout:
        failures.append("replay does not name engines.csv among what it wrote")
    path = os.path.join(out, "engines.csv")
    with open(path) as f:
        header = f.readline().rstrip("\n")
        rows = list(csv.DictReader(f, fieldnames=header.split(",")))
    if header != HEADER:
        failures.append(f"header {header!r}")
    by_engine = {}
    last_t = {}
    prev_t = -1
    for i, row in enumerate(rows, start=2):
        t = int(row["t_ns"])
        if t < prev_t:
            failures.append(f"line {i}: time goes back ({t} < {prev_t})")
        prev_t = t
        eng = row["engine"]
        if eng in last_t and t - last_t[eng] < 1_000_000_000:
            failures.append(f"line {i}: {eng} twice within 1 s")
        last_t[eng] = t
        if row["err_e_m"] == "":
            continue
        err = math.hypot(float(row["err_e_m"]), float(row["err_n_m"]))
        if not math.isfinite(err):
            failures.append(f"line {i}: error not finite")
        by_engine.setdefault(eng, []).append((t, err, row["status"]))
    for eng in ("dead-reckoning", "terrain", "route", "gnss"):
        if len(by_engine.get(eng, [])) < 60:
            failures.append(f"{eng}: {len(by_engine.get(eng, []))} rows with a reference (expected >= 60)")
    # (4) the fused track's row at the same time agrees with the engine row of the engine it showed,
    # when the fused estimate was that engine's own (dead reckoning before GNSS: the first rows)
    with open(os.path.join(out, "track.csv")) as f:
        track = list(csv.DictReader(f))
    t0 = int(track[0]["t_ns"])
    first = [x for x in rows if int(x["t_ns"]) == t0 and x["engine"] == track[0]["engine"]]
    if not first or first[0]["err_e_m"] == "" or track[0]["err_e_m"] == "":
        failures.append(f"no engine row with a reference at the track's first time {t0} ({track[0]['engine']})")
    else:
        d = abs(float(first[0]["err_e_m"]) - float(track[0]["err_e_m"])) + abs(float(first[0]["err_n_m"]) - float(track[0]["err_n_m"]))
        if d > 1e-3:
            failures.append(f"first row: engine error {first[0]['err_e_m']},{first[0]['err_n_m']} vs track {track[0]['err_e_m']},{track[0]['err_n_m']}")
    # (5) replay's median_error_percentile: the median squared Mahalanobis distance of the track's
    # errors in their covariances, as the chi^2(2) percentile, printed and in summary.json
    m2 = []
    for x in track:
        if x["err_e_m"] == "":
            continue
        a, b, c = float(x["cov_ee_m2"]), float(x["cov_en_m2"]), float(x["cov_nn_m2"])
        e, n = float(x["err_e_m"]), float(x["err_n_m"])
        det = a * c - b * b
        m2.append((c * e * e - 2 * b * e * n + a * n * n) / det if det > 0 and a > 0 else math.inf)
    pct = 100.0 * (1.0 - math.exp(-0.5 * statistics.median(m2))) if m2 else math.nan
    with open(os.path.join(out, "summary.json")) as f:
        js = json.load(f)
    printed = re.search(r"^median_error_percentile: (\S+) ", r.stdout, re.M)
    stated = js.get("errors", {}).get("median_percentile")
    if not printed or stated is None or abs(stated - pct) > 0.5 or abs(float(printed.group(1)) - stated) > 0.051:
        failures.append(f"median_error_percentile printed {printed.group(1) if printed else None}, summary.json {stated}, "
                        f"from track.csv {pct:.2f}")
    else:
        print(f"median_error_percentile {stated:.1f} (track.csv: {pct:.1f})")
    summary = {}
    for eng, v in sorted(by_engine.items()):
        ok = [e for _, e, s in v if s in ("ok", "degraded")] or [e for _, e, _ in v]
        summary[eng] = statistics.median(ok)
        print(f"engines.csv {eng}: {len(v)} rows, median error {summary[eng]:.1f} m")
    if summary.get("gnss", 1e9) > 10.0:
        failures.append(f"gnss median error {summary.get('gnss')}")
    for eng in ("route", "terrain"):
        if summary.get(eng, 1e9) > 60.0:
            failures.append(f"{eng} median error {summary.get(eng)}")
    if failures:
        print("FAIL:\n  " + "\n  ".join(failures))
        return 1
    print("engines.csv checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
