"""The product speaks of the product: no file outside tests/ says which
numbered issue, session or stage of the work something came from (git
history keeps that; results/ too, whose study files are the studies' own),
and no launcher or test finds the package by
inserting into sys.path (the launchers and tests/ import it through the
dynhet link beside them, pytest through pytest.ini)."""
import os
import re
import subprocess

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))

# "issue 26", "issue #26", "issues 12 and 14", "session 3", "stage 2 of the work", "(item 8 of ...)"
PROCESS = re.compile(r"\bissues? #?\d+|\bsessions? \d+|\bstage \d+ of the work|\bitem \d+ of (the )?issue", re.I)


def tracked_files():
    r = subprocess.run(["git", "-C", ROOT, "ls-files", "-z"], capture_output=True)
    if r.returncode == 0:
        names = [n for n in r.stdout.decode().split("\0") if n]
    else:  # not a git checkout: every file but the build's and the runs'
        names = []
        for d, dirs, files in os.walk(ROOT):
            dirs[:] = [x for x in dirs if x not in (".git", "build", "runs") and not x.startswith("build-")]
            names += [os.path.relpath(os.path.join(d, f), ROOT) for f in files]
    return [n for n in names if os.path.isfile(os.path.join(ROOT, n)) and not os.path.islink(os.path.join(ROOT, n))]


def text_of(name):
    with open(os.path.join(ROOT, name), "rb") as f:
        data = f.read()
    if b"\0" in data[:4096]:
        return None  # binary (HDF5, PNG)
    return data.decode("utf-8", errors="replace")


def test_no_file_outside_tests_names_an_issue_or_session():
    found = []
    for name in tracked_files():
        # tests/ may name what they guard. results/ is checked too: its study
        # files are the studies' own (an archive compares a study by its
        # content, not its comments), and its run entries are binary.
        if name.startswith("tests/"):
            continue
        text = text_of(name)
        if text is None:
            continue
        for no, line in enumerate(text.split("\n"), 1):
            if PROCESS.search(line):
                found.append(f"{name}:{no}: {line.strip()[:120]}")
    assert not found, "references to the work's process (say what a thing is, not where it came from):\n" + \
        "\n".join(found)


def test_the_pattern_catches_what_it_is_for():
    for s in ["see issue 26, item 8", "(issue #3)", "added in session 4", "stage 2 of the work"]:
        assert PROCESS.search(s), s
    for s in ["a known issue of lcm", "the session's bus key", "stage two", "issued 3 frames"]:
        assert not PROCESS.search(s), s


def test_no_launcher_or_test_inserts_into_sys_path():
    found = []
    for name in tracked_files():
        if not name.endswith(".py") or not name.startswith(("launch_scripts/", "tests/", "lcmtypes/", "bench/")):
            continue
        if name == "tests/python/test_product_voice.py":
            continue
        text = text_of(name) or ""
        for no, line in enumerate(text.split("\n"), 1):
            if re.search(r"sys\.path\.(insert|append)", line):
                found.append(f"{name}:{no}: {line.strip()}")
    assert not found, "sys.path changed by hand:\n" + "\n".join(found)
