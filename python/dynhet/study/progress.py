"""What a running run is doing, from its sim's own progress line (sim_node's
reporter: "[phase] t=T /END ... frames F/M  ETA h:mm:ss"), for the study's
periodic progress lines: a run of hours otherwise says nothing until it ends."""
import os
import re

LINE = re.compile(r"\[(\w+)\s*\] t=(\S+)\s*/(\S+)\s+phi=.*?frames (\d+)/(\d+)\s+ETA (\S+)")
# Seconds between the study's progress lines while runs go on
# (DYNHET_STUDY_PROGRESS_EVERY: the tests' shorter interval).
PROGRESS_EVERY = float(os.environ.get("DYNHET_STUDY_PROGRESS_EVERY", "600"))


def sim_progress(run_dir, since=0.0, tail_bytes=8192):
    """The run's last sim progress line as a dict (phase, t, end, frames,
    frames_total, eta), from the end of run_dir/sim_node.log; None without
    one (a run still in its pilot or its prepared state, or not started),
    or where the log was last written before `since` (an earlier attempt's,
    the run started again in the same directory)."""
    path = os.path.join(run_dir, "sim_node.log")
    try:
        if os.path.getmtime(path) < since:
            return None
        with open(path, "rb") as f:
            f.seek(0, os.SEEK_END)
            f.seek(max(0, f.tell() - tail_bytes))
            text = f.read().decode("utf-8", "replace")
    except OSError:
        return None
    for line in reversed(re.split(r"[\r\n]", text)):  # a terminal's lines end in \r, a log's in \n
        m = LINE.search(line)
        if m:
            try:
                t, end = float(m.group(2)), float(m.group(3))
            except ValueError:
                continue
            return {"phase": m.group(1), "t": t, "end": end, "frames": int(m.group(4)),
                    "frames_total": int(m.group(5)), "eta": m.group(6)}
    return None


def describe(name, run_dir, since=0.0):
    """One line of a running run: its phase, how far in simulated time, frames
    and the sim's ETA (from a log written since `since`, its start)."""
    p = sim_progress(run_dir, since)
    if p is None:
        return f"  {name}: starting (a pilot, a prepared state, or the sim's first line)"
    share = f" ({100 * p['t'] / p['end']:.0f}% of the phase)" if p["end"] > 0 else ""
    return (f"  {name}: {p['phase']} t = {p['t']:.4g} of {p['end']:.4g}{share}, frames {p['frames']}/"
            f"{p['frames_total']}, the sim's ETA {p['eta']}")


def eta_seconds(text):
    """The sim's ETA text (h:mm:ss, or "?") in seconds; None where it says none."""
    parts = text.split(":")
    if len(parts) != 3 or not all(p.isdigit() for p in parts):
        return None
    h, m, sec = (int(p) for p in parts)
    return 3600 * h + 60 * m + sec


def study_eta(running_left, queued, jobs):
    """When the study ends, in seconds from now: the running runs free their
    slots after what their sims say is left (0 where unknown), and the
    queued runs (their estimated seconds, in the order the pool takes them)
    go each to the slot free first; the last slot to finish ends it."""
    slots = sorted(list(running_left) + [0.0] * max(0, jobs - len(running_left)))
    for cost in queued:
        slots[0] += cost
        slots.sort()
    return max(slots) if slots else 0.0
