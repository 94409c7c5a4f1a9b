"""Row by row against an earlier table: for every row an earlier
reproduction.md judged "differs", what the table says now (same verdict,
another verdict, not judged, or no such row), so a change of method shows
its effect on each result (analyse_study.sh --restate OLD.md)."""
import difflib
import os
import re
import subprocess


def table_lines(path):
    """The lines of a table file, or of a file in git history: COMMIT:PATH
    (e.g. 556a0f6:docs/reproduction.md, read with git show from the checkout
    this package is in)."""
    path = str(path)
    if ":" in path and not os.path.exists(path):
        root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
        r = subprocess.run(["git", "-C", root, "show", path], capture_output=True, text=True)
        if r.returncode != 0:
            raise FileNotFoundError(f"{path}: not in this checkout's git history ({r.stderr.strip()})")
        return r.stdout.splitlines(keepends=True)
    with open(path, encoding="utf-8") as fh:
        return fh.readlines()


def exists(path):
    try:
        table_lines(path)
        return True
    except (OSError, FileNotFoundError):
        return False


def read_rows(path):
    """{result: (ours, verdict)} of a reproduction table (its first table)."""
    rows = {}
    for line in table_lines(path):
        if not line.startswith("| ") or line.startswith("| result") or line.startswith("|---"):
            if rows and not line.startswith("|"):
                break
            continue
        cells = [c.strip() for c in line.strip().strip("|").split(" | ")]
        if len(cells) >= 5:
            rows[cells[0]] = (cells[3], cells[4])
    return rows


def _key(item):
    """A row's name without what later tables added in parentheses."""
    return re.sub(r"\s*\([^()]*\)\s*$", "", item).strip()


def kind(verdict):
    v = verdict.split(" (")[0].split(";")[0].strip()
    for k in ("not judged", "not comparable", "not determined", "drifting"):   # (their reasons and rates follow)
        if v.startswith(k):
            return k
    return v


def find(item, table, fuzzy=True):
    """The row of `table` ({name: value}) for an earlier row named `item`: the
    same name, the same without a trailing parenthesis, the shortest name
    that grew from it (a range or an estimator added), else (fuzzy) the
    closest name; None where none is close."""
    by_key = {_key(k): k for k in table}
    name = item if item in table else by_key.get(_key(item))
    if name is None:
        longer = sorted((k for k in table if k.startswith(item) or k.startswith(_key(item))), key=len)
        name = longer[0] if longer else None
    if name is None and fuzzy:
        close = difflib.get_close_matches(_key(item), list(by_key), n=1, cutoff=0.75)
        name = by_key[close[0]] if close else None
    return None if name is None else table[name]


def short(ours, verdict):
    """A cell of a step: the value (up to its first parenthesis) and the verdict's kind with its sigma."""
    sig = re.search(r"\(([0-9.]+ σ)\)", verdict)
    return f"{ours.split(' (')[0]}; {kind(verdict)}" + (f" ({sig.group(1)})" if sig else "")


NUM = r"[-+]?[0-9]*\.?[0-9]+(?:e[-+]?[0-9]+)?"


def value_of(ours):
    """(value, error) of a cell's first "x ± e"; None without one."""
    m = re.search(rf"({NUM}) ± ({NUM})", ours or "")
    return (float(m.group(1)), float(m.group(2))) if m else None


def shifts(cells):
    """Between consecutive cells with a value and an error, how far the value
    moved in combined errors: "0.3", or "—" where either has none. A verdict
    that flips on a shift under one error is the threshold's, not the step's."""
    out = []
    for a, b in zip(cells, cells[1:]):
        va, vb = value_of(a), value_of(b)
        e = (va[1] ** 2 + vb[1] ** 2) ** 0.5 if va and vb else 0.0
        out.append(f"{abs(vb[0] - va[0]) / e:.1f}" if e > 0 else "—")
    return " / ".join(out)


def restate(old_path, rows, via=()):
    """Markdown lines: each row the old table had as "differs", against the
    row of the same result now (matched by name: `find`). `via`: [(label,
    table path)], tables made between the old one and now, in order: each
    gets a column, and the last column says at which step the verdict
    changed, so that each change is laid to what the step changed (a
    method, other seeds, a larger N)."""
    old = read_rows(old_path)
    now = {r["item"]: (r["ours"], r["verdict"]) for r in rows}
    steps = [(label, read_rows(path)) for label, path in via]
    head = "| result (earlier) | earlier: ours, verdict | " + "".join(f"{label} | " for label, _ in steps)
    out = ["", f"## Row by row against `{old_path}`", "",
           "Every row the earlier table judged \"differs\", and what this table says of the same result"
           + (" (and, between them, " + ", ".join(f"`{path}` ({label})" for label, path in via) + ")"
              if via else "") + ".", "",
           "The last column: how far the value moved at each step (earlier → " + " → ".join(
               [label for label, _ in via] + ["now"]) + "), in combined errors of the two (— where a step "
           "quotes no error): a verdict that moves on a shift under one error sits on its threshold.", "",
           head + "now: ours, verdict | change | moved (σ per step) |",
           "|---|---|" + "---|" * len(steps) + "---|---|---|"]
    n = {"same": 0, "new": 0, "gone": 0}
    for item, (ours, verdict) in old.items():
        if kind(verdict) != "differs":
            continue
        mids = [find(item, t, fuzzy=False) for _, t in steps]  # a step without the row says "—", never another row
        match = find(item, now)
        cells = [short(*m) if m else "—" for m in mids]
        if match is None:
            out.append(f"| {item} | {ours}; {verdict} | " + "".join(c + " | " for c in cells) + "— | no such row now | — |")
            n["gone"] += 1
            continue
        change = "same verdict" if kind(match[1]) == "differs" else f"now {kind(match[1])}"
        if steps:  # where the verdict moved: each step whose kind differs from the one before
            prev, moves = kind(verdict), []
            for lab, k in zip([label for label, _ in steps] + ["now"],
                              [kind(m[1]) if m else None for m in mids] + [kind(match[1])]):
                if k is not None and k != prev:
                    moves.append(f"{k} at {lab}")
                    prev = k
            if moves:
                change += " (" + ", ".join(moves) + ")"
        # a verdict can change because the value moved or because the error grew (one seed at a larger
        # N): the error's ratio to the earlier one says which
        vo, vn = value_of(ours), value_of(match[0])
        if kind(match[1]) != kind(verdict) and vo and vn and vo[1] > 0:
            change += f"; error {vn[1] / vo[1]:.2g}× the earlier one's"
        n["same" if kind(match[1]) == "differs" else "new"] += 1
        moved = shifts([ours] + [m[0] if m else "" for m in mids] + [match[0]])
        out.append(f"| {item} | {ours}; {verdict} | " + "".join(c + " | " for c in cells)
                   + f"{match[0]}; {match[1]} | {change} | {moved} |")
    out += ["", f"{n['same'] + n['new'] + n['gone']} rows differed; {n['same']} still differ, {n['new']} have another "
            f"verdict now, {n['gone']} have no row now."]
    return out


def _held(item):
    """A row's name with the joint fit's phi_c it holds masked ("ρ with the
    joint fit's φ_c = 0.8013"): the same result in a table whose joint fit
    moved."""
    return re.sub(rf"(joint fit's (?:φ_c = )?){NUM}", r"\1#", item)


NO_VERDICT = ("figure", "—", "")


def compare(ref_label, ref_path, rows, label="now"):
    """Markdown lines: every row of this table against the same result in
    another table of the same study design (`ref_path`, e.g. the table at
    N = 4096 before --largest-n took the larger boxes): the rows whose
    verdict changed, those whose value moved by 2 or more combined errors
    under the same verdict (or changed, where it quotes no error), and how
    many stayed. Rows without a verdict in either table ("figure", "—")
    are not compared."""
    ref = read_rows(ref_path)
    ref_by_fit = {_held(k): v for k, v in ref.items()}
    changed, moved, same, new = [], [], 0, []
    for r in rows:
        item, ours, verdict = r["item"], r["ours"], r["verdict"]
        m = find(item, ref, fuzzy=False) or ref_by_fit.get(_held(item))
        # a row is compared where either table gives it a verdict ("not resolved" is one)
        if kind(verdict) in NO_VERDICT and (m is None or kind(m[1]) in NO_VERDICT):
            continue
        if m is None:
            new.append(f"| {item} | — | {short(ours, verdict)} | new row | — |")
            continue
        step = shifts([m[0], ours])
        line = f"| {item} | {short(*m)} | {short(ours, verdict)} | "
        if kind(m[1]) != kind(verdict):
            changed.append(line + f"{kind(m[1])} → {kind(verdict)} | {step} |")
        elif step != "—" and float(step) >= 2:
            moved.append(line + f"same verdict, moved | {step} |")
        elif step == "—" and m[0].split(" (")[0] != ours.split(" (")[0]:   # no error to weigh it by
            moved.append(line + "same verdict, another value | — |")
        else:
            same += 1
    out = ["", f"## Against {ref_label} (`{ref_path}`)", "",
           f"Every row with a verdict, against the same result in that table ({ref_label}): the rows whose verdict "
           "changed, those whose value moved by 2 or more combined errors (the last column) under the same verdict "
           "(or changed, where it quotes no error), and the rows new here. Why each changed is in the findings below.", "",
           f"| result | {ref_label}: ours; verdict | {label}: ours; verdict | change | moved (σ) |",
           "|---|---|---|---|---|"] + changed + moved + new
    rows_ = lambda n: f"{n} row{'' if n == 1 else 's'}"
    out += ["", f"{rows_(len(changed))} changed verdict, {rows_(len(moved))} moved by 2σ or more (or changed, quoting "
            f"no error) under the same verdict, {rows_(same)} stayed within 2σ under the same verdict, {rows_(len(new))} new."]
    return out
