"""TOML written (scenes, status files, the index) atomically, and read."""
import math
import os
import socket
import threading
import tomllib


def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isinf(v) or math.isnan(v):
            return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")
        return repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(f"cannot write {v!r} as TOML")


def toml_dump(tables, header=""):
    """Tables of scalars and arrays (a scene, a status file)."""
    out = [header] if header else []
    top = {k: v for k, v in tables.items() if not isinstance(v, dict)}
    for k, v in top.items():
        out.append(f"{k} = {toml_value(v)}")
    for name, t in tables.items():
        if not isinstance(t, dict):
            continue
        out.append(f"\n[{name}]")
        for k, v in t.items():
            out.append(f"{k} = {toml_value(v)}")
    return "\n".join(out) + "\n"


def write_atomic(path, text):
    """Write text to path through a temporary file and a rename: a reader sees
    the old file or the new, never part. The temporary name is the host's, the
    process's and the thread's: two workers of one study writing the index at once had
    shared a name, and one's rename took the other's file away."""
    tmp = f"{path}.tmp.{socket.gethostname()}.{os.getpid()}.{threading.get_ident()}"  # (Slurm tasks share a filesystem)
    with open(tmp, "w") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def read_toml(path):
    with open(path, "rb") as f:
        return tomllib.load(f)
