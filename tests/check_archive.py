#!/usr/bin/python3
"""Checks of a results archive (dynhet.archive) against the study directory
it was written from.

  check_archive.py entries ARCHIVE STUDY_DIR
      every complete run of STUDY_DIR is listed, its file's size and sha256
      are the index's, at most 1 MiB, with the run's provenance (build,
      commit, resolved scene, command, CPU, dates) and every observable's
      final record equal to the run.h5's; no frames kept beyond two; every
      pilot's tau_alpha kept
  check_archive.py same-analysis A/study.h5 B/study.h5
      two analyses' study.h5 hold the same numbers (every dataset, every
      attribute but the path of the study they read)
"""
import os
import sys
import tomllib

import h5py
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from dynhet.archive import MAX_BYTES, sha256_of  # noqa: E402

fails = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        fails.append(what)


def final_records_equal(run_h5, entry):
    """Every observable dataset of entry equals the final record (or the
    fixed dataset) of run_h5."""
    bad = []
    with h5py.File(run_h5, "r") as a, h5py.File(entry, "r") as b:
        def visit(name, obj):
            if not isinstance(obj, h5py.Dataset):
                return
            src = a["observables/" + name]
            series = name.endswith("/value") and src.shape and src.shape[0] and obj.shape[0] == 1
            want = src[-1:] if series else src[()]
            got = obj[()]
            if not np.array_equal(np.asarray(want), np.asarray(got), equal_nan=np.asarray(got).dtype.kind == "f"):
                bad.append(name)
            if series:  # the final record's step and time, as the series group's attributes
                g_src, g_got = src.parent, obj.parent
                if (g_got.attrs.get("step") != g_src["step"][-1]
                        or g_got.attrs.get("time") != g_src["time"][-1]):
                    bad.append(name + " (step, time)")
        b["observables"].visititems(visit)
        # run.h5's datasets less each series' step and time (attributes in the entry)
        n_a = sum(1 for n in iter_datasets(a["observables"]) if not n.endswith(("/step", "/time")))
        n_b = sum(1 for _ in iter_datasets(b["observables"]))
    return bad, n_a, n_b


def iter_datasets(g):
    out = []
    g.visititems(lambda n, o: out.append(n) if isinstance(o, h5py.Dataset) else None)
    return out


def entries(archive, study_dir):
    idx = tomllib.load(open(os.path.join(archive, "index.toml"), "rb"))
    sidx = tomllib.load(open(os.path.join(study_dir, "index.toml"), "rb"))["runs"]
    complete = {n for n, r in sidx.items() if r["state"] == "complete"}
    check(idx.get("archive", {}).get("format") == 1, "the index says what it is ([archive] format 1)")
    check(set(idx["runs"]) == complete, f"every complete run listed ({len(idx['runs'])} of {len(complete)})")
    for name, e in sorted(idx["runs"].items()):
        p = os.path.join(archive, e["file"])
        check(os.path.getsize(p) == e["bytes"] and sha256_of(p) == e["sha256"], f"{name}: size and sha256 as indexed")
        check(e["bytes"] <= MAX_BYTES, f"{name}: {e['bytes']} bytes <= 1 MiB")
        run_h5 = os.path.join(study_dir, sidx[name]["path"], "run.h5")
        check(e["source_sha256"] == sha256_of(run_h5), f"{name}: names the hash of the run.h5 it was reduced from")
        with h5py.File(p, "r") as f:
            pv = dict(f["provenance"].attrs)
            scene = open(os.path.join(study_dir, sidx[name]["path"], "scene.toml")).read()
            check(pv.get("scene_toml") == scene and pv.get("build", "").count("-") >= 1 and
                  len(pv.get("commit", "")) >= 7 and pv.get("cpu_s", 0) > 0 and "run_study.sh" in pv.get("command", "")
                  and pv.get("archived", "").startswith("20"),
                  f"{name}: provenance (resolved scene, build {pv.get('build')}, commit, command, CPU, date)")
            frames = f["particles/all/position/value"].shape[0] if "particles/all/position" in f else 0
            check(frames <= 2, f"{name}: at most two frames kept ({frames})")
            check(int(f.attrs["complete"]) == 1, f"{name}: complete")
        bad, n_a, n_b = final_records_equal(run_h5, p)
        check(not bad and n_a == n_b, f"{name}: every observable's final record equals the run's ({n_b} datasets"
              + (f"; differ: {bad[:3]}" if bad else "") + ")")
    pilots = os.path.join(study_dir, "pilots")
    have = {n for n in os.listdir(pilots) if os.path.exists(os.path.join(pilots, n, "status.toml"))}
    check(set(idx.get("pilots", {})) == have and all(v["tau_alpha"] > 0 for v in idx["pilots"].values()),
          f"every pilot's tau_alpha kept ({len(idx.get('pilots', {}))} of {len(have)})")


def same_analysis(a, b):
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        da, db = iter_datasets(fa), iter_datasets(fb)
        check(sorted(da) == sorted(db) and len(da) > 20, f"the same datasets ({len(da)} and {len(db)})")
        diff = [n for n in set(da) & set(db)
                if not np.array_equal(fa[n][()], fb[n][()], equal_nan=fa[n].dtype.kind == "f")]
        check(not diff, "every dataset equal" + (f"; differ: {sorted(diff)[:5]}" if diff else ""))
        attr_diff = []

        def attrs(name, obj):
            o2 = fb.get(name) if name else fb
            for k, v in obj.attrs.items():
                if k in ("study_dir", "created"):
                    continue
                w = o2.attrs.get(k) if o2 is not None else None
                va, wa = np.asarray(v), np.asarray(w)
                if w is None or not np.array_equal(va, wa, equal_nan=va.dtype.kind == "f" and wa.dtype.kind == "f"):
                    attr_diff.append(f"{name}@{k}")
        attrs("", fa)
        fa.visititems(attrs)
        check(not attr_diff, "every attribute equal but the study's path" + (f"; differ: {attr_diff[:5]}" if attr_diff else ""))


if __name__ == "__main__":
    if sys.argv[1] == "entries":
        entries(sys.argv[2], sys.argv[3])
    else:
        same_analysis(sys.argv[2], sys.argv[3])
    sys.exit(1 if fails else 0)
