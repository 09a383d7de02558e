#!/usr/bin/python3
"""`pdnav rinex` on the real Mountain View log, then RTKLIB's rnx2rtkp (single point, its
defaults) on the written file, and `pdnav gnss` on the same file. Passes when RTKLIB reads the
file (a solution for >= 90 % of the epochs) and its median position agrees with pdnav's median
SPP position within 3 m horizontally (both static; truth 37.422578, -122.081678, -28)."""
import math
import os
import shutil
import subprocess
import sys
import tempfile

pdnav, shared = sys.argv[1], sys.argv[2]
rnx2rtkp = shutil.which("rnx2rtkp")
if not rnx2rtkp:
    sys.exit("rnx2rtkp not found (Debian package rtklib; tools/setup installs it)")
log = f"{shared}/gnss-mountainview/pseudoranges_log_2016_08_22_14_45_50.txt"
nav = f"{shared}/gnss-mountainview/hour2350.16n"
work = tempfile.mkdtemp(prefix="pdnav_rtklib_")
obs, pos, csv = (os.path.join(work, n) for n in ("mv.obs", "mv.pos", "mv.csv"))


def run(cmd):
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"{cmd[0]} failed ({out.returncode}): {out.stdout[-1500:]} {out.stderr[-1500:]}")
    return out.stdout


print(run([pdnav, "rinex", log, "-o", obs]))
run([rnx2rtkp, "-p", "0", "-o", pos, obs, nav])
rtk = []
for line in open(pos):
    if line.startswith("%") or not line.strip():
        continue
    f = line.split()
    rtk.append((float(f[2]), float(f[3])))
run([pdnav, "gnss", obs, "--nav", nav, "--out", csv, "--truth", "37.422578,-122.081678,-28"])
import csv as csvmod
ours = [(float(r["spp_lat_deg"]), float(r["spp_lon_deg"])) for r in csvmod.DictReader(open(csv)) if r["spp_ok"] == "1"]
epochs = sum(1 for line in open(obs) if line.startswith(">"))


def median(v):
    v = sorted(v)
    n = len(v)
    return 0.5 * (v[(n - 1) // 2] + v[n // 2])


def horiz_m(a, b):
    lat0 = math.radians(a[0])
    return math.hypot((a[0] - b[0]) * 111_132.0, (a[1] - b[1]) * 111_320.0 * math.cos(lat0))


truth = (37.422578, -122.081678)
m_rtk = (median([p[0] for p in rtk]), median([p[1] for p in rtk]))
m_our = (median([p[0] for p in ours]), median([p[1] for p in ours]))
d = horiz_m(m_rtk, m_our)
print(f"epochs {epochs}, RTKLIB solutions {len(rtk)}, pdnav SPP fixes {len(ours)}")
print(f"median position: RTKLIB {horiz_m(m_rtk, truth):.2f} m from truth, pdnav {horiz_m(m_our, truth):.2f} m; "
      f"RTKLIB vs pdnav {d:.2f} m")
if len(rtk) < 0.9 * epochs:
    sys.exit(f"RTKLIB solved only {len(rtk)} of {epochs} epochs")
if not d <= 3.0:
    sys.exit(f"RTKLIB and pdnav disagree by {d:.2f} m > 3 m")
print("rtklib check passed")
