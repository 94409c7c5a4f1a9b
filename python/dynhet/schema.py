"""The schema of run.h5's observables, from their declarations.

Each observable is declared once, in its .lcm file (lcmtypes/observables.py
says how); the build writes the declarations into dynhet._observables
(lcmtypes/gen_observables.py, as it writes the recorder's writers and
docs/run_h5.md from them). Here they answer what a group holds
(`describe`) and whether a file holds it (`check`).

    from dynhet import schema
    problems = schema.check("runs/tiny/run.h5")   # [] if the file fits
"""
import h5py

try:
    from ._observables import OBSERVABLES
except ImportError as e:  # a source tree that was never built
    raise ImportError("dynhet._observables is written by the build from lcmtypes/*.lcm: "
                      "run launch_scripts/setup.sh first") from e

BY_NAME = {o["name"]: o for o in OBSERVABLES}
CAGE_RELATIVE = "_cr"


def declaration(kind):
    """The declaration of a group kind ("chi4", or "chi4_cr" of a
    cage-relative one), or None."""
    if kind in BY_NAME:
        return BY_NAME[kind]
    base = kind[:-len(CAGE_RELATIVE)] if kind.endswith(CAGE_RELATIVE) else None
    d = BY_NAME.get(base)
    return d if d is not None and d["cage_relative"] else None


def cage_relative(kind):
    """The group kind of an observable's cage-relative variant ("chi4" ->
    "chi4_cr"), from its declaration; KeyError if it has none."""
    d = BY_NAME.get(kind)
    if d is None or not d["cage_relative"]:
        raise KeyError(f"{kind!r} has no cage-relative variant; those that have: "
                       + ", ".join(o["name"] for o in OBSERVABLES if o["cage_relative"]))
    return kind + CAGE_RELATIVE


def kinds():
    """Every group kind a run may have: each observable and its _cr variant."""
    out = []
    for d in OBSERVABLES:
        out.append(d["name"])
        if d["cage_relative"]:
            out.append(cage_relative(d["name"]))
    return out


def cutoff_label(a):
    """"a0.6": how a cutoff names its group (C++ cutoff_label, %g)."""
    return f"a{a:g}"


def group_path(kind, a=None):
    """observables/<kind>[/a<cutoff>]."""
    d = declaration(kind)
    if d is None:
        raise KeyError(f"no observable {kind!r}; declared: {', '.join(kinds())}")
    return f"observables/{kind}" + (f"/{cutoff_label(a)}" if d["per_cutoff"] else "")


def _shape(d, f):
    axes = [d["axes"].get(x, x) for x in f["dims"]]
    if f["role"] == "series":
        return "(" + ", ".join(["records"] + axes) + ")"
    if f["role"] == "fixed":
        return "(" + ", ".join(axes) + ",)"
    return "()"


def describe(kind):
    """What a group holds, one line per dataset and attribute: its kind
    (series: the last record is the final result; fixed; attribute), shape,
    dtype, unit and meaning."""
    d = declaration(kind)
    head = f"observables/{kind}" + ("/a<cutoff>" if d["per_cutoff"] else "")
    lines = [f"{head}: computed by {d['node']}_node (message {d['lcm_type']})."]
    if kind.endswith(CAGE_RELATIVE):
        lines.append("Of the cage-relative displacements.")
    for f in d["fields"]:
        role = {"series": "series", "fixed": "fixed", "attr": "attribute"}[f["role"]]
        lines.append(f"  {f['name']}: {role} {_shape(d, f)} {f['dtype']} [{f['unit']}] {f['meaning']}")
    for name, text in d["attrs"].items():
        lines.append(f"  {name}: attribute, {text}")
    return "\n".join(lines)


def _text(v):
    return v.decode() if isinstance(v, bytes) else v


class _Dims:
    """The sizes of a group's axes, bound by the first dataset that shows
    each and checked against every other."""

    def __init__(self):
        self.size, self.seen_in = {}, {}

    def take(self, dims, shape, where, problems):
        if len(shape) != len(dims):
            problems.append(f"{where}: shape {shape}, expected {len(dims)} dimension(s) ({', '.join(dims)})")
            return
        for d, n in zip(dims, shape):
            if d.isdigit():
                if n != int(d):
                    problems.append(f"{where}: shape {shape}, expected {d} along that axis")
            elif d not in self.size:
                self.size[d], self.seen_in[d] = n, where
            elif self.size[d] != n:
                problems.append(f"{where}: shape {shape}, but {d} is {self.size[d]} in {self.seen_in[d]}")


def _check_series(g, f, path, dims, problems):
    s = g[f["name"]]
    final_record = isinstance(s, h5py.Group) and "value" in s and "step" in s.attrs and "time" in s.attrs
    if not isinstance(s, h5py.Group) or not (final_record or all(k in s for k in ("step", "time", "value"))):
        problems.append(f"{path}: not a time series (step, time, value)")
        return
    n = s["value"].shape[0] if s["value"].shape else None
    if final_record:  # a results archive's entry (dynhet.archive): one record, its step and time attributes
        if n != 1:
            problems.append(f"{path}: an archived final record holds {n} records")
    elif s["step"].shape != (n,) or s["time"].shape != (n,):
        problems.append(f"{path}: step {s['step'].shape}, time {s['time'].shape} and value {s['value'].shape} "
                        "disagree on the records")
    if s["value"].dtype != f["dtype"]:
        problems.append(f"{path}/value: dtype {s['value'].dtype}, expected {f['dtype']}")
    dims.take(f["dims"], s["value"].shape[1:], f"{path}/value", problems)


def _check_group(f5, kind, d, a):
    path = group_path(kind, a)
    if path not in f5:
        return [f"{path}: missing"]
    g, problems, dims = f5[path], [], _Dims()
    for f in d["fields"]:
        where = f"{path}/{f['name']}"
        if f["role"] == "attr":
            if f["name"] not in g.attrs:
                problems.append(f"{path}: attribute {f['name']} missing")
        elif f["name"] not in g:
            problems.append(f"{where}: missing")
        elif f["role"] == "fixed":
            ds = g[f["name"]]
            if not isinstance(ds, h5py.Dataset):
                problems.append(f"{where}: not a dataset")
                continue
            if ds.dtype != f["dtype"]:
                problems.append(f"{where}: dtype {ds.dtype}, expected {f['dtype']}")
            dims.take(f["dims"], ds.shape, where, problems)
        else:
            _check_series(g, f, where, dims, problems)
    for name in d["attrs"]:
        if name not in g.attrs:
            problems.append(f"{path}: attribute {name} missing")
    if kind.endswith(CAGE_RELATIVE) and "displacements" not in g.attrs:
        problems.append(f"{path}: attribute displacements missing")
    return problems


def check(path):
    """Every way the file at `path` departs from the schema, one line each
    ([] if none): each observable the run computed (parameters/run_info
    observables) has its group, per cutoff where it is per cutoff, with
    every declared dataset and attribute, each dataset with its dtype and a
    shape whose axes agree across the group."""
    with h5py.File(path, "r") as f5:
        if "parameters/run_info" not in f5 or "observables/schedule/cutoff_a" not in f5:
            return [f"{path}: no parameters/run_info or observables/schedule/cutoff_a: not a run file"]
        computed = [k for k in _text(f5["parameters/run_info"].attrs.get("observables", "")).split(",") if k]
        cutoffs = [float(a) for a in f5["observables/schedule/cutoff_a"][()]]
        problems = []
        for kind in computed:
            d = declaration(kind)
            if d is None:
                problems.append(f"{kind}: computed by the run, but no observable of that name is declared")
                continue
            for a in cutoffs if d["per_cutoff"] else [None]:
                problems += _check_group(f5, kind, d, a)
        return problems


def main(argv=None):
    """python3 -m dynhet.schema RUN.h5...: the problems of each file; exit 1 if any."""
    import sys
    bad = 0
    for p in (argv if argv is not None else sys.argv[1:]):
        problems = check(p)
        bad += bool(problems)
        print(f"{p}: " + ("fits the schema" if not problems else f"{len(problems)} problem(s)"))
        for line in problems:
            print("  " + line)
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())
