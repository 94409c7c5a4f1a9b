#!/usr/bin/python3
"""What an observable is, read from the annotations of its .lcm file: the
one declaration that the registry, the recorder's writers, the Python
reader and docs/run_h5.md are generated from (gen_observables.py).

A result type declares itself in the comment block just above its struct:

    // @observable chi4          the name: scene key, run.h5 group, channel DYNHET_CHI4
    // @node overlap             the analysis node that computes it (overlap_node)
    // @per_cutoff               one group and one channel per cutoff a (a0.6/)
    // @cage_relative            a cage-relative variant too (group chi4_cr, channel DYNHET_CHI4_CR)
    // @record_when n_values     a message makes a record only when this count is > 0
    // @attr layout = TEXT       a constant attribute of the group ...
    // @+ MORE TEXT              ... continued (joined with one space)

and each field it stores says where it goes, in its trailing comment:

    double lag_time[n_lags];   // @fixed {time} the lags t
    double chi4[n_values];     // @series[n_grids][n_lags] {1} chi4(t), the pooled estimator
    double cutoff_a;           // @attr {length} the cutoff a

  @fixed   a dataset written once, the first time the message carries it
           (its length > 0): an axis such as lag_time, q, r
  @series  an H5MD time series {step, time, value}: one record per message
           at the frame the result is based on; an array field is recorded
           when its length is > 0, reshaped to [a][b]... if given (the
           length field must equal the product: the recorder refuses a
           message where it does not)
  @attr    an attribute of the group, set from the first message
  {unit}   length (the small radius r1), time, particles, count, index,
           1/length, length^2, length^2/time, 1 (a pure number)

A field with no annotation is not stored: the message's header (utime,
run_id, sim_time, frame_index, is_final, cage_relative) and the counts
that size its arrays. Any other field must say where it goes.
"""
import re

HEADER = {"utime", "run_id", "sim_time", "frame_index", "is_final", "cage_relative"}
INTEGERS = {"int8_t", "int16_t", "int32_t", "int64_t"}
# How each C type is stored in run.h5 (the recorder widens int8_t flags).
STORED = {"double": "float64", "int32_t": "int32", "int64_t": "int64", "int8_t": "int32"}
UNITS = {"length", "time", "particles", "count", "index", "1/length", "length^2", "length^2/time", "1"}
ROLES = ("fixed", "series", "attr")

_FIELD = re.compile(r"^\s*(\w+)\s+(\w+)\s*(?:\[\s*(\w+)\s*\])?\s*;\s*(?://(.*))?$")
_ANNOT = re.compile(r"@(fixed|series|attr)((?:\[\w+\])*)\s*\{([^}]*)\}\s*(.*)$")


class DeclarationError(Exception):
    pass


class Field:
    """One field of a result type and where run.h5 keeps it."""

    def __init__(self, ctype, name, length, role, dims, unit, meaning):
        self.ctype, self.name, self.length = ctype, name, length  # length: None, a count field or a number
        self.role, self.unit, self.meaning = role, unit, meaning
        # The stored shape after the record axis: the given dims, else the array's length.
        self.dims = dims or ([length] if length else [])

    @property
    def dtype(self):
        return STORED[self.ctype] if self.ctype in STORED else self.ctype

    def as_dict(self):
        return {"name": self.name, "role": self.role, "dtype": self.dtype, "dims": list(self.dims),
                "length": self.length, "unit": self.unit, "meaning": self.meaning}


class Observable:
    """One result type's declaration."""

    def __init__(self, lcm_type, path):
        self.lcm_type, self.path = lcm_type, path
        self.name = self.node = self.record_when = None
        self.per_cutoff = self.cage_relative = False
        self.attrs = []  # [(name, text)] constant attributes
        self.fields = []  # every field of the struct, stored or not
        self.stored = []  # the annotated ones, in declaration order

    @property
    def channel(self):
        return "DYNHET_" + self.name.upper()

    def axis(self, dim):
        """The name of an axis: n_lags -> lag, n_grids -> grid, 3 -> 3."""
        if dim.isdigit():
            return dim
        a = dim[2:] if dim.startswith("n_") else dim
        return a[:-1] if a.endswith("s") and len(a) > 2 else a

    def as_dict(self):
        return {"name": self.name, "lcm_type": self.lcm_type, "node": self.node, "channel": self.channel,
                "per_cutoff": self.per_cutoff, "cage_relative": self.cage_relative,
                "record_when": self.record_when, "attrs": dict(self.attrs),
                "fields": [f.as_dict() for f in self.stored],
                "axes": {d: self.axis(d) for f in self.stored for d in f.dims}}


def _fail(path, what):
    raise DeclarationError(f"{path}: {what}")


def _struct_block(lines, path):
    """The comment block above the struct and the struct's body lines."""
    for i, line in enumerate(lines):
        m = re.match(r"\s*struct\s+(\w+)", line)
        if m:
            j = i
            while j > 0 and lines[j - 1].lstrip().startswith("//"):
                j -= 1
            k = i + 1
            while k < len(lines) and lines[k].strip() != "}":
                k += 1
            return m.group(1), lines[j:i], [l for l in lines[i + 1:k] if l.strip() not in ("{", "")]
    _fail(path, "no struct")


def _read_header(obs, comments, path):
    last_attr = None
    for c in comments:
        m = re.match(r"\s*//\s*@(\+|\w+)\s*(.*?)\s*$", c)
        if not m:
            continue
        key, value = m.groups()
        if key == "+":
            if last_attr is None:
                _fail(path, "'@+' continues no '@attr'")
            name, text = obs.attrs[last_attr]
            obs.attrs[last_attr] = (name, text + " " + value)
            continue
        last_attr = None
        if key == "observable":
            obs.name = value
        elif key == "node":
            obs.node = value
        elif key == "per_cutoff":
            obs.per_cutoff = True
        elif key == "cage_relative":
            obs.cage_relative = True
        elif key == "record_when":
            obs.record_when = value
        elif key == "attr":
            a = re.fullmatch(r"(\w+)\s*=\s*(.*)", value)
            if not a:
                _fail(path, f"'@attr {value}': write '@attr NAME = TEXT'")
            obs.attrs.append((a.group(1), a.group(2)))
            last_attr = len(obs.attrs) - 1
        else:
            _fail(path, f"unknown annotation '@{key}'")


def _read_fields(obs, body, path):
    for line in body:
        if line.strip().startswith("//"):
            continue
        m = _FIELD.match(line)
        if not m:
            _fail(path, f"cannot read the field '{line.strip()}'")
        ctype, name, length, comment = m.groups()
        a = _ANNOT.search(comment or "")
        if not a:
            obs.fields.append(Field(ctype, name, length, None, [], None, None))
            continue
        role, dims, unit, meaning = a.groups()
        dims = re.findall(r"\[(\w+)\]", dims)
        f = Field(ctype, name, length, role, dims, unit.strip(), meaning.strip())
        obs.fields.append(f)
        obs.stored.append(f)


def _validate(obs, path):
    if not obs.name or not obs.node:
        _fail(path, "a result type needs '@observable NAME' and '@node NODE'")
    by_name = {f.name: f for f in obs.fields}
    lengths = {f.length for f in obs.fields if f.length} | {d for f in obs.stored for d in f.dims}
    for f in obs.fields:
        where = f"{obs.lcm_type}.{f.name}"
        if f.role is None:
            if f.name not in HEADER and not (f.ctype in INTEGERS and f.name in lengths):
                _fail(path, f"{where}: neither header nor an array's length: say where it goes "
                            f"(@fixed, @series or @attr)")
            continue
        if f.unit not in UNITS:
            _fail(path, f"{where}: unit {{{f.unit}}} is not one of {sorted(UNITS)}")
        if not f.meaning:
            _fail(path, f"{where}: a one-line meaning after the unit")
        if f.ctype not in STORED:
            _fail(path, f"{where}: type {f.ctype} cannot be stored")
        if f.role == "attr" and (f.length or f.ctype == "int8_t"):
            _fail(path, f"{where}: an @attr is a double, int32_t or int64_t scalar")
        if f.role == "fixed" and (not f.length or f.length.isdigit() or len(f.dims) != 1):
            _fail(path, f"{where}: a @fixed field is a one-dimensional array sized by a count")
        for d in f.dims:
            if not d.isdigit() and (d not in by_name or by_name[d].ctype not in INTEGERS):
                _fail(path, f"{where}: dimension {d} is not an integer field")
        if f.role == "series" and len(f.dims) > 1 and (not f.length or f.length.isdigit()):
            _fail(path, f"{where}: a reshaped series is a flat array sized by a count")
    if obs.per_cutoff and "cutoff_a" not in by_name:
        _fail(path, "@per_cutoff needs a field cutoff_a")
    if obs.cage_relative and "cage_relative" not in by_name:
        _fail(path, "@cage_relative needs a field cage_relative")
    if obs.record_when and (obs.record_when not in by_name or by_name[obs.record_when].ctype not in INTEGERS):
        _fail(path, f"@record_when {obs.record_when} is not an integer field")


def read(path):
    """The observable declared in one .lcm file, or None if it declares none."""
    lines = open(path).read().split("\n")
    lcm_type, comments, body = _struct_block(lines, path)
    if not any(re.match(r"\s*//\s*@observable\b", c) for c in comments):
        return None
    obs = Observable(lcm_type, path)
    _read_header(obs, comments, path)
    _read_fields(obs, body, path)
    _validate(obs, path)
    return obs


def read_all(paths):
    """Every observable declared in the files, by name."""
    out = [o for o in (read(p) for p in sorted(paths)) if o is not None]
    names = [o.name for o in out]
    if len(set(names)) != len(names):
        raise DeclarationError(f"an observable is declared twice: {names}")
    for a in out:  # subscriptions take a family by prefix (lcm_url.hpp: channel_family)
        for b in out:
            if a is not b and b.channel.startswith(a.channel):
                raise DeclarationError(f"channel {a.channel} is a prefix of {b.channel}: rename one")
    return sorted(out, key=lambda o: o.name)
