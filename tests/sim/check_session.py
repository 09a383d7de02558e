#!/usr/bin/python3
"""`pdnav simulate --session` writes a whole phone session that (1) is reproducible, (2) holds
every line type the phone writes, (3) has no GNSS rows during the scripted outage, (4) gives
GNSS fixes near the truth with `pdnav gnss`, and (5) replays through `pdnav replay`.

  check_session.py PDNAV DEM GRAPH NAV SCRATCH_DIR
"""
import bisect
import csv
import filecmp
import json
import math
import os
import subprocess
import sys


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"FAIL: {' '.join(cmd)} exited {r.returncode}:\n{r.stdout}\n{r.stderr}")
    return r.stdout


def simulate(pdnav, dem, graph, nav, log, seed):
    return run([pdnav, "simulate", "--session", "--dem", dem, "--graph", graph, "--nav", nav, "-o", log,
                "--seed", str(seed), "--lead", "150", "--outage-min", "2", "--outage-max", "2.5", "--tail", "90"])


def quantile(v, p):
    v = sorted(v)
    if not v:
        return float("nan")
    x = p * (len(v) - 1)
    i = int(x)
    return v[i] if i + 1 >= len(v) else v[i] + (x - i) * (v[i + 1] - v[i])


def main(argv):
    pdnav, dem, graph, nav, scratch = argv[1:6]
    os.makedirs(scratch, exist_ok=True)
    a, b = os.path.join(scratch, "session_a.txt"), os.path.join(scratch, "session_b.txt")
    print(simulate(pdnav, dem, graph, nav, a, 3), end="")
    simulate(pdnav, dem, graph, nav, b, 3)
    failures = []
    if not filecmp.cmp(a, b, shallow=False):
        failures.append("same seed gave different session logs")

    with open(a + ".truth.csv") as f:
        truth = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    t_truth = [r["t_ns"] for r in truth]
    out = [r["t_ns"] for r in truth if r["outage"] == 1]
    if not out:
        failures.append("no truth epoch inside the outage")
    counts, raw_in_outage, raw_t_col = {}, 0, None
    with open(a) as f:
        for line in f:
            if line.startswith("# Raw,"):
                raw_t_col = [c.strip() for c in line[2:].split(",")].index("elapsedRealtimeNanos")
            if line.startswith("#") or not line.strip():
                continue
            kind = line.split(",", 2)[0]
            counts[kind] = counts.get(kind, 0) + 1
            if kind == "Raw" and out:
                t = float(line.split(",")[raw_t_col])
                if out[0] <= t <= out[-1]:
                    raw_in_outage += 1
    print("line counts:", counts)
    for kind in ("Meta", "Accel", "Gyro", "RotationVector", "Pressure", "StepDetector", "Raw", "Fix", "Truth"):
        if counts.get(kind, 0) == 0:
            failures.append(f"no {kind} lines in the log")
    if raw_in_outage:
        failures.append(f"{raw_in_outage} Raw rows inside the scripted outage")

    # pdnav gnss on the log: SPP fixes near the truth (interpolated at the epoch time).
    csv_path = os.path.join(scratch, "gnss.csv")
    print(run([pdnav, "gnss", a, "--nav", nav, "--out", csv_path]), end="")
    errs, kf_errs = [], []
    lat0 = math.radians(truth[0]["lat_deg"])
    with open(csv_path) as f:
        for r in csv.DictReader(f):
            t = float(r["t_ns"])
            i = bisect.bisect_left(t_truth, t)
            if i <= 0 or i >= len(truth):
                continue
            p, q = truth[i - 1], truth[i]
            w = (t - p["t_ns"]) / (q["t_ns"] - p["t_ns"])
            lat = p["lat_deg"] + w * (q["lat_deg"] - p["lat_deg"])
            lon = p["lon_deg"] + w * (q["lon_deg"] - p["lon_deg"])
            if q["degraded"] == 1:
                continue
            for key, acc in (("spp", errs), ("kf", kf_errs)):
                if r[f"{key}_ok"] != "1" if key == "spp" else r.get("kf_ok") != "1":
                    continue
                dn = math.radians(float(r[f"{key}_lat_deg"]) - lat) * 6371000.0
                de = math.radians(float(r[f"{key}_lon_deg"]) - lon) * 6371000.0 * math.cos(lat0)
                acc.append(math.hypot(de, dn))
    print(f"gnss vs truth (open sky): SPP n={len(errs)} p50 {quantile(errs, .5):.2f} m p95 {quantile(errs, .95):.2f} m; "
          f"KF n={len(kf_errs)} p50 {quantile(kf_errs, .5):.2f} m p95 {quantile(kf_errs, .95):.2f} m")
    if len(errs) < 100:
        failures.append(f"only {len(errs)} SPP fixes")
    elif not (quantile(errs, .5) < 8.0 and quantile(errs, .95) < 30.0):
        failures.append("SPP fixes not near the truth (want p50 < 8 m, p95 < 30 m)")
    if len(kf_errs) < 100 or not quantile(kf_errs, .5) < 8.0:
        failures.append("KF fixes not near the truth (want >= 100 with p50 < 8 m)")

    # The log replays through the Navigator with every engine.
    out_dir = os.path.join(scratch, "replay")
    print(run([pdnav, "replay", a, "--out", out_dir, "--dem", dem, "--graph", graph, "--nav", nav, "--quiet"]), end="")
    with open(os.path.join(out_dir, "summary.json")) as f:
        summary = json.load(f)
    if summary.get("reference") is None or "errors" not in summary:
        failures.append("replay gave no error statistics against the Truth rows")
    elif not summary["errors"]["drms_m"] < 100.0:
        failures.append(f"replay DRMS {summary['errors']['drms_m']} m")
    pdr = summary.get("pdr", {})
    for key in ("steps", "distance_m", "placements", "steps_refused_handling", "steps_refused_vehicle", "vehicle_spans",
                "handling_spans"):
        if key not in pdr:
            failures.append(f"summary.json pdr has no '{key}'")
    if pdr.get("vehicle_spans"):
        failures.append(f"a simulated walk was classed as riding a vehicle: {pdr['vehicle_spans']}")
    if summary.get("skipped_lines_by_reason"):
        failures.append(f"the reader skipped lines: {summary['skipped_lines_by_reason']}")
    if failures:
        sys.exit("FAIL: " + "; ".join(failures))
    print("ok")


if __name__ == "__main__":
    main(sys.argv)
