"""The authenticated bus from Python (docs/bus.md; the C++ side is
common/bus_auth.cpp): a run's key file, the tag each message carries after
its LCM bytes, and the check of a whole lcm-logger log.

    LCM bytes | b"DHT2" | epoch (8 bytes, little-endian) | sender (8) | sequence (8) | tag (32)

tag = BLAKE2b-256 keyed with the run's 32-byte key (libsodium's
crypto_generichash is BLAKE2b; hashlib's blake2b with key= is the same
function) over b"dynhet bus tag v1\\0", the channel's length (8 bytes,
little-endian), the channel, the 28 bytes from the magic to the sequence,
and the LCM bytes. The epoch is the launch of the run's processes that sent
it (a log of a resumed run holds several); a log is checked for every
epoch at once.
"""
import hashlib
import hmac
import os
import stat
import struct

from . import lcmlog

KEY_BYTES = 32
TAG_BYTES = 4 + 8 + 8 + 8 + 32
HEAD = 4 + 8 + 8 + 8
MAGIC = b"DHT2"
DOMAIN = b"dynhet bus tag v1\0"


class KeyError_(Exception):
    """A key file that cannot be used, with the reason."""


def load_key(path):
    """The 32 bytes of a run's key file; refused (KeyError_ naming the file)
    when missing, not a regular file, readable or writable by others, empty
    or of another size: the checks of BusKey::load."""
    what = f"key file {path}: "
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW)
    except OSError as e:
        raise KeyError_(what + f"cannot be opened ({e.strerror})") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise KeyError_(what + "not a regular file")
        if st.st_mode & 0o077:
            raise KeyError_(what + f"readable or writable by others (mode {st.st_mode & 0o777:o}): "
                            "the key must be its owner's alone (chmod 600)")
        if st.st_size == 0:
            raise KeyError_(what + "empty")
        if st.st_size != KEY_BYTES:
            raise KeyError_(what + f"{st.st_size} bytes, not {KEY_BYTES}")
        return os.read(fd, KEY_BYTES)
    finally:
        os.close(fd)


def tag_of(key, channel, head, payload):
    """The tag of (channel, head = magic | epoch | sender | sequence, payload)."""
    ch = channel.encode("latin-1") if isinstance(channel, str) else channel
    h = hashlib.blake2b(digest_size=32, key=key)
    h.update(DOMAIN)
    h.update(struct.pack("<Q", len(ch)))
    h.update(ch)
    h.update(head)
    h.update(payload)
    return h.digest()


def sign(key, channel, payload, sender, sequence, epoch=0):
    """payload with its tag: what BusSigner::tag appends (tests)."""
    head = MAGIC + struct.pack("<QQQ", epoch, sender, sequence)
    return bytes(payload) + head + tag_of(key, channel, head, payload)


def verdict(key, channel, data, seen):
    """'ok', 'untagged', 'bad_tag' or 'replayed' for one message; seen: the
    set of (epoch, sender, channel, sequence) taken so far (updated when
    'ok'): a sender numbers its messages on each channel from 1."""
    n = len(data)
    if n < TAG_BYTES or data[n - TAG_BYTES:n - TAG_BYTES + 4] != MAGIC:
        return "untagged"
    at = n - TAG_BYTES
    head = bytes(data[at:at + HEAD])
    if not hmac.compare_digest(tag_of(key, channel, head, data[:at]), bytes(data[at + HEAD:])):
        return "bad_tag"
    epoch, sender, seq = struct.unpack("<QQQ", head[4:])
    if (epoch, sender, channel, seq) in seen:
        return "replayed"
    seen.add((epoch, sender, channel, seq))
    return "ok"


def check_log(path, key, keep=None):
    """Counts of each verdict over every message of the log on dynhet's
    channels (DYNHET_*; others, LCM's own LCM_SELF_TEST say, are counted as
    'other' and left out). keep: a path to write a log of the messages that
    verify (in their order)."""
    counts = {"ok": 0, "untagged": 0, "bad_tag": 0, "replayed": 0, "other": 0}
    seen = set()
    out = open(keep, "wb") if keep else None
    try:
        for channel, data, _size, raw in lcmlog.events(path, raw=out is not None):
            if not channel.startswith("DYNHET_"):
                counts["other"] += 1
                continue
            v = verdict(key, channel, data, seen)
            counts[v] += 1
            if out is not None and v == "ok":
                out.write(raw)
    finally:
        if out is not None:
            out.close()
    return counts
