#!/usr/bin/python3
"""Issue 15 part A through the CLI on the shared GSDC drive (first half): the kinematic KF
bar with SP3 (score <= 4.0 m, availability >= 0.95, 68 % coverage 0.5-0.85; the 1 s TDCP
displacement within 10 cm per axis of the truth's own), and the
duty-cycled run without carrier phase (`--keep-every 5 --strip-adr`), where the KF must not be
worse than SPP (it was 19.3 m vs 6.61 m with the position-only KF), also with a hardware clock
discontinuity on every epoch."""
import re
import subprocess
import sys

pdnav, shared = sys.argv[1], sys.argv[2]
extra = sys.argv[3:]  # e.g. --dynamics vehicle, to see a bar fail
d = f"{shared}/gnss-gsdc2021-pixel5"
base = [pdnav, "gnss", f"{d}/Pixel5_first_half.21o", "--nav", f"{d}/hour1180.21n",
        "--sp3", f"{d}/COD0MGXFIN_20211180000_01D_05M_ORB.SP3", "--truth-csv", f"{d}/ground_truth_first_half.csv"]


def run(args):
    out = subprocess.run(base + args + extra, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"pdnav gnss {' '.join(args)} failed ({out.returncode}): {out.stderr[-2000:]}")
    m = re.search(r"track_spp_score_m: (\S+) track_spp_avail: (\S+) track_kf_score_m: (\S+) "
                  r"track_kf_avail: (\S+) track_kf_cov68: (\S+)", out.stdout)
    if not m:
        sys.exit("no track line in the output:\n" + out.stdout[-3000:])
    v = [float(x) for x in m.groups()]
    print(" ".join(args) or "default", "spp score", v[0], "kf score", v[2], "kf avail", v[3], "cov68", v[4])
    run.stdout = out.stdout
    return v


def tdcp_against_truth(stdout):
    """The 1 s TDCP displacement's error against the truth track's own displacement: per-axis
    RMS (cm) and epochs, and the last line's tdcp_rms_cm (its worst axis)."""
    m = re.search(r"TDCP rms e/n/u (\S+) / (\S+) / (\S+) cm \((\d+) epochs\)", stdout)
    last = re.search(r"tdcp_rms_cm: (\S+)", stdout)
    if not m or not last:
        sys.exit("no TDCP-against-truth figures in the output:\n" + stdout[-3000:])
    return [float(x) for x in m.groups()[:3]], int(m.group(4)), float(last.group(1))


bad = []
spp, _, kf, avail, cov = run([])
if not kf <= 4.0: bad.append(f"KF score {kf} > 4.0")
if not avail >= 0.95: bad.append(f"KF availability {avail} < 0.95")
if not 0.5 <= cov <= 0.85: bad.append(f"KF 68 % coverage {cov} outside 0.5-0.85")
if not spp <= 7.5: bad.append(f"SPP score {spp} > 7.5")
# the car's 1 s carrier-phase displacement against the SPAN truth's: a few cm per axis (4.2 / 4.0
# / 6.9 cm over 774 epochs; Walker 2019: TDCP is cm-level), not the ~6 m a second the car moves
# (what the last line printed before it was scored against the truth's own displacement)
enu_cm, n_tdcp, last_cm = tdcp_against_truth(run.stdout)
print("TDCP vs truth rms e/n/u cm", enu_cm, "epochs", n_tdcp, "tdcp_rms_cm", last_cm)
if not n_tdcp >= 500: bad.append(f"only {n_tdcp} TDCP epochs scored against the truth")
if not max(enu_cm) <= 10.0: bad.append(f"TDCP displacement error {enu_cm} cm > 10 cm on an axis")
if not abs(last_cm - max(enu_cm)) <= 0.06: bad.append(f"last line tdcp_rms_cm {last_cm} is not the worst axis {max(enu_cm)}")
spp, _, kf, avail, cov = run(["--keep-every", "5", "--strip-adr"])
if not kf <= spp: bad.append(f"duty cycled: KF score {kf} > SPP {spp}")
if not 0.5 <= cov <= 0.85: bad.append(f"duty cycled: KF 68 % coverage {cov} outside 0.5-0.85")
# a clock discontinuity on every epoch as well: no epoch-to-epoch link at all, only the Doppler
# velocity of each epoch (was KF 62.6 m vs SPP 7.53 m before the unlinked Doppler update)
spp, _, kf, avail, cov = run(["--keep-every", "5", "--strip-adr", "--hw-discontinuities"])
if not kf <= spp: bad.append(f"duty cycled + discontinuities: KF score {kf} > SPP {spp}")
if bad:
    sys.exit("GSDC KF bar not met: " + "; ".join(bad))
print("GSDC KF bars met")
