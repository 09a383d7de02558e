#!/usr/bin/python3
"""`pdnav eval-outage` on a simulated phone session with GNSS throughout (issue 28):
(1) the last line is the bar line and the per-walk lines are printed; (2) the window is where
the options put it and the GNSS rows in it were removed; (3) the figures are within bounds on six
sessions pooled (fused beats dead reckoning restarted at the last fix, the fused 68 % region
holds the truth about as often as it says, no jump beyond 3 sigma when GNSS returns); (4) the per-walk CSV
and JSON exist and agree with the printed figures; (5) dead reckoning starts at the last fix;
(6) bad input is a clear error: a log without any reference, a window outside the GNSS span; a
log without GNSS is scored on its reference's span and says so.

  check_eval_outage.py PDNAV DEM GRAPH NAV SCRATCH_DIR
"""
import csv
import json
import math
import os
import re
import subprocess
import sys

BAR = re.compile(r"outage_ratio: (\S+) outage_rms_m: (\S+) coverage_68: (\S+) max_jump_sigma: (\S+) walks: (\d+)")


def run(cmd, ok=True):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if ok and r.returncode != 0:
        sys.exit(f"FAIL: {' '.join(cmd)} exited {r.returncode}:\n{r.stdout}\n{r.stderr}")
    return r


def main(argv):
    pdnav, dem, graph, nav, scratch = argv[1:6]
    os.makedirs(scratch, exist_ok=True)
    log = os.path.join(scratch, "session.log")
    # 8 min of walking with GNSS all the way (no scripted outage), seed fixed
    run([pdnav, "simulate", "--session", "--dem", dem, "--graph", graph, "--nav", nav, "-o", log, "--seed", "11",
         "--lead", "240", "--outage-min", "0", "--outage-max", "0", "--tail", "240"])
    out = os.path.join(scratch, "out")
    # the simulated phone is chest-mounted (the app's mount), declared here; `--mount auto` (the
    # PDR's placement estimate from the gait) must find the same walking direction (below)
    r = run([pdnav, "eval-outage", log, "--nav", nav, "--dem", dem, "--graph", graph, "--out", out, "--mount", "chest",
             "--start-frac", "0.4", "--length-frac", "0.4", "--max-s", "300"])
    print(r.stdout, end="")
    failures = []
    lines = r.stdout.rstrip("\n").split("\n")
    m = BAR.fullmatch(lines[-1])
    if not m:
        sys.exit(f"FAIL: last line is not the bar line: {lines[-1]!r}")
    ratio, rms, cov, _jump = (float(x) for x in m.groups()[:4])
    walks = int(m.group(5))
    if walks != 1:
        failures.append(f"walks {walks} != 1")
    if "eval-outage" not in r.stderr:
        failures.append("no progress on stderr")
    if not (0.1 < rms < 30.0):
        failures.append(f"outage_rms_m {rms} not in (0.1, 30)")
    # the bars, on six sessions (seeds 11-16) pooled as eval-outage pools them: one walk's
    # coverage is one route match early or late (seed 11 alone: 0.83 with the GNSS KF of 80cf665,
    # 0.48 with today's, 30 % tighter before the window, docs/fusion.md)
    logs = [log]
    for seed in range(12, 17):
        logs.append(os.path.join(scratch, f"session{seed}.log"))
        run([pdnav, "simulate", "--session", "--dem", dem, "--graph", graph, "--nav", nav, "-o", logs[-1], "--seed",
             str(seed), "--lead", "240", "--outage-min", "0", "--outage-max", "0", "--tail", "240"])
    rp = run([pdnav, "eval-outage", *logs, "--nav", nav, "--dem", dem, "--graph", graph, "--mount", "chest",
              "--start-frac", "0.4", "--length-frac", "0.4", "--max-s", "300", "--quiet"])
    print(rp.stdout, end="")
    mp = BAR.fullmatch(rp.stdout.rstrip("\n").split("\n")[-1])
    if not mp or int(mp.group(5)) != 6:
        sys.exit(f"FAIL: six sessions: no bar line with walks: 6: {rp.stdout[-300:]}")
    p_ratio, _p_rms, p_cov, p_jump = (float(x) for x in mp.groups()[:4])
    # measured 0.291 / 4.4 m / 0.795 / 0.653 (6 sessions, truth reference)
    if not (0.0 < p_ratio <= 0.5):
        failures.append(f"six sessions: outage_ratio {p_ratio} not in (0, 0.5]")
    if not (0.5 <= p_cov <= 0.9):
        failures.append(f"six sessions: coverage_68 {p_cov} not in [0.5, 0.9]")
    if not (0.0 <= p_jump <= 3.0):
        failures.append(f"six sessions: max_jump_sigma {p_jump} not in [0, 3]")
    w = re.search(r"window (\d+)-(\d+) s \((\d+) epochs; removed (\d+) Raw, (\d+) Fix rows\)", r.stdout)
    span = re.search(r"GNSS span (\d+) s", r.stdout)
    if not w or not span:
        sys.exit("FAIL: no window line")
    w0, w1, n_ep, n_raw, n_fix = (int(x) for x in w.groups())
    span_s = int(span.group(1))
    if abs(w0 - 0.4 * span_s) > 1.5 or abs((w1 - w0) - min(0.4 * span_s, 300)) > 1.5:
        failures.append(f"window {w0}-{w1} s not at 0.4 of the span {span_s} s for min(0.4 span, 300 s)")
    if n_raw < 100 or n_fix < 100 or n_ep < 100:
        failures.append(f"window removed {n_raw} Raw / {n_fix} Fix rows, scored {n_ep} epochs (expected >= 100 each)")
    if "calibration published before the window: scale" not in r.stdout:
        failures.append("no calibration published before the window")
    # per-walk outputs
    stem = os.path.join(out, "session")
    with open(stem + ".json") as f:
        js = json.load(f)
    with open(stem + ".csv") as f:
        rows = list(csv.DictReader(f))
    if js["reference"] != "truth":
        failures.append(f"reference {js['reference']} (the session has Truth rows)")
    if abs(js["outage_ratio"] - ratio) > 1e-3 or abs(js["coverage_68"] - cov) > 1e-3:
        failures.append("JSON figures differ from the bar line")
    inw = [x for x in rows if x["in_window"] == "1"]
    # the window's median squared Mahalanobis distance (the CSV's, in the window) and its chi^2(2)
    # percentile, in the JSON and on the printed line
    m2 = sorted(float(x["fused_mahalanobis2"]) for x in inw if math.isfinite(float(x["fused_mahalanobis2"])))
    m2_med = (m2[len(m2) // 2] if len(m2) % 2 else 0.5 * (m2[len(m2) // 2 - 1] + m2[len(m2) // 2])) if m2 else float("nan")
    pct = re.search(r"window_median_percentile: (\S+)", r.stdout)
    if (not m2 or abs(js["median_mahalanobis2"] - m2_med) > 2e-4 * max(1.0, m2_med)
            or abs(js["median_percentile"] - 100.0 * (1.0 - math.exp(-0.5 * m2_med))) > 0.05
            or not pct or abs(float(pct.group(1)) - js["median_percentile"]) > 0.051):
        failures.append(f"window median Mahalanobis^2 {js.get('median_mahalanobis2')} / percentile "
                        f"{js.get('median_percentile')} (printed {pct.group(1) if pct else None}) against the CSV's {m2_med}")
    if len(inw) != n_ep:
        failures.append(f"CSV has {len(inw)} rows in the window, printed {n_ep}")
    fe = [float(x["fused_err_m"]) for x in inw]
    csv_rms = math.sqrt(sum(e * e for e in fe) / len(fe))
    if abs(csv_rms - rms) > 0.06:
        failures.append(f"CSV fused RMS {csv_rms:.2f} != printed {rms}")
    # dead reckoning restarts at the last fix before the window: small error at the first epoch
    d0 = float(inw[0]["dr_err_m"])
    if not (d0 < 15.0):
        failures.append(f"dead reckoning error at the window start {d0:.1f} m (should start at the last fix)")
    if not all(math.isnan(float(x["dr_e_m"])) for x in rows if float(x["t_s"]) < w0 - 1):
        failures.append("dead reckoning rows before the window")
    # the placement from the motion alone: the camera axis forward (the inverted-pendulum phase
    # of the simulated gait, as on real walks), so the same window scores the same
    ra = run([pdnav, "eval-outage", log, "--nav", nav, "--dem", dem, "--graph", graph, "--mount", "auto",
              "--start-frac", "0.4", "--length-frac", "0.4", "--max-s", "300", "--quiet"])
    # (a reversed walking direction is hidden in the fused track, which GNSS calibrates by ~180 deg,
    # but not in the calibration's heading bias and the uncalibrated dead reckoning's ratio)
    ma = BAR.fullmatch(ra.stdout.rstrip("\n").split("\n")[-1])
    mb = re.search(r"calibration published before the window: scale \S+ \+- \S+, heading bias (\S+) \+-", ra.stdout)
    if (not ma or not mb or abs(float(ma.group(1)) - ratio) > 0.1 * ratio or abs(float(ma.group(2)) - rms) > 0.25 * rms
            or abs(float(mb.group(1))) > 30.0):
        failures.append(f"--mount auto on the chest-mounted session: {ra.stdout[-400:]} (declared chest: ratio {ratio}, rms {rms} m)")
    # explicit window
    r2 = run([pdnav, "eval-outage", log, "--nav", nav, "--mount", "chest", "--start-s", "100", "--length-s", "60", "--quiet"])
    if not re.search(r"window 100-160 s", r2.stdout) or not BAR.fullmatch(r2.stdout.rstrip("\n").split("\n")[-1]):
        failures.append(f"--start-s 100 --length-s 60 not honoured: {r2.stdout}")
    # a sweep: one walk per (recording, window), the 0.4 window identical to the single run
    sweep = os.path.join(scratch, "sweep")
    r5 = run([pdnav, "eval-outage", log, "--nav", nav, "--dem", dem, "--graph", graph, "--out", sweep, "--mount", "chest",
              "--start-fracs", "0.3,0.4", "--length-frac", "0.4", "--max-s", "300", "--quiet"])
    m5 = BAR.fullmatch(r5.stdout.rstrip("\n").split("\n")[-1])
    if not m5 or int(m5.group(5)) != 2:
        failures.append(f"--start-fracs 0.3,0.4: not 2 walks: {r5.stdout[-300:]}")
    if not os.path.isfile(os.path.join(sweep, "session@0.30.csv")) or not os.path.isfile(os.path.join(sweep, "session@0.40.json")):
        failures.append("--start-fracs: per-window CSV/JSON missing")
    else:
        with open(os.path.join(sweep, "session@0.40.json")) as f:
            j40 = json.load(f)
        if abs(j40["outage_ratio"] - js["outage_ratio"]) > 1e-9 or abs(j40["coverage_68"] - js["coverage_68"]) > 1e-9:
            failures.append("--start-fracs window 0.4 differs from --start-frac 0.4")
    r6 = run([pdnav, "eval-outage", log, "--start-fracs", "0.3,0.7", "--length-frac", "0.4", "--quiet"], ok=False)
    if r6.returncode == 0 or "start 0.700" not in (r6.stdout + r6.stderr):
        failures.append(f"--start-fracs beyond the span: exit {r6.returncode}, {r6.stderr.strip()}")
    # bad input: a window outside the span; a log without fixes or truth
    r3 = run([pdnav, "eval-outage", log, "--start-s", "100", "--length-s", "100000", "--quiet"], ok=False)
    if r3.returncode == 0 or "not inside the GNSS span" not in (r3.stdout + r3.stderr):
        failures.append(f"window outside the span: exit {r3.returncode}, {r3.stderr.strip()}")
    bare = os.path.join(scratch, "no_reference.log")
    with open(log) as f, open(bare, "w") as g:
        for ln in f:
            if not ln.startswith(("Fix,", "Truth,", "Raw,")):
                g.write(ln)
    r4 = run([pdnav, "eval-outage", bare, "--quiet"], ok=False)
    if r4.returncode == 0 or "no reference" not in (r4.stdout + r4.stderr) or "no_reference.log" not in r4.stderr:
        failures.append(f"log without reference: exit {r4.returncode}, {r4.stderr.strip()}")
    # a recording with Truth but no GNSS at all: the window is on the reference's span, and the
    # line says so (nothing was removed), not "GNSS span"
    no_gnss = os.path.join(scratch, "no_gnss.log")
    with open(log) as f, open(no_gnss, "w") as g:
        started = False
        for ln in f:
            if ln.startswith("Truth,") and not started:  # the start the fixes gave, stated
                _, t, lat, lon = ln.split(",")[:4]
                g.write(f"Meta,{t},StartLatitudeDegrees,{lat}\nMeta,{t},StartLongitudeDegrees,{lon}\n"
                        f"Meta,{t},StartSigmaMeters,3\n")
                started = True
            if not ln.startswith(("Fix,", "Raw,", "Nav,")):
                g.write(ln)
    r5 = run([pdnav, "eval-outage", no_gnss, "--quiet"], ok=False)
    if r5.returncode != 0 or "reference truth, reference span (no GNSS in the recording: nothing to remove)" not in r5.stdout \
            or "removed 0 Raw, 0 Fix rows" not in r5.stdout:
        failures.append(f"log without GNSS: exit {r5.returncode}, {r5.stdout[-300:]} {r5.stderr.strip()}")
    if failures:
        sys.exit("FAIL: " + "; ".join(failures))
    print("ok")


if __name__ == "__main__":
    main(sys.argv)
