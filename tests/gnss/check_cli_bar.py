#!/usr/bin/python3
"""Runs `pdnav gnss` on the real Mountain View log and asserts issue 7's bars on its last
line `spp_p50_h_m: A spp_p95_h_m: B kf_rms_h_m: C tdcp_rms_cm: D`."""
import subprocess
import sys

pdnav, shared = sys.argv[1], sys.argv[2]
log = f"{shared}/gnss-mountainview/pseudoranges_log_2016_08_22_14_45_50.txt"
nav = f"{shared}/gnss-mountainview/hour2350.16n"
bars = {"spp_p50_h_m": 4.0, "spp_p95_h_m": 8.0, "kf_rms_h_m": 2.5, "tdcp_rms_cm": 3.0}
out = subprocess.run([pdnav, "gnss", log, "--nav", nav, "--truth", "37.422578,-122.081678,-28"],
                     capture_output=True, text=True)
print(out.stdout[-3000:])
if out.returncode != 0:
    sys.exit(f"pdnav gnss failed ({out.returncode}): {out.stderr[-2000:]}")
last = out.stdout.strip().splitlines()[-1].split()
values = {last[i].rstrip(":"): float(last[i + 1]) for i in range(0, len(last) - 1, 2)}
failed = [f"{k} = {values.get(k)} > {v}" for k, v in bars.items() if not (values.get(k, float("inf")) <= v)]
if failed:
    sys.exit("bar not met: " + "; ".join(failed))
print("gnss bar met: " + ", ".join(f"{k} {values[k]} <= {v}" for k, v in bars.items()))
