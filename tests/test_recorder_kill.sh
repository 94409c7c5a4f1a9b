#!/bin/bash
# A writer killed with SIGKILL must leave a valid H5MD file: start
# h5md_kill_writer, let it write at least 50 records, kill -9 it, then open
# the file with h5py (and h5dump) and check the records it holds.
# Usage: test_recorder_kill.sh PATH/TO/h5md_kill_writer
set -euo pipefail
writer=$1
dir=$(mktemp -d)
trap 'kill -9 "$pid" 2>/dev/null || true; rm -rf "$dir"' EXIT
file=$dir/killed.h5

"$writer" "$file" >"$dir/progress" &
pid=$!
# Wait (at most 30 s) until the writer reports 60 flushed records.
for _ in $(seq 300); do
  kill -0 "$pid" 2>/dev/null || { echo "the writer died on its own"; exit 1; }
  n=$(tail -n 1 "$dir/progress" 2>/dev/null || echo 0)
  [ "${n:-0}" -ge 60 ] && break
  sleep 0.1
done
kill -9 "$pid"
wait "$pid" 2>/dev/null || true
reported=$(tail -n 1 "$dir/progress")
echo "writer reported $reported records when killed"

if command -v h5dump >/dev/null; then
  h5dump -H "$file" >/dev/null || { echo "h5dump cannot read the file"; exit 1; }
fi

/usr/bin/python3 - "$file" "$reported" <<'PY'
import sys
import h5py
import numpy as np

path, reported = sys.argv[1], int(sys.argv[2])
with h5py.File(path, "r") as f:
    assert tuple(f["h5md"].attrs["version"]) == (1, 1)
    for name, width in (("vector", 3), ("scalar", 1)):
        g = f["observables"][name]
        step, time, value = g["step"][()], g["time"][()], g["value"][()]
        # A kill during the last flush may leave one dataset a record ahead.
        n = min(len(step), len(time), len(value))
        assert n >= 50, f"{name}: only {n} records"
        assert n <= reported + 1, f"{name}: {n} records, writer reported {reported}"
        assert np.array_equal(step[:n], np.arange(n)), f"{name}: steps"
        assert np.array_equal(time[:n], 0.5 * np.arange(n)), f"{name}: times"
        expect = np.arange(n)[:, None] * np.arange(1, width + 1)[None, :]
        assert np.array_equal(value[:n].reshape(n, -1), expect), f"{name}: values"
        print(f"{name}: {n} consistent records (step {len(step)}, time {len(time)}, value {len(value)})")
    pos = f["particles/all/position/value"]
    assert pos.shape[1:] == (3, 2) and pos.shape[0] >= 5, pos.shape
PY
echo "PASS"
