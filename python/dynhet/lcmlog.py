"""The events of an lcm-logger log, read from its bytes (LCM's log format:
a sync word, event number, time, channel length, data length, channel, data;
no LCM bindings needed). One reader for the tools that look into logs
(lcmlog_runs.py: runs and frames; bus.py: every message's tag)."""
import mmap
import os
import struct

SYNC = 0xEDA1DA01
_SYNC_BYTES = struct.pack(">I", SYNC)
_HEADER = struct.Struct(">IqqII")  # sync, event number, utime, channel length, data length
_MAX_CHANNEL = 63  # LCM's longest channel name


def events(path, head=None, raw=False):
    """(channel, data, data length, raw) per event, in order. data is the
    message's first `head` bytes (None: all of it); raw the event's own bytes
    (header included) where raw=True, else None. The log is mapped, not read:
    a log of a large run holds gigabytes of frames. A damaged stretch is
    skipped to the next sync word (a sync word whose lengths run past the
end, or name a channel longer than LCM allows, counts as damage); a
truncated last event ends the log."""
    with open(path, "rb") as f:
        if os.fstat(f.fileno()).st_size == 0:
            return
        with mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as m:
            pos, n = 0, len(m)
            while pos + _HEADER.size <= n:
                sync, _event, _utime, clen, dlen = _HEADER.unpack_from(m, pos)
                if sync != SYNC:  # resynchronise on damage
                    pos = m.find(_SYNC_BYTES, pos + 1)
                    if pos < 0:
                        return
                    continue
                body = pos + _HEADER.size
                end = body + clen + dlen
                if end > n or clen > _MAX_CHANNEL:  # a damaged length (or a cut-short last event)
                    pos = m.find(_SYNC_BYTES, pos + 1)
                    if pos < 0:
                        return
                    continue
                data_end = end if head is None else body + clen + min(dlen, head)
                yield (m[body:body + clen].decode("latin-1"), m[body + clen:data_end], dlen,
                       m[pos:end] if raw else None)
                pos = end
