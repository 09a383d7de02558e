#!/usr/bin/python3
"""Runs `pdnav eval-fusion ...` (the arguments after --) and checks that it ends with the
bar line `outage_ratio: X max_jump_sigma: Y reacquire_s: Z open_sky_ratio: W`, that every
walk printed its scenario rows, and that the figures are sane (finite, in physical ranges).
It does not check the issue's bar itself.

  check_eval_fusion.py -- PDNAV eval-fusion ARGS...
"""
import math
import re
import subprocess
import sys


def main(argv):
    cmd = argv[argv.index("--") + 1:]
    walks = int(cmd[cmd.index("--walks") + 1])
    r = subprocess.run(cmd, capture_output=True, text=True)
    print(r.stdout, end="")
    if r.returncode != 0:
        sys.exit(f"FAIL: exit {r.returncode}: {r.stderr}")
    lines = r.stdout.rstrip("\n").split("\n")
    m = re.fullmatch(r"outage_ratio: (\S+) max_jump_sigma: (\S+) reacquire_s: (\S+) open_sky_ratio: (\S+)", lines[-1])
    if not m:
        sys.exit(f"FAIL: last line is not the bar line: {lines[-1]!r}")
    ratio, jump, reacq, open_sky = (float(x) for x in m.groups())
    failures = []
    for name in ("during-outage", "after-outage", "open-sky"):
        n = sum(1 for ln in lines if re.match(rf"\d+\s+\d+\s+{name}\s", ln))
        if n != walks:
            failures.append(f"{n} '{name}' rows for {walks} walks")
    if "walk" not in r.stderr:
        failures.append("no progress on stderr")
    if not (math.isfinite(ratio) and 0.0 < ratio < 20.0):
        failures.append(f"outage_ratio {ratio} not in (0, 20)")
    if not (math.isfinite(jump) and jump >= 0.0):
        failures.append(f"max_jump_sigma {jump} not finite")
    if not (math.isfinite(reacq) and 0.0 <= reacq <= 90.0):
        failures.append(f"reacquire_s {reacq} not in [0, tail]")
    if not (math.isfinite(open_sky) and 0.2 < open_sky < 10.0):
        failures.append(f"open_sky_ratio {open_sky} not in (0.2, 10)")
    dr = re.search(r"median DRMS during outages \(m\): fused (\S+) dr (\S+) gnss (\S+)", r.stdout)
    if not dr or not (0.5 < float(dr.group(2)) < 2000.0):
        failures.append("dead reckoning DRMS during the outages missing or not in (0.5, 2000) m")
    if failures:
        sys.exit("FAIL: " + "; ".join(failures))
    print("ok")


if __name__ == "__main__":
    main(sys.argv)
