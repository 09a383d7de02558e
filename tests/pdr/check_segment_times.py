#!/usr/bin/python3
"""eval-pdr --json: every heading segment carries its middle time (seg_mid_s, s after the walk's
first Truth line), so the heading error can be read as a time series. Checked against the logs'
own Truth lines: one time per segment, strictly increasing, each inside the walk's Truth span.

Usage: check_segment_times.py WALKS.jsonl LOG [LOG ...]   (the logs in the order eval-pdr took them)
"""
import json
import sys


def truth_span_s(path):
    ts = [int(line.split(",")[1]) for line in open(path) if line.startswith("Truth,")]
    return (max(ts) - ts[0]) / 1e9


def main():
    walks = [json.loads(line) for line in open(sys.argv[1])]
    logs = sys.argv[2:]
    if len(walks) != len(logs):
        sys.exit(f"{len(walks)} walks in {sys.argv[1]}, {len(logs)} logs")
    for w, log in zip(walks, logs):
        mids, errs = w["seg_mid_s"], w["seg_heading_err_deg"]
        span = truth_span_s(log)
        if len(mids) != len(errs) or not mids:
            sys.exit(f"{log}: {len(mids)} segment times for {len(errs)} segments")
        if any(b <= a for a, b in zip(mids, mids[1:])):
            sys.exit(f"{log}: segment times not increasing: {mids}")
        if mids[0] <= 0.0 or mids[-1] >= span:
            sys.exit(f"{log}: segment times {mids[0]:.1f}..{mids[-1]:.1f} s outside the Truth span 0..{span:.1f} s")
        print(f"{log.rsplit('/', 1)[-1]}: {len(mids)} segments, {mids[0]:.1f}..{mids[-1]:.1f} s of {span:.1f} s")
    print("segment times ok")


if __name__ == "__main__":
    main()
