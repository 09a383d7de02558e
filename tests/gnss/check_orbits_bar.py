#!/usr/bin/python3
"""Runs `pdnav orbits` (broadcast RINEX 3 vs CODE SP3, 2023-03-14) and asserts issue 7's
orbit bar on every satellite row: 3D difference <= 5 m for GPS and Galileo, <= 10 m for GLONASS,
and that each of the three systems was compared."""
import subprocess
import sys

pdnav, shared = sys.argv[1], sys.argv[2]
d = f"{shared}/gnss-orbits-2023-073"
out = subprocess.run([pdnav, "orbits", "--nav", f"{d}/BRDM00DLR_S_20230730000_01D_MN.rnx",
                      "--sp3", f"{d}/COD0OPSRAP_20230730000_01D_05M_ORB.SP3"], capture_output=True, text=True)
print(out.stdout[-4000:])
if out.returncode != 0:
    sys.exit(f"pdnav orbits failed ({out.returncode}): {out.stderr[-2000:]}")
bars = {"G": 5.0, "E": 5.0, "R": 10.0}
seen = {k: 0 for k in bars}
bad = []
lines = out.stdout.splitlines()
start = next(i for i, l in enumerate(lines) if l.startswith("sat ") and "max_3d_m" in l)
for line in lines[start + 1:]:
    f = line.split()
    if len(f) < 4 or len(f[0]) != 3 or f[0][0] not in "GRECJ" or not f[0][1:].isdigit():
        break
    sys_letter, max3d = f[0][0], float(f[3])
    if sys_letter in bars:
        seen[sys_letter] += 1
        if not (max3d <= bars[sys_letter]):
            bad.append(f"{f[0]} {max3d} m > {bars[sys_letter]} m")
missing = [k for k, n in seen.items() if n == 0]
if bad or missing:
    sys.exit("orbit bar not met: " + "; ".join(bad + [f"no {k} satellite compared" for k in missing]))
print("orbit bar met for", ", ".join(f"{k}: {n} sats" for k, n in seen.items()))
