"""Row by row against an earlier table: for every row an earlier
reproduction.md judged "differs", what the table says now (same verdict,
another verdict, not judged, or no such row), so a change of method shows
its effect on each result (analyse_study.sh --restate OLD.md)."""
import difflib
import re


def read_rows(path):
    """{result: (ours, verdict)} of a reproduction table (its first table)."""
    rows = {}
    for line in open(path, encoding="utf-8"):
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
    return "not judged" if v.startswith("not judged") else v


def restate(old_path, rows):
    """Markdown lines: each row the old table had as "differs", against the
    row of the same result now (matched by name, ignoring a trailing
    parenthesis; else the closest name)."""
    old = read_rows(old_path)
    now = {r["item"]: r for r in rows}
    by_key = {_key(k): k for k in now}
    out = ["", f"## Row by row against `{old_path}`", "",
           "Every row the earlier table judged \"differs\", and what this table says of the same result.", "",
           "| result (earlier) | earlier: ours, verdict | now: ours, verdict | change |", "|---|---|---|---|"]
    n = {"same": 0, "new": 0, "gone": 0}
    for item, (ours, verdict) in old.items():
        if kind(verdict) != "differs":
            continue
        match = now.get(item) or now.get(by_key.get(_key(item), ""))
        if match is None:  # a name that grew (a range or an estimator added): the shortest that starts with it
            longer = sorted((k for k in now if k.startswith(item) or k.startswith(_key(item))), key=len)
            match = now[longer[0]] if longer else None
        if match is None:
            close = difflib.get_close_matches(_key(item), list(by_key), n=1, cutoff=0.75)
            match = now[by_key[close[0]]] if close else None
        if match is None:
            out.append(f"| {item} | {ours}; {verdict} | — | no such row now |")
            n["gone"] += 1
            continue
        change = "same verdict" if kind(match["verdict"]) == "differs" else f"now {kind(match['verdict'])}"
        n["same" if change == "same verdict" else "new"] += 1
        out.append(f"| {item} | {ours}; {verdict} | {match['ours']}; {match['verdict']} | {change} |")
    out += ["", f"{n['same'] + n['new'] + n['gone']} rows differed; {n['same']} still differ, {n['new']} have another "
            f"verdict now, {n['gone']} have no row now."]
    return out
