#!/usr/bin/python3
"""The runs in an lcm-logger log, and how many of each run's frames the log
holds whole (every chunk of the frame present), read from the log's bytes
(the LCM log format and the encodings of dynhet's run_info_t and
frame_chunk_t headers; no LCM bindings needed).

Usage: lcmlog_runs.py LOG              one line per run: id, N, frames in the log / expected
       lcmlog_runs.py LOG --run-id ID  that run's line; exit 1 if the log does not hold it
                                       (--whole after it: exit 3 if it lacks frames)
       lcmlog_runs.py LOG --only       the id of the only run; exit 1 (with the list) if there are several
       lcmlog_runs.py LOG --channels   the messages per channel, one 'CHANNEL COUNT' a line
"""
import struct
import sys

from dynhet.lcmlog import events

HEAD = 128  # the bytes of a message its headers need (run_info_t: 92, frame_chunk_t: 60)


def scan(path):
    """{run_id: {"n": N, "frames": n_frames, "chunks": {frame: set(chunk)}, "count": {frame: chunk_count}}}"""
    runs = {}
    for channel, d, size, _ in events(path, head=HEAD):
        if channel == "DYNHET_RUN" and size >= 92:
            # hash utime run_id n_particles box phi eps radius[2] mass[2] n_small n_frames
            run_id, n = struct.unpack_from(">qi", d, 16)
            n_frames = struct.unpack_from(">i", d, 88)[0]
            r = runs.setdefault(run_id, {"chunks": {}, "count": {}})
            r.setdefault("n", n)
            r.setdefault("frames", n_frames)
        elif channel == "DYNHET_FRAME" and size >= 60:
            # hash utime run_id frame_index time n_particles chunk_index chunk_count
            run_id, frame = struct.unpack_from(">qi", d, 16)
            chunk, count = struct.unpack_from(">ii", d, 40)
            r = runs.setdefault(run_id, {"chunks": {}, "count": {}})
            r["chunks"].setdefault(frame, set()).add(chunk)
            r["count"][frame] = count
    return runs


def line(run_id, r):
    whole_frames = {f for f, c in r["chunks"].items() if len(c) == r["count"][f]}
    whole = len(whole_frames)
    expected = r.get("frames")
    text = (f"run {run_id}: N = {r.get('n', '?')}, {whole} of "
            f"{expected if expected is not None else '?'} frames whole in the log")
    if expected is not None and whole < expected:  # which, for whoever wonders why (a starved lcm-logger drops)
        lacking = [f for f in range(expected) if f not in whole_frames]
        text += " (lacking frame" + ("s " if len(lacking) > 1 else " ") + ", ".join(map(str, lacking[:10])) + \
            (", ..." if len(lacking) > 10 else "") + ")"
    return whole, expected, text


def main():
    if len(sys.argv) >= 2 and sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        return 0
    if len(sys.argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    args = sys.argv[2:]
    if args[:1] == ["--channels"]:
        counts = {}
        for channel, _d, _size, _ in events(sys.argv[1], head=0):
            counts[channel] = counts.get(channel, 0) + 1
        for channel in sorted(counts):
            print(channel, counts[channel])
        return 0
    runs = {k: v for k, v in scan(sys.argv[1]).items() if "frames" in v}
    if not runs:
        print(f"{sys.argv[1]}: no dynhet run info in the log", file=sys.stderr)
        return 1
    if args[:1] == ["--run-id"]:
        rid = int(args[1])
        if rid not in runs:
            print(f"{sys.argv[1]}: no run {rid}; the log holds: " + ", ".join(map(str, runs)), file=sys.stderr)
            return 1
        whole, expected, text = line(rid, runs[rid])
        print(text)
        return 3 if args[2:3] == ["--whole"] and expected is not None and whole < expected else 0
    if args[:1] == ["--only"]:
        if len(runs) > 1:
            print(f"{sys.argv[1]} holds {len(runs)} runs; choose one with --run-id:", file=sys.stderr)
            for rid, r in runs.items():
                print("  " + line(rid, r)[2], file=sys.stderr)
            return 1
        print(next(iter(runs)))
        return 0
    for rid, r in runs.items():
        print(line(rid, r)[2])
    return 0


if __name__ == "__main__":
    sys.exit(main())
