#!/usr/bin/python3
"""Runs `pdnav eval-fusion ...` (the arguments after --) and checks that it ends with the
bar line `outage_ratio: X max_jump_sigma: Y reacquire_s: Z open_sky_ratio: W`, that every
walk printed its scenario rows, and that the figures are sane (finite, in physical ranges);
then that the worst walk it names can be written again: its whole seed in the printed
`pdnav simulate --session` command gives a session of the same length and outage.
It does not check the issue's bar itself.

  check_eval_fusion.py -- PDNAV eval-fusion ARGS...
"""
import math
import os
import re
import shlex
import subprocess
import sys
import tempfile


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
    # where the outages' median errors fall in their stated distributions: a percentile
    pct = re.search(r"^outage_median_percentile: (\S+) ", r.stdout, re.M)
    if not pct or not (0.0 <= float(pct.group(1)) <= 100.0):
        failures.append(f"outage_median_percentile missing or not in [0, 100]: {pct.group(0) if pct else None}")
    failures += check_worst_walk_reproduces(cmd[0], r.stdout)
    if failures:
        sys.exit("FAIL: " + "; ".join(failures))
    print("ok")


def check_worst_walk_reproduces(pdnav, out):
    walks = {int(m.group(1)): (m.group(2), float(m.group(3)), float(m.group(4)))
             for m in re.finditer(r"^\s+walk (\d+) \(seed (\d+)\): (\d+) m, outage (\d+) s", out, re.M)}
    worst = re.search(r"^worst walks by outage_ratio: walk (\d+) \(seed (\d+)\)", out, re.M)
    how = re.search(r"^to write one: pdnav (simulate --session --seed SEED .*)$", out, re.M)
    if not walks or not worst or not how:
        return ["no per-walk seeds, worst-walk line or simulate command in the output"]
    k, seed = int(worst.group(1)), worst.group(2)
    if k not in walks or walks[k][0] != seed:
        return [f"the worst walk {k} (seed {seed}) is not a walk of the table"]
    with tempfile.TemporaryDirectory() as tmp:
        args = shlex.split(how.group(1).replace("SEED", seed).replace("-o walk.log", ""))
        sim = subprocess.run([pdnav] + args + ["-o", os.path.join(tmp, "walk.log")], capture_output=True, text=True)
    m = re.search(r"simulated session: (\d+) m, .*?outage (\d+)-(\d+) s", sim.stdout)
    if sim.returncode != 0 or not m:
        return [f"the printed simulate command failed: {sim.stderr.strip()[-200:]}"]
    length, outage = float(m.group(1)), float(m.group(3)) - float(m.group(2))
    if abs(length - walks[k][1]) > 1.0 or abs(outage - walks[k][2]) > 1.5:
        return [f"seed {seed} wrote {length:.0f} m / outage {outage:.0f} s, the table says {walks[k][1]:.0f} m / {walks[k][2]:.0f} s"]
    print(f"worst walk {k} written again from seed {seed}: {length:.0f} m, outage {outage:.0f} s")
    return []


if __name__ == "__main__":
    main(sys.argv)
