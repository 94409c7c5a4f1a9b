#!/usr/bin/python3
"""Checks every message of an lcm-logger log against a run's key (the tag
each message carries: docs/bus.md).

Usage: lcmlog_verify.py LOG --key-file KEY               counts; exit 1 if any message does not verify
       lcmlog_verify.py LOG --key-file KEY --keep OUT    also write the messages that verify to OUT
"""
import os
import sys

from dynhet import bus


def main(argv):
    if len(argv) >= 2 and argv[1] in ("-h", "--help"):
        print(__doc__)
        return 0
    args = argv[1:]
    if len(args) < 3 or args[1] != "--key-file" or (len(args) > 3 and (args[3] != "--keep" or len(args) != 5)):
        print(__doc__, file=sys.stderr)
        return 2
    log, key_path = args[0], args[2]
    keep = args[4] if len(args) == 5 else None
    try:
        key = bus.load_key(key_path)
    except bus.KeyError_ as e:
        print(f"lcmlog_verify: {e}", file=sys.stderr)
        return 2
    if not os.path.isfile(log):
        print(f"lcmlog_verify: no log file {log}", file=sys.stderr)
        return 2
    c = bus.check_log(log, key, keep)
    bad = c["untagged"] + c["bad_tag"] + c["replayed"]
    print(f"{c['ok']} messages verify, {bad} do not ({c['untagged']} without a tag, {c['bad_tag']} with a tag "
          f"that does not match this key, {c['replayed']} replayed copies)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
