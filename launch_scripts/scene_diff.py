#!/usr/bin/python3
"""Names the keys in which two scene files differ (table.key: old -> new), one a line.

Usage: scene_diff.py OLD.toml NEW.toml   (exit 0: same settings, 1: they differ)
"""
import sys
import tomllib


def flat(d, prefix=""):
    out = {}
    for k, v in d.items():
        key = f"{prefix}{k}"
        if isinstance(v, dict):
            out.update(flat(v, key + "."))
        else:
            out[key] = v
    return out


def main(old, new):
    with open(old, "rb") as f:
        a = flat(tomllib.load(f))
    with open(new, "rb") as f:
        b = flat(tomllib.load(f))
    keys = sorted(k for k in a.keys() | b.keys() if a.get(k, "(unset)") != b.get(k, "(unset)"))
    for k in keys:
        print(f"  {k}: {a.get(k, '(unset)')!r} -> {b.get(k, '(unset)')!r}")
    if not keys:
        print("  (the same settings; the files differ in comments or layout only)")
    return 1 if keys else 0


if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        sys.exit(0 if len(sys.argv) == 2 else 2)
    sys.exit(main(sys.argv[1], sys.argv[2]))
