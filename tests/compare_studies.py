#!/usr/bin/python3
"""Two study directories of the same study must hold the same results, run
for run, bit for bit (for example one run straight through, one interrupted
and resumed, or one on the local executor and one through Slurm).

Usage: compare_studies.py DIR_A DIR_B
"""
import os
import sys
import tomllib

from compare_runs import final_results, same


def main(a, b):
    with open(os.path.join(a, "index.toml"), "rb") as f:
        ia = tomllib.load(f)["runs"]
    with open(os.path.join(b, "index.toml"), "rb") as f:
        ib = tomllib.load(f)["runs"]
    ok = ia.keys() == ib.keys()
    if not ok:
        print(f"FAIL the studies hold other runs: {sorted(ia)} against {sorted(ib)}")
    for name in sorted(set(ia) & set(ib)):
        ra, rb = ia[name], ib[name]
        if ra["state"] != "complete" or rb["state"] != "complete":
            print(f"FAIL {name}: states {ra['state']} and {rb['state']}")
            ok = False
            continue
        (xa, _), (xb, _) = final_results(os.path.join(a, ra["path"], "run.h5")), final_results(
            os.path.join(b, rb["path"], "run.h5"))
        if same(xa, xb):
            print(f"ok   {name}: {len(xa)} final results equal bit for bit (tau_alpha {ra['tau_alpha']:.6g})")
        else:
            ok = False
            print(f"FAIL {name}: results differ")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
