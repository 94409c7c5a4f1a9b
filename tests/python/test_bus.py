"""The Python side of the authenticated bus (python/dynhet/bus.py): the tag
it computes is the one the C++ side checks (tests/test_bus_auth.cpp,
TheTagPythonComputesVerifiesHere, holds the same bytes); key files are
refused as BusKey::load refuses them; a log's replayed, changed and
untagged messages are counted apart and left out of the kept log."""
import os
import struct

import pytest

from dynhet import bus, lcmlog

KEY = bytes(range(32))
PINNED = bytes.fromhex("64796e68657444485432030000000000000008070605040302010900000000000000bd9d019218b1"
                       "5947e628224db93e06ab7c44fb6df5b978ca416db44b21eb6ce0")


def test_tag_is_the_one_the_cpp_side_checks():
    assert bus.sign(KEY, "DYNHET_RUN", b"dynhet", 0x0102030405060708, 9, epoch=3) == PINNED
    assert bus.verdict(KEY, "DYNHET_RUN", PINNED, set()) == "ok"
    assert bus.verdict(KEY, "DYNHET_FRAME", PINNED, set()) == "bad_tag"
    assert bus.verdict(bytes(32), "DYNHET_RUN", PINNED, set()) == "bad_tag"
    assert bus.verdict(KEY, "DYNHET_RUN", b"dynhet", set()) == "untagged"


def write_key(path, data, mode=0o600):
    with open(path, "wb") as f:
        f.write(data)
    os.chmod(path, mode)
    return str(path)


def test_key_files_are_refused_by_name(tmp_path):
    assert bus.load_key(write_key(tmp_path / "ok.key", KEY)) == KEY
    with pytest.raises(bus.KeyError_, match="cannot be opened"):
        bus.load_key(str(tmp_path / "none.key"))
    with pytest.raises(bus.KeyError_, match="empty"):
        bus.load_key(write_key(tmp_path / "empty.key", b""))
    with pytest.raises(bus.KeyError_, match="10 bytes, not 32"):
        bus.load_key(write_key(tmp_path / "short.key", b"0123456789"))
    with pytest.raises(bus.KeyError_, match="mode 644"):
        bus.load_key(write_key(tmp_path / "open.key", KEY, 0o644))
    with pytest.raises(bus.KeyError_, match="not a regular file"):
        bus.load_key(str(tmp_path))


def event(channel, data, number):
    ch = channel.encode()
    return struct.pack(">IqqII", lcmlog.SYNC, number, 1000 + number, len(ch), len(data)) + ch + data


def test_a_log_is_counted_and_what_verifies_is_kept(tmp_path):
    good = [bus.sign(KEY, "DYNHET_SIM_STATUS", b"status %d" % i, 7, i + 1) for i in range(5)]
    changed = bytearray(good[2])
    changed[3] ^= 1
    events = [event("DYNHET_SIM_STATUS", g, i) for i, g in enumerate(good)]
    events += [event("DYNHET_SIM_STATUS", good[1], 10),          # a replayed copy
               event("DYNHET_SIM_STATUS", bytes(changed), 11),   # changed under its tag
               event("DYNHET_SIM_STATUS", b"no tag at all", 12),  # untagged
               event("LCM_SELF_TEST", b"lcm self test", 13)]     # not dynhet's
    log = tmp_path / "run.lcmlog"
    log.write_bytes(b"".join(events))
    kept = tmp_path / "kept.lcmlog"
    c = bus.check_log(str(log), KEY, str(kept))
    assert c == {"ok": 5, "untagged": 1, "bad_tag": 1, "replayed": 1, "other": 1}
    assert kept.read_bytes() == b"".join(events[:5])


def test_the_log_reader_skips_damage_and_stops_at_a_truncated_event(tmp_path):
    evs = [event("DYNHET_RUN", b"x" * 200, 0), event("DYNHET_FRAME", b"frame one", 1),
           event("DYNHET_FRAME", b"frame two", 2)]
    log = tmp_path / "damaged.lcmlog"
    # garbage between the first two events, the last one cut short
    log.write_bytes(evs[0] + b"\x00garbage\xed" + evs[1] + evs[2][:-3])
    got = list(lcmlog.events(str(log), head=16, raw=True))
    assert [(c, d, n) for c, d, n, _ in got] == [("DYNHET_RUN", b"x" * 16, 200), ("DYNHET_FRAME", b"frame one", 9)]
    assert [r for *_, r in got] == evs[:2]
    (tmp_path / "empty.lcmlog").write_bytes(b"")
    assert list(lcmlog.events(str(tmp_path / "empty.lcmlog"))) == []


def test_the_log_reader_resynchronises_past_a_damaged_length(tmp_path):
    evs = [event("DYNHET_RUN", b"run", 0), event("DYNHET_FRAME", b"frame one", 1), event("DYNHET_FRAME", b"frame two", 2)]
    bad = bytearray(evs[1])
    bad[24:28] = struct.pack(">I", 1 << 30)  # its data length now runs past the end of the log
    log = tmp_path / "damaged.lcmlog"
    log.write_bytes(evs[0] + bytes(bad) + evs[2])
    assert [(c, d) for c, d, _, _ in lcmlog.events(str(log))] == [("DYNHET_RUN", b"run"), ("DYNHET_FRAME", b"frame two")]
