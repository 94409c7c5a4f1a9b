"""An observable group of run.h5 as an xarray.Dataset with named dimensions
(Debian's python3-xarray), from the observables' declarations (dynhet.schema):

    ds = run.chi4(0.6).to_xarray()         # the final result
    ds.chi4.sel(grid=2).plot()             # dims: grid, lag; coordinate lag_time on lag
    ds.chi4.attrs["units"], ds.chi4.attrs["long_name"]
    hist = run.overlap().to_xarray(history=True)   # every record: dim record, coordinate time

Each declared dataset is a variable with the group's axis names as its
dimensions (grid, lag, t0, set, target, bin, ...), its unit in
attrs["units"] and its one-line meaning in attrs["long_name"]; a fixed
one-dimensional dataset that is the first to span an axis (lag_time for
lag, subbox_particles for grid, t0 for t0) is that axis' coordinate; the
group's attributes are the Dataset's."""
import numpy as np

from . import schema


def _dims(decl, f):
    return [decl["axes"].get(d, d) for d in f["dims"]]


def _coords(group, decl):
    """{axis: (name, values)}: the first fixed 1-D dataset over each axis."""
    out = {}
    for f in decl["fields"]:
        if f["role"] == "fixed" and len(f["dims"]) == 1 and f["name"] in group:
            axis = _dims(decl, f)[0]
            out.setdefault(axis, (f["name"], np.asarray(group[f["name"]][()])))
    return out


def _series_values(ds, history):
    """The series' final record (history: every record, with their times)."""
    v = ds["value"]
    if history:
        t = ds["time"][()] if "time" in ds else np.atleast_1d(ds.attrs.get("time", np.nan))
        return v[()], t
    return (v[-1] if v.shape[0] else np.full(v.shape[1:], np.nan)), None


def to_xarray(obs, history=False):
    """obs: a dynhet.run.Observable. history: every record of each series
    along a dimension "record" (coordinate "time"), else the final record."""
    import xarray as xr
    group = obs._g
    kind = obs.name.split("/")[0]
    decl = schema.declaration(kind)
    if decl is None:
        raise KeyError(f"{obs.name}: no declaration for {kind!r} (declared: {', '.join(schema.kinds())})")
    coords = {axis: (axis, values, {"name": name}) for axis, (name, values) in _coords(group, decl).items()}
    data, times = {}, None
    for f in decl["fields"]:
        if f["role"] == "attr" or f["name"] not in group or f["name"] in coords:
            continue  # (a dataset named like its axis is that axis' coordinate)
        dims = _dims(decl, f)
        attrs = {"units": f["unit"], "long_name": f["meaning"]}
        if f["role"] == "series":
            values, t = _series_values(group[f["name"]], history)
            if history:
                dims = ["record"] + dims
                times = t if times is None or len(t) > len(times) else times
        else:
            values = group[f["name"]][()]
        if np.ndim(values) != len(dims):
            continue  # an empty series (no record yet) has no shape to name
        data[f["name"]] = (dims, np.asarray(values), attrs)
    ds = xr.Dataset(data, coords={a: (a, v, at) for a, (_, v, at) in coords.items()},
                    attrs={k: v for k, v in obs.attrs.items()})
    if history and times is not None and "record" in ds.dims and len(times) == ds.sizes["record"]:
        ds = ds.assign_coords(time=("record", np.asarray(times)))
    return ds
